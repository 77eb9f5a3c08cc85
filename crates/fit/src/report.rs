//! What one fit found: [`FitReport`] with its parameters, termination and
//! typed warnings.

use crate::data::{GateCount, Weighting};
use levenberg_marquardt::TerminationReason;
use serde::{Deserialize, Serialize};

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
    pub(crate) fn from_lm(reason: &TerminationReason) -> Termination {
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
    /// `NoImprovementPossible` counts: no step could lower the cost by more
    /// than rounding, which is a stationary point to machine precision.
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
    /// Standard error from s²(JᵀJ)⁻¹; `None` (`null` in fit.json) when
    /// there is none: the parameter is held fixed, ended at a bound (where
    /// the error of a bounded parameter means nothing), or JᵀJ is singular.
    pub stderr: Option<f64>,
    /// Heteroscedasticity-consistent standard error from the sandwich
    /// `m/(m−n) (JᵀJ)⁻¹ (Σ rᵢ² Jᵢ Jᵢᵀ) (JᵀJ)⁻¹`, which does not assume
    /// equal residual variances; `None` as for `stderr`.
    pub stderr_robust: Option<f64>,
    /// Ended at a physical bound (its standard error is then meaningless).
    pub at_bound: bool,
    /// Held fixed rather than fitted.
    pub fixed: bool,
}

impl ParamEstimate {
    /// The larger of the two standard errors: the one to show when the
    /// residuals' variance may not be uniform. `None` when there is none.
    pub fn uncertainty(&self) -> Option<f64> {
        match (self.stderr, self.stderr_robust) {
            (Some(a), Some(b)) => Some(a.max(b)),
            (a, b) => a.or(b),
        }
    }

    /// Why there is no standard error, for tables: `at bound`, `fixed` or
    /// `singular`; `None` when there is one.
    pub fn missing_error_reason(&self) -> Option<&'static str> {
        if self.stderr.is_some() {
            None
        } else if self.fixed {
            Some("fixed")
        } else if self.at_bound {
            Some("at bound")
        } else {
            Some("singular")
        }
    }
}

/// One starting point of the multi-start and where it ended.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StartRecord {
    /// Starting roughness (u, v).
    pub rough: [f64; 2],
    /// Cost reached on the multi-start's subsample (about 500 samples, so
    /// not comparable with the fit's `cost`).
    pub subsample_cost: f64,
    /// For the few best starts: the cost on every sample after the
    /// polish, comparable with the fit's `cost`, which is never above it.
    pub full_cost: Option<f64>,
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
    /// Selections applied before the fit, with what each removed.
    pub gates: Vec<GateCount>,
    /// Which weights were used.
    pub weighting: Weighting,
    /// RMS of `(m − y)/sqrt(y² + floor²)` over all samples and channels.
    pub rms_rel: f64,
    /// E1, the share of the measured light the material puts in the wrong
    /// place: `Σ ω |m − d| / Σ ω |d|` over the fitted samples and channels,
    /// ω the sample's weight (its solid angle by default), m and d in the
    /// file's quantity (times |cos θ_out| for DSF and raw-signal files).
    #[serde(default)]
    pub e1: Option<f64>,
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
    pub warnings: Vec<FitWarning>,
    /// Whether the model describes the data (made by [`crate::fit_set`]).
    #[serde(default)]
    pub adequacy: Option<crate::adequacy::Adequacy>,
    /// The robust loss's reweighting, when there was one.
    #[serde(default)]
    pub robust: Option<RobustRecord>,
}

impl FitReport {
    /// Value of the parameter called `name`.
    pub fn value(&self, name: &str) -> Option<f64> {
        self.params.iter().find(|p| p.name == name).map(|p| p.value)
    }

    /// Standard error of the parameter called `name`, when it has one.
    pub fn stderr(&self, name: &str) -> Option<f64> {
        self.params
            .iter()
            .find(|p| p.name == name)
            .and_then(|p| p.stderr)
    }
}

impl std::fmt::Display for Termination {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.label())
    }
}

/// How the robust loss's reweighting went.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RobustRecord {
    /// σ of the last round: 1.4826 × the median |residual|, the unit of
    /// the loss's threshold (Huber's c σ is scipy's `f_scale`).
    pub sigma: f64,
    /// Reweighting rounds made.
    pub rounds: usize,
    /// The parameters settled (moved by less than 1e-6, relative).
    pub settled: bool,
}

/// A parameter whose sandwich standard error exceeds the plain one.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StderrRatio {
    /// The parameter's name.
    pub param: String,
    /// `stderr_robust / stderr`.
    pub ratio: f64,
}

/// Something the user should know about one fit. Stored typed in
/// `fit.json`; the `Display` sentence is for people only.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "warning", rename_all = "snake_case")]
pub enum FitWarning {
    /// A parameter ended at a bound of its physical range.
    AtBound {
        /// The parameter's name.
        param: String,
        /// Its value.
        value: f64,
    },
    /// A free scale was fitted, so colour and scale are one product.
    FreeScaleColour,
    /// The sandwich standard errors exceed s²(JᵀJ)⁻¹ by more than 2×.
    UnderstatedErrors {
        /// The parameters concerned.
        params: Vec<StderrRatio>,
    },
    /// The specular part vanished, so its roughness means nothing.
    DegenerateLobe,
    /// The optimiser stopped without meeting a convergence test.
    NotConverged {
        /// Why it stopped.
        termination: Termination,
    },
    /// The robust loss's reweighting hit its round limit unsettled.
    RobustNotSettled {
        /// Rounds made.
        rounds: usize,
    },
    /// The data's ρ_dh (or τ_dh) and the model's differ by more than 5%.
    EnergyMismatch {
        /// The data's.
        data: f64,
        /// The model's.
        model: f64,
        /// A free scale's unit (`uA·sr`): then both are sums over the
        /// measured directions in the file's unit, not ρ/τ.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        unit: Option<String>,
    },
    /// The model's peak is more than 5° from the data's.
    PeakOffset {
        /// The angle between them.
        degrees: f64,
    },
    /// A parameter moves by more than 20% with another residual kind.
    ResidualKindSensitive {
        /// The comparison.
        check: crate::adequacy::ResidualCheck,
    },
    /// A lobe of a lobe sum carries almost none of the specularity, or two
    /// lobes have (nearly) one roughness: fewer lobes describe the data as
    /// well.
    CollapsedLobe {
        /// The lobe (1-based).
        lobe: usize,
        /// Why: `weight` (its share of the specularity) or `roughness`
        /// (equal to the next lobe's).
        reason: String,
        /// Its share of the specularity, or the roughnesses' relative difference.
        value: f64,
    },
}

impl FitWarning {
    /// The warning for a stop that met no convergence test, judged by
    /// [`Termination::converged`] (the one test every reader uses).
    pub(crate) fn not_converged(termination: &Termination) -> Option<FitWarning> {
        (!termination.converged()).then(|| FitWarning::NotConverged {
            termination: termination.clone(),
        })
    }
}

impl std::fmt::Display for FitWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FitWarning::AtBound { param, value } => {
                write!(f, "{param} = {value:.6} ended at a bound")
            }
            FitWarning::FreeScaleColour => f.write_str(
                "free scale: the colour is fixed at 1, so `scale` is scale × colour; \
                 give the beam integral or a known reflectance for absolute colour",
            ),
            FitWarning::UnderstatedErrors { params } => {
                let list: Vec<String> = params
                    .iter()
                    .map(|p| format!("{} ({:.1}×)", p.param, p.ratio))
                    .collect();
                write!(
                    f,
                    "the residuals' variance is not uniform, so the standard errors understate \
                     the uncertainty of {}; use stderr_robust in fit.json, or --residual log \
                     for multiplicative noise",
                    list.join(", ")
                )
            }
            FitWarning::DegenerateLobe => {
                f.write_str("specularity ≈ 0: the lobe is degenerate and its roughness meaningless")
            }
            FitWarning::NotConverged { termination } => {
                write!(f, "optimiser stopped without converging: {termination:?}")
            }
            FitWarning::RobustNotSettled { rounds } => write!(
                f,
                "the robust reweighting did not settle in {rounds} rounds: the parameters are \
                 not yet the robust loss's minimum"
            ),
            FitWarning::EnergyMismatch {
                data,
                model,
                unit: None,
            } => write!(
                f,
                "the model does not carry the data's energy: data ρ_dh {data:.4}, model {model:.4} \
                 ({:+.1}%); the model cannot describe this sample's scattering",
                100.0 * (model / data - 1.0)
            ),
            FitWarning::EnergyMismatch {
                data,
                model,
                unit: Some(unit),
            } => write!(
                f,
                "the fitted shape does not carry the data's energy: over the measured directions \
                 data {data:.4} {unit}, model × scale {model:.4} {unit} ({:+.1}%)",
                100.0 * (model / data - 1.0)
            ),
            FitWarning::PeakOffset { degrees } => write!(
                f,
                "the model's peak is {degrees:.1}° from the data's: the lobe is in the wrong place"
            ),
            FitWarning::CollapsedLobe {
                lobe,
                reason,
                value,
            } => match reason.as_str() {
                "weight" => write!(
                    f,
                    "lobe {lobe} carries {:.2}% of the specularity: it has collapsed, and a fit \
                     with one lobe fewer describes the data as well",
                    100.0 * value
                ),
                _ => write!(
                    f,
                    "lobes {lobe} and {} have the same roughness (within {:.1}%): they have \
                     collapsed into one",
                    lobe + 1,
                    100.0 * value
                ),
            },
            FitWarning::ResidualKindSensitive { check } => write!(
                f,
                "{} moves from {:.4} to {:.4} ({:.0}%) when fitted with {:?} residuals: \
                 the parameters depend on how the misfit is weighed, so the model does not \
                 describe the data",
                check.param,
                check.values[0],
                check.values[1],
                100.0 * check.relative_change,
                check.residual
            ),
        }
    }
}
