//! Per-incidence and all-incidence fits: data checks, data-driven starting
//! values, a multi-start over roughness on a subsample, the final
//! Levenberg-Marquardt fit on every sample, optional robust reweighting,
//! and the report with its standard errors.

use crate::config::{EnergyRule, FitConfig, FitError, RobustLoss};
use crate::data::{FitSample, IncidenceData, PatchPairs};
use crate::pair_geometry::PairGeometry;
use crate::params::{ParamMap, Target};
use crate::prepare;
use crate::problem::Block;
use crate::report::{
    FitReport, FitWarning, ParamEstimate, RobustRecord, StartRecord, StderrRatio, Termination,
};
use crate::robust;
use crate::solve::{Solved, Solver, Stage};
use crate::uncertainty::standard_errors;
use brtf_model::{
    Bsdf, Geometry, GeometryBatch, Material, Shape, ShapeArg, lobe_splits, lobe_weights,
};
use glam::DVec3;
use nalgebra::DVector;
use rayon::prelude::*;
use std::borrow::Cow;
use std::time::Instant;

/// Samples per start in the multi-start phase (every k-th sample, plus
/// the brightest ones): enough to find a basin.
const START_SAMPLES: usize = 250;
/// Fewest samples per incidence in the starts' subsample of an
/// all-incidence fit: with one or two, the 145 incidences of a Klems side
/// drove the starts to a corner (diffuse reflectance at 1) that the final
/// fit took 35 passes over ten million pairs to leave, or never left.
const START_SAMPLES_PER_INCIDENCE: usize = 16;
/// The brightest samples every subsample keeps, whatever its stride.
const BRIGHT_SAMPLES: usize = 250;
/// Samples of the polish of the best start before the fit on every
/// sample, which then needs a few passes.
const POLISH_SAMPLES: usize = 2000;
/// Multi-start ends polished and compared on every sample.
const CANDIDATES: usize = 3;
/// Robust reweighting stops when no parameter moves by more than this
/// (relative) in a round...
const IRLS_TOLERANCE: f64 = 1e-6;
/// ...or after this many rounds, with a warning.
const IRLS_MAX_ROUNDS: usize = 100;

/// Fits one incidence.
pub fn fit_incidence(data: &IncidenceData, config: &FitConfig) -> Result<FitReport, FitError> {
    fit_many(std::slice::from_ref(data), config, &data.source, None, None)
}

/// Fits one parameter set to all incidences at once. Each incidence gets
/// the same total weight, so densely sampled files do not dominate.
pub fn fit_global(data: &[IncidenceData], config: &FitConfig) -> Result<FitReport, FitError> {
    fit_many(data, config, "all incidences", None, None)
}

/// The argument-free geometry of one incidence's block, computed once and
/// shared by every fit of a fit set that uses it (the per-incidence fit,
/// the all-incidence fit and the adequacy diagnostics' second fit).
pub(crate) enum SharedGeometry {
    /// Patch-averaged data: their pairs' geometry.
    Pairs(PairGeometry),
    /// Measured data: each sample's geometry.
    Samples(GeometryBatch),
    /// Nothing kept (pairs beyond the memory budget): the kernel computes
    /// the geometry on every pass.
    Recomputed,
}

/// The geometry of each of `data`'s incidences (see [`SharedGeometry`]).
/// Patch pairs' geometry is kept for one incidence only (a few MB): a
/// Klems side's 10 million pairs would take 0.5 GB, so fits over many
/// incidences compute it on every pass (from coarse pairs until the last
/// solve), and each incidence's own fit keeps its own while it runs.
pub(crate) fn shared_geometry(
    data: &[IncidenceData],
    config: &FitConfig,
) -> Result<Vec<SharedGeometry>, FitError> {
    // A fitted orientation turns the tangent frame: no geometry to keep.
    if config.oriented {
        return Ok(data.iter().map(|_| SharedGeometry::Recomputed).collect());
    }
    let bsdf = geometry_bsdf(config)?;
    let keep_pairs = data.len() == 1;
    Ok(data
        .par_iter()
        .map(|d| match d.patch_pairs.as_deref() {
            Some(pairs) if keep_pairs => SharedGeometry::Pairs(PairGeometry::new(pairs, &bsdf)),
            Some(_) => SharedGeometry::Recomputed,
            None => SharedGeometry::Samples(sample_geometry(&bsdf, d.light(), &d.samples)),
        })
        .collect())
}

/// [`fit_incidence`] with the incidence's shared geometry.
pub(crate) fn fit_incidence_sharing(
    data: &IncidenceData,
    config: &FitConfig,
    geometry: &SharedGeometry,
) -> Result<FitReport, FitError> {
    fit_many(
        std::slice::from_ref(data),
        config,
        &data.source,
        Some(std::slice::from_ref(geometry)),
        None,
    )
}

/// [`fit_global`] with the incidences' shared geometry.
pub(crate) fn fit_global_sharing(
    data: &[IncidenceData],
    config: &FitConfig,
    geometry: &[SharedGeometry],
) -> Result<FitReport, FitError> {
    fit_many(data, config, "all incidences", Some(geometry), None)
}

/// [`fit_incidence_sharing`] of a lobe sum from its one-lobe fit `base`,
/// made already.
pub(crate) fn fit_incidence_from(
    data: &IncidenceData,
    config: &FitConfig,
    geometry: &SharedGeometry,
    base: &FitReport,
) -> Result<FitReport, FitError> {
    fit_many(
        std::slice::from_ref(data),
        config,
        &data.source,
        Some(std::slice::from_ref(geometry)),
        Some(base),
    )
}

/// The fit of `data` (one incidence, or all at once as `label`); a lobe
/// sum starts from its one-lobe fit, `base` when given.
fn fit_many(
    data: &[IncidenceData],
    config: &FitConfig,
    label: &str,
    geometry: Option<&[SharedGeometry]>,
    base: Option<&FitReport>,
) -> Result<FitReport, FitError> {
    let started = Instant::now();
    let channels = data[0].channels.clamp(1, 3);
    if data.iter().any(|d| d.channels.clamp(1, 3) != channels) {
        return Err(FitError::MixedChannels);
    }
    let gray = config.gray || channels == 1;
    let shape = config.shape();
    if !shape.is_single() && data.iter().any(|d| d.patch_pairs.is_some()) {
        return Err(FitError::Failed {
            origin: label.into(),
            reason: "lobe sums and a fitted orientation need gonio-photometer scans: patch \
                     averages are fitted with one primitive of fixed orientation"
                .into(),
        });
    }
    let map =
        ParamMap::new(shape, gray, config.free_scale).with_min_roughness(config.min_roughness);
    // A lobe sum starts from the one-lobe fit (and its split variations):
    // it can then only end at a cost at or below it.
    let base = match (shape.lobes > 1, base) {
        (false, _) => None,
        (true, Some(base)) => Some(base.clone()),
        (true, None) => {
            let one = FitConfig {
                lobes: 1,
                ..config.clone()
            };
            Some(fit_many(data, &one, label, geometry, None)?)
        }
    };
    // The blocks' geometry once per fit, or the fit set's shared one (an
    // incidence's patch pairs are not shared: this fit keeps them).
    let own_geometry = match geometry {
        Some([SharedGeometry::Recomputed]) if data[0].patch_pairs.is_some() => {
            Some(shared_geometry(data, config)?)
        }
        Some(_) => None,
        None => Some(shared_geometry(data, config)?),
    };
    let geometry = own_geometry.as_deref().or(geometry).unwrap_or_default();
    let mut blocks = Vec::with_capacity(data.len());
    let mut stats = Vec::with_capacity(data.len());
    for (k, d) in data.iter().enumerate() {
        let mut scan = prepare::scan(d, channels, config)?;
        match geometry.get(k) {
            Some(SharedGeometry::Pairs(g)) => scan.block.pair_geometry = Some(Cow::Borrowed(g)),
            Some(SharedGeometry::Samples(g)) => {
                scan.block.sample_geometry = Some(Cow::Borrowed(g));
            }
            Some(SharedGeometry::Recomputed) | None => {}
        }
        blocks.push(scan.block);
        stats.push(scan.stats);
    }
    let n_points: usize = blocks.iter().map(Block::len).sum();
    // Large enough to polish the best start on a subsample first.
    let polish = n_points > 2 * POLISH_SAMPLES;
    // Three independent order statistics over every sample (the floor, the
    // starting values, the subsamples' brightness threshold), side by side.
    let n_blocks = blocks.len().max(1);
    // Every incidence of an all-incidence fit keeps a few samples in the
    // starts' subsample, else its cost says little about the whole.
    let start_samples = START_SAMPLES.max(START_SAMPLES_PER_INCIDENCE * n_blocks);
    let start_stage = if data.len() > 1 {
        Stage::START_ALL_INCIDENCES
    } else {
        Stage::START
    };
    let share = move |count: usize| count / n_blocks;
    let ((floor, starts), bright) = rayon::join(
        || {
            rayon::join(
                || config.floor.unwrap_or_else(|| prepare::auto_floor(&stats)),
                || match &base {
                    Some(base) => lobe_starts(base, &map, config),
                    None => {
                        let starts = prepare::starting_points(&stats, &map, config, channels);
                        if shape.oriented {
                            with_orientations(starts, &map)
                        } else {
                            starts
                        }
                    }
                },
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
    // Patch-averaged data: the starts average over coarse pairs (an
    // eighth of a Klems incidence's), and so does an all-incidence fit
    // until its last solve, which alone runs on every pair. The starts
    // only choose a basin: an incidence's candidates are judged on every
    // pair.
    let coarse_pairs: Vec<Option<PatchPairs>> = blocks
        .iter()
        .map(|b| b.pairs.as_deref().map(PatchPairs::coarse))
        .collect();
    let coarse_geometry: Vec<Option<PairGeometry>> = if data.len() == 1 && !config.oriented {
        let bsdf = geometry_bsdf(config)?;
        coarse_pairs
            .iter()
            .map(|p| p.as_ref().map(|p| PairGeometry::new(p, &bsdf)))
            .collect()
    } else {
        vec![None; blocks.len()]
    };
    let mut coarse_blocks: Option<Vec<Block>> =
        coarse_pairs.iter().any(Option::is_some).then(|| {
            blocks
                .iter()
                .zip(coarse_pairs.iter().zip(&coarse_geometry))
                .map(|(b, (pairs, geometry))| Block {
                    pairs: pairs.as_ref().map(Cow::Borrowed),
                    pair_geometry: geometry.as_ref().map(Cow::Borrowed),
                    ..b.clone()
                })
                .collect()
        });
    let start_blocks: &[Block] = coarse_blocks.as_deref().unwrap_or(&blocks);
    // Where the candidates are judged: an incidence's on every pair, an
    // all-incidence fit's on the coarse pairs of every sample.
    let judge_blocks: &[Block] = if data.len() > 1 {
        start_blocks
    } else {
        &blocks
    };
    let solver = Solver {
        map: &map,
        config,
        orientation: DVec3::from_array(config.orientation),
        channels,
        floor,
    };
    let mut evaluations = 0;

    // Multi-start on a subsample; the best few ends (always with the
    // data-driven start's) polished and judged on every sample; the full
    // fit from the best of them. LM only lowers the cost from its start,
    // so the result is never worse than any candidate.
    let mut records = Vec::new();
    let thin = |target: usize| -> Vec<Block> {
        start_blocks
            .iter()
            .zip(&bright)
            .map(|(b, &t)| prepare::subsample(b, share(target), t))
            .collect()
    };
    let mut ends: Vec<DVector<f64>> = vec![starts[0].1.clone()];
    if starts.len() > 1 {
        let sub = thin(start_samples);
        // The starts are independent: run them in parallel; the order of
        // the candidates (lowest cost first, the first on ties) keeps the
        // choice deterministic.
        let solved: Vec<Solved> = starts
            .par_iter()
            .map(|(_, u0)| solver.solve(&sub, u0.clone(), start_stage))
            .collect();
        for ((rough, _), end) in starts.iter().zip(&solved) {
            evaluations += end.evaluations;
            records.push(StartRecord {
                rough: *rough,
                subsample_cost: end.cost,
                full_cost: None,
            });
        }
        let mut order: Vec<usize> = (0..solved.len()).collect();
        order.sort_by(|&a, &b| solved[a].cost.total_cmp(&solved[b].cost));
        order.truncate(CANDIDATES);
        // The data-driven start (the first) is always a candidate.
        if !order.contains(&0) {
            order.push(0);
        }
        // Ends that found the same basin as a better one are one candidate:
        // judging each would cost a pass over every sample for one point.
        let mut distinct: Vec<usize> = Vec::with_capacity(order.len());
        for &i in &order {
            if !distinct.iter().any(|&k| same_basin(&solved[k], &solved[i])) {
                distinct.push(i);
            }
        }
        let order = distinct;
        ends = order.iter().map(|&i| solved[i].u.clone()).collect();
        let full_costs = candidates_full_costs(
            &solver,
            judge_blocks,
            &mut ends,
            polish.then(|| thin(POLISH_SAMPLES)),
            start_stage,
            &mut evaluations,
        );
        for (&i, cost) in order.iter().zip(&full_costs) {
            records[i].full_cost = *cost;
        }
        let best = (0..ends.len())
            .min_by(|&a, &b| {
                let cost = |k: usize| full_costs[k].unwrap_or(f64::INFINITY);
                cost(a).total_cmp(&cost(b))
            })
            .expect("at least one candidate");
        ends.swap(0, best);
    } else if polish {
        candidates_full_costs(
            &solver,
            judge_blocks,
            &mut ends,
            Some(thin(POLISH_SAMPLES)),
            start_stage,
            &mut evaluations,
        );
    }
    let u_start = ends.swap_remove(0);
    // `--energy exact`: the starts and candidates are chosen on the
    // residuals alone (energy rows from a far start pull a fit onto its
    // bounds); the final solves, from the chosen candidate, carry them.
    if config.energy != EnergyRule::Free {
        for b in blocks.iter_mut().chain(coarse_blocks.iter_mut().flatten()) {
            b.set_energy(config.energy);
        }
    }
    let start_blocks: &[Block] = coarse_blocks.as_deref().unwrap_or(&blocks);
    // Over many incidences Gauss-Newton can converge linearly (a model
    // that cannot follow every incidence): extrapolated rounds there.
    let final_solve = |u: DVector<f64>| {
        if data.len() == 1 {
            return solver.solve(&blocks, u, Stage::FINAL);
        }
        let approximate = solver.solve_final(start_blocks, u);
        if coarse_blocks.is_none() || !approximate.cost.is_finite() {
            return approximate;
        }
        // From the coarse pairs' minimum, a few passes over every pair
        // (extrapolated too: the linear convergence is the model's).
        let mut exact = solver.solve_final(&blocks, approximate.u);
        exact.evaluations += approximate.evaluations;
        exact
    };
    let mut solved = final_solve(u_start);
    evaluations += solved.evaluations;
    // A lobe sum is never worse than its one-lobe fit, from which it can
    // restart exactly (every lobe at the one lobe's roughness).
    if let Some(base) = &base
        && matches!(
            solved.cost.partial_cmp(&base.cost),
            Some(std::cmp::Ordering::Greater) | None
        )
    {
        let (_, u) = &lobe_starts(base, &map, config)[0];
        solved = final_solve(u.clone());
        evaluations += solved.evaluations;
    }
    // One point per material: lobes by roughness, the orientation in
    // [0°, 180°) with the first lobe rougher along u than along v. The
    // turn changes nothing but the numbers; the final solve there gives
    // the report's standard errors in them.
    if solved.cost.is_finite()
        && let Some(u) = canonical(&map, &solved.u)
    {
        let again = final_solve(u);
        evaluations += again.evaluations;
        // Costs at rounding level (noise-free data) count as equal.
        if again.cost <= solved.cost * (1.0 + 1e-9) + 1e-20 {
            solved = again;
        }
    }
    if !solved.cost.is_finite() {
        return Err(FitError::Failed {
            origin: label.into(),
            reason: format!("no finite residuals ({:?})", solved.termination),
        });
    }

    // Robust loss by iteratively reweighted least squares.
    // Each round weighs the samples by the loss at the current residuals
    // and refits, until the parameters settle: then the weights and the
    // parameters agree, which is the robust loss's minimum.
    let mut robust_record = None;
    if config.loss != RobustLoss::None {
        let base = blocks.clone();
        let physical = |u: &DVector<f64>| -> Vec<f64> {
            (0..map.len()).map(|i| map.to_physical(i, u[i]).0).collect()
        };
        let mut record = RobustRecord {
            sigma: f64::NAN,
            rounds: 0,
            settled: false,
        };
        while record.rounds < IRLS_MAX_ROUNDS {
            let Some(r) = solver.problem(&base).residual_vector(&solved.u) else {
                break;
            };
            let (all, sigma) = robust::multipliers(&r, channels, config.loss);
            let mut rest = all.as_slice();
            for b in blocks.iter_mut() {
                let (mine, others) = rest.split_at(b.len());
                b.multipliers = Some(mine.to_vec());
                b.set_factors(config.residual, floor);
                rest = others;
            }
            let before = physical(&solved.u);
            solved = solver.solve(&blocks, solved.u.clone(), Stage::FINAL);
            evaluations += solved.evaluations;
            record.rounds += 1;
            record.sigma = sigma;
            let change = physical(&solved.u)
                .iter()
                .zip(&before)
                .map(|(a, b)| (a - b).abs() / b.abs().max(1e-6))
                .fold(0.0, f64::max);
            if change < IRLS_TOLERANCE {
                record.settled = true;
                break;
            }
        }
        robust_record = Some(record);
    }

    let report = Reported {
        robust: robust_record,
        label,
        data,
        n_points,
        floor,
        evaluations,
        records,
        started,
    };
    report.build(&solver, &blocks, solved)
}

/// The geometry of every sample seen from `light` (in parallel pieces for
/// many samples; each entry depends on its own sample only).
fn sample_geometry(bsdf: &Bsdf, light: DVec3, samples: &[FitSample]) -> GeometryBatch {
    const PIECE: usize = 16_384;
    let piece = |s: &[FitSample]| -> Vec<Geometry> {
        s.iter().map(|s| bsdf.geometry(light, s.view)).collect()
    };
    let pieces: Vec<Vec<Geometry>> = if samples.len() > PIECE {
        samples.par_chunks(PIECE).map(piece).collect()
    } else {
        vec![piece(samples)]
    };
    let mut batch = GeometryBatch::with_capacity(samples.len());
    batch.extend(pieces.into_iter().flatten());
    batch
}

/// A BSDF of the fit's type, orientation and options, for pair geometry:
/// the geometry does not depend on the arguments, so any valid set will do.
fn geometry_bsdf(config: &FitConfig) -> Result<Bsdf, FitError> {
    let args = vec![0.5; config.kind.n_args()];
    let material = Material::new(
        config.kind,
        &args,
        Some(DVec3::from_array(config.orientation)),
    )
    .map_err(|e| FitError::Failed {
        origin: "patch pairs".into(),
        reason: e.to_string(),
    })?;
    Ok(Bsdf::new(&material, &config.options))
}

/// Polishes each candidate on `polish` (when given; a candidate whose
/// polish fails keeps its point) and returns each one's cost on every
/// sample, or `None` for a lone candidate: with nothing to choose between,
/// the pass over every sample is left to the final fit.
fn candidates_full_costs(
    solver: &Solver<'_>,
    blocks: &[Block<'_>],
    candidates: &mut [DVector<f64>],
    polish: Option<Vec<Block<'_>>>,
    stage: Stage,
    evaluations: &mut usize,
) -> Vec<Option<f64>> {
    if let Some(sub) = &polish {
        let polished: Vec<Solved> = candidates
            .par_iter()
            .map(|u| solver.solve(sub, u.clone(), stage))
            .collect();
        for (u, p) in candidates.iter_mut().zip(polished) {
            *evaluations += p.evaluations;
            if p.cost.is_finite() {
                *u = p.u;
            }
        }
    }
    if candidates.len() < 2 {
        return vec![None; candidates.len()];
    }
    let problem = solver.problem(blocks);
    candidates
        .iter()
        .map(|u| {
            *evaluations += 1;
            Some(problem.cost(u).unwrap_or(f64::INFINITY))
        })
        .collect()
}

/// Whether two start ends found the same basin: costs equal to 1e-6 and
/// every unbounded parameter within 1e-2. Ends of one basin stop where
/// the subsample's cost changes by less than 1e-6, which leaves its flat
/// directions loose to about the square root of that; on the real scans
/// they agreed to 5e-4 (golden_paper, layer_020_030), while different
/// basins (a lobe too narrow, a roughness at its bound) differ in cost.
fn same_basin(a: &Solved, b: &Solved) -> bool {
    let close_costs = (a.cost - b.cost).abs() <= 1e-6 * a.cost.abs().max(b.cost.abs());
    close_costs
        && a.u
            .iter()
            .zip(b.u.iter())
            .all(|(x, y)| (x - y).abs() <= 1e-2)
}

/// Most samples of an incidence that the held-out folds use: a dense
/// scan's E1 is known well from fewer, and the folds' refits cost in
/// proportion.
const HELDOUT_SAMPLES: usize = 32_768;

/// The held-out E1 of `report` on `data`: the samples (at most
/// [`HELDOUT_SAMPLES`], drawn at random) are dealt into `folds` folds (by
/// a hash of their index, so neighbours fall apart); each fold is fitted
/// again without its samples, from `report`'s point (a short stage), and
/// judged on them. Returns E1's numerator and denominator summed over the
/// folds, so that incidences pool.
pub(crate) fn heldout_e1_parts(
    data: &IncidenceData,
    config: &FitConfig,
    report: &FitReport,
    folds: usize,
) -> Option<(f64, f64)> {
    // One draw per sample: its fold, or (beyond the budget) none.
    let keep = (HELDOUT_SAMPLES as f64 / data.samples.len() as f64).min(1.0);
    let fold_of = |i: usize| -> Option<usize> {
        let mut rng = brtf_model::Rng::new(0x00c0_ffee, i as u64);
        let x = rng.uniform() / keep;
        (x < 1.0).then(|| (x * folds as f64) as usize % folds)
    };
    let parts: Vec<Option<(f64, f64)>> = (0..folds)
        .into_par_iter()
        .map(|fold| {
            let split = |train: bool| {
                data.with_samples(
                    data.samples
                        .iter()
                        .enumerate()
                        .filter(|(i, _)| fold_of(*i).is_some_and(|f| (f == fold) != train))
                        .map(|(_, s)| *s)
                        .collect(),
                )
            };
            let (train, test) = (split(true), split(false));
            if train.samples.is_empty() || test.samples.is_empty() {
                return None;
            }
            let (args, scale) = refit(&train, config, report)?;
            e1_parts(&test, config, &args, scale, report.floor)
        })
        .collect();
    parts
        .into_iter()
        .try_fold((0.0, 0.0), |(m, t), p| p.map(|(a, b)| (m + a, t + b)))
}

/// The point the final stage reaches on `data` from `report`'s.
fn refit(data: &IncidenceData, config: &FitConfig, report: &FitReport) -> Option<(Vec<f64>, f64)> {
    let channels = data.channels.clamp(1, 3);
    let gray = config.gray || channels == 1;
    let map = ParamMap::new(config.shape(), gray, config.free_scale)
        .with_min_roughness(config.min_roughness);
    let mut scan = prepare::scan(data, channels, config).ok()?;
    scan.block.set_energy(config.energy);
    scan.block.set_factors(config.residual, report.floor);
    let blocks = [scan.block];
    let solver = Solver {
        map: &map,
        config,
        orientation: DVec3::from_array(config.orientation),
        channels,
        floor: report.floor,
    };
    let u0 = unconstrained(&map, &report.material_args, report.scale);
    let solved = solver.solve(&blocks, u0, Stage::REFIT);
    if !solved.cost.is_finite() {
        return None;
    }
    let p: Vec<f64> = (0..map.len())
        .map(|i| map.to_physical(i, solved.u[i]).0)
        .collect();
    Some(map.material_args(&p))
}

/// E1's numerator and denominator of the material `args` (times `scale`)
/// on `data`.
pub(crate) fn e1_parts(
    data: &IncidenceData,
    config: &FitConfig,
    args: &[f64],
    scale: f64,
    floor: f64,
) -> Option<(f64, f64)> {
    let channels = data.channels.clamp(1, 3);
    let map = ParamMap::new(
        config.shape(),
        config.gray || channels == 1,
        config.free_scale,
    );
    let scan = prepare::scan(data, channels, config).ok()?;
    let blocks = [scan.block];
    let solver = Solver {
        map: &map,
        config,
        orientation: DVec3::from_array(config.orientation),
        channels,
        floor,
    };
    let u = unconstrained(&map, args, scale);
    solver.problem(&blocks).e1_parts(&u)
}

/// The unconstrained point of physical flat arguments `args` and `scale`.
fn unconstrained(map: &ParamMap, args: &[f64], scale: f64) -> DVector<f64> {
    DVector::from_iterator(
        map.len(),
        map.slots.iter().enumerate().map(|(i, slot)| {
            let p = match slot.target {
                Target::Arg(a) => args[a],
                Target::Gray => args[0],
                Target::Scale => scale,
            };
            map.to_unconstrained(i, p)
        }),
    )
}

/// Roughness factors (first lobe, last lobe) and splits of the lobe-sum
/// starts besides the one-lobe fit itself.
const LOBE_SPREADS: [(f64, f64, f64); 6] = [
    (0.5, 2.0, 0.3),
    (0.5, 2.0, 0.6),
    (0.3, 1.5, 0.3),
    (0.3, 1.5, 0.6),
    (0.6, 3.0, 0.3),
    (0.6, 3.0, 0.6),
];

/// The starts of a lobe sum, from its one-lobe fit `base`: first the
/// one-lobe material itself (every lobe at its roughness: the same `f`),
/// then lobes spread narrower and wider around it with different splits.
fn lobe_starts(
    base: &FitReport,
    map: &ParamMap,
    config: &FitConfig,
) -> Vec<([f64; 2], DVector<f64>)> {
    let shape = map.shape;
    let one = Shape { lobes: 1, ..shape };
    let one_args = &base.material_args;
    let at = |a: ShapeArg| one_args[one.index_of(a).expect("a one-lobe argument")];
    let rough = [
        at(ShapeArg::RoughU(0)),
        if shape.kind.is_anisotropic() {
            at(ShapeArg::RoughV(0))
        } else {
            at(ShapeArg::RoughU(0))
        },
    ];
    let lowest = config.min_roughness.max(crate::MIN_ROUGHNESS);
    let clamp = |r: f64| r.clamp(lowest, crate::MAX_ROUGHNESS);
    let n = shape.lobes;
    let start = |factors: &[f64], weights: &[f64]| -> ([f64; 2], DVector<f64>) {
        let mut args = vec![0.0; shape.n_args()];
        args[..4].copy_from_slice(&one_args[..4]);
        for (j, s) in lobe_splits(weights).into_iter().enumerate() {
            args[shape.index_of(ShapeArg::Split(j)).expect("split")] = s;
        }
        for (k, f) in factors.iter().enumerate() {
            args[shape.index_of(ShapeArg::RoughU(k)).expect("rough")] = clamp(rough[0] * f);
            if let Some(v) = shape.index_of(ShapeArg::RoughV(k)) {
                args[v] = clamp(rough[1] * f);
            }
        }
        if let Some(o) = shape.index_of(ShapeArg::Orient) {
            args[o] = at(ShapeArg::Orient);
        }
        let first = [clamp(rough[0] * factors[0]), clamp(rough[1] * factors[0])];
        (first, unconstrained(map, &args, base.scale))
    };
    let even = vec![1.0 / n as f64; n];
    let mut starts = vec![start(&vec![1.0; n], &even)];
    for &(low, high, first) in &LOBE_SPREADS {
        // Factors from `low` to `high`, geometric; the first lobe's share
        // `first`, the rest evenly.
        let factors: Vec<f64> = (0..n)
            .map(|k| low * (high / low).powf(k as f64 / (n - 1) as f64))
            .collect();
        let mut weights = vec![(1.0 - first) / (n - 1) as f64; n];
        weights[0] = first;
        starts.push(start(&factors, &weights));
    }
    starts
}

/// Orientations of the starts of a fitted orientation, degrees.
const START_ORIENTATIONS: [f64; 4] = [0.0, 45.0, 90.0, 135.0];

/// The starts of an anisotropic type with its orientation fitted: each
/// start rougher along u than along v at every orientation of
/// [`START_ORIENTATIONS`] (rougher along v is the same at 90° more), an
/// isotropic start at 0° only.
fn with_orientations(
    starts: Vec<([f64; 2], DVector<f64>)>,
    map: &ParamMap,
) -> Vec<([f64; 2], DVector<f64>)> {
    let Some(slot) = map.slot_of_arg(map.shape.index_of(ShapeArg::Orient).expect("orient")) else {
        return starts;
    };
    let mut turned = Vec::new();
    for (rough, u) in starts {
        if rough[0] < rough[1] {
            continue;
        }
        let angles: &[f64] = if rough[0] > rough[1] {
            &START_ORIENTATIONS
        } else {
            &START_ORIENTATIONS[..1]
        };
        for &angle in angles {
            let mut u = u.clone();
            u[slot] = map.to_unconstrained(slot, angle);
            turned.push((rough, u));
        }
    }
    turned
}

/// The canonical point of the material at `u`, when it is another point:
/// lobes ordered by roughness (geometric mean of u and v), and a fitted
/// orientation in [0°, 180°) with the first lobe rougher along u than
/// along v (the same material at 90° more, u and v swapped).
fn canonical(map: &ParamMap, u: &DVector<f64>) -> Option<DVector<f64>> {
    let shape = map.shape;
    if shape.is_single() {
        return None;
    }
    let p: Vec<f64> = (0..map.len()).map(|i| map.to_physical(i, u[i]).0).collect();
    let (mut args, scale) = map.material_args(&p);
    let index = |a: ShapeArg| shape.index_of(a).expect("the shape's argument");
    let lobe = |args: &[f64], k: usize| -> (f64, Option<f64>) {
        (
            args[index(ShapeArg::RoughU(k))],
            shape.index_of(ShapeArg::RoughV(k)).map(|i| args[i]),
        )
    };
    let splits: Vec<f64> = (0..shape.lobes - 1)
        .map(|j| args[index(ShapeArg::Split(j))])
        .collect();
    let weights = lobe_weights(&splits);
    let mut order: Vec<usize> = (0..shape.lobes).collect();
    let size = |k: usize| {
        let (ru, rv) = lobe(&args, k);
        (ru * rv.unwrap_or(ru)).sqrt()
    };
    order.sort_by(|&a, &b| size(a).total_cmp(&size(b)));
    let old = args.clone();
    for (to, &from) in order.iter().enumerate() {
        let (ru, rv) = lobe(&old, from);
        args[index(ShapeArg::RoughU(to))] = ru;
        if let (Some(v), Some(i)) = (rv, shape.index_of(ShapeArg::RoughV(to))) {
            args[i] = v;
        }
    }
    let sorted: Vec<f64> = order.iter().map(|&k| weights[k]).collect();
    for (j, s) in lobe_splits(&sorted).into_iter().enumerate() {
        args[index(ShapeArg::Split(j))] = s;
    }
    if let Some(o) = shape.index_of(ShapeArg::Orient) {
        let (ru, rv) = lobe(&args, 0);
        if rv.is_some_and(|rv| ru < rv) {
            for k in 0..shape.lobes {
                let (iu, iv) = (index(ShapeArg::RoughU(k)), index(ShapeArg::RoughV(k)));
                args.swap(iu, iv);
            }
            args[o] += 90.0;
        }
        args[o] = args[o].rem_euclid(180.0);
    }
    let moved = args
        .iter()
        .zip(&old)
        .any(|(a, b)| (a - b).abs() > 1e-12 * a.abs().max(1.0));
    moved.then(|| unconstrained(map, &args, scale))
}

/// Lobes of a lobe sum that fewer lobes would describe as well: one with
/// under 1 % of the specularity, or two whose roughnesses differ by under
/// 2 %.
fn collapsed_lobes(shape: Shape, args: &[f64]) -> Vec<FitWarning> {
    if shape.lobes < 2 {
        return Vec::new();
    }
    let index = |a: ShapeArg| shape.index_of(a).expect("the shape's argument");
    let splits: Vec<f64> = (0..shape.lobes - 1)
        .map(|j| args[index(ShapeArg::Split(j))])
        .collect();
    let size = |k: usize| {
        let ru = args[index(ShapeArg::RoughU(k))];
        let rv = shape.index_of(ShapeArg::RoughV(k)).map_or(ru, |i| args[i]);
        (ru * rv).sqrt()
    };
    let mut warnings = Vec::new();
    for (k, &w) in lobe_weights(&splits).iter().enumerate() {
        if w < 0.01 {
            warnings.push(FitWarning::CollapsedLobe {
                lobe: k + 1,
                reason: "weight".into(),
                value: w,
            });
        }
    }
    for k in 0..shape.lobes - 1 {
        let (a, b) = (size(k), size(k + 1));
        let difference = (a - b).abs() / a.max(b);
        if difference < 0.02 {
            warnings.push(FitWarning::CollapsedLobe {
                lobe: k + 1,
                reason: "roughness".into(),
                value: difference,
            });
        }
    }
    warnings
}

/// What the report needs besides the solution.
struct Reported<'a> {
    robust: Option<RobustRecord>,
    label: &'a str,
    data: &'a [IncidenceData],
    n_points: usize,
    floor: f64,
    evaluations: usize,
    records: Vec<StartRecord>,
    started: Instant,
}

impl Reported<'_> {
    /// The report of `solved`: parameters in physical units with both
    /// standard errors, and the warnings.
    fn build(
        self,
        solver: &Solver<'_>,
        blocks: &[Block<'_>],
        solved: Solved,
    ) -> Result<FitReport, FitError> {
        let Solved {
            u,
            cost,
            termination,
            at_solution,
            ..
        } = solved;
        let failed = |reason: &str| FitError::Failed {
            origin: self.label.into(),
            reason: reason.into(),
        };
        let map = solver.map;
        let problem = solver.problem(blocks);
        let (p, dp, material, scale) = problem
            .physical(&u)
            .ok_or_else(|| failed("the solution is not a valid material"))?;
        // The solution's pass from the optimiser's own history.
        let final_pass = at_solution
            .ok_or_else(|| failed("non-finite residuals or Jacobian at the solution"))?;
        let errors = standard_errors(&final_pass, cost, problem.n_residuals(), map.len());
        // No standard error at a bound: the logistic's derivative is ~0
        // there, and a symmetric error bar would mean nothing anyway.
        let physical_error = |i: usize| {
            let known = |e: f64| Some(e * dp[i].abs()).filter(|v| v.is_finite());
            if map.at_bound(i, p[i]) {
                (None, None)
            } else {
                (known(errors.plain[i]), known(errors.robust[i]))
            }
        };

        // Every material argument by name, then the free scale.
        let args = material.args().expect("a fitted material").to_vec();
        let mut params = Vec::new();
        let mut warnings = Vec::new();
        for (a, name) in map.shape.param_names().iter().enumerate() {
            let estimate = match map.slot_of_arg(a) {
                Some(i) => {
                    let (stderr, stderr_robust) = physical_error(i);
                    ParamEstimate {
                        name: name.clone(),
                        value: args[a],
                        stderr,
                        stderr_robust,
                        at_bound: map.at_bound(i, p[i]),
                        fixed: false,
                    }
                }
                None => ParamEstimate {
                    name: name.clone(),
                    value: args[a],
                    stderr: None,
                    stderr_robust: None,
                    at_bound: false,
                    fixed: true,
                },
            };
            if estimate.at_bound {
                warnings.push(FitWarning::AtBound {
                    param: estimate.name.clone(),
                    value: estimate.value,
                });
            }
            params.push(estimate);
        }
        if let Some(i) = map.slots.iter().position(|s| s.target == Target::Scale) {
            let (stderr, stderr_robust) = physical_error(i);
            params.push(ParamEstimate {
                name: "scale".into(),
                value: scale,
                stderr,
                stderr_robust,
                at_bound: map.at_bound(i, p[i]),
                fixed: false,
            });
            warnings.push(FitWarning::FreeScaleColour);
        }
        // Unequal residual variances (multiplicative noise with absolute
        // residuals, or a model that misses the data's shape) make
        // s²(JᵀJ)⁻¹ too small; say so when the sandwich disagrees by more
        // than 2×.
        let understated: Vec<StderrRatio> = params
            .iter()
            .filter_map(|p| match (p.stderr, p.stderr_robust) {
                // A zero plain error (a parameter pinned at a bound) has no
                // finite ratio; JSON has no infinity, so it is not listed.
                (Some(plain), Some(robust))
                    if plain > 0.0 && robust > 2.0 * plain && (robust / plain).is_finite() =>
                {
                    Some(StderrRatio {
                        param: p.name.clone(),
                        ratio: robust / plain,
                    })
                }
                _ => None,
            })
            .collect();
        if !understated.is_empty() {
            warnings.push(FitWarning::UnderstatedErrors {
                params: understated,
            });
        }
        if args[3] < 1e-4 {
            warnings.push(FitWarning::DegenerateLobe);
        }
        warnings.extend(collapsed_lobes(map.shape, &args));
        if let Some(r) = &self.robust
            && !r.settled
        {
            warnings.push(FitWarning::RobustNotSettled { rounds: r.rounds });
        }
        let termination = Termination::from_lm(&termination);
        warnings.extend(FitWarning::not_converged(&termination));

        let single = self.data.len() == 1;
        let first = &self.data[0];
        Ok(FitReport {
            source: self.label.into(),
            theta_in: if single { first.theta_in } else { 0.0 },
            phi_in: if single { first.phi_in } else { 0.0 },
            params,
            material_args: args,
            scale,
            n_points: self.n_points,
            gates: if single {
                first.gates.clone()
            } else {
                Vec::new()
            },
            weighting: first.weighting,
            rms_rel: final_pass.rms_rel,
            e1: problem.e1(&u),
            cost,
            floor: self.floor,
            termination,
            evaluations: self.evaluations,
            elapsed_ms: self.started.elapsed().as_secs_f64() * 1e3,
            starts: self.records,
            warnings,
            adequacy: None,
            robust: self.robust,
        })
    }
}
