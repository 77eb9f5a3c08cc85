//! Batch evaluation: `f(l, v)` for many direction pairs at once, over
//! structure-of-arrays inputs, with the same values as [`Bsdf::eval`].
//!
//! [`Bsdf::eval`] branches per pair (front or back, cut-off, Fresnel) and
//! calls libm's `exp`, so the compiler cannot vectorise a loop over it.
//! The batch kernel computes every branch for every pair and selects the
//! result, with an `exp` made of plain arithmetic ([`exp_lane`]); the
//! loop over pairs then vectorises. The material-level switches (type,
//! variant, Fresnel) are const parameters of the kernel, so each
//! combination is its own loop without those branches.
//!
//! At run time the kernel is dispatched to the widest SIMD level the CPU
//! has (AVX-512, AVX2+FMA, else the SSE2 baseline) through `pulp`, which
//! keeps the `unsafe` target-feature calls in that crate. The kernel does
//! not use fused multiply-add (Rust never contracts `a * b + c`), so the
//! values do not depend on the level chosen.
//!
//! Values agree with [`Bsdf::eval`] to about 1e-15 relative: the only
//! difference is `exp` (a degree-12 Taylor polynomial after exact
//! range reduction, within 2 ulp of libm's).

use crate::bsdf::Bsdf;
use crate::kind::Variant;
use crate::material::FTINY;
use glam::DVec3;
use std::f64::consts::PI;

/// rtrace clamps the view cosine to at least this (`pdot >= .001`).
pub(crate) const MIN_VIEW_COSINE: f64 = 0.001;

/// Unit directions in the local frame as three coordinate arrays.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Directions {
    /// x coordinates.
    pub x: Vec<f64>,
    /// y coordinates.
    pub y: Vec<f64>,
    /// z coordinates (front normal).
    pub z: Vec<f64>,
}

impl Directions {
    /// Empty, with room for `n` directions.
    pub fn with_capacity(n: usize) -> Directions {
        Directions {
            x: Vec::with_capacity(n),
            y: Vec::with_capacity(n),
            z: Vec::with_capacity(n),
        }
    }

    /// `n` copies of `v` (one light for many views).
    pub fn repeated(v: DVec3, n: usize) -> Directions {
        Directions {
            x: vec![v.x; n],
            y: vec![v.y; n],
            z: vec![v.z; n],
        }
    }

    /// The directions of `vectors`, in order.
    pub fn from_vectors(vectors: &[DVec3]) -> Directions {
        let mut d = Directions::with_capacity(vectors.len());
        for &v in vectors {
            d.push(v);
        }
        d
    }

    /// Appends one direction.
    #[inline]
    pub fn push(&mut self, v: DVec3) {
        self.x.push(v.x);
        self.y.push(v.y);
        self.z.push(v.z);
    }

    /// Removes every direction (keeps the storage).
    pub fn clear(&mut self) {
        self.x.clear();
        self.y.clear();
        self.z.clear();
    }

    /// Number of directions (the length of `x`).
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// True if there are none.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// The three coordinate slices, checked to have the same length.
    fn slices(&self, what: &str) -> [&[f64]; 3] {
        assert!(
            self.y.len() == self.x.len() && self.z.len() == self.x.len(),
            "{what} directions: x, y and z have different lengths ({}, {}, {})",
            self.x.len(),
            self.y.len(),
            self.z.len()
        );
        [&self.x, &self.y, &self.z]
    }
}

/// RGB values as three channel arrays.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RgbBatch {
    /// Channel 0.
    pub r: Vec<f64>,
    /// Channel 1.
    pub g: Vec<f64>,
    /// Channel 2.
    pub b: Vec<f64>,
}

impl RgbBatch {
    /// Number of values (the length of `r`).
    pub fn len(&self) -> usize {
        self.r.len()
    }

    /// True if there are none.
    pub fn is_empty(&self) -> bool {
        self.r.is_empty()
    }

    /// Value `i` as an RGB triple.
    #[inline]
    pub fn get(&self, i: usize) -> [f64; 3] {
        [self.r[i], self.g[i], self.b[i]]
    }

    /// Adds `w ×` pair `i` of `other` to pair `i`.
    pub fn add_scaled(&mut self, w: f64, other: &RgbBatch) {
        for (c, o) in [
            (&mut self.r, &other.r),
            (&mut self.g, &other.g),
            (&mut self.b, &other.b),
        ] {
            for (x, y) in c.iter_mut().zip(o) {
                *x += w * y;
            }
        }
    }

    /// Sets all three channels to `n` zeros.
    pub fn resize(&mut self, n: usize) {
        for c in [&mut self.r, &mut self.g, &mut self.b] {
            c.clear();
            c.resize(n, 0.0);
        }
    }
}

/// The per-material numbers the kernel reads, copied out of [`Bsdf`].
#[derive(Debug, Clone, Copy)]
pub(crate) struct Constants {
    pub(crate) color: [f64; 3],
    pub(crate) spec: f64,
    pub(crate) trans: f64,
    pub(crate) tspec: f64,
    pub(crate) fresnel_k: f64,
    /// 1/(α² + widening) of the reflected lobe along û and v̂.
    pub(crate) inv_wu: f64,
    pub(crate) inv_wv: f64,
    /// `sqrt(inv_wu inv_wv)`.
    pub(crate) inv_w_root: f64,
    /// α² + ω/π of the transmitted lobe along û and v̂.
    pub(crate) bu: f64,
    pub(crate) bv: f64,
    /// `sqrt(bu bv)`.
    pub(crate) b_root: f64,
    /// ∂(α²_u, α²_v)/∂(a_u, a_v), for the gradient sums (`batch_gradient`).
    pub(crate) dalpha2: [[f64; 2]; 2],
    pub(crate) pure: bool,
    pub(crate) metal: bool,
    pub(crate) frame_u: [f64; 3],
    pub(crate) frame_v: [f64; 3],
}

pub(crate) const RADIANCE: u8 = 0;
pub(crate) const MANUAL2004: u8 = 1;
pub(crate) const WARD1992: u8 = 2;

impl Bsdf {
    /// `f(l, v)` for every pair `(light[i], view[i])`, written to `out`
    /// (resized to the number of pairs). Same conventions and, to about
    /// 1e-15 relative, the same values as [`Bsdf::eval`]; much faster for
    /// many pairs (see the module documentation of `batch`).
    ///
    /// # Panics
    /// If `light` and `view` hold different numbers of directions, or a
    /// [`Directions`] has coordinate arrays of different lengths.
    pub fn eval_batch(&self, light: &Directions, view: &Directions, out: &mut RgbBatch) {
        let l = light.slices("light");
        let v = view.slices("view");
        out.resize(l[0].len());
        let [r, g, b] = [&mut out.r, &mut out.g, &mut out.b];
        self.eval_soa(l, v, [r, g, b]);
    }

    /// [`Bsdf::eval_batch`] on borrowed arrays: `light = [x, y, z]`,
    /// `view = [x, y, z]`, `out = [r, g, b]`, all of one length.
    ///
    /// # Panics
    /// If the nine slices do not all have the same length.
    pub fn eval_soa(&self, light: [&[f64]; 3], view: [&[f64]; 3], out: [&mut [f64]; 3]) {
        let n = light[0].len();
        let lengths = [
            light[1].len(),
            light[2].len(),
            view[0].len(),
            view[1].len(),
            view[2].len(),
            out[0].len(),
            out[1].len(),
            out[2].len(),
        ];
        assert!(
            lengths.iter().all(|&m| m == n),
            "Bsdf::eval_soa: slices of different lengths (light x {n}, then {lengths:?})"
        );
        let k = self.batch_constants();
        let variant = self.options().variant;
        let fresnel = self.has_fresnel();
        let aniso = self.kind().is_anisotropic();
        let transmitting = self.kind().is_transmitting();
        // One monomorphised loop per combination of the material switches.
        macro_rules! run {
            ($a:literal, $t:literal) => {
                match (variant, fresnel) {
                    (Variant::Radiance, true) => {
                        kernel::<$a, $t, RADIANCE, true>(&k, light, view, out)
                    }
                    (Variant::Radiance, false) => {
                        kernel::<$a, $t, RADIANCE, false>(&k, light, view, out)
                    }
                    (Variant::Manual2004, _) => {
                        kernel::<$a, $t, MANUAL2004, false>(&k, light, view, out)
                    }
                    (Variant::Ward1992, _) => {
                        kernel::<$a, $t, WARD1992, false>(&k, light, view, out)
                    }
                }
            };
        }
        match (aniso, transmitting) {
            (false, false) => run!(false, false),
            (false, true) => run!(false, true),
            (true, false) => run!(true, false),
            (true, true) => run!(true, true),
        }
    }

    /// The material's numbers every batch kernel needs.
    pub(crate) fn batch_constants(&self) -> Constants {
        let (inv_wu, inv_wv) = self.reflect_inv_width();
        let (bu, bv) = self.transmit_width();
        let (fu, fv) = self.tangent_frame();
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
            frame_u: fu.to_array(),
            frame_v: fv.to_array(),
        }
    }
}

/// The loop over pairs, compiled for the best SIMD level of this CPU.
fn kernel<const ANISO: bool, const TRANS: bool, const V: u8, const FRESNEL: bool>(
    k: &Constants,
    light: [&[f64]; 3],
    view: [&[f64]; 3],
    out: [&mut [f64]; 3],
) {
    pulp::Arch::new().dispatch(
        #[inline(always)]
        || kernel_loop::<ANISO, TRANS, V, FRESNEL>(k, light, view, out),
    );
}

#[inline(always)]
fn kernel_loop<const ANISO: bool, const TRANS: bool, const V: u8, const FRESNEL: bool>(
    k: &Constants,
    light: [&[f64]; 3],
    view: [&[f64]; 3],
    out: [&mut [f64]; 3],
) {
    let [lx, ly, lz] = light;
    let [vx, vy, vz] = view;
    let [r, g, b] = out;
    let n = lx.len();
    // Re-slicing to one length lets the compiler drop the bounds checks.
    let (lx, ly, lz) = (&lx[..n], &ly[..n], &lz[..n]);
    let (vx, vy, vz) = (&vx[..n], &vy[..n], &vz[..n]);
    let (r, g, b) = (&mut r[..n], &mut g[..n], &mut b[..n]);
    for i in 0..n {
        let f =
            eval_lane::<ANISO, TRANS, V, FRESNEL>(k, [lx[i], ly[i], lz[i]], [vx[i], vy[i], vz[i]]);
        r[i] = f[0];
        g[i] = f[1];
        b[i] = f[2];
    }
}

/// `f(l, v)` for one pair without data-dependent branches: both sides
/// are computed and the right one selected. Mirrors `Bsdf::eval_impl`
/// operation for operation, so that the rounding is the same.
#[inline(always)]
fn eval_lane<const ANISO: bool, const TRANS: bool, const V: u8, const FRESNEL: bool>(
    k: &Constants,
    l: [f64; 3],
    v: [f64; 3],
) -> [f64; 3] {
    // Turn the surface towards the viewer.
    let flip = v[2] < 0.0;
    let (lx, ly) = (l[0], l[1]);
    let (vx, vy) = (v[0], v[1]);
    let lz = if flip { -l[2] } else { l[2] };
    let vz = if flip { -v[2] } else { v[2] };
    let ci = lz;
    let co = vz.max(MIN_VIEW_COSINE);
    let c = k.color;

    // View coefficients: the view-side Fresnel estimate on the specularity.
    let ward_e = if V == WARD1992 {
        exp_lane(-6.0 * co)
    } else {
        0.0
    };
    let spec = if FRESNEL {
        let f = exp_lane(-5.85 * co) - k.fresnel_k;
        k.spec + f * (1.0 - k.spec)
    } else if V == WARD1992 && !k.metal {
        k.spec + ward_e * (1.0 - k.spec)
    } else {
        k.spec
    };
    let t = k.trans * (1.0 - spec);
    let wrong_side = if ci < 0.0 {
        t <= FTINY
    } else {
        t >= 1.0 - FTINY
    };
    let ts = t * k.tspec;
    let td = t - ts;
    let rd = 1.0 - t - spec;
    let light_fresnel = if FRESNEL && (rd > FTINY || td > FTINY) {
        1.0 - (exp_lane(-5.85 * ci.abs()) - k.fresnel_k)
    } else {
        1.0
    };

    // Reflection (ci > FTINY).
    let hx = lx + vx;
    let hy = ly + vy;
    let hz = lz + vz;
    let hh = hx * hx + hy * hy + hz * hz;
    let inv_hn2 = 1.0 / (hz * hz);
    let lobe_factor = match V {
        RADIANCE => hh * inv_hn2 * inv_hn2 * (1.0 / PI),
        MANUAL2004 => 1.0 / (4.0 * PI * ci * co),
        _ => 1.0 / (4.0 * PI * (ci * co).sqrt()),
    };
    let exponent = if ANISO {
        let hu = hx * k.frame_u[0] + hy * k.frame_u[1] + hz * k.frame_u[2];
        let hv = hx * k.frame_v[0] + hy * k.frame_v[1] + hz * k.frame_v[2];
        let scale = if V == WARD1992 {
            2.0 / (hh * (1.0 + hz / hh.sqrt()))
        } else {
            inv_hn2
        };
        let xu = hu * hu * scale;
        let xv = hv * hv * scale;
        -(xu * k.inv_wu + xv * k.inv_wv)
    } else {
        let x = if V == WARD1992 {
            2.0 - 2.0 * hz / hh.sqrt()
        } else {
            hh * inv_hn2 - 1.0
        };
        -x * k.inv_wu
    };
    let lobe = if ANISO {
        lobe_factor * exp_lane(exponent) * k.inv_w_root
    } else {
        lobe_factor * exp_lane(exponent) * k.inv_wu
    };
    let ward_metal = V == WARD1992 && k.metal;
    let spec_on = if ward_metal {
        k.spec > FTINY
    } else {
        spec > FTINY
    };
    let lobe_on = !k.pure && spec_on && (V != RADIANCE || lobe > FTINY);
    let diffuse_k = rd * light_fresnel / PI;
    let mut reflected = [0.0; 3];
    for ch in 0..3 {
        let coloured = c[ch] * k.spec + (1.0 - c[ch] * k.spec) * ward_e;
        let diffuse = if ward_metal {
            c[ch] * (1.0 - coloured) / PI
        } else if rd > FTINY {
            c[ch] * diffuse_k
        } else {
            0.0
        };
        let s = if ward_metal {
            coloured
        } else if k.metal {
            c[ch] * k.spec
        } else {
            spec
        };
        reflected[ch] = if lobe_on { diffuse + s * lobe } else { diffuse };
    }

    if !TRANS {
        let front = !wrong_side && ci > FTINY;
        return reflected.map(|x| if front { x } else { 0.0 });
    }

    // Transmission (ci < -FTINY).
    let cit = -ci;
    let t_factor = if V == MANUAL2004 {
        1.0 / (cit * co)
    } else {
        1.0 / (cit * co).sqrt()
    };
    let t_lobe_on;
    let t_lobe = if ANISO {
        let cc = hh;
        let s2 = if cc > FTINY * FTINY {
            1.0 - hz * hz / cc
        } else {
            cc
        };
        let cu = hx * k.frame_u[0] + hy * k.frame_u[1] + hz * k.frame_u[2];
        let cv = hx * k.frame_v[0] + hy * k.frame_v[1] + hz * k.frame_v[2];
        let wide = s2 > FTINY * FTINY;
        let xu = if wide { cu * cu / s2 } else { 0.0 };
        let xv = if wide { cv * cv / s2 } else { 0.0 };
        let e = exp_lane(-(xu / k.bu + xv / k.bv));
        let value = e * t_factor / (PI * k.b_root);
        // rtrace applies its cut-off after multiplying by sqrt(|ci|/co).
        let cutoff_value = e * (cit / co).sqrt() / (PI * k.b_root);
        t_lobe_on = V != RADIANCE || cutoff_value > FTINY;
        value
    } else {
        let x = 2.0 + 2.0 * (vx * lx + vy * ly + vz * lz);
        let lobe = exp_lane(-x / k.bu) / (PI * k.bu);
        t_lobe_on = V != RADIANCE || lobe > FTINY;
        lobe * t_factor
    };
    let t_lobe_on = t_lobe_on && !k.pure && ts > FTINY;
    let td_k = td * light_fresnel / PI;
    let mut transmitted = [0.0; 3];
    for ch in 0..3 {
        let diffuse = if td > FTINY { c[ch] * td_k } else { 0.0 };
        transmitted[ch] = if t_lobe_on {
            diffuse + c[ch] * ts * t_lobe
        } else {
            diffuse
        };
    }
    let front = !wrong_side && ci > FTINY;
    let back = !wrong_side && ci < -FTINY;
    std::array::from_fn(|ch| {
        if front {
            reflected[ch]
        } else if back {
            transmitted[ch]
        } else {
            0.0
        }
    })
}

/// `1.5 · 2⁵²`: adding it rounds a double of magnitude < 2⁵¹ to an integer
/// and leaves that integer in the low bits of the representation.
pub(crate) const ROUND_MAGIC: f64 = 6_755_399_441_055_744.0;
/// ln 2 = `EXP_LN2_HI + EXP_LN2_LO`, the high part with 21 trailing zero
/// bits so that n·`EXP_LN2_HI` is exact (fdlibm's split). Shared by
/// [`exp_lane`] and the SIMD `exp` of the gradient kernel, which must give
/// the same bits.
pub(crate) const EXP_LN2_HI: f64 = f64::from_bits(0x3fe6_2e42_fee0_0000);
pub(crate) const EXP_LN2_LO: f64 = f64::from_bits(0x3dea_39ef_3579_3c76);
/// Below this, `eˣ` < 3.3e-308: flushed to 0.
pub(crate) const EXP_FLUSH_BELOW: f64 = -708.0;
/// Taylor coefficients 1/k!, k = 0 to 12, of `eʳ`.
pub(crate) const EXP_TAYLOR: [f64; 13] = [
    1.0,
    1.0,
    0.5,
    1.0 / 6.0,
    1.0 / 24.0,
    1.0 / 120.0,
    1.0 / 720.0,
    1.0 / 5_040.0,
    1.0 / 40_320.0,
    1.0 / 362_880.0,
    1.0 / 3_628_800.0,
    1.0 / 39_916_800.0,
    1.0 / 479_001_600.0,
];

/// `2ⁿ` for an integer-valued `n` in [−1022, 1023], from the bits.
#[inline(always)]
fn pow2(n: f64) -> f64 {
    let low = (n + ROUND_MAGIC).to_bits();
    f64::from_bits((low << 52).wrapping_add(1023 << 52))
}

/// `eˣ` in plain arithmetic (vectorises, unlike libm's): `x = n ln2 + r`
/// with `|r| ≤ ln2/2` (Cody-Waite, exact), a degree-12 Taylor polynomial
/// for `eʳ` (truncation < 2e-16, Estrin's scheme), then `2ⁿ` from the bits. Within 2 ulp
/// of libm for `−708 ≤ x ≤ 709` (∞ above; the kernel's arguments are all
/// ≤ 0); below −708 it returns 0 where libm returns
/// values under 3.3e-308 (subnormal results would cost a microcode assist
/// per lane). NaN stays NaN.
#[inline(always)]
pub fn exp_lane(x: f64) -> f64 {
    const LN2_HI: f64 = EXP_LN2_HI;
    const LN2_LO: f64 = EXP_LN2_LO;
    const FLUSH_BELOW: f64 = EXP_FLUSH_BELOW;
    const A: [f64; 13] = EXP_TAYLOR;
    // Clamped so that 2ⁿ stays representable; the comparisons keep NaN.
    let xc = x.clamp(FLUSH_BELOW, 709.0);
    let n = (xc * std::f64::consts::LOG2_E + ROUND_MAGIC) - ROUND_MAGIC;
    let r = (xc - n * LN2_HI) - n * LN2_LO;
    // Estrin's scheme: a dependency chain of 4 multiply-adds, not 12.
    let r2 = r * r;
    let r4 = r2 * r2;
    let r8 = r4 * r4;
    let q0 = A[0] + A[1] * r;
    let q1 = A[2] + A[3] * r;
    let q2 = A[4] + A[5] * r;
    let q3 = A[6] + A[7] * r;
    let q4 = A[8] + A[9] * r;
    let q5 = A[10] + A[11] * r;
    let s0 = q0 + q1 * r2;
    let s1 = q2 + q3 * r2;
    let s2 = q4 + q5 * r2;
    let t0 = s0 + s1 * r4;
    let t1 = s2 + A[12] * r4;
    let p = t0 + t1 * r8;
    let e = p * pow2(n);
    if x < FLUSH_BELOW {
        0.0
    } else if x > 709.0 {
        f64::INFINITY
    } else {
        e
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exp_lane_matches_libm() {
        let mut worst = 0.0f64;
        let mut x = -745.0;
        while x < 709.0 {
            let (a, b) = (exp_lane(x), x.exp());
            if x >= -708.0 {
                worst = worst.max(((a - b) / b).abs());
            } else {
                assert!(a == 0.0 && b < 3.3e-308, "x={x}: {a} vs {b}");
            }
            x += 0.0137;
        }
        assert!(worst < 5e-16, "worst relative error {worst:e}");
        for x in [-1e-300, 0.0, 1e-10, -0.34657359, 0.34657359] {
            assert!(((exp_lane(x) - x.exp()) / x.exp()).abs() < 3e-16);
        }
        assert!(exp_lane(f64::NAN).is_nan());
        assert_eq!(exp_lane(-1000.0), 0.0);
        assert_eq!(exp_lane(f64::NEG_INFINITY), 0.0);
        assert_eq!(exp_lane(800.0), f64::INFINITY);
    }
}
