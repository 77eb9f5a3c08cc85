//! [`Bsdf::geometry`] for many pairs at once, with SIMD vectors: what a
//! fit recomputes on every pass for the patch pairs it cannot keep.
//!
//! A Klems side has ~10 million (light, view) pairs: too many to keep
//! their [`Geometry`](crate::Geometry) for a whole fit, so each pass
//! computes a sample's pairs' geometry into a scratch [`GeometryBatch`]
//! just before summing over them. Pair by pair, that took as long as the
//! sums. Here the pairs are taken a vector at a time (8 with AVX-512) on
//! `pulp`'s vectors, like the sums of `batch_gradient`: every branch of
//! the scalar code (reflection, transmission, neither; the view flip) is
//! computed for every lane and the right one selected, and the material's
//! switches (anisotropy, transmission, formula set) are const parameters.
//!
//! Every lane repeats the scalar code's operations in the same order
//! (no fused multiply-add; division and square root are correctly
//! rounded at every SIMD level), so the columns hold exactly the bits
//! [`Bsdf::geometry`] gives.
//!
//! A product of lights and views (every light with every view, the common
//! Klems pattern) takes each light as a broadcast vector over the views,
//! which are transposed to coordinate arrays once per call.

use crate::batch::{Constants, MANUAL2004, MIN_VIEW_COSINE, RADIANCE, WARD1992};
use crate::batch_gradient::{GeometryBatch, Ops, SwitchedKernel};
use crate::bsdf::Bsdf;
use crate::material::FTINY;
use glam::DVec3;
use std::f64::consts::PI;

/// Views transposed at a time in [`Bsdf::geometry_product`] (on the stack).
const VIEW_CHUNK: usize = 64;

impl Bsdf {
    /// Writes the [`Geometry`](crate::Geometry) of every light of `lights`
    /// with every view of `views`, light-major (light 0 with every view,
    /// then light 1, …), as pairs `at..at + n` of `out` (n = lights ×
    /// views): `at = out.len()` appends; a smaller `at` overwrites, and
    /// `out` keeps the pairs before `at` and past `at + n` (a scratch batch
    /// is refilled at 0 without being cleared, its stale tail unread).
    /// Exactly what [`Bsdf::geometry`] gives pair by pair, computed with
    /// SIMD vectors.
    ///
    /// # Panics
    /// If `at > out.len()`.
    pub fn geometry_product(
        &self,
        lights: &[DVec3],
        views: &[DVec3],
        out: &mut GeometryBatch,
        at: usize,
    ) {
        let stride = views.len();
        let mut columns = out.columns_at(at, lights.len() * stride);
        if columns[0].is_empty() {
            return;
        }
        let mut x = [0.0; VIEW_CHUNK];
        let mut y = [0.0; VIEW_CHUNK];
        let mut z = [0.0; VIEW_CHUNK];
        for (c, chunk) in views.chunks(VIEW_CHUNK).enumerate() {
            let m = chunk.len();
            for (j, v) in chunk.iter().enumerate() {
                x[j] = v.x;
                y[j] = v.y;
                z[j] = v.z;
            }
            self.by_switches(Product {
                lights,
                views: [&x[..m], &y[..m], &z[..m]],
                out: columns.each_mut().map(|c| &mut **c),
                stride,
                offset: c * VIEW_CHUNK,
            });
        }
    }

    /// Writes the [`Geometry`](crate::Geometry) of every pair (`lights` i,
    /// `views` i), given as coordinate arrays `[x, y, z]`, as pairs
    /// `at..at + n` of `out` (see [`Bsdf::geometry_product`]). Exactly what [`Bsdf::geometry`] gives
    /// pair by pair, computed with SIMD vectors.
    ///
    /// # Panics
    /// If the six slices do not all have the same length, or
    /// `at > out.len()`.
    pub fn geometry_soa(
        &self,
        lights: [&[f64]; 3],
        views: [&[f64]; 3],
        out: &mut GeometryBatch,
        at: usize,
    ) {
        let n = lights[0].len();
        assert!(
            lights.iter().chain(&views).all(|s| s.len() == n),
            "Bsdf::geometry_soa: coordinate slices of different lengths"
        );
        let columns = out.columns_at(at, n);
        if n > 0 {
            self.by_switches(Pairs {
                lights,
                views,
                out: columns,
            });
        }
    }
}

/// Every light of `lights` with the views `views` (a chunk of a
/// product's views, starting at view `offset`); light `i`'s pairs are at
/// `i · stride + offset` of the columns `out`.
struct Product<'a> {
    lights: &'a [DVec3],
    views: [&'a [f64]; 3],
    out: [&'a mut [f64]; 6],
    stride: usize,
    offset: usize,
}

impl SwitchedKernel for Product<'_> {
    type Output = ();

    fn run<const ANISO: bool, const TRANS: bool, const V: u8, const FRESNEL: bool>(
        self,
        k: &Constants,
    ) {
        pulp::Arch::new().dispatch(ProductOp::<ANISO, TRANS, V> { k, p: self });
    }
}

/// [`Product`] as a `pulp` operation (a struct, not a closure: see
/// `Columns` in `batch_gradient` on why).
struct ProductOp<'a, const ANISO: bool, const TRANS: bool, const V: u8> {
    k: &'a Constants,
    p: Product<'a>,
}

impl<const ANISO: bool, const TRANS: bool, const V: u8> pulp::WithSimd
    for ProductOp<'_, ANISO, TRANS, V>
{
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) {
        let o = Ops(simd);
        let Product {
            lights,
            views,
            out,
            stride,
            offset,
        } = self.p;
        let m = views[0].len();
        let [lc, vc, lf, xu, xv, cut] = out;
        for (i, l) in lights.iter().enumerate() {
            let at = i * stride + offset..i * stride + offset + m;
            let light = Light::Broadcast([o.splat(l.x), o.splat(l.y), o.splat(l.z)]);
            let row = [
                &mut lc[at.clone()],
                &mut vc[at.clone()],
                &mut lf[at.clone()],
                &mut xu[at.clone()],
                &mut xv[at.clone()],
                &mut cut[at],
            ];
            fill::<S, ANISO, TRANS, V>(o, self.k, light, views, row);
        }
    }
}

/// Pairs given as coordinate arrays, into the columns `out`.
struct Pairs<'a> {
    lights: [&'a [f64]; 3],
    views: [&'a [f64]; 3],
    out: [&'a mut [f64]; 6],
}

impl SwitchedKernel for Pairs<'_> {
    type Output = ();

    fn run<const ANISO: bool, const TRANS: bool, const V: u8, const FRESNEL: bool>(
        self,
        k: &Constants,
    ) {
        pulp::Arch::new().dispatch(PairsOp::<ANISO, TRANS, V> { k, p: self });
    }
}

/// [`Pairs`] as a `pulp` operation.
struct PairsOp<'a, const ANISO: bool, const TRANS: bool, const V: u8> {
    k: &'a Constants,
    p: Pairs<'a>,
}

impl<const ANISO: bool, const TRANS: bool, const V: u8> pulp::WithSimd
    for PairsOp<'_, ANISO, TRANS, V>
{
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) {
        let o = Ops(simd);
        let Pairs { lights, views, out } = self.p;
        fill::<S, ANISO, TRANS, V>(o, self.k, Light::Each(lights), views, out);
    }
}

/// Where a run's lights come from.
#[derive(Clone, Copy)]
enum Light<'a, S: pulp::Simd> {
    /// One light for every view.
    Broadcast([S::f64s; 3]),
    /// Light i for view i, as coordinate arrays.
    Each([&'a [f64]; 3]),
}

/// The geometry of every view of `views` with its light, into the
/// columns `out` (all of the views' length; every column is written).
#[inline(always)]
fn fill<S: pulp::Simd, const ANISO: bool, const TRANS: bool, const V: u8>(
    o: Ops<S>,
    k: &Constants,
    light: Light<'_, S>,
    views: [&[f64]; 3],
    out: [&mut [f64]; 6],
) {
    let simd = o.0;
    let m = views[0].len();
    let (vx, vx_tail) = S::as_simd_f64s(&views[0][..m]);
    let (vy, vy_tail) = S::as_simd_f64s(&views[1][..m]);
    let (vz, vz_tail) = S::as_simd_f64s(&views[2][..m]);
    let n = vx.len();
    let (vy, vz) = (&vy[..n], &vz[..n]);
    let [lc, vc, lf, xu, xv, cut] = out;
    let (lc, lc_tail) = S::as_mut_simd_f64s(&mut lc[..m]);
    let (vc, vc_tail) = S::as_mut_simd_f64s(&mut vc[..m]);
    let (lf, lf_tail) = S::as_mut_simd_f64s(&mut lf[..m]);
    let (xu, xu_tail) = S::as_mut_simd_f64s(&mut xu[..m]);
    let (xv, xv_tail) = S::as_mut_simd_f64s(&mut xv[..m]);
    let (cut, cut_tail) = S::as_mut_simd_f64s(&mut cut[..m]);
    let (lc, vc, lf, xu) = (&mut lc[..n], &mut vc[..n], &mut lf[..n], &mut xu[..n]);
    let (xv, cut) = (&mut xv[..n], &mut cut[..n]);
    match light {
        Light::Broadcast(l) => {
            for i in 0..n {
                let g = lanes::<S, ANISO, TRANS, V>(o, k, l, [vx[i], vy[i], vz[i]]);
                [lc[i], vc[i], lf[i], xu[i], xv[i], cut[i]] = g;
            }
        }
        Light::Each(lights) => {
            let (lx, _) = S::as_simd_f64s(&lights[0][..m]);
            let (ly, _) = S::as_simd_f64s(&lights[1][..m]);
            let (lz, _) = S::as_simd_f64s(&lights[2][..m]);
            let (lx, ly, lz) = (&lx[..n], &ly[..n], &lz[..n]);
            for i in 0..n {
                let g =
                    lanes::<S, ANISO, TRANS, V>(o, k, [lx[i], ly[i], lz[i]], [vx[i], vy[i], vz[i]]);
                [lc[i], vc[i], lf[i], xu[i], xv[i], cut[i]] = g;
            }
        }
    }
    if vx_tail.is_empty() {
        return;
    }
    // The last views, fewer than a vector: lanes past the end load 0 and
    // are not stored.
    let load = |tail: &[f64]| simd.partial_load_f64s(tail);
    let l = match light {
        Light::Broadcast(l) => l,
        Light::Each(lights) => lights.map(|c| load(&c[m - vx_tail.len()..m])),
    };
    let g = lanes::<S, ANISO, TRANS, V>(o, k, l, [load(vx_tail), load(vy_tail), load(vz_tail)]);
    simd.partial_store_f64s(lc_tail, g[0]);
    simd.partial_store_f64s(vc_tail, g[1]);
    simd.partial_store_f64s(lf_tail, g[2]);
    simd.partial_store_f64s(xu_tail, g[3]);
    simd.partial_store_f64s(xv_tail, g[4]);
    simd.partial_store_f64s(cut_tail, g[5]);
}

/// One vector of pairs' geometry: light cosine, view cosine, lobe factor,
/// x_u, x_v, cut-off factor (the last two 0 for the isotropic types).
/// Mirrors `Bsdf::geometry` with its `reflection_geometry` and
/// `transmission_geometry` operation for operation. A vector whose pairs
/// are all reflection (or all transmission), as a Klems patch pair's
/// are, computes that side alone: the other side's values would not be
/// selected.
#[inline(always)]
fn lanes<S: pulp::Simd, const ANISO: bool, const TRANS: bool, const V: u8>(
    o: Ops<S>,
    k: &Constants,
    l: [S::f64s; 3],
    v: [S::f64s; 3],
) -> [S::f64s; 6] {
    let simd = o.0;
    let zero = o.splat(0.0);
    // Turn the surface towards the viewer.
    let flip = o.lt(v[2], zero);
    let l = [l[0], l[1], o.select(flip, o.neg(l[2]), l[2])];
    let v = [v[0], v[1], o.select(flip, o.neg(v[2]), v[2])];
    let ci = l[2];
    let co = simd.max_f64s(v[2], o.splat(MIN_VIEW_COSINE));
    let front = o.gt(ci, o.splat(FTINY));
    let behind = o.lt(ci, o.splat(-FTINY));
    let all = |m: S::m64s| simd.first_true_m64s(o.not(m)) == S::F64_LANES;
    if !TRANS || all(front) {
        let [factor, xu, xv] = reflection::<S, ANISO, V>(o, k, l, v, ci, co);
        if all(front) {
            return [ci, co, factor, xu, xv, zero];
        }
        // Opaque types: light from behind gives nothing.
        let reflected = |r: S::f64s| o.select(front, r, zero);
        return [
            ci,
            co,
            reflected(factor),
            reflected(xu),
            reflected(xv),
            zero,
        ];
    }
    if all(behind) {
        let [factor, xu, xv, cut] = transmission::<S, ANISO, V>(o, k, l, v, ci, co);
        return [ci, co, factor, xu, xv, cut];
    }
    let [r_factor, r_xu, r_xv] = reflection::<S, ANISO, V>(o, k, l, v, ci, co);
    let [t_factor, t_xu, t_xv, t_cut] = transmission::<S, ANISO, V>(o, k, l, v, ci, co);
    let pick = |r: S::f64s, t: S::f64s| o.select(front, r, o.select(behind, t, zero));
    [
        ci,
        co,
        pick(r_factor, t_factor),
        pick(r_xu, t_xu),
        pick(r_xv, t_xv),
        pick(zero, t_cut),
    ]
}

/// `a · b` for a vector `a` of lanes and a constant `b`, as glam's `dot`.
#[inline(always)]
fn dot<S: pulp::Simd>(o: Ops<S>, a: [S::f64s; 3], b: [f64; 3]) -> S::f64s {
    o.add(
        o.add(o.mul(a[0], o.splat(b[0])), o.mul(a[1], o.splat(b[1]))),
        o.mul(a[2], o.splat(b[2])),
    )
}

/// The reflected lobe's lobe factor, x_u and x_v (`reflection_geometry`),
/// for light cosine `ci` > FTINY (the light and view turned towards the
/// viewer; `co` the clamped view cosine).
#[inline(always)]
fn reflection<S: pulp::Simd, const ANISO: bool, const V: u8>(
    o: Ops<S>,
    k: &Constants,
    l: [S::f64s; 3],
    v: [S::f64s; 3],
    ci: S::f64s,
    co: S::f64s,
) -> [S::f64s; 3] {
    let simd = o.0;
    let sp = |x: f64| o.splat(x);
    let h = [o.add(l[0], v[0]), o.add(l[1], v[1]), o.add(l[2], v[2])];
    let hz = h[2];
    let hh = o.add(o.add(o.mul(h[0], h[0]), o.mul(h[1], h[1])), o.mul(hz, hz));
    let inv_hn2 = o.div(sp(1.0), o.mul(hz, hz));
    let factor = match V {
        RADIANCE => o.mul(o.mul(o.mul(hh, inv_hn2), inv_hn2), sp(1.0 / PI)),
        MANUAL2004 => o.div(sp(1.0), o.mul(o.mul(sp(4.0 * PI), ci), co)),
        _ => o.div(sp(1.0), o.mul(sp(4.0 * PI), simd.sqrt_f64s(o.mul(ci, co)))),
    };
    if ANISO {
        let hu = dot(o, h, k.frame_u);
        let hv = dot(o, h, k.frame_v);
        let scale = if V == WARD1992 {
            let root = simd.sqrt_f64s(hh);
            o.div(sp(2.0), o.mul(hh, o.add(sp(1.0), o.div(hz, root))))
        } else {
            inv_hn2
        };
        [
            factor,
            o.mul(o.mul(hu, hu), scale),
            o.mul(o.mul(hv, hv), scale),
        ]
    } else if V == WARD1992 {
        let root = simd.sqrt_f64s(hh);
        [
            factor,
            o.sub(sp(2.0), o.div(o.mul(sp(2.0), hz), root)),
            sp(0.0),
        ]
    } else {
        [factor, o.sub(o.mul(hh, inv_hn2), sp(1.0)), sp(0.0)]
    }
}

/// The transmitted lobe's lobe factor, x_u, x_v and cut-off factor
/// (`transmission_geometry`), for light cosine `ci` < −FTINY.
#[inline(always)]
fn transmission<S: pulp::Simd, const ANISO: bool, const V: u8>(
    o: Ops<S>,
    k: &Constants,
    l: [S::f64s; 3],
    v: [S::f64s; 3],
    ci: S::f64s,
    co: S::f64s,
) -> [S::f64s; 4] {
    let simd = o.0;
    let sp = |x: f64| o.splat(x);
    let zero = sp(0.0);
    let cit = o.neg(ci);
    let factor = if V == MANUAL2004 {
        o.div(sp(1.0), o.mul(cit, co))
    } else {
        o.div(sp(1.0), simd.sqrt_f64s(o.mul(cit, co)))
    };
    if !ANISO {
        // 2 + 2 v·l.
        let vl = o.add(
            o.add(o.mul(v[0], l[0]), o.mul(v[1], l[1])),
            o.mul(v[2], l[2]),
        );
        return [factor, o.add(sp(2.0), o.mul(sp(2.0), vl)), zero, zero];
    }
    let c = [o.add(l[0], v[0]), o.add(l[1], v[1]), o.add(l[2], v[2])];
    let cc = o.add(
        o.add(o.mul(c[0], c[0]), o.mul(c[1], c[1])),
        o.mul(c[2], c[2]),
    );
    let tiny2 = sp(FTINY * FTINY);
    let s2 = o.select(
        o.gt(cc, tiny2),
        o.sub(sp(1.0), o.div(o.mul(c[2], c[2]), cc)),
        cc,
    );
    let wide = o.gt(s2, tiny2);
    let cu = dot(o, c, k.frame_u);
    let cv = dot(o, c, k.frame_v);
    [
        factor,
        o.select(wide, o.div(o.mul(cu, cu), s2), zero),
        o.select(wide, o.div(o.mul(cv, cv), s2), zero),
        simd.sqrt_f64s(o.div(cit, co)),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kind::MaterialKind;
    use crate::material::Material;
    use crate::options::EvalOptions;
    use crate::{GeometryBatch, direction};
    use pulp::WithSimd;

    /// The columns on one SIMD level, for pairs (lights i, views i).
    fn on<S: pulp::Simd>(simd: S, bsdf: &Bsdf, lights: &[DVec3], views: &[DVec3]) -> GeometryBatch {
        let coordinates =
            |d: &[DVec3]| [0, 1, 2].map(|c| d.iter().map(|v| v[c]).collect::<Vec<_>>());
        let (l, v) = (coordinates(lights), coordinates(views));
        let mut out = GeometryBatch::new();
        let columns = out.columns_at(0, lights.len());
        let k = bsdf.batch_constants();
        let op = PairsOp::<true, true, RADIANCE> {
            k: &k,
            p: Pairs {
                lights: [&l[0], &l[1], &l[2]],
                views: [&v[0], &v[1], &v[2]],
                out: columns,
            },
        };
        op.with_simd(simd);
        out
    }

    /// Whatever level `pulp` picks (AVX-512, AVX2 or the scalar
    /// baseline), the columns are the scalar geometry's bits.
    #[test]
    fn every_simd_level_gives_the_scalar_bits() {
        let material = Material::new(
            MaterialKind::Trans2,
            &[0.6, 0.7, 0.8, 0.04, 0.05, 0.2, 0.6, 0.4],
            Some(DVec3::new(0.3, 1.0, 0.2)),
        )
        .unwrap();
        let bsdf = Bsdf::new(&material, &EvalOptions::default());
        let lights: Vec<DVec3> = (0..203)
            .map(|i| direction(0.45 * i as f64, 10.0 + i as f64))
            .collect();
        let views: Vec<DVec3> = (0..203)
            .map(|i| direction((7.3 * i as f64) % 180.0, 190.0 + 0.5 * i as f64))
            .collect();
        let want: Vec<String> = lights
            .iter()
            .zip(&views)
            .map(|(&l, &v)| format!("{:?}", bsdf.geometry(l, v)))
            .collect();
        let check = |got: GeometryBatch| {
            assert_eq!(got.len(), want.len());
            for (i, w) in want.iter().enumerate() {
                assert_eq!(&format!("{:?}", got.get(i)), w, "pair {i}");
            }
        };
        check(on(pulp::Scalar::new(), &bsdf, &lights, &views));
        #[cfg(target_arch = "x86_64")]
        {
            if let Some(v3) = pulp::x86::V3::try_new() {
                check(v3.vectorize(|| on(v3, &bsdf, &lights, &views)));
            }
            if let Some(v4) = pulp::x86::V4::try_new() {
                check(v4.vectorize(|| on(v4, &bsdf, &lights, &views)));
            }
        }
    }
}
