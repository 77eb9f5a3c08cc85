//! `Bsdf::sum_geometry_with_gradient` and `Bsdf::sum_geometry` (the
//! vectorised sums over a `GeometryBatch`) equal the sums of the scalar
//! `eval_geometry_channels_with_gradient::<CH>` / `eval_geometry` over the
//! same pairs, for every type, variant and switch, on runs of every
//! length and alignment, with geometry made under other arguments; and
//! the per-pair kernels (`eval_geometry_each[_with_gradient]`) equal the
//! scalar values pair by pair.

#![allow(clippy::needless_range_loop)] // channel loops index several arrays at once

use brtf_model::{
    Bsdf, EvalOptions, FRESNEL_K_PYRADIANCE, Geometry, GeometryBatch, Gradient, MAX_ARGS, Material,
    MaterialKind, PairTerms, Variant, cone_solid_angle, direction,
};
use glam::DVec3;
use std::ops::Range;

/// Agreement asked, relative to the sum ...
const RELATIVE: f64 = 1e-12;
/// ... or to the sum of the terms' magnitudes (for sums that cancel).
const OF_SCALE: f64 = 1e-15;

/// Argument sets per type: rough, smooth, roughness 0 with and without
/// rtrace's Fresnel switch (isotropic), trans at the all-through, opaque
/// and no-specular-transmission limits, an all-black plastic.
fn argument_sets(kind: MaterialKind) -> Vec<Vec<f64>> {
    match kind {
        MaterialKind::Plastic => vec![
            vec![0.5, 0.4, 0.3, 0.05, 0.1],
            vec![0.2, 0.6, 0.9, 0.9, 0.01],
            vec![0.5, 0.4, 0.3, 0.05, 0.0],
            vec![0.5, 0.4, 0.3, 0.01, 0.0],
            vec![0.0, 0.0, 0.0, 0.0, 0.3],
        ],
        MaterialKind::Metal => vec![
            vec![0.9, 0.8, 0.7, 0.9, 0.1],
            vec![0.9, 0.8, 0.7, 0.5, 0.005],
            vec![0.9, 0.8, 0.7, 0.9, 0.0],
            vec![0.3, 0.2, 0.1, 0.01, 0.0],
        ],
        MaterialKind::Trans => vec![
            vec![0.8, 0.8, 0.8, 0.05, 0.1, 0.5, 0.5],
            vec![0.6, 0.7, 0.8, 0.04, 0.05, 0.9, 0.2],
            vec![0.6, 0.7, 0.8, 0.04, 0.0, 0.5, 0.5],
            vec![0.6, 0.7, 0.8, 0.01, 0.0, 0.7, 0.3],
            vec![0.6, 0.7, 0.8, 0.0, 0.2, 1.0, 1.0],
            vec![0.6, 0.7, 0.8, 0.1, 0.2, 0.0, 0.5],
            vec![0.6, 0.7, 0.8, 0.1, 0.2, 0.6, 0.0],
        ],
        MaterialKind::Plastic2 => vec![
            vec![0.5, 0.4, 0.3, 0.05, 0.05, 0.2],
            vec![0.5, 0.4, 0.3, 0.9, 0.01, 0.3],
        ],
        MaterialKind::Metal2 => vec![
            vec![0.9, 0.8, 0.7, 0.9, 0.05, 0.2],
            vec![0.9, 0.8, 0.7, 0.4, 0.3, 0.02],
        ],
        MaterialKind::Trans2 => vec![
            vec![0.8, 0.8, 0.8, 0.05, 0.05, 0.2, 0.5, 0.5],
            vec![0.6, 0.7, 0.8, 0.04, 0.2, 0.01, 0.9, 0.8],
        ],
    }
}

/// Anisotropic types: an oblique orientation and one along the normal
/// (rtrace's arbitrary frame with the mean roughness).
fn orientations(kind: MaterialKind) -> Vec<DVec3> {
    if kind.is_anisotropic() {
        vec![DVec3::new(1.0, 1.0, 0.3), DVec3::Z]
    } else {
        vec![DVec3::X]
    }
}

/// Per variant: a point source, a widened flat source with jitter and
/// pyradiance's Fresnel constant, a widened non-flat source.
fn option_sets() -> Vec<EvalOptions> {
    let mut out = Vec::new();
    for variant in Variant::ALL {
        out.push(EvalOptions::with_variant(variant));
        out.push(EvalOptions {
            variant,
            fresnel_k: FRESNEL_K_PYRADIANCE,
            source_omega: cone_solid_angle(0.5),
            flat: true,
            source_jitter: 0.3,
        });
        out.push(EvalOptions {
            variant,
            source_omega: cone_solid_angle(2.0),
            flat: false,
            ..EvalOptions::default()
        });
    }
    out
}

/// About 3 000 pairs, incidence by incidence (front and back light):
/// views near the mirror and straight-through directions, grazing and at
/// the horizon, and spread over the sphere.
fn direction_pairs() -> (Vec<DVec3>, Vec<DVec3>) {
    let mut state = 0x2545_F491_4F6C_DD1Du64;
    let mut uniform = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let (mut lights, mut views) = (Vec::new(), Vec::new());
    for theta_l in [0.0, 20.0, 45.0, 70.0, 85.0, 89.9, 100.0, 135.0, 179.5] {
        for phi_l in [0.0, 37.0] {
            let l = direction(theta_l, phi_l);
            let mut push = |v: DVec3| {
                lights.push(l);
                views.push(v);
            };
            let mirror = (theta_l, phi_l + 180.0);
            let through = (180.0 - theta_l, phi_l + 180.0);
            for (t, p) in [mirror, through] {
                for dt in [0.0, 1e-6, 1e-3, 0.5, 3.0] {
                    for dp in [0.0, 1e-4, 0.7] {
                        push(direction((t + dt).min(180.0), p + dp));
                        push(direction((t - dt).max(0.0), p - dp));
                    }
                }
            }
            for theta_v in [89.9, 89.9999, 90.0, 90.0001, 90.1] {
                push(direction(theta_v, phi_l + 90.0));
            }
            for _ in 0..100 {
                push(direction(180.0 * uniform(), 360.0 * uniform()));
            }
        }
    }
    (lights, views)
}

/// Runs of 1, 7, 32 and 1024 pairs and longer, none aligned to a vector.
fn ranges(n: usize) -> Vec<Range<usize>> {
    vec![
        0..0,
        0..1,
        5..6,
        3..10,
        13..45,
        101..1125,
        1500..2524,
        1..n - 1,
        n - 7..n,
    ]
}

/// Neumaier-compensated sum and the sum of magnitudes.
#[derive(Default, Clone, Copy)]
struct Sum {
    sum: f64,
    compensation: f64,
    scale: f64,
}

impl Sum {
    fn add(&mut self, x: f64) {
        let t = self.sum + x;
        self.compensation += if self.sum.abs() >= x.abs() {
            (self.sum - t) + x
        } else {
            (x - t) + self.sum
        };
        self.sum = t;
        self.scale += x.abs();
    }

    fn value(&self) -> f64 {
        self.sum + self.compensation
    }
}

/// The scalar sums over `range`: value sums and gradient sums, each
/// channel `< CH`.
fn scalar_sums<const CH: usize>(
    bsdf: &Bsdf,
    geometry: &[Geometry],
    range: Range<usize>,
) -> ([Sum; 3], [[Sum; 3]; MAX_ARGS]) {
    let mut f_sum = [Sum::default(); 3];
    let mut grad_sum = [[Sum::default(); 3]; MAX_ARGS];
    let mut grad = Gradient::default();
    for g in &geometry[range] {
        let f = bsdf.eval_geometry_channels_with_gradient::<CH>(g, &mut grad);
        let plain = bsdf.eval_geometry(g);
        for ch in 0..3 {
            if ch < CH {
                assert_eq!(f[ch], plain[ch], "the scalar paths disagree");
                f_sum[ch].add(f[ch]);
                for (arg, sums) in grad_sum.iter_mut().enumerate() {
                    sums[ch].add(grad.d[arg][ch]);
                }
            } else {
                assert_eq!(f[ch], 0.0);
            }
        }
    }
    (f_sum, grad_sum)
}

fn assert_close(got: f64, want: &Sum, what: &dyn Fn() -> String) {
    let w = want.value();
    let tolerance = RELATIVE * w.abs() + OF_SCALE * want.scale;
    assert!(
        (got - w).abs() <= tolerance,
        "{}: batch sum {got:e} vs scalar {w:e} (diff {:e}, scale {:e})",
        what(),
        (got - w).abs(),
        want.scale
    );
}

/// Checks both channel counts over every range; returns how many value
/// sums and roughness-gradient sums were non-zero.
fn check_bsdf(bsdf: &Bsdf, batch: &GeometryBatch, geometry: &[Geometry]) -> (usize, usize) {
    let mut nonzero = (0, 0);
    for range in ranges(batch.len()) {
        nonzero = add(nonzero, check_channels::<1>(bsdf, batch, geometry, &range));
        nonzero = add(nonzero, check_channels::<3>(bsdf, batch, geometry, &range));
    }
    nonzero
}

fn add(a: (usize, usize), b: (usize, usize)) -> (usize, usize) {
    (a.0 + b.0, a.1 + b.1)
}

fn check_channels<const CH: usize>(
    bsdf: &Bsdf,
    batch: &GeometryBatch,
    geometry: &[Geometry],
    range: &Range<usize>,
) -> (usize, usize) {
    check_each::<CH>(bsdf, batch, geometry, range);
    let (f_want, grad_want) = scalar_sums::<CH>(bsdf, geometry, range.clone());
    // Channels from CH on must be left as they were.
    const UNTOUCHED: f64 = 7.25;
    let mut grad = Gradient {
        d: [[UNTOUCHED; 3]; MAX_ARGS],
    };
    let f = bsdf.sum_geometry_with_gradient::<CH>(batch, range.clone(), &mut grad);
    let values = bsdf.sum_geometry::<CH>(batch, range.clone());
    let what = |entry: String| {
        let options = *bsdf.options();
        let args = bsdf.material().args().to_vec();
        let kind = bsdf.kind();
        let range = range.clone();
        move || format!("{kind} {options:?} args {args:?} CH={CH} pairs {range:?}: {entry}")
    };
    let mut nonzero = (0, 0);
    for ch in 0..3 {
        if ch >= CH {
            assert_eq!((f[ch], values[ch]), (0.0, 0.0));
            for arg in 0..MAX_ARGS {
                assert_eq!(
                    grad.d[arg][ch],
                    UNTOUCHED,
                    "{}",
                    what(format!("d[{arg}][{ch}]"))()
                );
            }
            continue;
        }
        assert_close(f[ch], &f_want[ch], &what(format!("f[{ch}]")));
        assert_close(
            values[ch],
            &f_want[ch],
            &what(format!("values-only f[{ch}]")),
        );
        for arg in 0..MAX_ARGS {
            assert_close(
                grad.d[arg][ch],
                &grad_want[arg][ch],
                &what(format!("d[{arg}][{ch}]")),
            );
        }
        nonzero.0 += usize::from(f[ch] != 0.0);
        nonzero.1 += usize::from(grad.d[4][ch] != 0.0);
    }
    nonzero
}

/// Pair-by-pair agreement asked of the per-pair kernels, relative to the
/// pair's largest quantity (a derivative's diffuse and lobe parts can
/// cancel): only `exp` (≤ 2 ulp from libm) differs from the scalar code
/// ...
const EACH_RELATIVE: f64 = 1e-13;
/// ... and flushes results far below any BSDF value to 0.
const EACH_FLUSHED: f64 = 1e-250;

/// The per-pair kernels over `range` equal the scalar code pair by pair.
fn check_each<const CH: usize>(
    bsdf: &Bsdf,
    batch: &GeometryBatch,
    geometry: &[Geometry],
    range: &Range<usize>,
) {
    let mut terms = PairTerms::new();
    let mut values = PairTerms::new();
    bsdf.eval_geometry_each_with_gradient::<CH>(batch, range.clone(), &mut terms);
    bsdf.eval_geometry_each::<CH>(batch, range.clone(), &mut values);
    assert_eq!((terms.len(), values.len()), (range.len(), range.len()));
    assert_eq!(terms.is_empty(), range.is_empty());
    // The column views hold the same numbers.
    for ch in 0..CH {
        let column = terms.value_column(ch);
        assert_eq!(column.len(), range.len());
        for (i, &v) in column.iter().enumerate() {
            assert_eq!(v, terms.value(i, ch));
        }
        for arg in 0..MAX_ARGS {
            match terms.derivative_column(arg, ch) {
                Some(column) => {
                    for (i, &v) in column.iter().enumerate() {
                        assert_eq!(v, terms.derivative(i, arg, ch));
                    }
                }
                None => {
                    assert!((0..range.len()).all(|i| terms.derivative(i, arg, ch) == 0.0))
                }
            }
            assert!(values.derivative_column(arg, ch).is_none());
        }
    }
    let mut grad = Gradient::default();
    for (i, g) in geometry[range.clone()].iter().enumerate() {
        let f = bsdf.eval_geometry_channels_with_gradient::<CH>(g, &mut grad);
        let largest = grad
            .d
            .iter()
            .flatten()
            .chain(&f)
            .fold(0.0f64, |m, x| m.max(x.abs()));
        let close = |got: f64, want: f64, what: &str| {
            assert!(
                (got - want).abs() <= EACH_RELATIVE * largest + EACH_FLUSHED,
                "{} {:?} args {:?} CH={CH} pair {}: {what} {got:e} vs scalar {want:e}",
                bsdf.kind(),
                bsdf.options(),
                bsdf.material().args(),
                range.start + i,
            )
        };
        for ch in 0..3 {
            let want = if ch < CH { f[ch] } else { 0.0 };
            close(terms.value(i, ch), want, "f");
            close(values.value(i, ch), want, "values-only f");
            for arg in 0..MAX_ARGS {
                let want = if ch < CH { grad.d[arg][ch] } else { 0.0 };
                close(terms.derivative(i, arg, ch), want, &format!("d[{arg}]"));
                // Without gradients there are none.
                assert_eq!(values.derivative(i, arg, ch), 0.0);
            }
        }
    }
}

fn check_kind(kind: MaterialKind) {
    let (lights, views) = direction_pairs();
    let sets = argument_sets(kind);
    let (mut nonzero, mut cases) = ((0, 0), 0);
    for orientation in orientations(kind) {
        for options in option_sets() {
            // The geometry is made under the first argument set and used
            // for all: it must not depend on the arguments.
            let maker = Material::new(kind, &sets[0], Some(orientation)).unwrap();
            let maker = Bsdf::new(&maker, &options);
            let mut batch = GeometryBatch::new();
            maker.geometry_batch(&lights, &views, &mut batch);
            let geometry: Vec<Geometry> = (0..batch.len()).map(|i| batch.get(i)).collect();
            for args in &sets {
                let material = Material::new(kind, args, Some(orientation)).unwrap();
                let bsdf = Bsdf::new(&material, &options);
                let own: Vec<Geometry> = lights
                    .iter()
                    .zip(&views)
                    .map(|(&l, &v)| bsdf.geometry(l, v))
                    .collect();
                assert_eq!(own, geometry, "geometry depends on the arguments");
                nonzero = add(nonzero, check_bsdf(&bsdf, &batch, &geometry));
                cases += 4 * ranges(batch.len()).len();
            }
        }
    }
    // Not vacuous: most value sums and many roughness derivatives are
    // non-zero (roughness-0 sets have none).
    assert!(
        nonzero.0 * 10 > cases * 7,
        "{kind}: {} of {cases} value sums non-zero",
        nonzero.0
    );
    assert!(
        nonzero.1 * 10 > cases * 3,
        "{kind}: {} of {cases} roughness sums non-zero",
        nonzero.1
    );
}

#[test]
fn plastic_sums_equal_scalar_sums() {
    check_kind(MaterialKind::Plastic);
}

#[test]
fn metal_sums_equal_scalar_sums() {
    check_kind(MaterialKind::Metal);
}

#[test]
fn trans_sums_equal_scalar_sums() {
    check_kind(MaterialKind::Trans);
}

#[test]
fn plastic2_sums_equal_scalar_sums() {
    check_kind(MaterialKind::Plastic2);
}

#[test]
fn metal2_sums_equal_scalar_sums() {
    check_kind(MaterialKind::Metal2);
}

#[test]
fn trans2_sums_equal_scalar_sums() {
    check_kind(MaterialKind::Trans2);
}

#[test]
fn geometry_batch_keeps_what_is_pushed() {
    let material = Material::new(
        MaterialKind::Trans,
        &[0.6, 0.7, 0.8, 0.04, 0.05, 0.5, 0.5],
        None,
    )
    .unwrap();
    let bsdf = Bsdf::new(&material, &EvalOptions::default());
    let (lights, views) = direction_pairs();
    let mut batch = GeometryBatch::with_capacity(10);
    assert!(batch.is_empty());
    bsdf.geometry_batch(&lights[..10], &views[..10], &mut batch);
    bsdf.geometry_batch(&lights[10..], &views[10..], &mut batch);
    assert_eq!(batch.len(), lights.len());
    for (i, (&l, &v)) in lights.iter().zip(&views).enumerate() {
        assert_eq!(batch.get(i), bsdf.geometry(l, v));
    }
    let collected: GeometryBatch = (0..batch.len()).map(|i| batch.get(i)).collect();
    assert_eq!(collected, batch);
    batch.clear();
    assert_eq!(batch.len(), 0);
    assert_eq!(bsdf.sum_geometry::<3>(&batch, 0..0), [0.0; 3]);
}

#[test]
#[should_panic(expected = "outside")]
fn a_range_past_the_end_is_refused() {
    let material = Material::new(MaterialKind::Plastic, &[0.5, 0.4, 0.3, 0.05, 0.1], None).unwrap();
    let bsdf = Bsdf::new(&material, &EvalOptions::default());
    let mut batch = GeometryBatch::new();
    bsdf.geometry_batch(&[DVec3::Z], &[DVec3::Z], &mut batch);
    bsdf.sum_geometry::<1>(&batch, 0..2);
}
