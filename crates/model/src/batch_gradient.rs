//! Sums over many direction pairs of `f` and its gradient, from geometry
//! computed once: the inner loop of a fit to patch averages.
//!
//! A fitter that models each data sample as the average of `f` over a run
//! of (light, view) pairs keeps every pair's [`Geometry`] (it does not
//! depend on the material's arguments) in a [`GeometryBatch`], and on
//! every iteration asks [`Bsdf::sum_geometry_with_gradient`] for the sum
//! of `f` and of its gradient over each sample's run.
//!
//! The kernel works as [`Bsdf::eval_batch`] does (see the `batch`
//! module): every branch of the scalar code is computed for every pair and
//! the right one selected, `exp` is [`exp_lane`], the material switches are
//! const parameters, and `pulp` dispatches the loop to the widest SIMD
//! level. Two differences: one `exp` serves both sides (a pair is either
//! reflection or transmission, so the lobe's exponent is selected before
//! the `exp`), and the sums are kept in [`LANES`] partial sums per
//! quantity, because the compiler does not reorder a floating-point
//! reduction by itself. Pairs are evaluated in blocks of [`BLOCK`] into a
//! buffer (a loop of the same shape as `eval_soa`'s, which vectorises),
//! then each block is added lane-wise into a block sum that joins the
//! running total: about `BLOCK/LANES + n/BLOCK` additions per partial sum,
//! not `n/LANES`, which keeps the rounding of long runs small.
//!
//! Every pair's terms mirror `Bsdf::eval_impl` operation for operation, so
//! the sums differ from the scalar sums only by `exp_lane` (≤ 2 ulp) and the
//! order of the additions.

#![allow(clippy::needless_range_loop)] // channel and lane loops index several arrays at once

use crate::batch::{MANUAL2004, RADIANCE, WARD1992, exp_lane};
use crate::bsdf::{Bsdf, Geometry, Gradient, Rgb};
use crate::kind::Variant;
use crate::material::FTINY;
use glam::DVec3;
use std::f64::consts::PI;
use std::ops::Range;

/// Pairs evaluated into the buffer at a time.
const BLOCK: usize = 64;
/// Partial sums per quantity (one AVX-512 vector of f64).
const LANES: usize = 8;
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
        for column in [
            &mut self.light_cosine,
            &mut self.view_cosine,
            &mut self.lobe_factor,
            &mut self.x_u,
            &mut self.x_v,
            &mut self.cutoff_factor,
        ] {
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
#[derive(Clone, Copy)]
struct Columns<'a> {
    light_cosine: &'a [f64],
    view_cosine: &'a [f64],
    lobe_factor: &'a [f64],
    x_u: &'a [f64],
    x_v: &'a [f64],
    cutoff_factor: &'a [f64],
}

/// The per-material numbers the kernel reads, copied out of [`Bsdf`].
#[derive(Debug, Clone, Copy)]
struct Constants {
    color: [f64; 3],
    spec: f64,
    trans: f64,
    tspec: f64,
    fresnel_k: f64,
    /// 1/(α² + widening) of the reflected lobe along û and v̂.
    inv_wu: f64,
    inv_wv: f64,
    /// `sqrt(inv_wu inv_wv)`.
    inv_w_root: f64,
    /// α² + ω/π of the transmitted lobe along û and v̂.
    bu: f64,
    bv: f64,
    /// `sqrt(bu bv)`.
    b_root: f64,
    /// ∂(α²_u, α²_v)/∂(a_u, a_v).
    dalpha2: [[f64; 2]; 2],
    pure: bool,
    metal: bool,
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

    /// Picks the kernel for this material's switches.
    fn sum_dispatch<const GRAD: bool, const CH: usize>(&self, g: Columns) -> [[f64; 3]; ROWS] {
        assert!(CH <= 3, "CH = {CH}: at most 3 channels");
        let k = self.sum_constants();
        let variant = self.options().variant;
        let fresnel = self.has_fresnel();
        macro_rules! run {
            ($a:literal, $t:literal) => {
                match (variant, fresnel) {
                    (Variant::Radiance, true) => {
                        sum_kernel::<GRAD, CH, $a, $t, RADIANCE, true>(&k, g)
                    }
                    (Variant::Radiance, false) => {
                        sum_kernel::<GRAD, CH, $a, $t, RADIANCE, false>(&k, g)
                    }
                    (Variant::Manual2004, _) => {
                        sum_kernel::<GRAD, CH, $a, $t, MANUAL2004, false>(&k, g)
                    }
                    (Variant::Ward1992, _) => {
                        sum_kernel::<GRAD, CH, $a, $t, WARD1992, false>(&k, g)
                    }
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

    fn sum_constants(&self) -> Constants {
        let (inv_wu, inv_wv) = self.reflect_inv_width();
        let (bu, bv) = self.transmit_width();
        Constants {
            color: self.material().color(),
            spec: self.spec_arg(),
            trans: self.trans_arg(),
            tspec: self.tspec_arg(),
            fresnel_k: self.options().fresnel_k,
            inv_wu,
            inv_wv,
            inv_w_root: (inv_wu * inv_wv).sqrt(),
            bu,
            bv,
            b_root: (bu * bv).sqrt(),
            dalpha2: self.width_derivatives(),
            pure: self.is_pure(),
            metal: self.kind().is_metal(),
        }
    }
}

/// The sums, compiled for the best SIMD level of this CPU.
fn sum_kernel<
    const GRAD: bool,
    const CH: usize,
    const ANISO: bool,
    const TRANS: bool,
    const V: u8,
    const FRESNEL: bool,
>(
    k: &Constants,
    g: Columns,
) -> [[f64; 3]; ROWS] {
    pulp::Arch::new().dispatch(
        #[inline(always)]
        || sum_loop::<GRAD, CH, ANISO, TRANS, V, FRESNEL>(k, g),
    )
}

#[inline(always)]
fn sum_loop<
    const GRAD: bool,
    const CH: usize,
    const ANISO: bool,
    const TRANS: bool,
    const V: u8,
    const FRESNEL: bool,
>(
    k: &Constants,
    g: Columns,
) -> [[f64; 3]; ROWS] {
    let rows = if GRAD {
        4 + usize::from(ANISO) + 2 * usize::from(TRANS)
    } else {
        1
    };
    // Quantity q = row * CH + ch.
    let quantities = rows * CH;
    let mut buffer = [[0.0f64; BLOCK]; ROWS * 3];
    let mut total = [[0.0f64; LANES]; ROWS * 3];
    let n = g.light_cosine.len();
    let mut start = 0;
    while start < n {
        let m = (n - start).min(BLOCK);
        let end = start + m;
        // Re-slicing to one length lets the compiler drop the bounds checks.
        let ci = &g.light_cosine[start..end];
        let co = &g.view_cosine[start..end];
        let lf = &g.lobe_factor[start..end];
        let xu = &g.x_u[start..end];
        let xv = &g.x_v[start..end];
        let cut = &g.cutoff_factor[start..end];
        for i in 0..m {
            let (xv, cut) = if ANISO { (xv[i], cut[i]) } else { (0.0, 0.0) };
            let terms = pair_terms::<GRAD, CH, ANISO, TRANS, V, FRESNEL>(
                k, ci[i], co[i], lf[i], xu[i], xv, cut,
            );
            for row in 0..rows {
                for ch in 0..CH {
                    buffer[row * CH + ch][i] = terms[row][ch];
                }
            }
        }
        // Whole vectors: the tail of a short block adds zeros.
        let padded = m.div_ceil(LANES) * LANES;
        for (q, column) in buffer.iter_mut().enumerate().take(quantities) {
            column[m..padded].fill(0.0);
            let mut block_sum = [0.0f64; LANES];
            for chunk in column[..padded].chunks_exact(LANES) {
                for j in 0..LANES {
                    block_sum[j] += chunk[j];
                }
            }
            for j in 0..LANES {
                total[q][j] += block_sum[j];
            }
        }
        start = end;
    }
    let mut sums = [[0.0f64; 3]; ROWS];
    for row in 0..rows {
        for ch in 0..CH {
            let t = total[row * CH + ch];
            sums[row][ch] = ((t[0] + t[1]) + (t[2] + t[3])) + ((t[4] + t[5]) + (t[6] + t[7]));
        }
    }
    sums
}

/// One pair's `f` and gradient terms without data-dependent branches:
/// row 0 is `f`, row 1 ∂f_c/∂colour_c, row r ≥ 2 ∂f/∂(argument r + 1)
/// (channels `< CH`; the rest 0). Mirrors `Bsdf::eval_impl` (with its
/// `add_reflection`, `add_transmission` and lobes) operation for
/// operation, both sides computed and the right one selected.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn pair_terms<
    const GRAD: bool,
    const CH: usize,
    const ANISO: bool,
    const TRANS: bool,
    const V: u8,
    const FRESNEL: bool,
>(
    k: &Constants,
    ci: f64,
    co: f64,
    lobe_factor: f64,
    xu: f64,
    xv: f64,
    cutoff_factor: f64,
) -> [[f64; 3]; ROWS] {
    let c = k.color;
    let (s_arg, t_arg, ts_arg) = (k.spec, k.trans, k.tspec);

    // View coefficients: the view-side Fresnel estimate on the specularity.
    let ward_e = if V == WARD1992 {
        exp_lane(-6.0 * co)
    } else {
        0.0
    };
    let (spec, dspec) = if FRESNEL {
        let f = exp_lane(-5.85 * co) - k.fresnel_k;
        (s_arg + f * (1.0 - s_arg), 1.0 - f)
    } else if V == WARD1992 && !k.metal {
        (s_arg + ward_e * (1.0 - s_arg), 1.0 - ward_e)
    } else {
        (s_arg, 1.0)
    };
    let t = t_arg * (1.0 - spec);
    let rd = 1.0 - t - spec;
    let wrong_side = if ci < 0.0 {
        t <= FTINY
    } else {
        t >= 1.0 - FTINY
    };
    let ts = t * ts_arg;
    let td = t - ts;
    let light_fresnel = if FRESNEL && (rd > FTINY || td > FTINY) {
        1.0 - (exp_lane(-5.85 * ci.abs()) - k.fresnel_k)
    } else {
        1.0
    };
    let front = !wrong_side && ci > FTINY;
    let behind = TRANS && !wrong_side && ci < -FTINY;

    // One exp for the lobe of whichever side the pair is on. FRESNEL
    // implies roughness 0: no lobe at all.
    let transmitted_lobe = TRANS && ci < 0.0;
    let exponent = if ANISO {
        let reflected = -(xu * k.inv_wu + xv * k.inv_wv);
        let through = -(xu / k.bu + xv / k.bv);
        if transmitted_lobe { through } else { reflected }
    } else {
        let reflected = -xu * k.inv_wu;
        let through = -xu / k.bu;
        if transmitted_lobe { through } else { reflected }
    };
    let e = if FRESNEL { 0.0 } else { exp_lane(exponent) };

    // The reflected lobe and its derivatives by the squared widths.
    let (r_value, r_du, r_dv) = if ANISO {
        let value = lobe_factor * e * k.inv_w_root;
        (
            value,
            value * (xu * k.inv_wu - 0.5) * k.inv_wu,
            value * (xv * k.inv_wv - 0.5) * k.inv_wv,
        )
    } else {
        let value = lobe_factor * e * k.inv_wu;
        (value, value * (xu * k.inv_wu - 1.0) * k.inv_wu, 0.0)
    };
    let r_passes = V != RADIANCE || r_value > FTINY;
    // The transmitted lobe.
    let (t_value, t_du, t_dv, t_passes) = if ANISO {
        let value = e * lobe_factor / (PI * k.b_root);
        // rtrace applies its cut-off after multiplying by sqrt(|ci|/co).
        let cutoff_value = e * cutoff_factor / (PI * k.b_root);
        (
            value,
            value * (xu / k.bu - 0.5) / k.bu,
            value * (xv / k.bv - 0.5) / k.bv,
            V != RADIANCE || cutoff_value > FTINY,
        )
    } else {
        let lobe = e / (PI * k.bu);
        let value = lobe * lobe_factor;
        (
            value,
            value * (xu / k.bu - 1.0) / k.bu,
            0.0,
            V != RADIANCE || lobe > FTINY,
        )
    };

    let ward_metal = V == WARD1992 && k.metal;
    let spec_on = if ward_metal {
        s_arg > FTINY
    } else {
        spec > FTINY
    };
    let r_lobe_on = !FRESNEL && !k.pure && spec_on && r_passes;
    let t_lobe_on = TRANS && !FRESNEL && !k.pure && ts > FTINY && t_passes;
    let rd_on = rd > FTINY;
    let td_on = TRANS && td > FTINY;
    let r_k = rd * light_fresnel / PI;
    let t_k = td * light_fresnel / PI;
    let g_lf = light_fresnel / PI;
    let da = k.dalpha2;
    let pick = |reflected: f64, through: f64| {
        if front {
            reflected
        } else if behind {
            through
        } else {
            0.0
        }
    };

    let mut out = [[0.0; 3]; ROWS];
    for ch in 0..CH {
        let cc = c[ch];
        // Reflection: diffuse, then the lobe.
        let coloured = cc * s_arg + (1.0 - cc * s_arg) * ward_e;
        let (rf, rdc, rds, rdt) = if ward_metal {
            (
                cc * (1.0 - coloured) / PI,
                ((1.0 - coloured) - cc * s_arg * (1.0 - ward_e)) / PI,
                -cc * cc * (1.0 - ward_e) / PI,
                0.0,
            )
        } else if rd_on {
            (
                cc * r_k,
                r_k,
                cc * g_lf * (-(1.0 - t_arg) * dspec),
                cc * g_lf * (-(1.0 - spec)),
            )
        } else {
            (0.0, 0.0, 0.0, 0.0)
        };
        let (s, ds_dc, ds_drs) = if ward_metal {
            (coloured, s_arg * (1.0 - ward_e), cc * (1.0 - ward_e))
        } else if k.metal {
            (cc * s_arg, s_arg, cc)
        } else {
            (spec, 0.0, dspec)
        };
        let (rf, rdc, rds, rru, rrv) = if r_lobe_on {
            (
                rf + s * r_value,
                rdc + ds_dc * r_value,
                rds + ds_drs * r_value,
                s * (r_du * da[0][0] + r_dv * da[1][0]),
                s * (r_du * da[0][1] + r_dv * da[1][1]),
            )
        } else {
            (rf, rdc, rds, 0.0, 0.0)
        };

        out[0][ch] = pick(rf, 0.0);
        if !GRAD && !TRANS {
            continue;
        }
        // Transmission: diffuse, then the lobe.
        let (tf, tdc, tds, tdt, tdts) = if td_on {
            (
                cc * t_k,
                t_k,
                cc * g_lf * (-t_arg * (1.0 - ts_arg) * dspec),
                cc * g_lf * (1.0 - spec) * (1.0 - ts_arg),
                cc * g_lf * (-t_arg * (1.0 - spec)),
            )
        } else {
            (0.0, 0.0, 0.0, 0.0, 0.0)
        };
        let coef = cc * ts;
        let (tf, tdc, tds, tdt, tdts, tru, trv) = if t_lobe_on {
            (
                tf + cc * ts * t_value,
                tdc + ts * t_value,
                tds + cc * (-t_arg * ts_arg * dspec) * t_value,
                tdt + cc * ts_arg * (1.0 - spec) * t_value,
                tdts + cc * t_arg * (1.0 - spec) * t_value,
                coef * (t_du * da[0][0] + t_dv * da[1][0]),
                coef * (t_du * da[0][1] + t_dv * da[1][1]),
            )
        } else {
            (tf, tdc, tds, tdt, tdts, 0.0, 0.0)
        };

        out[0][ch] = pick(rf, tf);
        if GRAD {
            out[1][ch] = pick(rdc, tdc);
            out[2][ch] = pick(rds, tds);
            out[3][ch] = pick(rru, tru);
            if ANISO {
                out[4][ch] = pick(rrv, trv);
            }
            if TRANS {
                let it = 4 + usize::from(ANISO);
                out[it][ch] = pick(rdt, tdt);
                out[it + 1][ch] = pick(0.0, tdts);
            }
        }
    }
    out
}
