//! `Bsdf::geometry_product` and `Bsdf::geometry_soa` (the vectorised
//! geometry) give exactly the bits of the scalar `Bsdf::geometry`, pair by
//! pair, for every type, variant and orientation, on random directions on
//! both sides with grazing, near-`FTINY`, mirror and straight-through
//! cases, runs of every length, appended after what a batch holds or
//! written over part of it.

use brtf_model::{
    Bsdf, EvalOptions, FTINY, Geometry, GeometryBatch, Material, MaterialKind, Rng, Variant,
};
use glam::DVec3;
use proptest::prelude::*;

/// A valid argument set per type (the geometry does not depend on the
/// values, but isotropic roughness 0 is its own case).
fn args(kind: MaterialKind, rough: f64) -> Vec<f64> {
    match kind {
        MaterialKind::Plastic | MaterialKind::Metal => vec![0.5, 0.4, 0.3, 0.05, rough],
        MaterialKind::Trans => vec![0.6, 0.7, 0.8, 0.04, rough, 0.5, 0.5],
        MaterialKind::Plastic2 | MaterialKind::Metal2 => vec![0.5, 0.4, 0.3, 0.05, 0.05, 0.2],
        MaterialKind::Trans2 => vec![0.8, 0.8, 0.8, 0.05, 0.05, 0.2, 0.5, 0.5],
    }
}

/// Light cosines at and around the thresholds of the scalar code.
const SPECIAL_Z: [f64; 16] = [
    0.0,
    -0.0,
    FTINY,
    -FTINY,
    1.000_000_1e-6,
    -1.000_000_1e-6,
    9.999_999e-7,
    -9.999_999e-7,
    1e-300,
    -1e-300,
    0.001,
    0.000_999_9,
    -0.001,
    -0.000_999_9,
    1.0,
    -1.0,
];

/// A random direction: mostly uniform on the sphere, else one at a
/// special cosine, or the negation or mirror of `near` (straight-through
/// and mirror pairs, where `l + v` is 0 or along the normal).
fn random_direction(rng: &mut Rng, near: DVec3) -> DVec3 {
    let pick = rng.uniform();
    if pick < 0.6 {
        let z = 2.0 * rng.uniform() - 1.0;
        let phi = std::f64::consts::TAU * rng.uniform();
        let s = (1.0 - z * z).max(0.0).sqrt();
        DVec3::new(s * phi.cos(), s * phi.sin(), z)
    } else if pick < 0.8 {
        let z = SPECIAL_Z[(rng.next_u64() % SPECIAL_Z.len() as u64) as usize];
        let phi = std::f64::consts::TAU * rng.uniform();
        let s = (1.0 - z * z).max(0.0).sqrt();
        DVec3::new(s * phi.cos(), s * phi.sin(), z)
    } else if pick < 0.9 {
        -near
    } else {
        DVec3::new(-near.x, -near.y, near.z)
    }
}

fn directions(rng: &mut Rng, n: usize, near: &[DVec3]) -> Vec<DVec3> {
    (0..n)
        .map(|i| {
            let other = near.get(i % near.len().max(1)).copied().unwrap_or(DVec3::Z);
            random_direction(rng, other)
        })
        .collect()
}

/// Every field's bits (`-0.0` and `0.0` differ; NaN equals NaN).
fn bits(g: &Geometry) -> String {
    format!("{g:?}")
}

fn kinds() -> impl Strategy<Value = MaterialKind> {
    prop::sample::select(MaterialKind::ALL.to_vec())
}

fn variants() -> impl Strategy<Value = Variant> {
    prop::sample::select(vec![
        Variant::Radiance,
        Variant::Manual2004,
        Variant::Ward1992,
    ])
}

fn bsdf(kind: MaterialKind, variant: Variant, rough: f64, orientation: DVec3) -> Bsdf {
    let material = Material::new(kind, &args(kind, rough), Some(orientation)).unwrap();
    let options = EvalOptions {
        variant,
        source_omega: 6.8e-5,
        ..EvalOptions::default()
    };
    Bsdf::new(&material, &options)
}

/// A batch holding `before` pairs of some other geometry, then `stale`
/// pairs of another type's geometry that the writer must overwrite or
/// drop.
fn prefilled(bsdf: &Bsdf, before: usize, stale: usize) -> GeometryBatch {
    let mut out = GeometryBatch::new();
    for k in 0..before {
        out.push(bsdf.geometry(DVec3::Z, brtf_model::direction(10.0 * k as f64, 30.0)));
    }
    let other = self::bsdf(MaterialKind::Trans2, Variant::Ward1992, 0.1, DVec3::X);
    for k in 0..stale {
        let v = brtf_model::direction(0.03 * k as f64, 7.0 * k as f64);
        out.push(other.geometry(brtf_model::direction(150.0, 20.0), v));
    }
    out
}

/// `out` holds its `before` pairs, then `want`, then what it held past
/// `before + want.len()` (of `stale`).
fn check(bsdf: &Bsdf, out: &GeometryBatch, before: usize, stale: usize, want: &[Geometry]) {
    let old = prefilled(bsdf, before, stale);
    let end = before + want.len();
    assert_eq!(out.len(), end.max(before + stale));
    for (k, w) in want.iter().enumerate() {
        assert_eq!(bits(&out.get(before + k)), bits(w), "pair {k}");
    }
    for k in (0..before).chain(end..out.len()) {
        assert_eq!(bits(&out.get(k)), bits(&old.get(k)), "kept pair {k}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(600))]

    /// Every light with every view, light-major, as the scalar code.
    #[test]
    fn product_geometry_is_the_scalar_geometry(
        kind in kinds(),
        variant in variants(),
        rough in prop::sample::select(vec![0.0, 0.05, 0.3]),
        orientation in prop::sample::select(vec![
            DVec3::new(1.0, 1.0, 0.0), DVec3::new(0.3, -0.8, 0.5), DVec3::Z,
        ]),
        n_lights in 0usize..5,
        n_views in 0usize..150,
        before in 0usize..3,
        stale in prop::sample::select(vec![0usize, 1, 37, 5000]),
        side in prop::sample::select(vec![0.0, 1.0, -1.0]),
        seed in any::<u64>(),
    ) {
        let bsdf = bsdf(kind, variant, rough, orientation);
        let mut rng = Rng::new(seed, 1);
        let mut lights = directions(&mut rng, n_lights, &[]);
        let mut views = directions(&mut rng, n_views, &lights);
        // A Klems patch pair: lights in front, views all on one side, so
        // that whole vectors are reflection or transmission.
        if side != 0.0 {
            lights.iter_mut().for_each(|l| l.z = l.z.abs());
            views.iter_mut().for_each(|v| v.z = side * v.z.abs());
        }
        let mut out = prefilled(&bsdf, before, stale);
        bsdf.geometry_product(&lights, &views, &mut out, before);
        let want: Vec<Geometry> = lights
            .iter()
            .flat_map(|&l| views.iter().map(move |&v| (l, v)))
            .map(|(l, v)| bsdf.geometry(l, v))
            .collect();
        check(&bsdf, &out, before, stale, &want);
    }

    /// Pairs given as coordinate arrays, as the scalar code.
    #[test]
    fn paired_geometry_is_the_scalar_geometry(
        kind in kinds(),
        variant in variants(),
        rough in prop::sample::select(vec![0.0, 0.05, 0.3]),
        orientation in prop::sample::select(vec![
            DVec3::new(1.0, 1.0, 0.0), DVec3::new(0.3, -0.8, 0.5), DVec3::Z,
        ]),
        n in 0usize..100,
        before in 0usize..3,
        stale in prop::sample::select(vec![0usize, 1, 37, 5000]),
        seed in any::<u64>(),
    ) {
        let bsdf = bsdf(kind, variant, rough, orientation);
        let mut rng = Rng::new(seed, 2);
        let lights = directions(&mut rng, n, &[]);
        let views = directions(&mut rng, n, &lights);
        let coordinates = |d: &[DVec3]| {
            [
                d.iter().map(|v| v.x).collect::<Vec<_>>(),
                d.iter().map(|v| v.y).collect(),
                d.iter().map(|v| v.z).collect(),
            ]
        };
        let (l, v) = (coordinates(&lights), coordinates(&views));
        let mut out = prefilled(&bsdf, before, stale);
        bsdf.geometry_soa(
            [&l[0], &l[1], &l[2]],
            [&v[0], &v[1], &v[2]],
            &mut out,
            before,
        );
        let want: Vec<Geometry> =
            lights.iter().zip(&views).map(|(&l, &v)| bsdf.geometry(l, v)).collect();
        check(&bsdf, &out, before, stale, &want);
    }
}

/// The random cases are not vacuous: reflection, transmission and the
/// light-behind-an-opaque-surface case all occur, with non-zero factors.
#[test]
fn every_branch_is_taken() {
    let bsdf = bsdf(
        MaterialKind::Trans2,
        Variant::Radiance,
        0.05,
        DVec3::new(1.0, 1.0, 0.0),
    );
    let mut rng = Rng::new(7, 3);
    let lights = directions(&mut rng, 8, &[]);
    let views = directions(&mut rng, 64, &lights);
    let mut out = GeometryBatch::new();
    bsdf.geometry_product(&lights, &views, &mut out, 0);
    let text: Vec<String> = (0..out.len()).map(|i| bits(&out.get(i))).collect();
    let (mut front, mut behind, mut cut) = (0, 0, 0);
    for (k, (l, v)) in lights
        .iter()
        .flat_map(|&l| views.iter().map(move |&v| (l, v)))
        .enumerate()
    {
        let z = if v.z < 0.0 { -l.z } else { l.z };
        front += usize::from(z > FTINY);
        behind += usize::from(z < -FTINY);
        cut += usize::from(!text[k].contains("cutoff_factor: 0.0"));
    }
    assert!(
        front > 50 && behind > 50 && cut > 50,
        "{front} {behind} {cut}"
    );
}

#[test]
#[should_panic(expected = "past the 1 pairs held")]
fn writing_past_the_end_is_refused() {
    let bsdf = bsdf(MaterialKind::Plastic, Variant::Radiance, 0.1, DVec3::Z);
    let mut out = prefilled(&bsdf, 1, 0);
    bsdf.geometry_product(&[DVec3::Z], &[DVec3::Z], &mut out, 2);
}

#[test]
#[should_panic(expected = "different lengths")]
fn slices_of_different_lengths_are_refused() {
    let bsdf = bsdf(MaterialKind::Plastic, Variant::Radiance, 0.1, DVec3::Z);
    let mut out = GeometryBatch::new();
    bsdf.geometry_soa([&[0.0], &[0.0], &[1.0]], [&[0.0], &[0.0], &[]], &mut out, 0);
}
