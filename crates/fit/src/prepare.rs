//! From an incidence's samples to what the fitter needs, in one pass over
//! the samples (they are large, so every extra pass costs memory
//! bandwidth): the data checks, the fitter's [`Block`], and the statistics
//! behind the automatic floor and the starting values.

use crate::config::{FitConfig, FitError};
use crate::data::{FitSample, IncidenceData};
use crate::params::{MIN_ROUGHNESS, ParamMap, Target};
use crate::problem::Block;
use brtf_model::GeometryBatch;
use glam::DVec3;
use nalgebra::DVector;
use rayon::prelude::*;
use std::borrow::Cow;
use std::cell::RefCell;
use std::f64::consts::PI;

/// Samples per piece of the pass; pieces run in parallel on large files.
const PIECE: usize = 8192;
/// Incidences with at least this many samples are scanned in parallel.
const PARALLEL_SAMPLES: usize = 16_384;
/// Half-angle around the mirror direction searched for the peak.
const PEAK_CONE_RAD: f64 = 0.5;

/// One incidence after the pass.
pub(crate) struct Scan<'a> {
    /// The fitter's samples (residual factors not yet set).
    pub block: Block<'a>,
    /// Statistics for the floor and the starting values.
    pub stats: ScanStats,
}

/// What the starting values and the automatic floor are read from, kept
/// in the pass's pieces: joining them would cost fresh memory, and fresh
/// pages are dear.
pub(crate) struct ScanStats {
    pieces: Vec<Piece>,
    /// The incidence's θ_in in degrees and cos θ_in.
    theta_in: f64,
    cos_in: f64,
}

/// One piece's share of the pass.
#[derive(Default)]
struct Piece {
    /// Every positive value, all channels.
    positive: Vec<f64>,
    /// Channel means of the front (v.z > 0) and back (v.z < 0) samples.
    front: Vec<f64>,
    back: Vec<f64>,
    /// (cosine to the mirror direction, channel mean) of the front
    /// samples within [`PEAK_CONE_RAD`] of it.
    near: Vec<(f64, f64)>,
    /// Per-channel sums over the front samples.
    front_sums: [f64; 3],
    weight_sum: f64,
    /// Index of the first sample with a non-finite value or weight.
    non_finite: Option<usize>,
}

thread_local! {
    /// Scratch for the order statistics, kept between fits so that each
    /// fit does not fault in fresh pages for a throw-away copy.
    static SCRATCH: RefCell<Vec<f64>> = const { RefCell::new(Vec::new()) };
}

/// The value at rank `rank(len)` of `values` (or `None` when there are
/// none), by selection in the thread's scratch buffer.
fn order_statistic(
    values: impl Iterator<Item = f64>,
    rank: impl Fn(usize) -> usize,
) -> Option<f64> {
    SCRATCH.with_borrow_mut(|all| {
        all.clear();
        all.extend(values);
        if all.is_empty() {
            return None;
        }
        let k = rank(all.len());
        Some(*all.select_nth_unstable_by(k, f64::total_cmp).1)
    })
}

/// Checks, prepares and summarises one incidence in one pass.
///
/// Weights are normalised to average 1, so the cost reads like an
/// unweighted sum and, in the all-incidence fit, every incidence counts
/// the same; without any positive weight every sample weighs 1.
pub(crate) fn scan<'a>(
    d: &'a IncidenceData,
    channels: usize,
    config: &FitConfig,
) -> Result<Scan<'a>, FitError> {
    let n = d.samples.len();
    if n == 0 {
        let gates: Vec<String> = d
            .gates
            .iter()
            .map(|g| format!("{} removed {}", g.gate, g.removed))
            .collect();
        return Err(FitError::EmptySelection {
            origin: d.source.clone(),
            gates: if gates.is_empty() {
                "none".into()
            } else {
                gates.join(", ")
            },
        });
    }
    let light = d.light();
    let mirror = DVec3::new(-light.x, -light.y, light.z);
    let near_cosine = PEAK_CONE_RAD.cos();
    let work = |(index, samples): (usize, &[FitSample])| {
        let mut piece = Piece {
            positive: Vec::with_capacity(samples.len() * channels),
            front: Vec::with_capacity(samples.len()),
            ..Piece::default()
        };
        for (i, s) in samples.iter().enumerate() {
            let value = &s.value[..channels];
            if piece.non_finite.is_none()
                && (!s.weight.is_finite() || value.iter().any(|v| !v.is_finite()))
            {
                piece.non_finite = Some(index * PIECE + i);
            }
            piece.weight_sum += s.weight.max(0.0);
            for &v in value {
                if v > 0.0 {
                    piece.positive.push(v);
                }
            }
            let mean = channel_mean(s, channels);
            if s.view.z > 0.0 {
                piece.front.push(mean);
                for (sum, v) in piece.front_sums.iter_mut().zip(value) {
                    *sum += v;
                }
                let cosine = s.view.dot(mirror);
                if cosine > near_cosine {
                    piece.near.push((cosine, mean));
                }
            } else if s.view.z < 0.0 {
                piece.back.push(mean);
            }
        }
        piece
    };
    let pieces: Vec<Piece> = if n >= PARALLEL_SAMPLES {
        d.samples.par_chunks(PIECE).enumerate().map(work).collect()
    } else {
        d.samples.chunks(PIECE).enumerate().map(work).collect()
    };
    if let Some(index) = pieces.iter().find_map(|p| p.non_finite) {
        return Err(FitError::NonFinite {
            origin: d.source.clone(),
            index,
        });
    }
    if pieces.iter().all(|p| p.positive.is_empty()) {
        return Err(FitError::AllZero {
            origin: d.source.clone(),
            count: n,
        });
    }
    if config.kind.is_transmitting() && pieces.iter().all(|p| p.back.is_empty()) {
        return Err(FitError::NoTransmission {
            origin: d.source.clone(),
            kind: config.kind,
        });
    }
    let weight_sum: f64 = pieces.iter().map(|p| p.weight_sum).sum();
    let unit_weights = weight_sum <= 0.0;
    Ok(Scan {
        block: Block {
            light,
            samples: Cow::Borrowed(&d.samples),
            pairs: d.patch_pairs.as_deref().map(Cow::Borrowed),
            pair_geometry: None,
            sample_geometry: None,
            weight_scale: if unit_weights {
                1.0
            } else {
                (n as f64 / weight_sum).sqrt()
            },
            unit_weights,
            multipliers: None,
            factors: Vec::new(),
            log_values: Vec::new(),
            channels,
            cosine_weighted: d.cosine_weighted,
            energy_weights: Vec::new(),
            energy_rows: Vec::new(),
        },
        stats: ScanStats {
            pieces,
            theta_in: d.theta_in,
            cos_in: light.z.abs().max(0.05),
        },
    })
}

/// 10% of the 10th percentile of the positive values of every incidence:
/// below this, values count as noise for relative and log residuals.
pub(crate) fn auto_floor(stats: &[ScanStats]) -> f64 {
    let values = stats
        .iter()
        .flat_map(|s| s.pieces.iter().flat_map(|p| p.positive.iter().copied()));
    let tenth = order_statistic(values, |len| len / 10).unwrap_or(1e-5);
    (0.1 * tenth).max(1e-12)
}

/// The mean of a sample's first `channels` values: its brightness.
fn channel_mean(s: &FitSample, channels: usize) -> f64 {
    s.value[..channels].iter().sum::<f64>() / channels as f64
}

/// The channel mean of the `count`-th brightest sample of `b` (minus
/// infinity when it has no more samples than that).
pub(crate) fn bright_threshold(b: &Block<'_>, count: usize) -> f64 {
    let channels = b.channels;
    if count == 0 || count >= b.len() {
        return f64::NEG_INFINITY;
    }
    let means = b.samples.iter().map(|s| channel_mean(s, channels));
    order_statistic(means, |len| len - count).unwrap_or(f64::NEG_INFINITY)
}

/// A subsample standing for the whole block: every sample at least as
/// bright as `bright` (the lobe, which decides specularity and roughness,
/// however few samples it covers) at its own weight, and every `step`-th
/// of the others at `step` times theirs, so the cost stays an estimate of
/// the whole block's.
pub(crate) fn subsample<'a>(b: &Block<'_>, target: usize, bright: f64) -> Block<'a> {
    let step = (b.len() / target.max(1)).max(1);
    let channels = b.channels;
    let mut samples = Vec::new();
    let mut kept = Vec::new();
    let mut multipliers = Vec::new();
    let mut factors = Vec::new();
    let mut log_values = Vec::new();
    let mut energy_weights = Vec::new();
    let expand = (step as f64).sqrt();
    for (i, s) in b.samples.iter().enumerate() {
        let mean = channel_mean(s, channels);
        let m = if mean >= bright {
            1.0
        } else if i % step == 0 {
            expand
        } else {
            continue;
        };
        samples.push(*s);
        kept.push(i);
        if let Some(w) = b.energy_weights.get(i) {
            energy_weights.push(w * m * m);
        }
        multipliers.push(m * b.multipliers.as_ref().map_or(1.0, |r| r[i]));
        factors.extend(
            b.factors[i * channels..(i + 1) * channels]
                .iter()
                .map(|k| k * m),
        );
        if !b.log_values.is_empty() {
            log_values.extend_from_slice(&b.log_values[i * channels..(i + 1) * channels]);
        }
    }
    let mut sub = Block {
        light: b.light,
        samples: Cow::Owned(samples),
        pairs: b
            .pairs
            .as_ref()
            .map(|p| Cow::Owned(p.select(kept.iter().copied()))),
        pair_geometry: b
            .pair_geometry
            .as_ref()
            .map(|g| Cow::Owned(g.select(kept.iter().copied()))),
        sample_geometry: b.sample_geometry.as_ref().map(|g| {
            let mut selected = GeometryBatch::with_capacity(kept.len());
            selected.extend(kept.iter().map(|&i| g.get(i)));
            Cow::Owned(selected)
        }),
        weight_scale: b.weight_scale,
        unit_weights: b.unit_weights,
        multipliers: Some(multipliers),
        factors,
        log_values,
        channels,
        cosine_weighted: b.cosine_weighted,
        energy_weights,
        energy_rows: Vec::new(),
    };
    sub.set_energy_rows();
    sub
}

/// Lobe features read off the data of one incidence.
struct DataFeatures {
    /// Diffuse reflectance estimate (π × a low percentile).
    diffuse: f64,
    /// Peak height above the floor, in the data's unit.
    peak: f64,
    /// Angle (rad) from the mirror direction where the lobe falls to 1/e.
    width: f64,
    /// cos θ_in.
    cos_in: f64,
    /// Transmission estimate (back hemisphere).
    transmission: f64,
}

/// The `q` quantile (by rank `⌊(len − 1) q⌋`) of the concatenated parts.
fn quantile<'p>(parts: impl Iterator<Item = &'p [f64]>, q: f64) -> f64 {
    let values = parts.flat_map(|p| p.iter().copied());
    order_statistic(values, |len| ((len - 1) as f64 * q) as usize).unwrap_or(0.0)
}

fn features(s: &ScanStats) -> DataFeatures {
    let floor = quantile(s.pieces.iter().map(|p| p.front.as_slice()), 0.2).max(0.0);
    // The peak: the largest value near the mirror direction (compared as
    // cosines; the angle is taken once, for the width).
    let near = || s.pieces.iter().flat_map(|p| p.near.iter());
    let peak = near().map(|(_, y)| *y).fold(0.0, f64::max) - floor;
    let threshold = floor + peak / std::f64::consts::E;
    let widest = near()
        .filter(|(_, y)| *y >= threshold)
        .map(|(cos_delta, _)| *cos_delta)
        .fold(1.0, f64::min);
    let width = widest.clamp(-1.0, 1.0).acos().max(0.005);
    let back_median = quantile(s.pieces.iter().map(|p| p.back.as_slice()), 0.5).max(0.0);
    DataFeatures {
        diffuse: (PI * floor).min(1.0),
        peak: peak.max(0.0),
        width,
        cos_in: s.cos_in,
        transmission: (PI * back_median).min(1.0),
    }
}

/// Starting points: the data-driven roughness first, then a roughness
/// grid. Each start derives the amplitudes from the data for its roughness.
pub(crate) fn starting_points(
    stats: &[ScanStats],
    map: &ParamMap,
    config: &FitConfig,
    channels: usize,
) -> Vec<([f64; 2], DVector<f64>)> {
    // Features of the incidence closest to 30° stand for all of them.
    let reference = stats
        .iter()
        .min_by(|a, b| {
            (a.theta_in - 30.0)
                .abs()
                .total_cmp(&(b.theta_in - 30.0).abs())
        })
        .expect("at least one incidence");
    let f = features(reference);
    // Starts below a raised roughness bound (Klems fits) would all start
    // at the bound: one start there is enough.
    let lowest = config.min_roughness.max(MIN_ROUGHNESS);
    let alpha0 = (0.5 * f.width).clamp(MIN_ROUGHNESS * 2.0, 0.5).max(lowest);
    let mut roughs: Vec<[f64; 2]> = vec![[alpha0, alpha0]];
    if config.multistart {
        let grid = [0.01_f64, 0.03, 0.08, 0.2, 0.4];
        if config.kind.is_anisotropic() {
            for &a in &[0.02_f64, 0.08, 0.25] {
                for &b in &[0.02_f64, 0.08, 0.25] {
                    let start = [a.max(lowest), b.max(lowest)];
                    if !roughs.contains(&start) {
                        roughs.push(start);
                    }
                }
            }
        } else {
            for &a in &grid {
                let a = a.max(lowest);
                if roughs.iter().all(|r| (a / r[0]).ln().abs() > 0.3) {
                    roughs.push([a, a]);
                }
            }
        }
    }
    // Colour ratios of the front data.
    let mut sums = [0.0; 3];
    for p in &reference.pieces {
        for (total, part) in sums.iter_mut().zip(p.front_sums) {
            *total += part;
        }
    }
    let total: f64 = sums[..channels].iter().sum::<f64>().max(1e-300);
    let means = if channels == 3 {
        sums.map(|mc| 3.0 * mc / total)
    } else {
        [1.0; 3]
    };
    roughs
        .into_iter()
        .map(|rough| {
            let alpha2 = rough[0] * rough[1];
            // W-G-M-D peak height at the mirror direction: S/(4π α² cos²θ_in).
            let spec_amp = (f.peak * 4.0 * PI * alpha2 * f.cos_in * f.cos_in).max(1e-4);
            let total = (f.diffuse + spec_amp).max(1e-6);
            let mut phys = Vec::new();
            for slot in &map.slots {
                let value = match slot.target {
                    Target::Scale => total,
                    Target::Gray => total.min(0.95),
                    Target::Arg(a) if a < 3 => (total * means[a]).min(0.95),
                    Target::Arg(3) => {
                        let spec = if config.free_scale || config.kind.is_metal() {
                            spec_amp / total
                        } else {
                            spec_amp
                        };
                        spec.clamp(0.01, 0.95)
                    }
                    Target::Arg(_) if slot.name == "rough" || slot.name == "rough_u" => rough[0],
                    Target::Arg(_) if slot.name == "rough_v" => rough[1],
                    Target::Arg(_) if slot.name == "trans" => f.transmission.clamp(0.05, 0.9),
                    Target::Arg(_) => 0.5,
                };
                phys.push(value);
            }
            let u = DVector::from_iterator(
                phys.len(),
                phys.iter()
                    .enumerate()
                    .map(|(i, &p)| map.to_unconstrained(i, p)),
            );
            (rough, u)
        })
        .collect()
}
