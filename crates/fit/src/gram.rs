//! The Gram matrix `[J | r]ᵀ[J | r]` of a run of residual rows, summed with
//! SIMD vectors: the accumulation half of a fit's pass over measured
//! samples (the model half is brtf-model's per-pair kernel).
//!
//! The rows come as columns (`W` of them: the parameters' Jacobian columns,
//! then the residuals), each `stride` long and zero past the rows, so
//! padding adds nothing. Each vector lane sums its own rows; the lanes are
//! added at the end of the run. The order of the additions therefore
//! depends on the SIMD level `pulp` picks (8 lanes with AVX-512, 4 with
//! AVX2), not on the thread count: results are deterministic on a machine
//! and agree to rounding between machines.

/// Columns of one run: column `c` at `c · stride .. c · stride + rows`,
/// zeros after it up to the next column.
#[derive(Debug, Default)]
pub(crate) struct RunColumns {
    pub data: Vec<f64>,
    pub rows: usize,
    pub stride: usize,
}

/// Rows are padded to a multiple of the widest vector (AVX-512, 8 lanes),
/// so that every column is whole vectors at every level.
const MAX_LANES: usize = 8;

impl RunColumns {
    /// Room for `rows` rows of `width` columns; the padding is zero, the
    /// rows are to be written.
    pub(crate) fn reset(&mut self, rows: usize, width: usize) {
        let stride = rows.div_ceil(MAX_LANES) * MAX_LANES;
        if self.stride != stride || self.data.len() != stride * width {
            self.data.clear();
            self.data.resize(stride * width, 0.0);
        } else {
            for c in 0..width {
                self.data[c * stride + rows..(c + 1) * stride].fill(0.0);
            }
        }
        self.rows = rows;
        self.stride = stride;
    }

    /// Column `c`'s rows.
    pub(crate) fn column_mut(&mut self, c: usize) -> &mut [f64] {
        &mut self.data[c * self.stride..c * self.stride + self.rows]
    }
}

/// Adds the run's `Σ x_a x_b` (a ≤ b < W) to `gram` and, with `REPORT`,
/// `Σ r² x_a x_b` (a ≤ b < W − 1, r the last column) to `meat`.
pub(crate) fn accumulate<const W: usize, const REPORT: bool>(
    columns: &RunColumns,
    gram: &mut [[f64; W]; W],
    meat: &mut [[f64; W]; W],
) {
    let (sums, meats) = pulp::Arch::new().dispatch(GramOp::<W, REPORT> {
        data: &columns.data,
        stride: columns.stride,
    });
    for a in 0..W {
        for b in a..W {
            gram[a][b] += sums[a][b];
            if REPORT {
                meat[a][b] += meats[a][b];
            }
        }
    }
}

/// The accumulation as a `pulp` operation. Not `Copy`, so that its
/// closure is `FnOnce` and inlines into pulp's target-feature function.
struct GramOp<'a, const W: usize, const REPORT: bool> {
    data: &'a [f64],
    stride: usize,
}

impl<const W: usize, const REPORT: bool> pulp::WithSimd for GramOp<'_, W, REPORT> {
    type Output = ([[f64; W]; W], [[f64; W]; W]);

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) -> Self::Output {
        let (vectors, _) = S::as_simd_f64s(self.data);
        let lanes = std::mem::size_of::<S::f64s>() / std::mem::size_of::<f64>();
        let per_column = self.stride / lanes;
        let zero = simd.splat_f64s(0.0);
        let mut acc = [[zero; W]; W];
        let mut macc = [[zero; W]; W];
        for i in 0..per_column {
            let x: [S::f64s; W] = std::array::from_fn(|c| vectors[c * per_column + i]);
            for a in 0..W {
                for b in a..W {
                    acc[a][b] = simd.mul_add_f64s(x[a], x[b], acc[a][b]);
                }
            }
            if REPORT {
                let r = x[W - 1];
                let y: [S::f64s; W] = std::array::from_fn(|c| simd.mul_f64s(r, x[c]));
                for a in 0..W - 1 {
                    for b in a..W - 1 {
                        macc[a][b] = simd.mul_add_f64s(y[a], y[b], macc[a][b]);
                    }
                }
            }
        }
        let mut sums = [[0.0; W]; W];
        let mut meats = [[0.0; W]; W];
        for a in 0..W {
            for b in a..W {
                sums[a][b] = simd.reduce_sum_f64s(acc[a][b]);
                if REPORT {
                    meats[a][b] = simd.reduce_sum_f64s(macc[a][b]);
                }
            }
        }
        (sums, meats)
    }
}
