//! The least-squares problem handed to the levenberg-marquardt crate:
//! residuals and the exact Jacobian from brtf-model's analytic gradients,
//! in the unconstrained coordinates of [`ParamMap`].

use crate::params::{ParamMap, Target};
use brtf_model::{Bsdf, EvalOptions, Gradient, Material};
use glam::DVec3;
use levenberg_marquardt::LeastSquaresProblem;
use nalgebra::{DMatrix, DVector, Dyn, Owned};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::cell::{Cell, RefCell};

/// How a model value m is compared with a measured value y.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum ResidualKind {
    /// `m − y`, weighted by solid angle: the squared error integrated over
    /// the sphere. The peak counts most, and the fitted lobe keeps the
    /// data's energy even when the model cannot follow the data's shape.
    /// The default.
    #[default]
    Absolute,
    /// `(m − y) / sqrt(y² + floor²)`: every direction counts alike; right
    /// for multiplicative noise on top of a noise floor when the model can
    /// describe the data exactly.
    Relative,
    /// `ln(m + floor) − ln(max(y, 0) + floor)`.
    Log,
}

/// The samples of one incidence, ready for the inner loop.
#[derive(Debug, Clone)]
pub(crate) struct Block {
    pub light: DVec3,
    pub views: Vec<DVec3>,
    pub values: Vec<[f64; 3]>,
    /// √(weight) per sample, including any robust-loss reweighting.
    pub sqrt_weights: Vec<f64>,
    /// Per sample and channel, the factor turning `m − y` into a residual
    /// (relative and absolute kinds).
    pub factors: Vec<[f64; 3]>,
}

impl Block {
    pub(crate) fn len(&self) -> usize {
        self.views.len()
    }

    /// Recomputes the residual factors for `kind` and `floor`.
    pub(crate) fn set_factors(&mut self, kind: ResidualKind, floor: f64) {
        self.factors = self
            .values
            .iter()
            .zip(&self.sqrt_weights)
            .map(|(y, &sw)| {
                y.map(|yc| match kind {
                    ResidualKind::Relative => sw / (yc * yc + floor * floor).sqrt(),
                    ResidualKind::Absolute | ResidualKind::Log => sw,
                })
            })
            .collect();
    }
}

pub(crate) struct Problem<'a> {
    pub map: &'a ParamMap,
    pub options: EvalOptions,
    pub orientation: DVec3,
    pub blocks: &'a [Block],
    pub channels: usize,
    pub kind: ResidualKind,
    pub floor: f64,
    pub u: DVector<f64>,
    pub evaluations: Cell<usize>,
    pub cached_jacobian: RefCell<Option<(DVector<f64>, DMatrix<f64>)>>,
}

impl Problem<'_> {
    pub(crate) fn n_residuals(&self) -> usize {
        self.blocks.iter().map(Block::len).sum::<usize>() * self.channels
    }

    /// Physical parameters, their derivatives dp/du, the material and scale.
    pub(crate) fn physical(&self, u: &DVector<f64>) -> Option<(Vec<f64>, Vec<f64>, Material, f64)> {
        let (p, dp): (Vec<f64>, Vec<f64>) = (0..self.map.len())
            .map(|i| self.map.to_physical(i, u[i]))
            .unzip();
        let (args, scale) = self.map.material_args(&p);
        let material = Material::new(self.map.kind, &args, Some(self.orientation)).ok()?;
        Some((p, dp, material, scale))
    }

    pub(crate) fn residual_vector(&self, u: &DVector<f64>) -> Option<DVector<f64>> {
        self.evaluate::<false>(u).map(|e| e.residuals)
    }

    pub(crate) fn jacobian_matrix(&self, u: &DVector<f64>) -> Option<DMatrix<f64>> {
        self.evaluate::<true>(u).and_then(|e| e.jacobian)
    }

    /// Residuals, and with `JACOBIAN` the Jacobian on the same pass (one
    /// BSDF evaluation per sample serves both), plus the unweighted RMS of
    /// `(m − y)/sqrt(y² + floor²)` reported as `rms_rel`. Large problems
    /// are split into fixed chunks evaluated in parallel; the chunking and
    /// the order of the final sums do not depend on the thread count, so
    /// results are deterministic.
    pub(crate) fn evaluate<const JACOBIAN: bool>(&self, u: &DVector<f64>) -> Option<Evaluation> {
        let (_, dp, material, scale) = self.physical(u)?;
        let bsdf = Bsdf::new(&material, &self.options);
        let n = self.map.len();
        let m = self.n_residuals();
        let channels = self.channels;
        let columns: Vec<(Target, f64)> = self
            .map
            .slots
            .iter()
            .zip(&dp)
            .map(|(s, &d)| (s.target, d))
            .collect();
        // (block, first sample, end sample, first row)
        let mut chunks = Vec::new();
        let mut row = 0;
        for (b, block) in self.blocks.iter().enumerate() {
            let mut start = 0;
            while start < block.len() {
                let end = (start + CHUNK).min(block.len());
                chunks.push((b, start, end, row));
                row += (end - start) * channels;
                start = end;
            }
        }
        let (floor, kind, blocks) = (self.floor, self.kind, self.blocks);
        let floor2 = floor * floor;
        let mut residuals = DVector::zeros(m);
        let mut jac = if JACOBIAN {
            DMatrix::zeros(m, n)
        } else {
            DMatrix::zeros(0, 0)
        };
        // Hand every chunk its own rows of the residual vector and of each
        // Jacobian column, so chunks write in place, in parallel.
        let mut outputs: Vec<ChunkOutput> = Vec::with_capacity(chunks.len());
        {
            let mut rest = residuals.as_mut_slice();
            let mut columns_rest: Vec<&mut [f64]> = if JACOBIAN {
                jac.as_mut_slice().chunks_mut(m).collect()
            } else {
                Vec::new()
            };
            for &(_, start, end, _) in &chunks {
                let rows = (end - start) * channels;
                let (head, tail) = std::mem::take(&mut rest).split_at_mut(rows);
                rest = tail;
                let mut cols = Vec::with_capacity(columns_rest.len());
                for column in columns_rest.iter_mut() {
                    let (head, tail) = std::mem::take(column).split_at_mut(rows);
                    *column = tail;
                    cols.push(head);
                }
                outputs.push((head, cols));
            }
        }
        let run_chunk = |(&(b, start, end, _), (r, cols)): (&Chunk, &mut ChunkOutput)| {
            let block = &blocks[b];
            let mut grad = Gradient::default();
            let mut sum_rel = 0.0;
            let mut finite = true;
            let mut row = 0;
            for i in start..end {
                let (v, y, k) = (block.views[i], &block.values[i], &block.factors[i]);
                let f = if JACOBIAN {
                    bsdf.eval_with_gradient(block.light, v, &mut grad)
                } else {
                    bsdf.eval(block.light, v)
                };
                for ch in 0..channels {
                    let model = scale * f[ch];
                    let (res, dr_dm) = residual(kind, floor, model, y[ch], k[ch]);
                    r[row] = res;
                    finite &= res.is_finite();
                    let e = model - y[ch];
                    sum_rel += e * e / (y[ch] * y[ch] + floor2);
                    if JACOBIAN {
                        for (column, &(target, dp_du)) in cols.iter_mut().zip(&columns) {
                            let dm_dp = match target {
                                Target::Arg(a) => scale * grad.d[a][ch],
                                Target::Gray => {
                                    scale * (grad.d[0][ch] + grad.d[1][ch] + grad.d[2][ch])
                                }
                                Target::Scale => f[ch],
                            };
                            let value = dr_dm * dm_dp * dp_du;
                            finite &= value.is_finite();
                            column[row] = value;
                        }
                    }
                    row += 1;
                }
            }
            (sum_rel, finite)
        };
        let parts: Vec<(f64, bool)> = if m >= PARALLEL_ROWS {
            chunks
                .par_iter()
                .zip(outputs.par_iter_mut())
                .map(run_chunk)
                .collect()
        } else {
            chunks
                .iter()
                .zip(outputs.iter_mut())
                .map(run_chunk)
                .collect()
        };
        drop(outputs);
        self.evaluations.set(self.evaluations.get() + 1);
        let sum_rel: f64 = parts.iter().map(|p| p.0).sum();
        let finite = parts.iter().all(|p| p.1);
        finite.then(|| Evaluation {
            residuals,
            jacobian: JACOBIAN.then_some(jac),
            rms_rel: (sum_rel / m.max(1) as f64).sqrt(),
        })
    }
}

/// A chunk of one block: (block, first sample, end sample, first row).
type Chunk = (usize, usize, usize, usize);

/// A chunk's rows of the residual vector and of each Jacobian column.
type ChunkOutput<'a> = (&'a mut [f64], Vec<&'a mut [f64]>);

/// Residual for model `m` and measured `y` with factor `k`, and dr/dm.
#[inline(always)]
fn residual(kind: ResidualKind, floor: f64, m: f64, y: f64, k: f64) -> (f64, f64) {
    match kind {
        ResidualKind::Absolute | ResidualKind::Relative => (k * (m - y), k),
        ResidualKind::Log => {
            let a = m.max(0.0) + floor;
            (k * (a.ln() - (y.max(0.0) + floor).ln()), k / a)
        }
    }
}

/// Samples per chunk of a pass.
const CHUNK: usize = 4096;
/// Passes with at least this many residuals run their chunks in parallel.
const PARALLEL_ROWS: usize = 16_384;

/// One pass over the data.
pub(crate) struct Evaluation {
    pub residuals: DVector<f64>,
    pub jacobian: Option<DMatrix<f64>>,
    pub rms_rel: f64,
}

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

    /// Computes the Jacobian on the same pass and keeps it: LM asks for
    /// the Jacobian at the last accepted point, which is almost always the
    /// point of the last residual call.
    fn residuals(&self) -> Option<DVector<f64>> {
        let e = self.evaluate::<true>(&self.u)?;
        *self.cached_jacobian.borrow_mut() = e.jacobian.map(|j| (self.u.clone(), j));
        Some(e.residuals)
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let cached = self.cached_jacobian.borrow_mut().take();
        match cached {
            Some((u, j)) if u == self.u => Some(j),
            _ => self.jacobian_matrix(&self.u),
        }
    }
}
