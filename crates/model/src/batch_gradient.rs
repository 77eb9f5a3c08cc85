//! Sums over many direction pairs of `f` and its gradient, from geometry
//! computed once: the inner loop of a fit to patch averages.
//!
//! A fitter that models each data sample as the average of `f` over a run
//! of (light, view) pairs keeps every pair's [`Geometry`] (it does not
//! depend on the material's arguments) in a [`GeometryBatch`], and on
//! every iteration asks [`Bsdf::sum_geometry_with_gradient`] for the sum
//! of `f` and of its gradient over each sample's run.
//!
//! The kernel follows [`Bsdf::eval_batch`] (see the `batch` module):
//! every branch of the scalar code is computed for every pair and the
//! right one selected, `exp` is [`exp_lane`]'s algorithm, the material
//! switches are const parameters, and `pulp` dispatches to the widest SIMD
//! level (AVX-512: 8 pairs per vector). Unlike `eval_batch` it is written
//! on pulp's vector type directly rather than left to the compiler's
//! auto-vectoriser, which kept this loop scalar (too many outputs and
//! selects for its cost model). One `exp` serves both sides: a pair is
//! either reflection or transmission, so the lobe's exponent is selected
//! before the `exp`. Each quantity is summed per lane, in blocks of
//! [`BLOCK_VECTORS`] vectors that then join a running total, which keeps
//! the rounding of long runs small.
//!
//! Every pair's terms mirror `Bsdf::eval_impl` operation for operation (no
//! fused multiply-add), so the sums differ from the scalar sums only by
//! `exp` (≤ 2 ulp from libm) and the order of the additions: about 1e-16
//! of the sum of the terms' magnitudes in the tests.
//!
//! [`exp_lane`]: crate::exp_lane

#![allow(clippy::needless_range_loop)] // channel and lane loops index several arrays at once

use crate::batch::{
    Constants, EXP_FLUSH_BELOW, EXP_LN2_HI, EXP_LN2_LO, EXP_TAYLOR, MANUAL2004, RADIANCE,
    ROUND_MAGIC, WARD1992,
};
use crate::bsdf::{Bsdf, Geometry, Gradient, Rgb};
use crate::kind::Variant;
use crate::material::FTINY;
use glam::DVec3;
use std::f64::consts::PI;
use std::ops::Range;

/// Rows of per-pair terms: `f`, ∂f/∂colour (own channel), then
/// ∂f/∂(argument 3 + j) for j = 0..5.
const ROWS: usize = 7;

/// [`Geometry`] of many pairs as one array per field (structure of
/// arrays), for [`Bsdf::sum_geometry`] and
/// [`Bsdf::sum_geometry_with_gradient`]. Like a [`Geometry`], it is valid
/// for every [`Bsdf`] of the type, orientation and options it was made
/// under, whatever their arguments.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GeometryBatch {
    light_cosine: Vec<f64>,
    view_cosine: Vec<f64>,
    lobe_factor: Vec<f64>,
    x_u: Vec<f64>,
    x_v: Vec<f64>,
    cutoff_factor: Vec<f64>,
}

impl GeometryBatch {
    /// Empty.
    pub fn new() -> GeometryBatch {
        GeometryBatch::default()
    }

    /// Empty, with room for `n` pairs.
    pub fn with_capacity(n: usize) -> GeometryBatch {
        GeometryBatch {
            light_cosine: Vec::with_capacity(n),
            view_cosine: Vec::with_capacity(n),
            lobe_factor: Vec::with_capacity(n),
            x_u: Vec::with_capacity(n),
            x_v: Vec::with_capacity(n),
            cutoff_factor: Vec::with_capacity(n),
        }
    }

    /// Room for `n` more pairs.
    pub fn reserve(&mut self, n: usize) {
        for column in self.columns_mut() {
            column.reserve(n);
        }
    }

    /// Appends one pair's geometry.
    #[inline]
    pub fn push(&mut self, g: Geometry) {
        self.light_cosine.push(g.light_cosine);
        self.view_cosine.push(g.view_cosine);
        self.lobe_factor.push(g.lobe_factor);
        self.x_u.push(g.x_u);
        self.x_v.push(g.x_v);
        self.cutoff_factor.push(g.cutoff_factor);
    }

    /// Every column, for what is done to all alike.
    fn columns_mut(&mut self) -> [&mut Vec<f64>; 6] {
        [
            &mut self.light_cosine,
            &mut self.view_cosine,
            &mut self.lobe_factor,
            &mut self.x_u,
            &mut self.x_v,
            &mut self.cutoff_factor,
        ]
    }

    /// The columns of pairs `at..at + n`, in the order light cosine, view
    /// cosine, lobe factor, x_u, x_v, cut-off factor, for a writer that
    /// fills all six. The batch grows to `at + n` pairs if it is shorter
    /// (with zeros); the values there are what it held, and the pairs
    /// past `at + n` stay: a scratch batch refilled sample after sample
    /// is neither cleared nor zero-filled again.
    ///
    /// # Panics
    /// If `at > self.len()`.
    pub(crate) fn columns_at(&mut self, at: usize, n: usize) -> [&mut [f64]; 6] {
        assert!(
            at <= self.len(),
            "GeometryBatch: writing at {at}, past the {} pairs held",
            self.len()
        );
        let end = at + n;
        if self.len() < end {
            for column in self.columns_mut() {
                column.resize(end, 0.0);
            }
        }
        self.columns_mut().map(|column| &mut column[at..end])
    }

    /// Pair `i`'s geometry, as pushed.
    ///
    /// # Panics
    /// If `i >= self.len()`.
    pub fn get(&self, i: usize) -> Geometry {
        Geometry {
            light_cosine: self.light_cosine[i],
            view_cosine: self.view_cosine[i],
            lobe_factor: self.lobe_factor[i],
            x_u: self.x_u[i],
            x_v: self.x_v[i],
            cutoff_factor: self.cutoff_factor[i],
        }
    }

    /// Number of pairs.
    pub fn len(&self) -> usize {
        self.light_cosine.len()
    }

    /// True if there are none.
    pub fn is_empty(&self) -> bool {
        self.light_cosine.is_empty()
    }

    /// Removes every pair (keeps the storage).
    pub fn clear(&mut self) {
        for column in self.columns_mut() {
            column.clear();
        }
    }

    /// The pairs `range` as slices.
    fn columns(&self, range: Range<usize>) -> Columns<'_> {
        assert!(
            range.start <= range.end && range.end <= self.len(),
            "GeometryBatch: range {range:?} outside 0..{}",
            self.len()
        );
        Columns {
            light_cosine: &self.light_cosine[range.clone()],
            view_cosine: &self.view_cosine[range.clone()],
            lobe_factor: &self.lobe_factor[range.clone()],
            x_u: &self.x_u[range.clone()],
            x_v: &self.x_v[range.clone()],
            cutoff_factor: &self.cutoff_factor[range],
        }
    }
}

impl Extend<Geometry> for GeometryBatch {
    fn extend<I: IntoIterator<Item = Geometry>>(&mut self, iter: I) {
        let mut iter = iter.into_iter();
        let (low, high) = iter.size_hint();
        if high != Some(low) {
            self.reserve(low);
            for g in iter {
                self.push(g);
            }
            return;
        }
        // A known length: the columns grow once and are written in place,
        // without a capacity check per field and pair (a fit that
        // recomputes patch pairs' geometry on every pass spends most of
        // its time here).
        let start = self.len();
        for column in self.columns_mut() {
            column.resize(start + low, 0.0);
        }
        let rows = self.light_cosine[start..]
            .iter_mut()
            .zip(&mut self.view_cosine[start..])
            .zip(&mut self.lobe_factor[start..])
            .zip(&mut self.x_u[start..])
            .zip(&mut self.x_v[start..])
            .zip(&mut self.cutoff_factor[start..]);
        let mut written = 0;
        for ((((((lc, vc), lf), xu), xv), cf), g) in rows.zip(&mut iter) {
            *lc = g.light_cosine;
            *vc = g.view_cosine;
            *lf = g.lobe_factor;
            *xu = g.x_u;
            *xv = g.x_v;
            *cf = g.cutoff_factor;
            written += 1;
        }
        // An iterator whose length was not what it said.
        if written < low {
            for column in self.columns_mut() {
                column.truncate(start + written);
            }
        }
        for g in iter {
            self.push(g);
        }
    }
}

impl FromIterator<Geometry> for GeometryBatch {
    fn from_iter<I: IntoIterator<Item = Geometry>>(iter: I) -> GeometryBatch {
        let mut batch = GeometryBatch::new();
        batch.extend(iter);
        batch
    }
}

/// A range of a [`GeometryBatch`], all slices of one length.
///
/// Not `Copy` on purpose: the kernel's closure moves it, which makes the
/// closure `FnOnce` only; a closure that is also `Fn` is called through a
/// shim that LLVM does not inline into pulp's target-feature function, and
/// the loop is then compiled for the SSE2 baseline.
struct Columns<'a> {
    light_cosine: &'a [f64],
    view_cosine: &'a [f64],
    lobe_factor: &'a [f64],
    x_u: &'a [f64],
    x_v: &'a [f64],
    cutoff_factor: &'a [f64],
}

impl Bsdf {
    /// Appends the [`Geometry`] of every pair `(lights[i], views[i])` to
    /// `out` (see [`Bsdf::geometry`]).
    ///
    /// # Panics
    /// If `lights` and `views` have different lengths.
    pub fn geometry_batch(&self, lights: &[DVec3], views: &[DVec3], out: &mut GeometryBatch) {
        assert_eq!(
            lights.len(),
            views.len(),
            "Bsdf::geometry_batch: {} lights but {} views",
            lights.len(),
            views.len()
        );
        for (&l, &v) in lights.iter().zip(views) {
            out.push(self.geometry(l, v));
        }
    }

    /// The sum of `f` over the pairs `range` of `g` (made under this
    /// type, orientation and options), channels `< CH` (1 or 3; the
    /// others are returned as 0). Equals the sum of
    /// [`Bsdf::eval_geometry`] over those pairs to about 1e-15 relative.
    ///
    /// # Panics
    /// If `range` is not within `0..g.len()`, or `CH > 3`.
    pub fn sum_geometry<const CH: usize>(&self, g: &GeometryBatch, range: Range<usize>) -> Rgb {
        let sums = self.sum_dispatch::<false, CH>(g.columns(range));
        std::array::from_fn(|ch| if ch < CH { sums[0][ch] } else { 0.0 })
    }

    /// The sum of `f` over the pairs `range` of `g` and, into `grad_sum`,
    /// the sum of its gradients: what summing
    /// [`Bsdf::eval_geometry_channels_with_gradient::<CH>`] over those
    /// pairs gives (to about 1e-15 relative), with a vectorised kernel.
    /// Channels `CH..3` of the value are 0 and of `grad_sum` untouched;
    /// channels `< CH` of `grad_sum` are overwritten (0 beyond the type's
    /// arguments).
    ///
    /// [`Bsdf::eval_geometry_channels_with_gradient::<CH>`]: Bsdf::eval_geometry_channels_with_gradient
    ///
    /// # Panics
    /// If `range` is not within `0..g.len()`, or `CH > 3`.
    pub fn sum_geometry_with_gradient<const CH: usize>(
        &self,
        g: &GeometryBatch,
        range: Range<usize>,
        grad_sum: &mut Gradient,
    ) -> Rgb {
        let sums = self.sum_dispatch::<true, CH>(g.columns(range));
        for d in &mut grad_sum.d {
            d[..CH].fill(0.0);
        }
        let anisotropic = self.kind().is_anisotropic();
        let transmitting = self.kind().is_transmitting();
        // Rows 2.. hold ∂f/∂(argument 3 + j) for the arguments the type has.
        let rows = 4 + usize::from(anisotropic) + 2 * usize::from(transmitting);
        for ch in 0..CH {
            grad_sum.d[ch][ch] = sums[1][ch];
            for row in 2..rows {
                grad_sum.d[row + 1][ch] = sums[row][ch];
            }
        }
        std::array::from_fn(|ch| if ch < CH { sums[0][ch] } else { 0.0 })
    }

    /// The sums, for this material's switches.
    fn sum_dispatch<const GRAD: bool, const CH: usize>(&self, g: Columns) -> [[f64; 3]; ROWS] {
        assert!(CH <= 3, "CH = {CH}: at most 3 channels");
        self.by_switches(Sums::<GRAD, CH> { g })
    }

    /// Runs `kernel` compiled for this material's switches: its type's
    /// anisotropy and transmission, the formula set, and rtrace's Fresnel
    /// switch.
    pub(crate) fn by_switches<K: SwitchedKernel>(&self, kernel: K) -> K::Output {
        let k = self.batch_constants();
        let variant = self.options().variant;
        let fresnel = self.has_fresnel();
        macro_rules! run {
            ($a:literal, $t:literal) => {
                match (variant, fresnel) {
                    (Variant::Radiance, true) => kernel.run::<$a, $t, RADIANCE, true>(&k),
                    (Variant::Radiance, false) => kernel.run::<$a, $t, RADIANCE, false>(&k),
                    (Variant::Manual2004, _) => kernel.run::<$a, $t, MANUAL2004, false>(&k),
                    (Variant::Ward1992, _) => kernel.run::<$a, $t, WARD1992, false>(&k),
                }
            };
        }
        match (self.kind().is_anisotropic(), self.kind().is_transmitting()) {
            (false, false) => run!(false, false),
            (false, true) => run!(false, true),
            (true, false) => run!(true, false),
            (true, true) => run!(true, true),
        }
    }
}

/// A kernel compiled once per material switch: anisotropic, transmitting,
/// the formula set `V` and rtrace's Fresnel switch.
pub(crate) trait SwitchedKernel {
    type Output;
    fn run<const ANISO: bool, const TRANS: bool, const V: u8, const FRESNEL: bool>(
        self,
        k: &Constants,
    ) -> Self::Output;
}

/// The sums over pairs, compiled for the best SIMD level of this CPU.
struct Sums<'a, const GRAD: bool, const CH: usize> {
    g: Columns<'a>,
}

impl<const GRAD: bool, const CH: usize> SwitchedKernel for Sums<'_, GRAD, CH> {
    type Output = [[f64; 3]; ROWS];

    fn run<const ANISO: bool, const TRANS: bool, const V: u8, const FRESNEL: bool>(
        self,
        k: &Constants,
    ) -> Self::Output {
        pulp::Arch::new().dispatch(SumOp::<GRAD, CH, ANISO, TRANS, V, FRESNEL> { k, g: self.g })
    }
}

/// Every pair's `f` and gradient, from [`Bsdf::eval_geometry_each`] and
/// [`Bsdf::eval_geometry_each_with_gradient`]: what
/// [`Bsdf::eval_geometry_channels_with_gradient`] gives pair by pair, in
/// structure-of-arrays form. Reused between calls, it keeps its storage.
#[derive(Debug, Clone, Default)]
pub struct PairTerms {
    /// Pairs held.
    len: usize,
    /// Each quantity's column length: `len` rounded up to whole vectors.
    stride: usize,
    /// Channels evaluated (`CH`).
    channels: usize,
    /// Term rows held (see `term_rows`).
    rows: usize,
    /// Quantity `q = row · channels + ch` of pair `i` at `q · stride + i`.
    data: Vec<f64>,
}

impl PairTerms {
    /// Empty.
    pub fn new() -> PairTerms {
        PairTerms::default()
    }

    /// Number of pairs.
    pub fn len(&self) -> usize {
        self.len
    }

    /// True if there are none.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// `f` of pair `i`, channel `ch` (0 beyond the channels evaluated).
    #[inline(always)]
    pub fn value(&self, i: usize, ch: usize) -> f64 {
        if ch < self.channels {
            self.data[ch * self.stride + i]
        } else {
            0.0
        }
    }

    /// `∂f_ch/∂argument a` of pair `i`: entry `d[a][ch]` of the
    /// [`Gradient`] that [`Bsdf::eval_geometry_channels_with_gradient`]
    /// fills (0 for the arguments the type does not have, and without
    /// gradients).
    #[inline(always)]
    pub fn derivative(&self, i: usize, a: usize, ch: usize) -> f64 {
        // Row 1 is ∂f_c/∂colour_c; row r ≥ 2 is ∂f/∂(argument r + 1).
        let row = if a < 3 {
            if a != ch {
                return 0.0;
            }
            1
        } else {
            a - 1
        };
        if row < self.rows && ch < self.channels {
            self.data[(row * self.channels + ch) * self.stride + i]
        } else {
            0.0
        }
    }

    /// `f` of every pair, channel `ch < CH`, as one slice.
    ///
    /// # Panics
    /// If `ch` is not among the channels evaluated.
    pub fn value_column(&self, ch: usize) -> &[f64] {
        assert!(ch < self.channels, "channel {ch} was not evaluated");
        &self.data[ch * self.stride..ch * self.stride + self.len]
    }

    /// `∂f_ch/∂argument a` of every pair as one slice (see
    /// [`PairTerms::derivative`]), or `None` where it is 0 for every pair
    /// (another channel's colour, an argument the type does not have, no
    /// gradients, or a channel not evaluated).
    pub fn derivative_column(&self, a: usize, ch: usize) -> Option<&[f64]> {
        let row = if a < 3 {
            if a != ch {
                return None;
            }
            1
        } else {
            a - 1
        };
        (row < self.rows && ch < self.channels).then(|| {
            let start = (row * self.channels + ch) * self.stride;
            &self.data[start..start + self.len]
        })
    }

    /// Room for `len` pairs of `rows` rows and `channels` channels.
    fn reset(&mut self, len: usize, rows: usize, channels: usize) {
        self.len = len;
        self.stride = len.div_ceil(MAX_LANES) * MAX_LANES;
        self.rows = rows;
        self.channels = channels;
        // Every entry read is written by the kernel first: no clearing.
        let needed = rows * channels * self.stride;
        if self.data.len() < needed {
            self.data.resize(needed, 0.0);
        }
    }

    /// The storage the kernel writes: each quantity's column.
    fn columns_mut(&mut self) -> &mut [f64] {
        let needed = self.rows * self.channels * self.stride;
        &mut self.data[..needed]
    }
}

/// The widest SIMD vector in f64 lanes (AVX-512): [`PairTerms`] columns
/// are whole vectors at every level.
const MAX_LANES: usize = 8;

impl Bsdf {
    /// `f` (channels `< CH`) of every pair `range` of `g` (made under this
    /// type, orientation and options), into `out`: what
    /// [`Bsdf::eval_geometry`] gives pair by pair, to `exp`'s 2 ulp.
    ///
    /// # Panics
    /// If `range` is not within `0..g.len()`, or `CH > 3`.
    pub fn eval_geometry_each<const CH: usize>(
        &self,
        g: &GeometryBatch,
        range: Range<usize>,
        out: &mut PairTerms,
    ) {
        self.each_dispatch::<false, CH>(g.columns(range), out);
    }

    /// `f` and its gradient (channels `< CH`) of every pair `range` of
    /// `g`, into `out`: what
    /// [`Bsdf::eval_geometry_channels_with_gradient::<CH>`] gives pair by
    /// pair (to `exp`'s 2 ulp), with the vectorised kernel of
    /// [`Bsdf::sum_geometry_with_gradient`].
    ///
    /// [`Bsdf::eval_geometry_channels_with_gradient::<CH>`]: Bsdf::eval_geometry_channels_with_gradient
    ///
    /// # Panics
    /// If `range` is not within `0..g.len()`, or `CH > 3`.
    pub fn eval_geometry_each_with_gradient<const CH: usize>(
        &self,
        g: &GeometryBatch,
        range: Range<usize>,
        out: &mut PairTerms,
    ) {
        self.each_dispatch::<true, CH>(g.columns(range), out);
    }

    /// The per-pair terms, for this material's switches.
    fn each_dispatch<const GRAD: bool, const CH: usize>(&self, g: Columns, out: &mut PairTerms) {
        assert!(CH <= 3, "CH = {CH}: at most 3 channels");
        let rows = term_rows(
            GRAD,
            self.kind().is_anisotropic(),
            self.kind().is_transmitting(),
        );
        out.reset(g.light_cosine.len(), rows, CH);
        let out = out.columns_mut();
        self.by_switches(Each::<GRAD, CH> { g, out });
    }
}

/// The per-pair terms, compiled for the best SIMD level of this CPU.
struct Each<'a, const GRAD: bool, const CH: usize> {
    g: Columns<'a>,
    out: &'a mut [f64],
}

impl<const GRAD: bool, const CH: usize> SwitchedKernel for Each<'_, GRAD, CH> {
    type Output = ();

    fn run<const ANISO: bool, const TRANS: bool, const V: u8, const FRESNEL: bool>(
        self,
        k: &Constants,
    ) {
        let (g, out) = (self.g, self.out);
        pulp::Arch::new().dispatch(EachOp::<GRAD, CH, ANISO, TRANS, V, FRESNEL> { k, g, out });
    }
}

/// The per-pair kernel as a `pulp` operation (see [`SumOp`]): the same
/// terms, stored instead of summed.
struct EachOp<
    'a,
    const GRAD: bool,
    const CH: usize,
    const ANISO: bool,
    const TRANS: bool,
    const V: u8,
    const FRESNEL: bool,
> {
    k: &'a Constants,
    g: Columns<'a>,
    out: &'a mut [f64],
}

impl<
    const GRAD: bool,
    const CH: usize,
    const ANISO: bool,
    const TRANS: bool,
    const V: u8,
    const FRESNEL: bool,
> pulp::WithSimd for EachOp<'_, GRAD, CH, ANISO, TRANS, V, FRESNEL>
{
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) -> Self::Output {
        let ops = Ops(simd);
        let k = self.k;
        let g = self.g;
        let rows = term_rows(GRAD, ANISO, TRANS);
        let quantities = rows * CH;
        let zero = ops.splat(0.0);
        // The loads and the loop are written out as in SumOp: a shared
        // driver taking the loop body as a closure was not inlined into
        // pulp's target-feature function (17× slower).
        let (ci, ci_tail) = S::as_simd_f64s(g.light_cosine);
        let (co, co_tail) = S::as_simd_f64s(g.view_cosine);
        let (lf, lf_tail) = S::as_simd_f64s(g.lobe_factor);
        let (xu, xu_tail) = S::as_simd_f64s(g.x_u);
        let (xv, xv_tail) = S::as_simd_f64s(g.x_v);
        let (cut, cut_tail) = S::as_simd_f64s(g.cutoff_factor);
        let n = ci.len();
        let (co, lf, xu) = (&co[..n], &lf[..n], &xu[..n]);
        let (xv, cut) = if ANISO {
            (&xv[..n], &cut[..n])
        } else {
            (&xv[..0], &cut[..0])
        };
        // Each quantity's column is whole vectors long (PairTerms::reset).
        let (out, _) = S::as_mut_simd_f64s(self.out);
        let vectors = out.len().checked_div(quantities).unwrap_or(0);
        let mut store = |i: usize, t: &[[S::f64s; 3]; ROWS]| {
            for row in 0..rows {
                for ch in 0..CH {
                    out[(row * CH + ch) * vectors + i] = t[row][ch];
                }
            }
        };
        for i in 0..n {
            let (v, c) = if ANISO { (xv[i], cut[i]) } else { (zero, zero) };
            let t = simd_terms::<S, GRAD, CH, ANISO, TRANS, V, FRESNEL>(
                ops, k, ci[i], co[i], lf[i], xu[i], v, c,
            );
            store(i, &t);
        }
        if !ci_tail.is_empty() {
            // Lanes past the end load 0 and give 0.
            let load = |tail: &[f64]| simd.partial_load_f64s(tail);
            let (v, c) = if ANISO {
                (load(xv_tail), load(cut_tail))
            } else {
                (zero, zero)
            };
            let t = simd_terms::<S, GRAD, CH, ANISO, TRANS, V, FRESNEL>(
                ops,
                k,
                load(ci_tail),
                load(co_tail),
                load(lf_tail),
                load(xu_tail),
                v,
                c,
            );
            store(n, &t);
        }
    }
}

/// Number of term rows a kernel fills: `f` alone, or `f`, ∂/∂colour,
/// ∂/∂spec, ∂/∂rough_u, then ∂/∂rough_v (anisotropic) and ∂/∂trans,
/// ∂/∂tspec (transmitting).
const fn term_rows(grad: bool, aniso: bool, trans: bool) -> usize {
    if grad {
        4 + aniso as usize + 2 * trans as usize
    } else {
        1
    }
}

/// The kernel as a `pulp` operation: written on pulp's SIMD vectors
/// (`S::f64s`, 8 lanes with AVX-512), since the compiler would not
/// vectorise the scalar form of this loop.
struct SumOp<
    'a,
    const GRAD: bool,
    const CH: usize,
    const ANISO: bool,
    const TRANS: bool,
    const V: u8,
    const FRESNEL: bool,
> {
    k: &'a Constants,
    g: Columns<'a>,
}

impl<
    const GRAD: bool,
    const CH: usize,
    const ANISO: bool,
    const TRANS: bool,
    const V: u8,
    const FRESNEL: bool,
> pulp::WithSimd for SumOp<'_, GRAD, CH, ANISO, TRANS, V, FRESNEL>
{
    type Output = [[f64; 3]; ROWS];

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) -> Self::Output {
        let ops = Ops(simd);
        let k = self.k;
        let g = self.g;
        let rows = term_rows(GRAD, ANISO, TRANS);
        let quantities = rows * CH;
        let zero = ops.splat(0.0);
        let mut total = [zero; ROWS * 3];
        let mut block = [zero; ROWS * 3];
        let (ci, ci_tail) = S::as_simd_f64s(g.light_cosine);
        let (co, co_tail) = S::as_simd_f64s(g.view_cosine);
        let (lf, lf_tail) = S::as_simd_f64s(g.lobe_factor);
        let (xu, xu_tail) = S::as_simd_f64s(g.x_u);
        let (xv, xv_tail) = S::as_simd_f64s(g.x_v);
        let (cut, cut_tail) = S::as_simd_f64s(g.cutoff_factor);
        let n = ci.len();
        // Re-sliced to one length: no bounds checks in the loop.
        let (co, lf, xu) = (&co[..n], &lf[..n], &xu[..n]);
        let (xv, cut) = if ANISO {
            (&xv[..n], &cut[..n])
        } else {
            (&xv[..0], &cut[..0])
        };
        let add_terms = |sums: &mut [S::f64s; ROWS * 3], t: &[[S::f64s; 3]; ROWS]| {
            for row in 0..rows {
                for ch in 0..CH {
                    let q = row * CH + ch;
                    sums[q] = ops.add(sums[q], t[row][ch]);
                }
            }
        };
        for i in 0..n {
            let (v, c) = if ANISO { (xv[i], cut[i]) } else { (zero, zero) };
            let t = simd_terms::<S, GRAD, CH, ANISO, TRANS, V, FRESNEL>(
                ops, k, ci[i], co[i], lf[i], xu[i], v, c,
            );
            add_terms(&mut block, &t);
            // A block sum of BLOCK_VECTORS vectors joins the total.
            if i % BLOCK_VECTORS == BLOCK_VECTORS - 1 {
                for q in 0..quantities {
                    total[q] = ops.add(total[q], block[q]);
                    block[q] = zero;
                }
            }
        }
        if !ci_tail.is_empty() {
            // Lanes past the end load 0: light cosine 0 contributes nothing.
            let load = |tail: &[f64]| simd.partial_load_f64s(tail);
            let (v, c) = if ANISO {
                (load(xv_tail), load(cut_tail))
            } else {
                (zero, zero)
            };
            let t = simd_terms::<S, GRAD, CH, ANISO, TRANS, V, FRESNEL>(
                ops,
                k,
                load(ci_tail),
                load(co_tail),
                load(lf_tail),
                load(xu_tail),
                v,
                c,
            );
            add_terms(&mut block, &t);
        }
        let mut sums = [[0.0f64; 3]; ROWS];
        for row in 0..rows {
            for ch in 0..CH {
                let q = row * CH + ch;
                sums[row][ch] = simd.reduce_sum_f64s(ops.add(total[q], block[q]));
            }
        }
        sums
    }
}

/// Vectors added into a block sum before it joins the running total:
/// about `BLOCK_VECTORS + n/(lanes·BLOCK_VECTORS)` additions per partial
/// sum instead of `n/lanes`, which keeps the rounding of long runs small.
const BLOCK_VECTORS: usize = 8;

/// pulp's vector operations under short names.
#[derive(Clone, Copy)]
pub(crate) struct Ops<S>(pub(crate) S);

impl<S: pulp::Simd> Ops<S> {
    #[inline(always)]
    pub(crate) fn splat(self, x: f64) -> S::f64s {
        self.0.splat_f64s(x)
    }
    #[inline(always)]
    pub(crate) fn add(self, a: S::f64s, b: S::f64s) -> S::f64s {
        self.0.add_f64s(a, b)
    }
    #[inline(always)]
    pub(crate) fn sub(self, a: S::f64s, b: S::f64s) -> S::f64s {
        self.0.sub_f64s(a, b)
    }
    #[inline(always)]
    pub(crate) fn mul(self, a: S::f64s, b: S::f64s) -> S::f64s {
        self.0.mul_f64s(a, b)
    }
    #[inline(always)]
    pub(crate) fn div(self, a: S::f64s, b: S::f64s) -> S::f64s {
        self.0.div_f64s(a, b)
    }
    #[inline(always)]
    pub(crate) fn neg(self, a: S::f64s) -> S::f64s {
        self.0.neg_f64s(a)
    }
    #[inline(always)]
    pub(crate) fn lt(self, a: S::f64s, b: S::f64s) -> S::m64s {
        self.0.less_than_f64s(a, b)
    }
    #[inline(always)]
    pub(crate) fn le(self, a: S::f64s, b: S::f64s) -> S::m64s {
        self.0.less_than_or_equal_f64s(a, b)
    }
    #[inline(always)]
    pub(crate) fn gt(self, a: S::f64s, b: S::f64s) -> S::m64s {
        self.0.greater_than_f64s(a, b)
    }
    #[inline(always)]
    pub(crate) fn ge(self, a: S::f64s, b: S::f64s) -> S::m64s {
        self.0.greater_than_or_equal_f64s(a, b)
    }
    #[inline(always)]
    pub(crate) fn and(self, a: S::m64s, b: S::m64s) -> S::m64s {
        self.0.and_m64s(a, b)
    }
    #[inline(always)]
    pub(crate) fn or(self, a: S::m64s, b: S::m64s) -> S::m64s {
        self.0.or_m64s(a, b)
    }
    #[inline(always)]
    pub(crate) fn not(self, a: S::m64s) -> S::m64s {
        self.0.not_m64s(a)
    }
    /// All lanes `value`.
    #[inline(always)]
    pub(crate) fn mask(self, value: bool) -> S::m64s {
        let zero = self.splat(0.0);
        if value {
            self.le(zero, zero)
        } else {
            self.lt(zero, zero)
        }
    }
    /// `if mask { a } else { b }` per lane.
    #[inline(always)]
    pub(crate) fn select(self, mask: S::m64s, a: S::f64s, b: S::f64s) -> S::f64s {
        self.0.select_f64s(mask, a, b)
    }

    /// [`exp_lane`] on every lane, operation for operation (the same
    /// values, bit for bit).
    #[inline(always)]
    pub(crate) fn exp(self, x: S::f64s) -> S::f64s {
        const LN2_HI: f64 = EXP_LN2_HI;
        const LN2_LO: f64 = EXP_LN2_LO;
        const FLUSH_BELOW: f64 = EXP_FLUSH_BELOW;
        const A: [f64; 13] = EXP_TAYLOR;
        let a = |k: usize| self.splat(A[k]);
        let s = self.0;
        // Clamped so that 2ⁿ stays representable (max then min, as
        // f64::clamp; a NaN lane stays NaN-derived and is never selected).
        let xc = s.min_f64s(s.max_f64s(x, self.splat(FLUSH_BELOW)), self.splat(709.0));
        let magic = self.splat(ROUND_MAGIC);
        let shifted = self.add(self.mul(xc, self.splat(std::f64::consts::LOG2_E)), magic);
        let n = self.sub(shifted, magic);
        let r = self.sub(
            self.sub(xc, self.mul(n, self.splat(LN2_HI))),
            self.mul(n, self.splat(LN2_LO)),
        );
        let r2 = self.mul(r, r);
        let r4 = self.mul(r2, r2);
        let r8 = self.mul(r4, r4);
        let q0 = self.add(a(0), self.mul(a(1), r));
        let q1 = self.add(a(2), self.mul(a(3), r));
        let q2 = self.add(a(4), self.mul(a(5), r));
        let q3 = self.add(a(6), self.mul(a(7), r));
        let q4 = self.add(a(8), self.mul(a(9), r));
        let q5 = self.add(a(10), self.mul(a(11), r));
        let s0 = self.add(q0, self.mul(q1, r2));
        let s1 = self.add(q2, self.mul(q3, r2));
        let s2 = self.add(q4, self.mul(q5, r2));
        let t0 = self.add(s0, self.mul(s1, r4));
        let t1 = self.add(s2, self.mul(a(12), r4));
        let p = self.add(t0, self.mul(t1, r8));
        // 2ⁿ from the bits: n + 1.5·2⁵² holds n in its low bits; times 2⁵²
        // (a shift by 52, wrapping) puts it in the exponent field.
        let low = s.transmute_u64s_f64s(shifted);
        let exponent = s.add_u64s(
            s.mul_u64s(low, s.splat_u64s(1 << 52)),
            s.splat_u64s(1023 << 52),
        );
        let e = self.mul(p, s.transmute_f64s_u64s(exponent));
        let below = self.lt(x, self.splat(FLUSH_BELOW));
        let above = self.gt(x, self.splat(709.0));
        self.select(
            below,
            self.splat(0.0),
            self.select(above, self.splat(f64::INFINITY), e),
        )
    }
}

/// One vector of pairs' `f` and gradient terms: row 0 is `f`, row 1
/// ∂f_c/∂colour_c, row r ≥ 2 ∂f/∂(argument r + 1) (channels `< CH`; the
/// rest 0). Mirrors `Bsdf::eval_impl` (with its `add_reflection`,
/// `add_transmission` and lobes) operation for operation, every branch
/// computed and the right one selected per lane.
///
/// A vector whose pairs all have the light in front (or all behind), as
/// a Klems patch pair's do, computes that side's terms alone: the other
/// side's would not be selected, so the values are the same bits.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn simd_terms<
    S: pulp::Simd,
    const GRAD: bool,
    const CH: usize,
    const ANISO: bool,
    const TRANS: bool,
    const V: u8,
    const FRESNEL: bool,
>(
    o: Ops<S>,
    k: &Constants,
    ci: S::f64s,
    co: S::f64s,
    lobe_factor: S::f64s,
    xu: S::f64s,
    xv: S::f64s,
    cutoff_factor: S::f64s,
) -> [[S::f64s; 3]; ROWS] {
    // One monomorphisation per side: the side is a const parameter.
    macro_rules! on_side {
        ($side:expr) => {
            simd_terms_on::<S, GRAD, CH, ANISO, TRANS, V, FRESNEL, { $side }>(
                o,
                k,
                ci,
                co,
                lobe_factor,
                xu,
                xv,
                cutoff_factor,
            )
        };
    }
    if TRANS {
        let all = |m: S::m64s| o.0.first_true_m64s(o.not(m)) == S::F64_LANES;
        if all(o.gt(ci, o.splat(FTINY))) {
            return on_side!(FRONT);
        }
        if all(o.lt(ci, o.splat(-FTINY))) {
            return on_side!(BEHIND);
        }
    }
    on_side!(BOTH)
}

/// [`simd_terms`] for vectors whose lights are on either side.
const BOTH: u8 = 0;
/// ... all in front (light cosine > FTINY): transmission terms not computed.
const FRONT: u8 = 1;
/// ... all behind (light cosine < −FTINY): reflection terms not computed.
const BEHIND: u8 = 2;

/// [`simd_terms`] for pairs on the sides `SIDE`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn simd_terms_on<
    S: pulp::Simd,
    const GRAD: bool,
    const CH: usize,
    const ANISO: bool,
    const TRANS: bool,
    const V: u8,
    const FRESNEL: bool,
    const SIDE: u8,
>(
    o: Ops<S>,
    k: &Constants,
    ci: S::f64s,
    co: S::f64s,
    lobe_factor: S::f64s,
    xu: S::f64s,
    xv: S::f64s,
    cutoff_factor: S::f64s,
) -> [[S::f64s; 3]; ROWS] {
    let c = k.color;
    let (s_arg, t_arg, ts_arg) = (k.spec, k.trans, k.tspec);
    let sp = |x: f64| o.splat(x);
    let zero = sp(0.0);
    let one = sp(1.0);
    let tiny = sp(FTINY);

    // View coefficients: the view-side Fresnel estimate on the specularity.
    let ward_e = if V == WARD1992 {
        o.exp(o.mul(sp(-6.0), co))
    } else {
        zero
    };
    let (spec, dspec) = if FRESNEL {
        let f = o.sub(o.exp(o.mul(sp(-5.85), co)), sp(k.fresnel_k));
        (o.add(sp(s_arg), o.mul(f, sp(1.0 - s_arg))), o.sub(one, f))
    } else if V == WARD1992 && !k.metal {
        (
            o.add(sp(s_arg), o.mul(ward_e, sp(1.0 - s_arg))),
            o.sub(one, ward_e),
        )
    } else {
        (sp(s_arg), one)
    };
    let t = o.mul(sp(t_arg), o.sub(one, spec));
    let rd = o.sub(o.sub(one, t), spec);
    let light_behind = o.lt(ci, zero);
    let wrong_side = o.or(
        o.and(light_behind, o.le(t, tiny)),
        o.and(o.not(light_behind), o.ge(t, sp(1.0 - FTINY))),
    );
    let ts = o.mul(t, sp(ts_arg));
    let td = o.sub(t, ts);
    let light_fresnel = if FRESNEL {
        let abs_ci = o.0.abs_f64s(ci);
        let f = o.sub(o.exp(o.mul(sp(-5.85), abs_ci)), sp(k.fresnel_k));
        let on = o.or(o.gt(rd, tiny), o.gt(td, tiny));
        o.select(on, o.sub(one, f), one)
    } else {
        one
    };
    let front = o.and(o.not(wrong_side), o.gt(ci, tiny));
    let behind = if TRANS {
        o.and(o.not(wrong_side), o.lt(ci, sp(-FTINY)))
    } else {
        o.mask(false)
    };

    // One exp for the lobe of whichever side the pair is on. FRESNEL
    // implies roughness 0: no lobe at all.
    let exponent = if ANISO {
        let reflected = || o.neg(o.add(o.mul(xu, sp(k.inv_wu)), o.mul(xv, sp(k.inv_wv))));
        let through = || o.neg(o.add(o.div(xu, sp(k.bu)), o.div(xv, sp(k.bv))));
        match (TRANS, SIDE) {
            (false, _) | (_, FRONT) => reflected(),
            (_, BEHIND) => through(),
            _ => o.select(light_behind, through(), reflected()),
        }
    } else {
        let reflected = || o.mul(o.neg(xu), sp(k.inv_wu));
        let through = || o.div(o.neg(xu), sp(k.bu));
        match (TRANS, SIDE) {
            (false, _) | (_, FRONT) => reflected(),
            (_, BEHIND) => through(),
            _ => o.select(light_behind, through(), reflected()),
        }
    };
    let e = if FRESNEL { zero } else { o.exp(exponent) };

    // The reflected lobe and its derivatives by the squared widths.
    let (r_value, r_du, r_dv) = if ANISO {
        let value = o.mul(o.mul(lobe_factor, e), sp(k.inv_w_root));
        let du = o.mul(
            o.mul(value, o.sub(o.mul(xu, sp(k.inv_wu)), sp(0.5))),
            sp(k.inv_wu),
        );
        let dv = o.mul(
            o.mul(value, o.sub(o.mul(xv, sp(k.inv_wv)), sp(0.5))),
            sp(k.inv_wv),
        );
        (value, du, dv)
    } else {
        let value = o.mul(o.mul(lobe_factor, e), sp(k.inv_wu));
        let du = o.mul(
            o.mul(value, o.sub(o.mul(xu, sp(k.inv_wu)), one)),
            sp(k.inv_wu),
        );
        (value, du, zero)
    };
    let r_passes = if V == RADIANCE {
        o.gt(r_value, tiny)
    } else {
        o.mask(true)
    };
    // The transmitted lobe.
    let (t_value, t_du, t_dv, t_passes) = if !TRANS || SIDE == FRONT {
        (zero, zero, zero, o.mask(false))
    } else if ANISO {
        let root = sp(PI * k.b_root);
        let value = o.div(o.mul(e, lobe_factor), root);
        // rtrace applies its cut-off after multiplying by sqrt(|ci|/co).
        let cutoff_value = o.div(o.mul(e, cutoff_factor), root);
        let du = o.div(o.mul(value, o.sub(o.div(xu, sp(k.bu)), sp(0.5))), sp(k.bu));
        let dv = o.div(o.mul(value, o.sub(o.div(xv, sp(k.bv)), sp(0.5))), sp(k.bv));
        let passes = if V == RADIANCE {
            o.gt(cutoff_value, tiny)
        } else {
            o.mask(true)
        };
        (value, du, dv, passes)
    } else {
        let lobe = o.div(e, sp(PI * k.bu));
        let value = o.mul(lobe, lobe_factor);
        let du = o.div(o.mul(value, o.sub(o.div(xu, sp(k.bu)), one)), sp(k.bu));
        let passes = if V == RADIANCE {
            o.gt(lobe, tiny)
        } else {
            o.mask(true)
        };
        (value, du, zero, passes)
    };

    let ward_metal = V == WARD1992 && k.metal;
    let spec_on = if ward_metal {
        o.mask(s_arg > FTINY)
    } else {
        o.gt(spec, tiny)
    };
    let lobes = !FRESNEL && !k.pure;
    let r_lobe_on = o.and(o.mask(lobes), o.and(spec_on, r_passes));
    let t_lobe_on = o.and(o.mask(TRANS && lobes), o.and(o.gt(ts, tiny), t_passes));
    let rd_on = o.gt(rd, tiny);
    let td_on = o.gt(td, tiny);
    let r_k = o.div(o.mul(rd, light_fresnel), sp(PI));
    let t_k = o.div(o.mul(td, light_fresnel), sp(PI));
    let g_lf = o.div(light_fresnel, sp(PI));
    let da = k.dalpha2;
    // Only the side(s) SIDE computes are read: the other's terms are
    // dead code.
    let pick = |reflected: S::f64s, through: S::f64s| match SIDE {
        FRONT => o.select(front, reflected, zero),
        BEHIND => o.select(behind, through, zero),
        _ => o.select(front, reflected, o.select(behind, through, zero)),
    };
    // Roughness chain rule: coef · (du ∂α²_u/∂a + dv ∂α²_v/∂a).
    let chain = |coef: S::f64s, du: S::f64s, dv: S::f64s, j: usize| {
        o.mul(
            coef,
            o.add(o.mul(du, sp(da[0][j])), o.mul(dv, sp(da[1][j]))),
        )
    };

    let mut out = [[zero; 3]; ROWS];
    for ch in 0..CH {
        let cc = c[ch];
        let ccv = sp(cc);
        // Reflection: diffuse, then the lobe.
        let cs = cc * s_arg;
        let coloured = o.add(sp(cs), o.mul(sp(1.0 - cs), ward_e));
        let (rf, rdc, rds, rdt) = if ward_metal {
            let one_minus_e = o.sub(one, ward_e);
            (
                o.div(o.mul(ccv, o.sub(one, coloured)), sp(PI)),
                o.div(
                    o.sub(o.sub(one, coloured), o.mul(sp(cs), one_minus_e)),
                    sp(PI),
                ),
                o.div(o.mul(sp(-cc * cc), one_minus_e), sp(PI)),
                zero,
            )
        } else {
            let cg = o.mul(ccv, g_lf);
            (
                o.select(rd_on, o.mul(ccv, r_k), zero),
                o.select(rd_on, r_k, zero),
                o.select(rd_on, o.mul(cg, o.mul(sp(-(1.0 - t_arg)), dspec)), zero),
                o.select(rd_on, o.mul(cg, o.neg(o.sub(one, spec))), zero),
            )
        };
        let (s, ds_dc, ds_drs) = if ward_metal {
            let one_minus_e = o.sub(one, ward_e);
            (
                coloured,
                o.mul(sp(s_arg), one_minus_e),
                o.mul(ccv, one_minus_e),
            )
        } else if k.metal {
            (sp(cs), sp(s_arg), ccv)
        } else {
            (spec, zero, dspec)
        };
        let rf = o.select(r_lobe_on, o.add(rf, o.mul(s, r_value)), rf);
        out[0][ch] = pick(rf, zero);
        let rdc = o.select(r_lobe_on, o.add(rdc, o.mul(ds_dc, r_value)), rdc);
        let rds = o.select(r_lobe_on, o.add(rds, o.mul(ds_drs, r_value)), rds);
        let rru = o.select(r_lobe_on, chain(s, r_du, r_dv, 0), zero);
        let rrv = o.select(r_lobe_on, chain(s, r_du, r_dv, 1), zero);
        if GRAD {
            out[1][ch] = pick(rdc, zero);
            out[2][ch] = pick(rds, zero);
            out[3][ch] = pick(rru, zero);
            if ANISO {
                out[4][ch] = pick(rrv, zero);
            }
            if TRANS {
                out[4 + usize::from(ANISO)][ch] = pick(rdt, zero);
            }
        }
        if !TRANS {
            continue;
        }
        // Transmission: diffuse, then the lobe.
        let cg = o.mul(ccv, g_lf);
        let one_minus_spec = o.sub(one, spec);
        let tf = o.select(td_on, o.mul(ccv, t_k), zero);
        let coef = o.mul(ccv, ts);
        let tf = o.select(t_lobe_on, o.add(tf, o.mul(coef, t_value)), tf);
        out[0][ch] = pick(rf, tf);
        if !GRAD {
            continue;
        }
        let tdc = o.select(td_on, t_k, zero);
        let tds = o.select(
            td_on,
            o.mul(cg, o.mul(sp(-t_arg * (1.0 - ts_arg)), dspec)),
            zero,
        );
        let tdt = o.select(
            td_on,
            o.mul(o.mul(cg, one_minus_spec), sp(1.0 - ts_arg)),
            zero,
        );
        let tdts = o.select(td_on, o.mul(cg, o.mul(sp(-t_arg), one_minus_spec)), zero);
        let tdc = o.select(t_lobe_on, o.add(tdc, o.mul(ts, t_value)), tdc);
        let tds = o.select(
            t_lobe_on,
            o.add(
                tds,
                o.mul(o.mul(ccv, o.mul(sp(-t_arg * ts_arg), dspec)), t_value),
            ),
            tds,
        );
        let tdt = o.select(
            t_lobe_on,
            o.add(tdt, o.mul(o.mul(sp(cc * ts_arg), one_minus_spec), t_value)),
            tdt,
        );
        let tdts = o.select(
            t_lobe_on,
            o.add(tdts, o.mul(o.mul(sp(cc * t_arg), one_minus_spec), t_value)),
            tdts,
        );
        let tru = o.select(t_lobe_on, chain(coef, t_du, t_dv, 0), zero);
        out[1][ch] = pick(rdc, tdc);
        out[2][ch] = pick(rds, tds);
        out[3][ch] = pick(rru, tru);
        if ANISO {
            let trv = o.select(t_lobe_on, chain(coef, t_du, t_dv, 1), zero);
            out[4][ch] = pick(rrv, trv);
        }
        let it = 4 + usize::from(ANISO);
        out[it][ch] = pick(rdt, tdt);
        out[it + 1][ch] = pick(zero, tdts);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::direction;
    use crate::kind::MaterialKind;
    use crate::material::Material;
    use crate::options::EvalOptions;
    use pulp::WithSimd;

    /// The kernel's sums on one SIMD level, for `bsdf` (rough trans,
    /// Radiance variant) over `range`.
    fn sums_on<S: pulp::Simd>(
        simd: S,
        bsdf: &Bsdf,
        batch: &GeometryBatch,
        range: Range<usize>,
    ) -> [[f64; 3]; ROWS] {
        let k = bsdf.batch_constants();
        let op = SumOp::<true, 3, false, true, RADIANCE, false> {
            k: &k,
            g: batch.columns(range),
        };
        op.with_simd(simd)
    }

    /// A vector's terms computed for its side alone (one lane per vector
    /// on the scalar level: every pair is one-sided) are the bits of the
    /// terms computed for both sides, on both sides and at the thresholds.
    #[test]
    fn one_sided_terms_are_the_two_sided_bits() {
        fn check<const ANISO: bool, const V: u8, const FRESNEL: bool>(bsdf: &Bsdf) -> usize {
            let o = Ops(pulp::Scalar::new());
            let k = bsdf.batch_constants();
            let mut sided = 0;
            for i in 0..400 {
                let theta_in = [0.0, 30.0, 60.0, 85.0, 89.9999][i % 5];
                let l = direction(theta_in, 10.0 + i as f64);
                let v = direction((7.3 * i as f64) % 180.0, 190.0 + 0.5 * i as f64);
                let mut g = bsdf.geometry(l, v);
                if i % 7 == 0 {
                    g.light_cosine = [FTINY, -FTINY, 0.0, 2.0 * FTINY][i % 4];
                }
                let args = (
                    g.light_cosine,
                    g.view_cosine,
                    g.lobe_factor,
                    g.x_u,
                    g.x_v,
                    g.cutoff_factor,
                );
                let one = simd_terms::<_, true, 3, ANISO, true, V, FRESNEL>(
                    o, &k, args.0, args.1, args.2, args.3, args.4, args.5,
                );
                let both = simd_terms_on::<_, true, 3, ANISO, true, V, FRESNEL, BOTH>(
                    o, &k, args.0, args.1, args.2, args.3, args.4, args.5,
                );
                assert_eq!(format!("{one:?}"), format!("{both:?}"), "pair {i}: {g:?}");
                sided += usize::from(g.light_cosine.abs() > FTINY);
            }
            sided
        }
        let orient = Some(DVec3::new(0.3, 1.0, 0.2));
        let trans = |args: &[f64]| Material::new(MaterialKind::Trans, args, None).unwrap();
        let trans2 = Material::new(
            MaterialKind::Trans2,
            &[0.6, 0.7, 0.8, 0.04, 0.05, 0.2, 0.6, 0.4],
            orient,
        )
        .unwrap();
        let rough = trans(&[0.6, 0.7, 0.8, 0.04, 0.05, 0.6, 0.4]);
        let smooth = trans(&[0.6, 0.7, 0.8, 0.04, 0.0, 0.6, 0.4]);
        let with = |m: &Material, v: Variant| Bsdf::new(m, &EvalOptions::with_variant(v));
        let radiance = Variant::Radiance;
        assert!(with(&smooth, radiance).has_fresnel());
        let sided = check::<false, RADIANCE, false>(&with(&rough, radiance))
            + check::<false, RADIANCE, true>(&with(&smooth, radiance))
            + check::<false, MANUAL2004, false>(&with(&rough, Variant::Manual2004))
            + check::<false, WARD1992, false>(&with(&rough, Variant::Ward1992))
            + check::<true, RADIANCE, false>(&with(&trans2, radiance))
            + check::<true, MANUAL2004, false>(&with(&trans2, Variant::Manual2004))
            + check::<true, WARD1992, false>(&with(&trans2, Variant::Ward1992));
        assert!(sided > 7 * 300, "{sided} one-sided pairs");
    }

    /// Whatever level `pulp` picks (AVX-512, AVX2 or the scalar baseline),
    /// one pair's terms are the same bits, and long sums agree to rounding.
    #[test]
    fn every_simd_level_gives_the_same_terms() {
        let material = Material::new(
            MaterialKind::Trans,
            &[0.6, 0.7, 0.8, 0.04, 0.05, 0.6, 0.4],
            None,
        )
        .unwrap();
        let bsdf = Bsdf::new(&material, &EvalOptions::default());
        let mut batch = GeometryBatch::new();
        for i in 0..203 {
            let l = direction(20.0 + 0.3 * i as f64, 10.0);
            let v = direction((7.3 * i as f64) % 180.0, 190.0 + 0.5 * i as f64);
            batch.push(bsdf.geometry(l, v));
        }
        let n = batch.len();
        let scalar = pulp::Scalar::new();
        let whole = sums_on(scalar, &bsdf, &batch, 0..n);
        // Not vacuous: values, colour, specularity, roughness, trans and
        // tspec derivatives are all non-zero.
        for row in 0..6 {
            assert!(whole[row].iter().all(|&x| x != 0.0), "row {row}: {whole:?}");
        }
        let check = |sums: &dyn Fn(Range<usize>) -> [[f64; 3]; ROWS]| {
            for i in 0..n {
                assert_eq!(sums(i..i + 1), sums_on(scalar, &bsdf, &batch, i..i + 1));
            }
            let (got, want) = (sums(0..n), sums_on(scalar, &bsdf, &batch, 0..n));
            for (g, w) in got.iter().flatten().zip(want.iter().flatten()) {
                assert!((g - w).abs() <= 1e-14 * w.abs(), "{g} vs {w}");
            }
        };
        #[cfg(target_arch = "x86_64")]
        {
            if let Some(v3) = pulp::x86::V3::try_new() {
                check(&|r| v3.vectorize(|| sums_on(v3, &bsdf, &batch, r)));
            }
            if let Some(v4) = pulp::x86::V4::try_new() {
                check(&|r| v4.vectorize(|| sums_on(v4, &bsdf, &batch, r)));
            }
        }
    }
}
