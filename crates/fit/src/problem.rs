//! The least-squares problem handed to the levenberg-marquardt crate:
//! residuals and the exact Jacobian from brtf-model's analytic gradients,
//! in the unconstrained coordinates of [`ParamMap`].

use crate::params::{ParamMap, Target};
use brtf_model::{Bsdf, EvalOptions, Geometry, Gradient, Material};
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
    /// The argument-free part of the BSDF per sample (brtf-model's
    /// [`Geometry`]), computed once per fit since light and views are fixed.
    pub geometry: Vec<Geometry>,
    /// Measured values, `channels` per sample.
    pub values: Vec<f64>,
    /// √(weight) per sample, including any robust-loss reweighting.
    pub sqrt_weights: Vec<f64>,
    /// Per value, the factor turning `m − y` into a residual.
    pub factors: Vec<f64>,
    pub channels: usize,
}

impl Block {
    pub(crate) fn len(&self) -> usize {
        self.geometry.len()
    }

    /// Recomputes the residual factors for `kind` and `floor`.
    pub(crate) fn set_factors(&mut self, kind: ResidualKind, floor: f64) {
        let channels = self.channels;
        self.factors = self
            .values
            .iter()
            .enumerate()
            .map(|(row, &y)| {
                let sw = self.sqrt_weights[row / channels];
                match kind {
                    ResidualKind::Relative => sw / (y * y + floor * floor).sqrt(),
                    ResidualKind::Absolute | ResidualKind::Log => sw,
                }
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
    /// Every compressed evaluation so far, by point: LM asks for the
    /// Jacobian of its last accepted point, and the fit's final report
    /// needs the triangle at the solution; neither needs a new pass.
    pub history: RefCell<Vec<(DVector<f64>, Compressed)>>,
}

impl<'a> Problem<'a> {
    /// The problem over `blocks` for `config`, at the origin of `u`.
    pub(crate) fn new(
        map: &'a ParamMap,
        config: &crate::FitConfig,
        orientation: DVec3,
        blocks: &'a [Block],
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
            history: RefCell::new(Vec::new()),
        }
    }

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
    /// factorises an (n + 1) × n matrix instead of an m × n one. The QR is
    /// computed chunk by chunk as the samples are evaluated (TSQR), so the
    /// m × n Jacobian is never stored.
    pub(crate) fn compressed(&self, u: &DVector<f64>) -> Option<Compressed> {
        match self.pass::<true>(u)? {
            Pass::Compressed { triangle, rms_rel } => {
                let n = self.map.len();
                let residuals = DVector::from_column_slice(&triangle[n * (n + 1)..]);
                let jacobian = DMatrix::from_column_slice(n + 1, n, &triangle[..n * (n + 1)]);
                Some(Compressed {
                    residuals,
                    jacobian,
                    rms_rel,
                })
            }
            Pass::Full { .. } => None,
        }
    }

    /// One pass over the data: with `COMPRESS`, values and gradients
    /// reduced to the triangle of `[J | r]`; without, the residuals alone.
    /// Also the unweighted RMS of `(m − y)/sqrt(y² + floor²)`, reported
    /// as `rms_rel`. Large problems are split into fixed chunks evaluated
    /// in parallel; the chunking and the order of the reductions do not
    /// depend on the thread count, so results are deterministic.
    fn pass<const COMPRESS: bool>(&self, u: &DVector<f64>) -> Option<Pass> {
        let (_, dp, material, scale) = self.physical(u)?;
        let bsdf = Bsdf::new(&material, &self.options);
        let n = self.map.len();
        let width = n + 1;
        let m = self.n_residuals();
        let channels = self.channels;
        let columns: Vec<(Target, f64)> = self
            .map
            .slots
            .iter()
            .zip(&dp)
            .map(|(s, &d)| (s.target, d))
            .collect();
        let mut chunks: Vec<Chunk> = Vec::new();
        for (b, block) in self.blocks.iter().enumerate() {
            let mut start = 0;
            while start < block.len() {
                let end = (start + CHUNK).min(block.len());
                chunks.push((b, start, end));
                start = end;
            }
        }
        let (floor, kind, blocks) = (self.floor, self.kind, self.blocks);
        let floor2 = floor * floor;
        let run_chunk = |&(b, start, end): &Chunk| -> ChunkResult {
            let block = &blocks[b];
            let rows = (end - start) * channels;
            // Column-major [J | r] of this chunk, or just r.
            let mut a = vec![0.0; if COMPRESS { rows * width } else { rows }];
            let residual_column = if COMPRESS { n * rows } else { 0 };
            let mut grad = Gradient::default();
            let mut sum_rel = 0.0;
            let mut finite = true;
            let mut row = 0;
            for i in start..end {
                let g = &block.geometry[i];
                let y = &block.values[i * channels..(i + 1) * channels];
                let k = &block.factors[i * channels..(i + 1) * channels];
                let f = if COMPRESS {
                    bsdf.eval_geometry_with_gradient(g, &mut grad)
                } else {
                    bsdf.eval_geometry(g)
                };
                for ch in 0..channels {
                    let model = scale * f[ch];
                    let (res, dr_dm) = residual(kind, floor, model, y[ch], k[ch]);
                    a[residual_column + row] = res;
                    finite &= res.is_finite();
                    let e = model - y[ch];
                    sum_rel += e * e / (y[ch] * y[ch] + floor2);
                    if COMPRESS {
                        for (j, &(target, dp_du)) in columns.iter().enumerate() {
                            let dm_dp = match target {
                                Target::Arg(a) => scale * grad.d[a][ch],
                                Target::Gray => {
                                    scale * (grad.d[0][ch] + grad.d[1][ch] + grad.d[2][ch])
                                }
                                Target::Scale => f[ch],
                            };
                            let value = dr_dm * dm_dp * dp_du;
                            finite &= value.is_finite();
                            a[j * rows + row] = value;
                        }
                    }
                    row += 1;
                }
            }
            let data = if COMPRESS && finite {
                householder_triangle(&mut a, rows, width)
            } else {
                a
            };
            ChunkResult {
                data,
                sum_rel,
                finite,
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
        let rms_rel = (parts.iter().map(|p| p.sum_rel).sum::<f64>() / m.max(1) as f64).sqrt();
        if !COMPRESS {
            let mut residuals = Vec::with_capacity(m);
            for p in &parts {
                residuals.extend_from_slice(&p.data);
            }
            return Some(Pass::Full {
                residuals: DVector::from_vec(residuals),
            });
        }
        // Stack the chunks' triangles (in chunk order) and reduce again.
        let rows = parts.len() * width;
        let mut stacked = vec![0.0; rows * width];
        for (c, p) in parts.iter().enumerate() {
            for j in 0..width {
                let target = &mut stacked[j * rows + c * width..j * rows + (c + 1) * width];
                target.copy_from_slice(&p.data[j * width..(j + 1) * width]);
            }
        }
        let triangle = householder_triangle(&mut stacked, rows, width);
        Some(Pass::Compressed { triangle, rms_rel })
    }
}

/// Householder QR of the column-major `rows × cols` matrix `a` (which it
/// overwrites); returns the `cols × cols` upper-triangular factor R,
/// column-major, with zero rows where `rows < cols`.
fn householder_triangle(a: &mut [f64], rows: usize, cols: usize) -> Vec<f64> {
    let mut r = vec![0.0; cols * cols];
    if rows == 0 {
        return r;
    }
    let mut diagonal = vec![0.0; cols];
    for k in 0..cols.min(rows) {
        let (left, right) = a.split_at_mut((k + 1) * rows);
        let v = &mut left[k * rows + k..];
        let norm2 = dot(v, v);
        if norm2 == 0.0 {
            continue;
        }
        let norm = norm2.sqrt();
        // Reflect x onto alpha·e₁ with the sign that avoids cancellation.
        let alpha = if v[0] > 0.0 { -norm } else { norm };
        v[0] -= alpha;
        let v_norm2 = norm2 - 2.0 * alpha * (v[0] + alpha) + alpha * alpha;
        for column in right.chunks_exact_mut(rows) {
            let x = &mut column[k..];
            let s = 2.0 * dot(v, x) / v_norm2;
            for (xi, vi) in x.iter_mut().zip(v.iter()) {
                *xi -= s * vi;
            }
        }
        diagonal[k] = alpha;
    }
    for j in 0..cols {
        for k in 0..=j.min(rows - 1) {
            r[j * cols + k] = if k == j { diagonal[k] } else { a[j * rows + k] };
        }
    }
    r
}

/// `a · b` over the common length, with four running sums so the loop is
/// not one long chain of dependent additions (the order is fixed, so the
/// result is deterministic).
#[inline]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut sums = [0.0; 4];
    let (a4, b4) = (a.chunks_exact(4), b.chunks_exact(4));
    let tail: f64 = a4
        .remainder()
        .iter()
        .zip(b4.remainder())
        .map(|(x, y)| x * y)
        .sum();
    for (x, y) in a4.zip(b4) {
        for k in 0..4 {
            sums[k] += x[k] * y[k];
        }
    }
    (sums[0] + sums[1]) + (sums[2] + sums[3]) + tail
}

/// A chunk of one block: (block, first sample, end sample).
type Chunk = (usize, usize, usize);

/// What one chunk contributes to a pass.
struct ChunkResult {
    /// Its triangle of `[J | r]`, or its residuals.
    data: Vec<f64>,
    sum_rel: f64,
    finite: bool,
}

enum Pass {
    Full { residuals: DVector<f64> },
    Compressed { triangle: Vec<f64>, rms_rel: f64 },
}

/// The problem at one point, compressed to n + 1 rows (see
/// [`Problem::compressed`]).
#[derive(Debug, Clone)]
pub(crate) struct Compressed {
    pub residuals: DVector<f64>,
    /// `[R; 0]`, (n + 1) × n: `JᵀJ = RᵀR`.
    pub jacobian: DMatrix<f64>,
    pub rms_rel: f64,
}

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
    /// accepted point, which it has always evaluated already.
    fn residuals(&self) -> Option<DVector<f64>> {
        let c = self.compressed(&self.u)?;
        let residuals = c.residuals.clone();
        self.history.borrow_mut().push((self.u.clone(), c));
        Some(residuals)
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        self.evaluated(&self.u).map(|c| c.jacobian)
    }
}

impl Problem<'_> {
    /// The compressed problem at `u`, from the history or a new pass.
    pub(crate) fn evaluated(&self, u: &DVector<f64>) -> Option<Compressed> {
        let known = self
            .history
            .borrow()
            .iter()
            .rev()
            .find(|(at, _)| at == u)
            .map(|(_, c)| c.clone());
        known.or_else(|| {
            let c = self.compressed(u)?;
            self.history.borrow_mut().push((u.clone(), c.clone()));
            Some(c)
        })
    }
}
