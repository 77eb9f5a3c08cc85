//! Per-incidence and all-incidence fits: data checks, data-driven starting
//! values, a multi-start over roughness on a subsample, the final
//! Levenberg-Marquardt fit on every sample, optional robust reweighting,
//! and standard errors from s²(JᵀJ)⁻¹.

use crate::data::{GateReport, IncidenceData};
use crate::params::{ParamMap, Target};
use crate::prepare;
use crate::problem::{Block, Compressed, Problem, ResidualKind};
use brtf_model::{EvalOptions, MaterialKind};
use glam::DVec3;
use levenberg_marquardt::{LevenbergMarquardt, TerminationReason};
use nalgebra::DVector;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// Robust loss, applied by iteratively reweighting the residuals.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
pub enum RobustLoss {
    /// Plain least squares.
    #[default]
    None,
    /// Huber with threshold `c` in robust standard deviations.
    Huber(f64),
    /// Cauchy with scale `c` in robust standard deviations.
    Cauchy(f64),
}

/// Everything that decides a fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitConfig {
    /// The model.
    #[serde(with = "crate::serde_kind")]
    pub kind: MaterialKind,
    /// Variant, Fresnel constant and source size of the model.
    #[serde(with = "options_serde")]
    pub options: EvalOptions,
    /// Orientation vector of the `*2` types.
    pub orientation: [f64; 3],
    /// Tie R = G = B.
    pub gray: bool,
    /// Fit a free overall scale (raw-signal data of unknown scale).
    pub free_scale: bool,
    /// How model and data are compared.
    pub residual: ResidualKind,
    /// Floor (same unit as the data) for relative and log residuals;
    /// `None` picks 10% of the data's 10th percentile.
    pub floor: Option<f64>,
    /// Robust loss.
    pub loss: RobustLoss,
    /// Try several starting roughnesses and keep the best.
    pub multistart: bool,
}

impl FitConfig {
    /// Defaults for `kind`: radiance variant, RGB, absolute residuals, multi-start.
    pub fn new(kind: MaterialKind) -> FitConfig {
        FitConfig {
            kind,
            options: EvalOptions::default(),
            orientation: [1.0, 0.0, 0.0],
            gray: false,
            free_scale: false,
            residual: ResidualKind::Absolute,
            floor: None,
            loss: RobustLoss::None,
            multistart: true,
        }
    }
}

mod options_serde {
    use brtf_model::{EvalOptions, Variant};
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    #[derive(Serialize, Deserialize)]
    struct Options {
        variant: String,
        fresnel_k: f64,
        source_omega: f64,
        flat: bool,
        source_jitter: f64,
    }

    pub fn serialize<S: Serializer>(o: &EvalOptions, s: S) -> Result<S::Ok, S::Error> {
        Options {
            variant: o.variant.name().into(),
            fresnel_k: o.fresnel_k,
            source_omega: o.source_omega,
            flat: o.flat,
            source_jitter: o.source_jitter,
        }
        .serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<EvalOptions, D::Error> {
        let o = Options::deserialize(d)?;
        let variant: Variant = o.variant.parse().map_err(serde::de::Error::custom)?;
        Ok(EvalOptions {
            variant,
            fresnel_k: o.fresnel_k,
            source_omega: o.source_omega,
            flat: o.flat,
            source_jitter: o.source_jitter,
        })
    }
}

/// Why a fit could not run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FitError {
    /// No samples are left after the selections.
    #[error("{origin}: no samples left to fit after the selections ({gates})")]
    EmptySelection {
        /// The data's origin.
        origin: String,
        /// The selections applied.
        gates: String,
    },
    /// Every value is zero or negative.
    #[error("{origin}: all {count} values are zero or negative; nothing to fit")]
    AllZero {
        /// The data's origin.
        origin: String,
        /// How many samples.
        count: usize,
    },
    /// A value is NaN or infinite.
    #[error("{origin}: sample {index} has a non-finite value or weight")]
    NonFinite {
        /// The data's origin.
        origin: String,
        /// Sample index.
        index: usize,
    },
    /// A transmitting model needs back-hemisphere data.
    #[error("{origin}: a {kind} fit needs transmission data (back hemisphere), found none")]
    NoTransmission {
        /// The data's origin.
        origin: String,
        /// The model.
        kind: MaterialKind,
    },
    /// Incidences differ in channel count.
    #[error("incidences mix single-channel and RGB data")]
    MixedChannels,
    /// The optimiser failed at the start.
    #[error("{origin}: the fit could not start: {reason}")]
    Failed {
        /// The data's origin.
        origin: String,
        /// What went wrong.
        reason: String,
    },
}

/// Why the optimiser stopped (from the levenberg-marquardt crate).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Termination {
    /// Relative reduction of the cost (ftol) or step (xtol) below tolerance.
    Converged {
        /// ftol criterion met.
        ftol: bool,
        /// xtol criterion met.
        xtol: bool,
    },
    /// Residuals orthogonal to every Jacobian column to within gtol (the
    /// cosine; 1e-6 in the final fit, where that puts the cost within about
    /// 1e-12 of the minimum's and each parameter well under 1e-3 standard
    /// errors from it): converged on the gradient.
    Orthogonal,
    /// Residuals exactly zero.
    ResidualsZero,
    /// Evaluation budget exhausted.
    LostPatience,
    /// Tolerances too tight for floating point.
    NoImprovementPossible(String),
    /// NaN or infinity met.
    Numerical(String),
    /// Anything else.
    Other(String),
}

impl Termination {
    fn from_lm(reason: &TerminationReason) -> Termination {
        match reason {
            TerminationReason::Converged { ftol, xtol } => Termination::Converged {
                ftol: *ftol,
                xtol: *xtol,
            },
            TerminationReason::Orthogonal => Termination::Orthogonal,
            TerminationReason::ResidualsZero => Termination::ResidualsZero,
            TerminationReason::LostPatience => Termination::LostPatience,
            TerminationReason::NoImprovementPossible(s) => {
                Termination::NoImprovementPossible((*s).into())
            }
            TerminationReason::Numerical(s) => Termination::Numerical((*s).into()),
            other => Termination::Other(format!("{other:?}")),
        }
    }

    /// The optimiser reached a stationary point (not a judgement of physics).
    pub fn converged(&self) -> bool {
        matches!(
            self,
            Termination::Converged { .. }
                | Termination::Orthogonal
                | Termination::ResidualsZero
                | Termination::NoImprovementPossible(_)
        )
    }

    /// A short label for tables.
    pub fn label(&self) -> &'static str {
        match self {
            Termination::Converged { .. } => "converged",
            Termination::Orthogonal => "converged (gradient)",
            Termination::ResidualsZero => "residuals_zero",
            Termination::LostPatience => "lost_patience",
            Termination::NoImprovementPossible(_) => "no_improvement_possible",
            Termination::Numerical(_) => "numerical",
            Termination::Other(_) => "other",
        }
    }
}

/// One fitted parameter.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParamEstimate {
    /// Name (`red`, `spec`, `rough`, `scale`, ...).
    pub name: String,
    /// Fitted value.
    pub value: f64,
    /// Standard error from s²(JᵀJ)⁻¹ (0 for a parameter held fixed).
    pub stderr: f64,
    /// Heteroscedasticity-consistent standard error from the sandwich
    /// `m/(m−n) (JᵀJ)⁻¹ (Σ rᵢ² Jᵢ Jᵢᵀ) (JᵀJ)⁻¹`, which does not assume
    /// equal residual variances (absent in fit.json files written before
    /// it existed: 0).
    #[serde(default)]
    pub stderr_robust: f64,
    /// Ended at a physical bound (its standard error is then meaningless).
    pub at_bound: bool,
    /// Held fixed rather than fitted.
    pub fixed: bool,
}

impl ParamEstimate {
    /// The larger of the two standard errors (a non-finite one is
    /// ignored): the one to show when the residuals' variance may not be
    /// uniform.
    pub fn uncertainty(&self) -> f64 {
        [self.stderr, self.stderr_robust]
            .into_iter()
            .filter(|v| v.is_finite())
            .fold(f64::NAN, f64::max)
    }
}

/// One starting point of the multi-start and where it ended.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StartRecord {
    /// Starting roughness (u, v).
    pub rough: [f64; 2],
    /// Cost reached on the subsample.
    pub cost: f64,
}

/// The result of fitting one incidence (or all at once).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitReport {
    /// Where the data came from.
    pub source: String,
    /// Incident polar angle in degrees (NaN-free; 0 for the global fit).
    pub theta_in: f64,
    /// Incident azimuth in degrees.
    pub phi_in: f64,
    /// Every material argument by name, then `scale` when free.
    pub params: Vec<ParamEstimate>,
    /// The fitted material's real arguments, in Radiance order.
    pub material_args: Vec<f64>,
    /// Free scale (1 when not fitted).
    pub scale: f64,
    /// Samples used.
    pub n_points: usize,
    /// Selections applied before the fit.
    pub gates: Vec<GateReport>,
    /// Which weights were used.
    pub weighting: String,
    /// RMS of `(m − y)/sqrt(y² + floor²)` over all samples and channels.
    pub rms_rel: f64,
    /// ½ Σ r² at the solution (the optimiser's objective).
    pub cost: f64,
    /// The floor used by relative/log residuals.
    pub floor: f64,
    /// Why the optimiser stopped.
    pub termination: Termination,
    /// Residual + Jacobian evaluations over all starts and passes.
    pub evaluations: usize,
    /// Wall time in milliseconds.
    pub elapsed_ms: f64,
    /// The multi-start record.
    pub starts: Vec<StartRecord>,
    /// Things the user should know (bounds, degenerate lobes, ...).
    pub warnings: Vec<String>,
}

impl FitReport {
    /// Value of the parameter called `name`.
    pub fn value(&self, name: &str) -> Option<f64> {
        self.params.iter().find(|p| p.name == name).map(|p| p.value)
    }

    /// Standard error of the parameter called `name`.
    pub fn stderr(&self, name: &str) -> Option<f64> {
        self.params
            .iter()
            .find(|p| p.name == name)
            .map(|p| p.stderr)
    }
}

/// Samples per start in the multi-start phase (every k-th sample, plus
/// the brightest ones): enough to find a basin.
const START_SAMPLES: usize = 250;
/// The brightest samples every subsample keeps, whatever its stride.
const BRIGHT_SAMPLES: usize = 250;
/// Samples of the polish of the best start before the fit on every
/// sample: from its optimum, the full fit converges in three steps.
const POLISH_SAMPLES: usize = 2000;

/// Fits one incidence.
pub fn fit_incidence(data: &IncidenceData, config: &FitConfig) -> Result<FitReport, FitError> {
    fit_many(std::slice::from_ref(data), config, &data.source)
}

/// Fits one parameter set to all incidences at once. Each incidence gets
/// the same total weight, so densely sampled files do not dominate.
pub fn fit_global(data: &[IncidenceData], config: &FitConfig) -> Result<FitReport, FitError> {
    fit_many(data, config, "all incidences")
}

fn fit_many(
    data: &[IncidenceData],
    config: &FitConfig,
    label: &str,
) -> Result<FitReport, FitError> {
    let started = Instant::now();
    let channels = data[0].channels.clamp(1, 3);
    if data.iter().any(|d| d.channels.clamp(1, 3) != channels) {
        return Err(FitError::MixedChannels);
    }
    let gray = config.gray || channels == 1;
    let map = ParamMap::new(config.kind, gray, config.free_scale);
    let orientation = DVec3::from_array(config.orientation);
    let mut blocks = Vec::with_capacity(data.len());
    let mut stats = Vec::with_capacity(data.len());
    for d in data {
        let scan = prepare::scan(d, channels, config)?;
        blocks.push(scan.block);
        stats.push(scan.stats);
    }
    let n_points: usize = blocks.iter().map(Block::len).sum();
    // Large enough to polish the best start on a subsample first.
    let polish = n_points > 2 * POLISH_SAMPLES;
    // Three independent order statistics over every sample (the floor, the
    // starting values, the subsamples' brightness threshold), side by side.
    let n_blocks = blocks.len().max(1);
    let share = move |count: usize| count / n_blocks;
    let ((floor, starts), bright) = rayon::join(
        || {
            rayon::join(
                || config.floor.unwrap_or_else(|| prepare::auto_floor(&stats)),
                || prepare::starting_points(&stats, &map, config, channels),
            )
        },
        // Subsamples are taken only by the multi-start and the polish.
        || -> Vec<f64> {
            if config.multistart || polish {
                blocks
                    .iter()
                    .map(|b| prepare::bright_threshold(b, share(BRIGHT_SAMPLES)))
                    .collect()
            } else {
                Vec::new()
            }
        },
    );
    for b in &mut blocks {
        b.set_factors(config.residual, floor);
    }
    let mut evaluations = 0;
    let solve = |blocks: &[Block], u0: DVector<f64>, stage: Stage| -> Solved {
        let mut problem = Problem::new(&map, config, orientation, blocks, channels, floor);
        problem.u = u0.clone();
        problem.report = stage.report;
        let (problem, report) = LevenbergMarquardt::new()
            .with_ftol(stage.tolerance)
            .with_xtol(stage.tolerance)
            .with_gtol(stage.gtol)
            .with_patience(stage.patience)
            .minimize(problem);
        // After User/Numerical stops the problem holds the rejected trial
        // point; fall back to the start then.
        let failed = matches!(
            report.termination,
            TerminationReason::User(_) | TerminationReason::Numerical(_)
        );
        let u = if failed { u0 } else { problem.u.clone() };
        let at_solution = problem.evaluated(&u);
        Solved {
            cost: at_solution
                .as_ref()
                .map_or(f64::INFINITY, |c| 0.5 * c.residuals.norm_squared()),
            u,
            termination: report.termination,
            evaluations: problem.evaluations.get(),
            at_solution,
        }
    };

    // Multi-start on a subsample, then the full fit from the best start.
    let mut records = Vec::new();
    let mut best: Option<(DVector<f64>, f64)> = None;
    let thin = |target: usize| -> Vec<Block> {
        blocks
            .iter()
            .zip(&bright)
            .map(|(b, &t)| prepare::subsample(b, share(target), t))
            .collect()
    };
    if starts.len() > 1 {
        let sub = thin(START_SAMPLES);
        // The starts are independent: run them in parallel, then pick the
        // lowest cost (the first on ties), so the choice is deterministic.
        let ends: Vec<Solved> = starts
            .par_iter()
            .map(|(_, u0)| solve(&sub, u0.clone(), Stage::START))
            .collect();
        for ((rough, _), end) in starts.iter().zip(ends) {
            evaluations += end.evaluations;
            records.push(StartRecord {
                rough: *rough,
                cost: end.cost,
            });
            if best.as_ref().is_none_or(|(_, c)| end.cost < *c) {
                best = Some((end.u, end.cost));
            }
        }
    }
    let mut u_start = best.map_or_else(|| starts[0].1.clone(), |(u, _)| u);
    if polish {
        let polished = solve(&thin(POLISH_SAMPLES), u_start.clone(), Stage::START);
        evaluations += polished.evaluations;
        if polished.cost.is_finite() {
            u_start = polished.u;
        }
    }
    let mut solved = solve(&blocks, u_start, Stage::FINAL);
    evaluations += solved.evaluations;
    if !solved.cost.is_finite() {
        return Err(FitError::Failed {
            origin: label.into(),
            reason: format!("no finite residuals ({:?})", solved.termination),
        });
    }

    // Robust loss by iteratively reweighted least squares.
    if config.loss != RobustLoss::None {
        let base = blocks.clone();
        for _ in 0..5 {
            let problem = Problem::new(&map, config, orientation, &base, channels, floor);
            let Some(r) = problem.residual_vector(&solved.u) else {
                break;
            };
            let sigma = robust_sigma(&r);
            let mut row = 0;
            for b in blocks.iter_mut() {
                let mut multipliers = Vec::with_capacity(b.len());
                for _ in 0..b.len() {
                    let z = (0..channels).map(|c| r[row + c].abs()).fold(0.0, f64::max) / sigma;
                    row += channels;
                    let w = match config.loss {
                        RobustLoss::Huber(c) => {
                            if z <= c {
                                1.0
                            } else {
                                c / z
                            }
                        }
                        RobustLoss::Cauchy(c) => 1.0 / (1.0 + (z / c) * (z / c)),
                        RobustLoss::None => 1.0,
                    };
                    multipliers.push(w.sqrt());
                }
                b.multipliers = Some(multipliers);
                b.set_factors(config.residual, floor);
            }
            let previous = solved.u.clone();
            solved = solve(&blocks, previous.clone(), Stage::FINAL);
            evaluations += solved.evaluations;
            if (&solved.u - &previous).amax() < 1e-8 {
                break;
            }
        }
    }

    let Solved {
        u,
        cost,
        termination,
        at_solution,
        ..
    } = solved;
    let problem = Problem::new(&map, config, orientation, &blocks, channels, floor);
    let (p, dp, material, scale) = problem.physical(&u).ok_or_else(|| FitError::Failed {
        origin: label.into(),
        reason: "the solution is not a valid material".into(),
    })?;
    let m_res = problem.n_residuals();
    // The solution's pass from the optimiser's own history.
    let final_pass = at_solution.ok_or_else(|| FitError::Failed {
        origin: label.into(),
        reason: "non-finite residuals or Jacobian at the solution".into(),
    })?;
    let rms_rel = final_pass.rms_rel;
    // JᵀJ = RᵀR for the compressed Jacobian [R; 0].
    let jacobian = final_pass.jacobian;
    let dof = m_res.saturating_sub(map.len()).max(1) as f64;
    let s2 = 2.0 * cost / dof;
    let n = map.len();
    let inverse = (jacobian.transpose() * &jacobian).try_inverse();
    let stderr_u: Vec<f64> = match &inverse {
        Some(inv) => (0..n).map(|i| (s2 * inv[(i, i)]).max(0.0).sqrt()).collect(),
        None => vec![f64::NAN; n],
    };
    let robust_u: Vec<f64> = match (&inverse, &final_pass.meat) {
        (Some(inv), Some(meat)) => {
            let sandwich = inv * meat * inv * (m_res as f64 / dof);
            (0..n).map(|i| sandwich[(i, i)].max(0.0).sqrt()).collect()
        }
        _ => vec![f64::NAN; n],
    };
    // Report every material argument by name.
    let args = material.args().to_vec();
    let mut params = Vec::new();
    let mut warnings = Vec::new();
    for (a, name) in config.kind.param_names().iter().enumerate() {
        let slot = map.slot_of_arg(a);
        let (stderr, stderr_robust, at_bound, fixed) = match slot {
            Some(i) => (
                stderr_u[i] * dp[i].abs(),
                robust_u[i] * dp[i].abs(),
                map.at_bound(i, p[i]),
                false,
            ),
            None => (0.0, 0.0, false, true),
        };
        if at_bound {
            warnings.push(format!("{name} = {:.6} ended at a bound", args[a]));
        }
        params.push(ParamEstimate {
            name: (*name).into(),
            value: args[a],
            stderr,
            stderr_robust,
            at_bound,
            fixed,
        });
    }
    if let Some(i) = map.slots.iter().position(|s| s.target == Target::Scale) {
        params.push(ParamEstimate {
            name: "scale".into(),
            value: scale,
            stderr: stderr_u[i] * dp[i].abs(),
            stderr_robust: robust_u[i] * dp[i].abs(),
            at_bound: map.at_bound(i, p[i]),
            fixed: false,
        });
        warnings.push(
            "free scale: the colour is fixed at 1, so `scale` is scale × colour; give the beam integral or a known reflectance for absolute colour".into(),
        );
    }
    // Unequal residual variances (multiplicative noise with absolute
    // residuals, or a model that misses the data's shape) make s²(JᵀJ)⁻¹
    // too small; say so when the sandwich disagrees by more than 2×.
    let understated: Vec<String> = params
        .iter()
        .filter(|p| !p.fixed && !p.at_bound && p.stderr_robust > 2.0 * p.stderr)
        .map(|p| format!("{} ({:.1}×)", p.name, p.stderr_robust / p.stderr))
        .collect();
    if !understated.is_empty() {
        warnings.push(format!(
            "the residuals' variance is not uniform, so the standard errors understate the uncertainty of {}; use stderr_robust in fit.json, or --residual log for multiplicative noise",
            understated.join(", ")
        ));
    }
    if args[3] < 1e-4 {
        warnings
            .push("specularity ≈ 0: the lobe is degenerate and its roughness meaningless".into());
    }
    if !termination.was_successful() {
        warnings.push(format!(
            "optimiser stopped without converging: {termination:?}"
        ));
    }

    let single = data.len() == 1;
    Ok(FitReport {
        source: label.into(),
        theta_in: if single { data[0].theta_in } else { 0.0 },
        phi_in: if single { data[0].phi_in } else { 0.0 },
        params,
        material_args: args,
        scale,
        n_points,
        gates: if single {
            data[0].gates.clone()
        } else {
            Vec::new()
        },
        weighting: data[0].weighting.clone(),
        rms_rel,
        cost,
        floor,
        termination: Termination::from_lm(&termination),
        evaluations,
        elapsed_ms: started.elapsed().as_secs_f64() * 1e3,
        starts: records,
        warnings,
    })
}

/// Tolerances of one Levenberg-Marquardt run.
#[derive(Clone, Copy)]
struct Stage {
    /// ftol and xtol.
    tolerance: f64,
    /// Largest cosine between the residuals and a Jacobian column at a
    /// stationary point.
    gtol: f64,
    /// Evaluation budget in units of (parameters + 1).
    patience: usize,
    /// Its passes compute what the report uses (the sandwich's middle
    /// term, `rms_rel`); only the final fit's solution is reported.
    report: bool,
}

impl Stage {
    /// A start on the subsample only has to find its basin, within a budget
    /// of 8 (n + 1) evaluations: a start that has not converged by then
    /// (typically one far too narrow, whose lobe misses the data) is
    /// compared at the cost it reached. The best start is polished and fitted
    /// to every sample afterwards.
    const START: Stage = Stage {
        tolerance: 1e-6,
        gtol: 1e-14,
        patience: 8,
        report: false,
    };
    /// The fit on every sample. From the polished start it takes three
    /// steps; the gradient test stops it after the third, where ftol alone
    /// would spend a fourth pass confirming a zero reduction.
    const FINAL: Stage = Stage {
        tolerance: 1e-12,
        gtol: 1e-6,
        patience: 200,
        report: true,
    };
}

/// Where one Levenberg-Marquardt run ended.
struct Solved {
    u: DVector<f64>,
    /// ½‖r‖² at `u` (infinite when it could not be evaluated).
    cost: f64,
    termination: TerminationReason,
    evaluations: usize,
    /// The compressed problem at `u`.
    at_solution: Option<Compressed>,
}

/// 1.4826 × the median absolute residual, a robust standard deviation.
fn robust_sigma(r: &DVector<f64>) -> f64 {
    let mut a: Vec<f64> = r.iter().map(|x| x.abs()).collect();
    let mid = a.len() / 2;
    a.select_nth_unstable_by(mid, f64::total_cmp);
    (1.4826 * a[mid]).max(1e-300)
}
