//! The least-squares problem handed to the levenberg-marquardt crate:
//! residuals and the exact Jacobian from brtf-model's analytic gradients,
//! in the unconstrained coordinates of [`ParamMap`].

use crate::data::{FitSample, PatchPairs};
use crate::gram::{self, RunColumns};
use crate::lobes::{LobeModel, LobeTerms};
use crate::pair_geometry::PairGeometry;
use crate::params::{ParamMap, Target};
use brtf_model::{Bsdf, Composite, EvalOptions, GeometryBatch, Gradient, PairTerms};
use glam::DVec3;
use levenberg_marquardt::LeastSquaresProblem;
use nalgebra::{DMatrix, DVector, Dyn, Owned};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::borrow::Cow;
use std::cell::{Cell, RefCell};
use std::ops::Range;

/// How a model value m is compared with a measured value y.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum ResidualKind {
    /// `m − y` in the file's own quantity (times |cos θ_out| for a raw
    /// signal or DSF, whose values are the BSDF times it), weighted by
    /// solid angle: the squared error integrated over the sphere, in the
    /// quantity the instrument measured. The peak counts most, and the
    /// fitted lobe keeps the data's energy even when the model cannot
    /// follow the data's shape. The default.
    #[default]
    Absolute,
    /// `(m − y) / sqrt(y² + floor²)`: every direction counts alike; right
    /// for multiplicative noise on top of a noise floor when the model can
    /// describe the data exactly.
    Relative,
    /// `ln(m + floor) − ln(max(y, 0) + floor)`.
    Log,
}

brtf_model::option_words!(ResidualKind {
    Absolute => "absolute",
    Relative => "relative",
    Log => "log",
});

/// The samples of one incidence, ready for the inner loop.
#[derive(Debug, Clone)]
pub(crate) struct Block<'a> {
    /// Unit vector towards the light.
    pub light: DVec3,
    /// The samples, borrowed from the caller (owned for a subsample).
    pub samples: Cow<'a, [FitSample]>,
    /// Patch-averaged data: the (light, view) pairs each sample's model
    /// value is averaged over (then `light` and the samples' views are
    /// not used by the kernel).
    pub pairs: Option<Cow<'a, PatchPairs>>,
    /// The pairs' geometry, computed once (see [`PairGeometry`]); without
    /// it the kernel computes it from `pairs` on every pass.
    pub pair_geometry: Option<Cow<'a, PairGeometry>>,
    /// Measured samples: each sample's (light, view) geometry, computed
    /// once per fit (it does not depend on the arguments); without it the
    /// kernel computes it on every pass.
    pub sample_geometry: Option<Cow<'a, GeometryBatch>>,
    /// √(weight) of sample i is `√max(wᵢ, 0) · weight_scale` (or
    /// `weight_scale` alone with `unit_weights`), times `multipliers[i]`
    /// when a robust loss has reweighted the samples or a subsample stands
    /// for more samples than it holds.
    pub weight_scale: f64,
    pub unit_weights: bool,
    pub multipliers: Option<Vec<f64>>,
    /// Per value (sample × channel), the factor turning `m − y` into a
    /// residual.
    pub factors: Vec<f64>,
    /// Per value, `ln(max(y, 0) + floor)` for [`ResidualKind::Log`] (empty
    /// for the other kinds): the data's side of every log residual.
    pub log_values: Vec<f64>,
    pub channels: usize,
    /// E1 weighs each sample's misfit by |cos θ_out| (see
    /// [`crate::IncidenceData::cosine_weighted`]).
    pub cosine_weighted: bool,
    /// [`crate::EnergyRule::Exact`]: sample i's weight in its side's
    /// energy integral (its solid angle × |cos θ_out|, times the samples
    /// a subsample's sample stands for); empty when the energy is free.
    pub energy_weights: Vec<f64>,
    /// The energy rows made from `energy_weights` (see
    /// [`Block::set_energy_rows`]).
    pub energy_rows: Vec<EnergyRow>,
}

/// One penalty row of [`crate::EnergyRule::Exact`]: for one side and
/// channel, `factor · (Σ w m − data)` over the block's samples on that
/// side (w its energy weight, m the model's value).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct EnergyRow {
    /// 0: the front (reflection), 1: the back (transmission).
    pub side: usize,
    pub channel: usize,
    /// Σ w y, the data's energy over the block's samples on the side.
    pub data: f64,
    /// Turns the misfit in energy into a residual: stiff against the
    /// block's data residuals (see [`ENERGY_STIFFNESS`]).
    pub factor: f64,
}

/// An energy row's weight against the block's data residuals: the row is
/// the relative misfit in energy times this times the residuals' own
/// scale (the root of their sum of squares with a zero model), so a
/// model pulled off the data's energy by the shape's residuals misses it
/// by about 1e-6 relative.
const ENERGY_STIFFNESS: f64 = 1e3;

/// Energies below this fraction of the covered projected solid angle
/// (÷ π) count as this: a side with almost no light is held to the same
/// absolute closeness, not to a relative one it cannot see (the floor of
/// the export's energy check).
const ENERGY_FLOOR: f64 = 0.02;

/// The side of a sample: 0 front, 1 back.
#[inline(always)]
fn side_of(s: &FitSample) -> usize {
    usize::from(s.view.z < 0.0)
}

impl Block<'_> {
    pub(crate) fn len(&self) -> usize {
        self.samples.len()
    }

    /// Recomputes the residual factors for `kind` and `floor` (in
    /// parallel pieces for large blocks; each factor depends on its own
    /// sample only, so the result does not depend on the split).
    pub(crate) fn set_factors(&mut self, kind: ResidualKind, floor: f64) {
        let channels = self.channels;
        let mut factors = std::mem::take(&mut self.factors);
        factors.resize(self.samples.len() * channels, 0.0);
        let this = &*self;
        let fill = |(piece, out): (usize, &mut [f64])| {
            let first = piece * FACTOR_PIECE;
            let samples = &this.samples[first..first + out.len() / channels];
            for (i, (s, out)) in samples
                .iter()
                .zip(out.chunks_exact_mut(channels))
                .enumerate()
            {
                let sw = this.sqrt_weight(first + i, s);
                // Absolute residuals are taken in the file's own quantity:
                // for a raw signal or DSF, the BSDF times |cos θ_out|.
                let cosine = if this.cosine_weighted {
                    s.view.z.abs()
                } else {
                    1.0
                };
                for (o, &y) in out.iter_mut().zip(&s.value[..channels]) {
                    *o = match kind {
                        ResidualKind::Relative => sw / (y * y + floor * floor).sqrt(),
                        ResidualKind::Absolute => sw * cosine,
                        ResidualKind::Log => sw,
                    };
                }
            }
        };
        if self.samples.len() >= PARALLEL_ROWS {
            factors
                .par_chunks_mut(FACTOR_PIECE * channels)
                .enumerate()
                .for_each(fill);
        } else {
            factors
                .chunks_mut(FACTOR_PIECE * channels)
                .enumerate()
                .for_each(fill);
        }
        self.factors = factors;
        // The data's side of every log residual, written in place (one
        // value per sample and channel; no allocation per sample).
        let mut log_values = std::mem::take(&mut self.log_values);
        if kind == ResidualKind::Log {
            log_values.resize(self.samples.len() * channels, 0.0);
            let samples = &self.samples;
            let fill = |(piece, out): (usize, &mut [f64])| {
                let first = piece * FACTOR_PIECE;
                for (s, out) in samples[first..].iter().zip(out.chunks_exact_mut(channels)) {
                    for (o, &y) in out.iter_mut().zip(&s.value[..channels]) {
                        *o = (y.max(0.0) + floor).ln();
                    }
                }
            };
            if self.samples.len() >= PARALLEL_ROWS {
                log_values
                    .par_chunks_mut(FACTOR_PIECE * channels)
                    .enumerate()
                    .for_each(fill);
            } else {
                log_values
                    .chunks_mut(FACTOR_PIECE * channels)
                    .enumerate()
                    .for_each(fill);
            }
        } else {
            log_values.clear();
        }
        self.log_values = log_values;
        self.set_energy_rows();
    }

    /// Sets the energy weights of [`crate::EnergyRule::Exact`] (each
    /// sample's solid angle × |cos θ_out|), or clears them for
    /// [`crate::EnergyRule::Free`], and makes the rows.
    pub(crate) fn set_energy(&mut self, rule: crate::EnergyRule) {
        self.energy_weights = match rule {
            crate::EnergyRule::Free => Vec::new(),
            crate::EnergyRule::Exact => self
                .samples
                .iter()
                .map(|s| s.weight.max(0.0) * s.view.z.abs())
                .collect(),
        };
        self.set_energy_rows();
    }

    /// The energy rows from `energy_weights`, the samples and the
    /// residual factors (which scale the rows: call after
    /// [`Block::set_factors`], which does).
    pub(crate) fn set_energy_rows(&mut self) {
        self.energy_rows.clear();
        if self.energy_weights.is_empty() {
            return;
        }
        let channels = self.channels;
        let log = !self.log_values.is_empty();
        // The data residuals' scale: their root sum of squares for a zero
        // model (log residuals: their factors).
        let mut scale2 = 0.0;
        let mut data = [[0.0; 3]; 2];
        let mut covered = [0.0; 2];
        let mut present = [false; 2];
        for (i, (s, &w)) in self.samples.iter().zip(&self.energy_weights).enumerate() {
            let side = side_of(s);
            present[side] = true;
            covered[side] += w;
            for (ch, (&y, total)) in s
                .value
                .iter()
                .zip(&mut data[side])
                .take(channels)
                .enumerate()
            {
                let k = self.factors.get(i * channels + ch).copied().unwrap_or(0.0);
                scale2 += if log { k * k } else { k * k * y * y };
                *total += w * y;
            }
        }
        let stiffness = ENERGY_STIFFNESS * scale2.sqrt().max(f64::MIN_POSITIVE);
        for side in 0..2 {
            if !present[side] {
                continue;
            }
            for (channel, &d) in data[side][..channels].iter().enumerate() {
                let unit = d
                    .abs()
                    .max(ENERGY_FLOOR * covered[side] / std::f64::consts::PI);
                if unit > 0.0 && unit.is_finite() {
                    self.energy_rows.push(EnergyRow {
                        side,
                        channel,
                        data: d,
                        factor: stiffness / unit,
                    });
                }
            }
        }
    }

    /// The energy rows' squared residuals for model energies `energy`
    /// (`[side][channel]`, Σ w m over the block's samples).
    fn energy_squares(&self, energy: &[[f64; 3]; 2]) -> f64 {
        self.energy_rows
            .iter()
            .map(|row| {
                let r = row.factor * (energy[row.side][row.channel] - row.data);
                r * r
            })
            .sum()
    }

    /// The data's log of value `row` (see `log_values`), or NaN for
    /// the other residual kinds, which do not use it.
    #[inline(always)]
    fn log_value(&self, row: usize) -> f64 {
        self.log_values.get(row).copied().unwrap_or(f64::NAN)
    }

    /// √(weight) of sample `i`.
    #[inline]
    fn sqrt_weight(&self, i: usize, s: &FitSample) -> f64 {
        let base = if self.unit_weights {
            1.0
        } else {
            s.weight.max(0.0).sqrt()
        };
        base * self.weight_scale * self.multipliers.as_ref().map_or(1.0, |r| r[i])
    }
}

/// Samples per parallel piece of [`Block::set_factors`].
const FACTOR_PIECE: usize = 8192;

pub(crate) struct Problem<'a> {
    pub map: &'a ParamMap,
    pub options: EvalOptions,
    pub orientation: DVec3,
    pub blocks: &'a [Block<'a>],
    pub channels: usize,
    pub kind: ResidualKind,
    pub floor: f64,
    pub u: DVector<f64>,
    pub evaluations: Cell<usize>,
    /// A pass of the final fit, whose numbers the report uses: also
    /// accumulate `Σ rᵢ² Jᵢ Jᵢᵀ` (the sandwich standard errors' middle)
    /// and `rms_rel`, which the other stages do not need.
    pub report: bool,
    /// Every compressed evaluation so far, by point: LM asks for the
    /// Jacobian of its last accepted point, and the fit's final report
    /// needs the triangle at the solution; neither needs a new pass.
    pub history: RefCell<Vec<(DVector<f64>, Compressed)>>,
    /// The large-residual correction of LM's Hessian, when the stage uses
    /// one (see [`Secant`]).
    pub secant: Option<RefCell<Secant>>,
    /// The caller's stop request: no pass runs once it is raised.
    pub stop: crate::StopFlag,
}

impl<'a> Problem<'a> {
    /// The problem over `blocks` for `config`, at the origin of `u`.
    pub(crate) fn new(
        map: &'a ParamMap,
        config: &crate::FitConfig,
        orientation: DVec3,
        blocks: &'a [Block<'a>],
        channels: usize,
        floor: f64,
    ) -> Problem<'a> {
        Problem {
            map,
            options: config.options,
            orientation,
            blocks,
            channels,
            kind: config.residual,
            floor,
            u: DVector::zeros(map.len()),
            evaluations: Cell::new(0),
            report: false,
            history: RefCell::new(Vec::new()),
            secant: None,
            stop: config.stop.clone(),
        }
    }

    pub(crate) fn n_residuals(&self) -> usize {
        self.blocks.iter().map(Block::len).sum::<usize>() * self.channels
    }

    /// Physical parameters, their derivatives dp/du, the material and scale.
    pub(crate) fn physical(
        &self,
        u: &DVector<f64>,
    ) -> Option<(Vec<f64>, Vec<f64>, Composite, f64)> {
        let (p, dp): (Vec<f64>, Vec<f64>) = (0..self.map.len())
            .map(|i| self.map.to_physical(i, u[i]))
            .unzip();
        let (args, scale) = self.map.material_args(&p);
        let material = Composite::new(self.map.shape, &args, Some(self.orientation)).ok()?;
        Some((p, dp, material, scale))
    }

    /// Every residual, in sample order (for robust reweighting and reports).
    pub(crate) fn residual_vector(&self, u: &DVector<f64>) -> Option<DVector<f64>> {
        match self.pass::<false>(u)? {
            Pass::Full { residuals } => Some(residuals),
            Pass::Compressed { .. } => None,
        }
    }

    /// The least-squares problem at `u` compressed to n + 1 rows.
    ///
    /// With `A = [J | r]` (m × (n + 1)) and its QR factorisation
    /// `A = Q [[R, z], [0, ρ]]`, the short residual vector `(z, ρ)` and
    /// Jacobian `[R; 0]` have the same cost `½‖r‖²`, the same gradient
    /// `Jᵀr`, the same column norms and the same linearised model
    /// `‖r + J δ‖²` as the full problem. Levenberg-Marquardt therefore
    /// takes exactly the same steps on it, while each of its iterations
    /// factorises an (n + 1) × n matrix instead of an m × n one. The
    /// triangle comes from the Gram matrix of `A`, accumulated chunk by
    /// chunk as the samples are evaluated, so the m × n Jacobian is never
    /// stored (see `augmented_cholesky`).
    pub(crate) fn compressed(&self, u: &DVector<f64>) -> Option<Compressed> {
        match self.pass::<true>(u)? {
            Pass::Compressed {
                triangle,
                rms_rel,
                meat,
            } => {
                let n = self.map.len();
                let residuals = DVector::from_column_slice(&triangle[n * (n + 1)..]);
                let jacobian = DMatrix::from_column_slice(n + 1, n, &triangle[..n * (n + 1)]);
                Some(Compressed {
                    residuals,
                    jacobian,
                    rms_rel,
                    meat,
                    model: None,
                })
            }
            Pass::Full { .. } => None,
        }
    }

    /// The pass kernel at `u` and the fixed chunks of the samples.
    fn kernel(&self, u: &DVector<f64>) -> Option<(Kernel<'_>, Vec<Chunk>)> {
        let (_, dp, material, scale) = self.physical(u)?;
        let mut chunks: Vec<Chunk> = Vec::new();
        for (b, block) in self.blocks.iter().enumerate() {
            let mut start = 0;
            while start < block.len() {
                let end = (start + CHUNK).min(block.len());
                chunks.push((b, start, end));
                start = end;
            }
        }
        let model = match material.single() {
            Some(m) if self.map.shape.is_single() => Model::Single(Bsdf::new(m, &self.options)),
            _ => Model::Lobes(LobeModel::new(self.map.shape, &material, &self.options)),
        };
        let kernel = Kernel {
            model,
            columns: self
                .map
                .slots
                .iter()
                .zip(&dp)
                .map(|(s, &d)| (s.target, d))
                .collect(),
            scale,
            floor: self.floor,
            kind: self.kind,
            channels: self.channels,
            blocks: self.blocks,
        };
        Some((kernel, chunks))
    }

    /// E1 at `u`: `Σ ω c |m − d| / Σ ω c |d|` over every sample and
    /// channel, ω the sample's weight, c its |cos θ_out| for cosine-weighted
    /// data (see [`crate::FitReport::e1`]); `None` when not finite.
    pub(crate) fn e1(&self, u: &DVector<f64>) -> Option<f64> {
        let (misfit, total) = self.e1_parts(u)?;
        let e1 = misfit / total;
        e1.is_finite().then_some(e1)
    }

    /// E1's numerator and denominator at `u` (see [`Problem::e1`]).
    pub(crate) fn e1_parts(&self, u: &DVector<f64>) -> Option<(f64, f64)> {
        let (kernel, chunks) = self.kernel(u)?;
        let (blocks, channels) = (self.blocks, self.channels);
        let sums = |&(b, start, end): &Chunk| -> (f64, f64) {
            let block = &blocks[b];
            let (mut misfit, mut total) = (0.0, 0.0);
            kernel.for_each_value(block, start..end, |i, f| {
                let s = &block.samples[i];
                let weight = if block.unit_weights {
                    1.0
                } else {
                    s.weight.max(0.0)
                };
                let c = if block.cosine_weighted {
                    s.view.z.abs()
                } else {
                    1.0
                };
                for (&m, &y) in f.iter().zip(&s.value).take(channels) {
                    misfit += weight * c * (kernel.scale * m - y).abs();
                    total += weight * c * y.abs();
                }
            });
            (misfit, total)
        };
        let parts: Vec<(f64, f64)> = if self.n_residuals() >= PARALLEL_ROWS {
            chunks.par_iter().map(sums).collect()
        } else {
            chunks.iter().map(sums).collect()
        };
        Some(
            parts
                .iter()
                .fold((0.0, 0.0), |(m, t), (a, b)| (m + a, t + b)),
        )
    }

    /// The cost ½‖r‖² at `u` (`None` when a residual is not finite), from
    /// one pass that keeps neither the residuals nor the relative errors:
    /// what choosing among candidates needs. Summed per chunk, then over
    /// the chunks in order, so the result does not depend on the threads.
    pub(crate) fn cost(&self, u: &DVector<f64>) -> Option<f64> {
        let (kernel, chunks) = self.kernel(u)?;
        let squares = |chunk: &Chunk| kernel.squares(*chunk);
        let parts: Vec<(f64, [[f64; 3]; 2])> = if self.n_residuals() >= PARALLEL_ROWS {
            chunks.par_iter().map(squares).collect()
        } else {
            chunks.iter().map(squares).collect()
        };
        self.evaluations.set(self.evaluations.get() + 1);
        let mut sum: f64 = parts.iter().map(|p| p.0).sum();
        // The energy rows, from each block's energies summed over its chunks.
        let mut energy = [[0.0; 3]; 2];
        for (k, (&(b, _, _), part)) in chunks.iter().zip(&parts).enumerate() {
            for (total, value) in energy.iter_mut().flatten().zip(part.1.iter().flatten()) {
                *total += value;
            }
            if chunks.get(k + 1).is_none_or(|next| next.0 != b) {
                sum += self.blocks[b].energy_squares(&energy);
                energy = [[0.0; 3]; 2];
            }
        }
        sum.is_finite().then_some(0.5 * sum)
    }

    /// One pass over the data: with `COMPRESS`, values and gradients
    /// reduced to the triangle of `[J | r]`; without, the residuals alone.
    /// Also the unweighted RMS of `(m − y)/sqrt(y² + floor²)`, reported
    /// as `rms_rel`. Large problems are split into fixed chunks evaluated
    /// in parallel; the chunking and the order of the reductions do not
    /// depend on the thread count, so results are deterministic.
    fn pass<const COMPRESS: bool>(&self, u: &DVector<f64>) -> Option<Pass> {
        let (kernel, chunks) = self.kernel(u)?;
        let n = self.map.len();
        let width = n + 1;
        let m = self.n_residuals();
        let report = self.report;
        let run_chunk = |chunk: &Chunk| -> ChunkResult {
            if !COMPRESS {
                return kernel.residuals(*chunk);
            }
            match (width, report) {
                (2, false) => kernel.gram::<2, false>(*chunk),
                (2, true) => kernel.gram::<2, true>(*chunk),
                (3, false) => kernel.gram::<3, false>(*chunk),
                (3, true) => kernel.gram::<3, true>(*chunk),
                (4, false) => kernel.gram::<4, false>(*chunk),
                (4, true) => kernel.gram::<4, true>(*chunk),
                (5, false) => kernel.gram::<5, false>(*chunk),
                (5, true) => kernel.gram::<5, true>(*chunk),
                (6, false) => kernel.gram::<6, false>(*chunk),
                (6, true) => kernel.gram::<6, true>(*chunk),
                (7, false) => kernel.gram::<7, false>(*chunk),
                (7, true) => kernel.gram::<7, true>(*chunk),
                (8, false) => kernel.gram::<8, false>(*chunk),
                (8, true) => kernel.gram::<8, true>(*chunk),
                (9, false) => kernel.gram::<9, false>(*chunk),
                (9, true) => kernel.gram::<9, true>(*chunk),
                (10, false) => kernel.gram::<10, false>(*chunk),
                (10, true) => kernel.gram::<10, true>(*chunk),
                (11, false) => kernel.gram::<11, false>(*chunk),
                (11, true) => kernel.gram::<11, true>(*chunk),
                (12, false) => kernel.gram::<12, false>(*chunk),
                (12, true) => kernel.gram::<12, true>(*chunk),
                (13, false) => kernel.gram::<13, false>(*chunk),
                (13, true) => kernel.gram::<13, true>(*chunk),
                (14, false) => kernel.gram::<14, false>(*chunk),
                (14, true) => kernel.gram::<14, true>(*chunk),
                (15, false) => kernel.gram::<15, false>(*chunk),
                (15, true) => kernel.gram::<15, true>(*chunk),
                (16, false) => kernel.gram::<16, false>(*chunk),
                (16, true) => kernel.gram::<16, true>(*chunk),
                _ => unreachable!("at most {} parameters", MAX_WIDTH - 1),
            }
        };
        let parts: Vec<ChunkResult> = if m >= PARALLEL_ROWS {
            chunks.par_iter().map(run_chunk).collect()
        } else {
            chunks.iter().map(run_chunk).collect()
        };
        self.evaluations.set(self.evaluations.get() + 1);
        if !parts.iter().all(|p| p.finite) {
            return None;
        }
        // Only report passes sum the relative errors (NaN marks the others).
        let rms_rel = if COMPRESS && !self.report {
            f64::NAN
        } else {
            (parts.iter().map(|p| p.sum_rel).sum::<f64>() / m.max(1) as f64).sqrt()
        };
        if !COMPRESS {
            let mut residuals = Vec::with_capacity(m);
            for p in &parts {
                residuals.extend_from_slice(&p.data);
            }
            return Some(Pass::Full {
                residuals: DVector::from_vec(residuals),
            });
        }
        // Sum the chunks' Gram matrices (and meat) in chunk order, then
        // factorise.
        let mut sums = vec![0.0; parts[0].data.len()];
        for p in &parts {
            for (total, value) in sums.iter_mut().zip(&p.data) {
                *total += value;
            }
        }
        self.add_energy_rows(&chunks, &parts, &mut sums[..width * width], width);
        let triangle = augmented_cholesky(&sums[..width * width], width);
        let meat = self.report.then(|| {
            // W × W layout, the first n × n used; upper triangle filled.
            let m = &sums[width * width..];
            DMatrix::from_fn(n, n, |a, b| m[a.min(b) * width + a.max(b)])
        });
        Some(Pass::Compressed {
            triangle,
            rms_rel,
            meat,
        })
    }
}

impl Problem<'_> {
    /// Adds each block's energy rows (from its chunks' parts, summed in
    /// chunk order) to the Gram matrix `gram` (upper triangle, row-major,
    /// `width × width`). Not to the sandwich's middle: the rows are
    /// constraints, which its outer factors carry.
    fn add_energy_rows(
        &self,
        chunks: &[Chunk],
        parts: &[ChunkResult],
        gram: &mut [f64],
        width: usize,
    ) {
        let mut energy = vec![0.0; 6 * width];
        for (k, (&(b, _, _), part)) in chunks.iter().zip(parts).enumerate() {
            for (total, value) in energy.iter_mut().zip(&part.energy) {
                *total += value;
            }
            if chunks.get(k + 1).is_some_and(|next| next.0 == b) {
                continue;
            }
            let mut x = vec![0.0; width];
            for row in &self.blocks[b].energy_rows {
                let sums = &energy[(row.side * 3 + row.channel) * width..][..width];
                for (xj, &e) in x.iter_mut().zip(sums) {
                    *xj = row.factor * e;
                }
                x[width - 1] = row.factor * (sums[width - 1] - row.data);
                for a in 0..width {
                    for c in a..width {
                        gram[a * width + c] += x[a] * x[c];
                    }
                }
            }
            energy.fill(0.0);
        }
    }
}

/// The material of a pass.
enum Model {
    /// One primitive, its orientation fixed: brtf-model's kernel alone.
    Single(Bsdf),
    /// A lobe sum, or a fitted orientation.
    Lobes(LobeModel),
}

impl Model {
    /// The primitive of patch-averaged fits, which take one (lobe sums and
    /// fitted orientations are refused for them before the fit).
    fn single(&self) -> &Bsdf {
        match self {
            Model::Single(bsdf) => bsdf,
            Model::Lobes(_) => unreachable!("patch-averaged fits take one primitive"),
        }
    }
}

/// Everything one pass needs per sample.
struct Kernel<'a> {
    model: Model,
    /// What each free parameter drives, and dp/du.
    columns: Vec<(Target, f64)>,
    scale: f64,
    floor: f64,
    kind: ResidualKind,
    channels: usize,
    blocks: &'a [Block<'a>],
}

// Channel loops index values, factors and the gradient together.
#[allow(clippy::needless_range_loop)]
impl Kernel<'_> {
    /// The residuals of one chunk.
    fn residuals(&self, (b, start, end): Chunk) -> ChunkResult {
        let block = &self.blocks[b];
        let channels = self.channels;
        let mut data = Vec::with_capacity((end - start) * channels);
        let mut sum_rel = 0.0;
        let add = |i: usize, f: [f64; 3]| {
            let s = &block.samples[i];
            for ch in 0..channels {
                let row = i * channels + ch;
                let (res, _, rel2) =
                    self.residual(f[ch], s.value[ch], block.factors[row], block.log_value(row));
                data.push(res);
                sum_rel += rel2;
            }
        };
        self.for_each_value(block, start..end, add);
        ChunkResult {
            finite: data.iter().all(|r| r.is_finite()),
            data,
            sum_rel,
            energy: Vec::new(),
        }
    }

    /// Calls `visit(i, f)` with the model value `f` of each of `block`'s
    /// samples `range`, in order: averaged over the sample's pairs for
    /// patch-averaged data, else from the per-pair kernel in runs.
    #[inline(always)]
    fn for_each_value(
        &self,
        block: &Block<'_>,
        range: Range<usize>,
        mut visit: impl FnMut(usize, [f64; 3]),
    ) {
        if block.pairs.is_some() {
            let mut scratch = GeometryBatch::new();
            for i in range {
                visit(i, self.average(block, i, &mut scratch));
            }
        } else {
            let mut run = Run::new();
            for first in range.clone().step_by(RUN) {
                let last = (first + RUN).min(range.end);
                run.evaluate::<false>(self, block, first..last);
                for i in first..last {
                    visit(i, run.value(self, i - first));
                }
            }
        }
    }

    /// The sum of the squared residuals of one chunk (not finite when a
    /// residual is not).
    /// Also the chunk's part of the model's energies (`[side][channel]`,
    /// Σ w m; zero without energy rows).
    fn squares(&self, (b, start, end): Chunk) -> (f64, [[f64; 3]; 2]) {
        let block = &self.blocks[b];
        let channels = self.channels;
        let mut sum = 0.0;
        let mut energy = [[0.0; 3]; 2];
        let weights = &block.energy_weights;
        let add = |i: usize, f: [f64; 3]| {
            let s = &block.samples[i];
            for ch in 0..channels {
                let row = i * channels + ch;
                let (res, _, _) =
                    self.residual(f[ch], s.value[ch], block.factors[row], block.log_value(row));
                sum += res * res;
            }
            if let Some(&w) = weights.get(i) {
                for ch in 0..channels {
                    energy[side_of(s)][ch] += w * self.scale * f[ch];
                }
            }
        };
        self.for_each_value(block, start..end, add);
        (sum, energy)
    }

    /// The upper triangle of `[J | r]ᵀ[J | r]` of one chunk (row-major,
    /// `W × W`), for `W − 1` parameters; the fixed width lets the compiler
    /// unroll the accumulation.
    fn gram<const W: usize, const REPORT: bool>(&self, (b, start, end): Chunk) -> ChunkResult {
        let block = &self.blocks[b];
        let mut sums = GramSums::<W>::new();
        // Energy rows' parts: per side and channel, Σ w ∂m/∂u then Σ w m.
        let mut energy = if block.energy_weights.is_empty() {
            Vec::new()
        } else {
            vec![0.0; 6 * W]
        };
        if block.pairs.is_some() {
            let mut grad = Gradient::default();
            let mut scratch = GeometryBatch::new();
            for i in start..end {
                let f = self.average_with_gradient(block, i, &mut grad, &mut scratch);
                self.add_rows::<W, REPORT>(&mut sums, &mut energy, block, i, f, |a, ch| {
                    grad.d[a][ch]
                });
            }
        } else {
            // Samples in short runs: the model through brtf-model's
            // vectorised per-pair kernel, the rows into columns, the
            // columns' products summed with SIMD vectors.
            let mut run = Run::new();
            let mut columns = RunColumns::default();
            let mut dr_dm = Vec::with_capacity(RUN * self.channels);
            for first in (start..end).step_by(RUN) {
                let last = (first + RUN).min(end);
                run.evaluate::<true>(self, block, first..last);
                match &self.model {
                    Model::Single(_) => self.put_columns::<W, REPORT>(
                        &run.terms,
                        block,
                        first,
                        &mut columns,
                        &mut dr_dm,
                        &mut sums,
                        &mut energy,
                    ),
                    Model::Lobes(_) => self.put_columns::<W, REPORT>(
                        &run.lobe_terms,
                        block,
                        first,
                        &mut columns,
                        &mut dr_dm,
                        &mut sums,
                        &mut energy,
                    ),
                }
                gram::accumulate::<W, REPORT>(&columns, &mut sums.gram, &mut sums.meat);
            }
        }
        let mut data: Vec<f64> = sums.gram.iter().flatten().copied().collect();
        if REPORT {
            data.extend(sums.meat.iter().flatten());
        }
        ChunkResult {
            finite: data.iter().all(|v| v.is_finite()) && energy.iter().all(|v| v.is_finite()),
            data,
            sum_rel: sums.sum_rel,
            energy,
        }
    }

    /// Writes the rows of the run of `block`'s samples from `first` (one
    /// per sample and channel; the run's model terms `terms`) into
    /// `columns`: the Jacobian's columns, then the residuals; adds their
    /// relative errors to `sums` and their energies to `energy` (see
    /// [`Kernel::gram`]). Column by column, from the terms' columns, so
    /// that the loops are plain array arithmetic.
    #[allow(clippy::too_many_arguments)] // the run's scratch, passed down
    fn put_columns<const W: usize, const REPORT: bool>(
        &self,
        terms: &impl Terms,
        block: &Block<'_>,
        first: usize,
        columns: &mut RunColumns,
        dr_dm: &mut Vec<f64>,
        sums: &mut GramSums<W>,
        energy: &mut [f64],
    ) {
        let channels = self.channels;
        let n = terms.value_column(0).len();
        let rows = n * channels;
        columns.reset(rows, W);
        dr_dm.clear();
        dr_dm.resize(rows, 0.0);
        let samples = &block.samples[first..first + n];
        let factors = &block.factors[first * channels..][..rows];
        let logs =
            (!block.log_values.is_empty()).then(|| &block.log_values[first * channels..][..rows]);
        let residuals = columns.column_mut(W - 1);
        for ch in 0..channels {
            for (j, (s, &f)) in samples.iter().zip(terms.value_column(ch)).enumerate() {
                let r = j * channels + ch;
                let log_y = logs.map_or(f64::NAN, |l| l[r]);
                let (res, d, rel2) = self.residual(f, s.value[ch], factors[r], log_y);
                if REPORT {
                    sums.sum_rel += rel2;
                }
                residuals[r] = res;
                dr_dm[r] = d;
            }
        }
        let weights = (!energy.is_empty()).then(|| &block.energy_weights[first..first + n]);
        if let Some(weights) = weights {
            for ch in 0..channels {
                for ((s, &f), &w) in samples.iter().zip(terms.value_column(ch)).zip(weights) {
                    energy[(side_of(s) * 3 + ch) * W + W - 1] += w * self.scale * f;
                }
            }
        }
        for (c, &(target, dp_du)) in self.columns[..W - 1].iter().enumerate() {
            let out = columns.column_mut(c);
            for ch in 0..channels {
                // dm/dp: the scale times ∂f/∂p, or f for the scale itself.
                // A grey parameter drives all three colours; only channel
                // ch's own colour moves f_ch.
                let (source, factor) = match target {
                    Target::Arg(a) => (terms.derivative_column(a, ch), self.scale * dp_du),
                    Target::Gray => (terms.derivative_column(ch, ch), self.scale * dp_du),
                    Target::Scale => (Some(terms.value_column(ch)), dp_du),
                };
                match (source, channels) {
                    // One channel: plain slices, which the compiler
                    // vectorises.
                    (Some(source), 1) => {
                        for ((o, &g), &d) in out.iter_mut().zip(dr_dm.iter()).zip(source) {
                            *o = g * d * factor;
                        }
                    }
                    (Some(source), _) => {
                        for (j, &d) in source.iter().enumerate() {
                            let r = j * channels + ch;
                            out[r] = dr_dm[r] * d * factor;
                        }
                    }
                    (None, _) => {
                        for j in 0..n {
                            out[j * channels + ch] = 0.0;
                        }
                    }
                }
                if let (Some(weights), Some(source)) = (weights, source) {
                    for ((s, &d), &w) in samples.iter().zip(source).zip(weights) {
                        energy[(side_of(s) * 3 + ch) * W + c] += w * d * factor;
                    }
                }
            }
        }
    }

    /// Adds sample `i`'s rows (one per channel) to `sums`, for model value
    /// `f` and `∂f_ch/∂argument a = d(a, ch)`.
    #[inline(always)]
    fn add_rows<const W: usize, const REPORT: bool>(
        &self,
        sums: &mut GramSums<W>,
        energy: &mut [f64],
        block: &Block<'_>,
        i: usize,
        f: [f64; 3],
        d: impl Fn(usize, usize) -> f64,
    ) {
        let s = &block.samples[i];
        let columns: &[(Target, f64)] = &self.columns[..W - 1];
        let mut x = [0.0; W];
        let weight = block.energy_weights.get(i).copied();
        for ch in 0..self.channels {
            let row = i * self.channels + ch;
            let (res, dr_dm, rel2) =
                self.residual(f[ch], s.value[ch], block.factors[row], block.log_value(row));
            if REPORT {
                sums.sum_rel += rel2;
            }
            let slot = (side_of(s) * 3 + ch) * W;
            for (j, (xj, &(target, dp_du))) in x.iter_mut().zip(columns).enumerate() {
                let dm_dp = match target {
                    Target::Arg(a) => self.scale * d(a, ch),
                    Target::Gray => self.scale * (d(0, ch) + d(1, ch) + d(2, ch)),
                    Target::Scale => f[ch],
                };
                *xj = dr_dm * dm_dp * dp_du;
                if let Some(w) = weight {
                    energy[slot + j] += w * dm_dp * dp_du;
                }
            }
            if let Some(w) = weight {
                energy[slot + W - 1] += w * self.scale * f[ch];
            }
            x[W - 1] = res;
            for a in 0..W {
                for b in a..W {
                    sums.gram[a][b] += x[a] * x[b];
                }
            }
            if REPORT {
                let r2 = res * res;
                for a in 0..W - 1 {
                    for b in a..W - 1 {
                        sums.meat[a][b] += r2 * x[a] * x[b];
                    }
                }
            }
        }
    }

    /// The BSDF and its gradient averaged over sample `i`'s pairs (the
    /// patch average is linear, so its gradient is the average gradient):
    /// from the pairs' cached geometry, or else from the pairs, through
    /// `scratch`. Either way the sums run in brtf-model's vectorised kernel.
    fn average_with_gradient(
        &self,
        block: &Block<'_>,
        i: usize,
        grad: &mut Gradient,
        scratch: &mut GeometryBatch,
    ) -> [f64; 3] {
        let (geometry, range) = self.pair_geometry(block, i, scratch);
        let inverse = 1.0 / range.len().max(1) as f64;
        let bsdf = self.model.single();
        let sum = if self.channels == 1 {
            bsdf.sum_geometry_with_gradient::<1>(geometry, range, grad)
        } else {
            bsdf.sum_geometry_with_gradient::<3>(geometry, range, grad)
        };
        for d in grad.d.iter_mut() {
            for c in d.iter_mut() {
                *c *= inverse;
            }
        }
        sum.map(|s| s * inverse)
    }

    /// The BSDF averaged over sample `i`'s pairs; see
    /// [`Kernel::average_with_gradient`].
    fn average(&self, block: &Block<'_>, i: usize, scratch: &mut GeometryBatch) -> [f64; 3] {
        let (geometry, range) = self.pair_geometry(block, i, scratch);
        let inverse = 1.0 / range.len().max(1) as f64;
        self.model
            .single()
            .sum_geometry::<3>(geometry, range)
            .map(|s| s * inverse)
    }

    /// The geometry of sample `i`'s pairs: cached, or computed into
    /// `scratch`.
    fn pair_geometry<'s>(
        &self,
        block: &'s Block<'_>,
        i: usize,
        scratch: &'s mut GeometryBatch,
    ) -> (&'s GeometryBatch, Range<usize>) {
        match (&block.pair_geometry, &block.pairs) {
            (Some(cached), _) => (&cached.geometry, cached.range(i)),
            (None, Some(pairs)) => {
                // Refilled in place, neither cleared nor zero-filled: its
                // pairs past this sample's are stale and not read.
                pairs.geometry(self.model.single(), i, scratch, 0);
                let n = pairs.count(i);
                (&*scratch, 0..n)
            }
            (None, None) => unreachable!("patch-averaged blocks have pairs"),
        }
    }

    /// The residual for BSDF value `f`, measured `y`, factor `k` and
    /// (log residuals) `log_y = ln(max(y, 0) + floor)`, dr/dm, and the
    /// squared relative error for `rms_rel`.
    #[inline(always)]
    fn residual(&self, f: f64, y: f64, k: f64, log_y: f64) -> (f64, f64, f64) {
        let model = self.scale * f;
        let e = model - y;
        let floor = self.floor;
        let rel2 = e * e / (y * y + floor * floor);
        let (res, dr_dm) = match self.kind {
            ResidualKind::Absolute | ResidualKind::Relative => (k * e, k),
            ResidualKind::Log => {
                let a = model.max(0.0) + floor;
                (k * (a.ln() - log_y), k / a)
            }
        };
        (res, dr_dm, rel2)
    }
}

/// The running sums of one chunk's [`Kernel::gram`].
struct GramSums<const W: usize> {
    gram: [[f64; W]; W],
    meat: [[f64; W]; W],
    sum_rel: f64,
}

impl<const W: usize> GramSums<W> {
    fn new() -> Self {
        GramSums {
            gram: [[0.0; W]; W],
            meat: [[0.0; W]; W],
            sum_rel: 0.0,
        }
    }
}

/// Samples per run of the per-pair kernel: a run's geometry and terms
/// stay in the first-level cache.
const RUN: usize = 256;

/// One run of a measured block's samples: their geometry and their
/// model terms.
struct Run {
    geometry: GeometryBatch,
    terms: PairTerms,
    /// A lobe model's terms, and its turned geometry (fitted orientation).
    lobe_terms: LobeTerms,
    turned: [GeometryBatch; 2],
    views: Vec<DVec3>,
}

impl Run {
    fn new() -> Run {
        Run {
            geometry: GeometryBatch::with_capacity(RUN),
            terms: PairTerms::new(),
            lobe_terms: LobeTerms::default(),
            turned: [GeometryBatch::new(), GeometryBatch::new()],
            views: Vec::new(),
        }
    }

    /// `f` (and with `GRAD` its gradient) of `block`'s samples `range`,
    /// from the block's geometry or else the run's own.
    fn evaluate<const GRAD: bool>(
        &mut self,
        kernel: &Kernel<'_>,
        block: &Block<'_>,
        range: Range<usize>,
    ) {
        let lobes = match &kernel.model {
            Model::Single(bsdf) => {
                let (geometry, range) = match &block.sample_geometry {
                    Some(cached) => (&**cached, range),
                    None => {
                        self.geometry.clear();
                        for s in &block.samples[range] {
                            self.geometry.push(bsdf.geometry(block.light, s.view));
                        }
                        (&self.geometry, 0..self.geometry.len())
                    }
                };
                let terms = &mut self.terms;
                match (GRAD, kernel.channels) {
                    (true, 1) => bsdf.eval_geometry_each_with_gradient::<1>(geometry, range, terms),
                    (true, _) => bsdf.eval_geometry_each_with_gradient::<3>(geometry, range, terms),
                    (false, 1) => bsdf.eval_geometry_each::<1>(geometry, range, terms),
                    (false, _) => bsdf.eval_geometry_each::<3>(geometry, range, terms),
                }
                return;
            }
            Model::Lobes(lobes) => lobes,
        };
        // A fitted orientation turns the tangent frame: the geometry is the
        // point's own, and the turned ones give its derivative.
        let cached = block
            .sample_geometry
            .as_deref()
            .filter(|_| !lobes.oriented());
        let (geometry, range) = match cached {
            Some(cached) => (cached, range),
            None => {
                self.views.clear();
                self.views
                    .extend(block.samples[range].iter().map(|s| s.view));
                lobes.geometry(0, block.light, &self.views, &mut self.geometry);
                (&self.geometry, 0..self.views.len())
            }
        };
        let turned = (GRAD && lobes.oriented()).then(|| {
            let [minus, plus] = &mut self.turned;
            lobes.geometry(-1, block.light, &self.views, minus);
            lobes.geometry(1, block.light, &self.views, plus);
            [&*minus, &*plus]
        });
        let terms = &mut self.lobe_terms;
        match (GRAD, kernel.channels) {
            (true, 1) => terms.evaluate::<true, 1>(lobes, geometry, range, turned),
            (true, _) => terms.evaluate::<true, 3>(lobes, geometry, range, turned),
            (false, 1) => terms.evaluate::<false, 1>(lobes, geometry, range, None),
            (false, _) => terms.evaluate::<false, 3>(lobes, geometry, range, None),
        }
    }

    /// Sample `j` of the run's `f`.
    #[inline(always)]
    fn value(&self, kernel: &Kernel<'_>, j: usize) -> [f64; 3] {
        match kernel.model {
            Model::Single(_) => std::array::from_fn(|ch| self.terms.value(j, ch)),
            Model::Lobes(_) => std::array::from_fn(|ch| self.lobe_terms.value(j, ch)),
        }
    }
}

/// The columns [`Kernel::put_columns`] reads: one primitive's terms or a
/// lobe model's.
trait Terms {
    fn value_column(&self, ch: usize) -> &[f64];
    fn derivative_column(&self, a: usize, ch: usize) -> Option<&[f64]>;
}

impl Terms for PairTerms {
    fn value_column(&self, ch: usize) -> &[f64] {
        PairTerms::value_column(self, ch)
    }
    fn derivative_column(&self, a: usize, ch: usize) -> Option<&[f64]> {
        PairTerms::derivative_column(self, a, ch)
    }
}

impl Terms for LobeTerms {
    fn value_column(&self, ch: usize) -> &[f64] {
        LobeTerms::value_column(self, ch)
    }
    fn derivative_column(&self, a: usize, ch: usize) -> Option<&[f64]> {
        LobeTerms::derivative_column(self, a, ch)
    }
}

/// Widest `[J | r]`: every argument of a shape, a free scale, the residual.
const MAX_WIDTH: usize = brtf_model::MAX_SHAPE_ARGS + 2;

/// The triangle `[[R, z], [0, ρ]]` (column-major, `width × width`) of the
/// augmented Gram matrix `G = [J | r]ᵀ[J | r]` (upper triangle, row-major):
/// `RᵀR = JᵀJ`, `Rᵀz = Jᵀr` and `ρ² = ‖r‖² − ‖z‖²`, so `‖(z, ρ)‖² = ‖r‖²`.
///
/// A column whose part independent of the columns before it falls below
/// 1e-6 of its norm counts as dependent: its row of R is zero, as in a
/// rank-revealing QR (LM copes with a zero diagonal). The test is relative
/// to the column itself, so parameter scaling does not affect it. Forming
/// JᵀJ squares the condition number; with at most nine well-scaled
/// parameters LM's steps lose nothing that matters, and the cost ‖r‖²,
/// which decides every step, is summed directly.
fn augmented_cholesky(gram: &[f64], width: usize) -> Vec<f64> {
    let n = width - 1;
    let g = |a: usize, b: usize| gram[a.min(b) * width + a.max(b)];
    // Column-major: entry (row i, column j) at j * width + i.
    let mut r = vec![0.0; width * width];
    for k in 0..width {
        let mut pivot = g(k, k);
        for i in 0..k {
            pivot -= r[k * width + i] * r[k * width + i];
        }
        if k == n {
            r[k * width + k] = pivot.max(0.0).sqrt();
            break;
        }
        if pivot.is_nan() || pivot <= 1e-12 * g(k, k) {
            continue;
        }
        let diagonal = pivot.sqrt();
        r[k * width + k] = diagonal;
        for j in k + 1..width {
            let mut value = g(k, j);
            for i in 0..k {
                value -= r[k * width + i] * r[j * width + i];
            }
            r[j * width + k] = value / diagonal;
        }
    }
    r
}

/// A chunk of one block: (block, first sample, end sample).
type Chunk = (usize, usize, usize);

/// What one chunk contributes to a pass.
struct ChunkResult {
    /// Its Gram matrix of `[J | r]`, or its residuals.
    data: Vec<f64>,
    sum_rel: f64,
    finite: bool,
    /// A Gram pass with energy rows: per side and channel (`(side · 3 +
    /// channel) · W`), Σ w ∂m/∂u of each parameter then Σ w m; else empty.
    energy: Vec<f64>,
}

enum Pass {
    Full {
        residuals: DVector<f64>,
    },
    Compressed {
        triangle: Vec<f64>,
        rms_rel: f64,
        meat: Option<DMatrix<f64>>,
    },
}

/// The problem at one point, compressed to n + 1 rows (see
/// [`Problem::compressed`]).
#[derive(Debug, Clone)]
pub(crate) struct Compressed {
    pub residuals: DVector<f64>,
    /// `[R; 0]`, (n + 1) × n: `JᵀJ = RᵀR`.
    pub jacobian: DMatrix<f64>,
    /// RMS relative error (NaN outside report passes).
    pub rms_rel: f64,
    /// `Σ rᵢ² Jᵢ Jᵢᵀ` (n × n), the middle of the sandwich covariance, in a
    /// report pass.
    pub meat: Option<DMatrix<f64>>,
    /// What LM sees instead of `(residuals, jacobian)` when a [`Secant`]
    /// corrects the Hessian: the same cost and gradient, Hessian
    /// `JᵀJ + S`. The Gauss-Newton pair above stays for the report.
    pub model: Option<(DVector<f64>, DMatrix<f64>)>,
}

/// A quasi-Newton estimate `S` of the Hessian's second-order part
/// `Σ rᵢ ∇²rᵢ`, which Gauss-Newton leaves out.
///
/// Where the model cannot follow the data (a large residual, as on real
/// scans), Gauss-Newton converges only linearly: on golden_paper each
/// step covered about 70 % of the remaining distance, nine passes for the
/// main fit and thirteen for the log one. `S` is kept by the structured
/// secant update of Dennis, Gay and Welsch (the one in NL2SOL): after each
/// step `s` that lowered the cost, `S` is sized down when it overstates
/// the curvature along `s`, then changed by the smallest symmetric
/// rank-two term for which `(JᵀJ + S) s` equals the change `y` of the
/// gradient `Jᵀr`. Everything it needs (`JᵀJ`, `Jᵀr`, `‖r‖²`) is in the
/// compressed pass. A point where `JᵀJ + S` is not positive definite, or
/// a column is dependent, gets the plain Gauss-Newton model.
#[derive(Debug, Default)]
pub(crate) struct Secant {
    /// `S` (n × n), zero until the first step.
    estimate: Option<DMatrix<f64>>,
    /// The lowest-cost point so far: `u`, the gradient `Jᵀr` there and
    /// `‖r‖²`.
    last: Option<(DVector<f64>, DVector<f64>, f64)>,
}

impl Secant {
    /// Takes in the pass `c` at `u`, and returns the model LM should see
    /// there (`None`: Gauss-Newton's).
    fn model_at(
        &mut self,
        u: &DVector<f64>,
        c: &Compressed,
    ) -> Option<(DVector<f64>, DMatrix<f64>)> {
        let n = u.len();
        let r = c.jacobian.rows(0, n).into_owned();
        let z = c.residuals.rows(0, n).into_owned();
        let squares = c.residuals.norm_squared();
        let gradient = r.transpose() * &z;
        let gauss_newton = r.transpose() * &r;
        let lower = self
            .last
            .as_ref()
            .is_none_or(|(_, _, best)| squares < *best);
        if !lower {
            // A rejected trial: LM returns to the last point and its model.
            return self.model(&gauss_newton, &gradient, squares);
        }
        if let Some((u_last, g_last, _)) = &self.last {
            let s = u - u_last;
            let y = &gradient - g_last;
            let y_sharp = &y - &gauss_newton * &s;
            self.update(&s, &y, &y_sharp);
        }
        self.last = Some((u.clone(), gradient.clone(), squares));
        self.model(&gauss_newton, &gradient, squares)
    }

    /// The Dennis-Gay-Welsch update of `S` for step `s`, gradient change
    /// `y` and its part `y♯ = y − JᵀJ s` that Gauss-Newton misses.
    fn update(&mut self, s: &DVector<f64>, y: &DVector<f64>, y_sharp: &DVector<f64>) {
        // Only a step along which the gradient grows carries curvature.
        let ys = y.dot(s);
        let informative = ys.is_finite() && ys > 1e-12 * y.norm() * s.norm();
        if !informative {
            return;
        }
        let n = s.len();
        let mut estimate = self.estimate.take().unwrap_or_else(|| DMatrix::zeros(n, n));
        // Sizing: S must not claim more curvature along s than y♯ shows.
        let curvature = s.dot(&(&estimate * s));
        if curvature != 0.0 {
            let tau = (s.dot(y_sharp) / curvature).abs().min(1.0);
            estimate *= tau;
        }
        let w = y_sharp - &estimate * s;
        let ws = w.dot(s);
        let updated = &estimate + (&w * y.transpose() + y * w.transpose()) / ys
            - (y * y.transpose()) * (ws / (ys * ys));
        let finite = updated.iter().all(|v| v.is_finite());
        self.estimate = Some(if finite { updated } else { estimate });
    }

    /// `(z̃, ρ̃)` and `[R̃; 0]` with `R̃ᵀR̃ = JᵀJ + S`, `R̃ᵀz̃ = Jᵀr` and
    /// `‖(z̃, ρ̃)‖² = ‖r‖²`, or `None` where that does not exist.
    fn model(
        &self,
        gauss_newton: &DMatrix<f64>,
        gradient: &DVector<f64>,
        squares: f64,
    ) -> Option<(DVector<f64>, DMatrix<f64>)> {
        let estimate = self.estimate.as_ref()?;
        let n = gradient.len();
        if (0..n).any(|k| gauss_newton[(k, k)] <= 0.0) {
            return None;
        }
        let hessian = gauss_newton + estimate;
        let hessian = (&hessian + hessian.transpose()) * 0.5;
        let factor = hessian.cholesky()?;
        // L Lᵀ = H, so R̃ = Lᵀ and z̃ = L⁻¹ g.
        let lower = factor.l();
        let z = lower.solve_lower_triangular(gradient)?;
        let rest = squares - z.norm_squared();
        if rest.is_nan() || rest < 0.0 {
            return None;
        }
        let mut residuals = DVector::zeros(n + 1);
        residuals.rows_mut(0, n).copy_from(&z);
        residuals[n] = rest.sqrt();
        let mut jacobian = DMatrix::zeros(n + 1, n);
        jacobian.rows_mut(0, n).copy_from(&lower.transpose());
        Some((residuals, jacobian))
    }
}

/// Samples per chunk of a pass: the unit of parallel work and of the
/// fixed summation order.
const CHUNK: usize = 2048;
/// Passes with at least this many residuals run their chunks in parallel.
const PARALLEL_ROWS: usize = 16_384;

impl LeastSquaresProblem<f64, Dyn, Dyn> for Problem<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, u: &DVector<f64>) {
        self.u.copy_from(u);
    }

    fn params(&self) -> DVector<f64> {
        self.u.clone()
    }

    /// The compressed residuals. The pass's compressed Jacobian is kept
    /// with them: the short residuals depend on the point's Q, so LM must
    /// get the Jacobian of the same pass, and it asks for it at its last
    /// accepted point, which it has always evaluated already. A point
    /// already in the history (a seeded start) is not evaluated again.
    fn residuals(&self) -> Option<DVector<f64>> {
        let c = self.evaluated(&self.u)?;
        Some(c.model.map_or(c.residuals, |(residuals, _)| residuals))
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let c = self.evaluated(&self.u)?;
        Some(c.model.map_or(c.jacobian, |(_, jacobian)| jacobian))
    }
}

impl Problem<'_> {
    /// The compressed problem at `u`, from the history or a new pass.
    pub(crate) fn evaluated(&self, u: &DVector<f64>) -> Option<Compressed> {
        // A stopped fit ends here: Levenberg-Marquardt stops at residuals
        // it cannot have.
        if self.stop.is_raised() {
            return None;
        }
        let known = self
            .history
            .borrow()
            .iter()
            .rev()
            .find(|(at, _)| at == u)
            .map(|(_, c)| c.clone());
        known.or_else(|| {
            let mut c = self.compressed(u)?;
            if let Some(secant) = &self.secant {
                c.model = secant.borrow_mut().model_at(u, &c);
            }
            self.history.borrow_mut().push((u.clone(), c.clone()));
            Some(c)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A compressed pass with `R`, `z` and `ρ` as given.
    fn pass(r: &DMatrix<f64>, z: &DVector<f64>, rho: f64) -> Compressed {
        let n = r.ncols();
        let mut jacobian = DMatrix::zeros(n + 1, n);
        jacobian.rows_mut(0, n).copy_from(r);
        let mut residuals = DVector::zeros(n + 1);
        residuals.rows_mut(0, n).copy_from(z);
        residuals[n] = rho;
        Compressed {
            residuals,
            jacobian,
            rms_rel: f64::NAN,
            meat: None,
            model: None,
        }
    }

    #[test]
    fn a_secant_step_matches_the_change_of_the_gradient() {
        // Two passes of a problem whose gradient Jᵀr changes by more than
        // JᵀJ explains along the step: the updated model's Hessian must
        // map the step onto the gradient's change exactly.
        let r0 = DMatrix::from_row_slice(3, 3, &[2.0, 0.5, 0.1, 0.0, 1.5, 0.3, 0.0, 0.0, 1.0]);
        let z0 = DVector::from_vec(vec![0.4, -0.2, 0.3]);
        let r1 = DMatrix::from_row_slice(3, 3, &[2.1, 0.4, 0.1, 0.0, 1.4, 0.2, 0.0, 0.0, 1.1]);
        let z1 = DVector::from_vec(vec![0.1, -0.05, 0.2]);
        let (u0, u1) = (
            DVector::from_vec(vec![0.0, 0.0, 0.0]),
            DVector::from_vec(vec![-0.2, 0.1, -0.15]),
        );
        let mut secant = Secant::default();
        assert!(secant.model_at(&u0, &pass(&r0, &z0, 2.0)).is_none());
        let (residuals, jacobian) = secant
            .model_at(&u1, &pass(&r1, &z1, 1.9))
            .expect("a model after one step");
        let gradient = |r: &DMatrix<f64>, z: &DVector<f64>| r.transpose() * z;
        let s = &u1 - &u0;
        let y = gradient(&r1, &z1) - gradient(&r0, &z0);
        let hessian = jacobian.transpose() * &jacobian;
        assert!((&hessian * &s - &y).norm() < 1e-12 * y.norm(), "{hessian}");
        // Same gradient and cost as the Gauss-Newton pass.
        let g = jacobian.transpose() * &residuals;
        assert!((g - gradient(&r1, &z1)).norm() < 1e-14);
        let squares = z1.norm_squared() + 1.9 * 1.9;
        assert!((residuals.norm_squared() - squares).abs() < 1e-14 * squares);
        // Its correction is the symmetric difference from JᵀJ.
        let correction = &hessian - r1.transpose() * &r1;
        assert!((&correction - correction.transpose()).norm() < 1e-12);
    }

    #[test]
    fn a_trial_without_gain_leaves_the_secant_as_it_was() {
        let r = DMatrix::from_row_slice(2, 2, &[1.0, 0.2, 0.0, 0.8]);
        let mut secant = Secant::default();
        let u0 = DVector::from_vec(vec![0.0, 0.0]);
        secant.model_at(&u0, &pass(&r, &DVector::from_vec(vec![0.5, 0.5]), 1.0));
        secant.model_at(
            &DVector::from_vec(vec![-0.1, -0.1]),
            &pass(&r, &DVector::from_vec(vec![0.2, 0.3]), 1.0),
        );
        let kept = secant.estimate.clone().expect("an estimate after a step");
        // A trial that costs more is not taken into the estimate.
        let model = secant.model_at(
            &DVector::from_vec(vec![0.5, 0.5]),
            &pass(&r, &DVector::from_vec(vec![0.9, 0.9]), 1.0),
        );
        assert_eq!(secant.estimate.as_ref(), Some(&kept));
        assert!(secant.last.as_ref().is_some_and(|(u, _, _)| u[0] == -0.1));
        // Its model still has the pass's cost.
        if let Some((residuals, _)) = model {
            assert!((residuals.norm_squared() - (0.81 + 0.81 + 1.0)).abs() < 1e-12);
        }
    }
}
