//! `Bsdf::eval_batch` (the vectorised structure-of-arrays kernel) gives
//! the values of the scalar `Bsdf::eval` on every type, variant and
//! switch, including near-mirror, grazing and back-side directions, and
//! matches the rtrace oracle tables like the scalar path does.

use brtf_model::{
    Bsdf, Directions, EvalOptions, FRESNEL_K_PYRADIANCE, Material, MaterialKind, RgbBatch, Variant,
    cone_solid_angle, direction,
};
use glam::DVec3;

/// Relative agreement asked of the batch kernel.
const RELATIVE: f64 = 1e-12;
/// Below this both paths are "zero": the batch `exp` flushes results
/// under 3.3e-308 to 0 (times the lobe's normalisation at grazing
/// half vectors, at most ~1e-280), where libm returns subnormals.
const ABSOLUTE: f64 = 1e-250;

/// Argument sets per type: rough, smooth, roughness 0 (isotropic only,
/// with and without rtrace's Fresnel switch), trans near the all-through
/// and opaque limits.
fn materials(kind: MaterialKind) -> Vec<Material> {
    let sets: Vec<Vec<f64>> = match kind {
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
            vec![0.6, 0.7, 0.8, 0.0, 0.2, 1.0, 1.0],
            vec![0.6, 0.7, 0.8, 0.1, 0.2, 0.0, 0.5],
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
    };
    // Anisotropic types: an oblique orientation and one along the normal
    // (rtrace's arbitrary tangent frame with the mean roughness).
    let orients: &[DVec3] = if kind.is_anisotropic() {
        &[DVec3::new(1.0, 1.0, 0.3), DVec3::Z]
    } else {
        &[DVec3::X]
    };
    sets.iter()
        .flat_map(|a| {
            orients
                .iter()
                .map(move |&o| Material::new(kind, a, Some(o)).unwrap())
        })
        .collect()
}

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

/// Direction pairs: a grid of incidences on both sides (normal, oblique,
/// near-grazing) with views spread over the sphere, near the mirror and
/// straight-through directions, grazing and exactly at the horizon.
fn direction_pairs() -> Vec<(DVec3, DVec3)> {
    let mut pairs = Vec::new();
    let mut state = 0x2545_F491_4F6C_DD1Du64;
    let mut uniform = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    for theta_l in [
        0.0, 0.5, 20.0, 45.0, 70.0, 85.0, 89.9, 89.999, 100.0, 135.0, 179.5,
    ] {
        for phi_l in [0.0, 37.0, 200.0] {
            let l = direction(theta_l, phi_l);
            let mirror = (theta_l, phi_l + 180.0);
            let through = (180.0 - theta_l, phi_l + 180.0);
            for (t, p) in [mirror, through] {
                for dt in [0.0, 1e-6, 1e-3, 0.05, 0.5, 3.0] {
                    for dp in [0.0, 1e-4, 0.7] {
                        pairs.push((l, direction((t + dt).min(180.0), p + dp)));
                        pairs.push((l, direction((t - dt).max(0.0), p - dp)));
                    }
                }
            }
            for theta_v in [0.0, 89.9, 89.9999, 90.0, 90.0001, 90.1, 180.0] {
                pairs.push((l, direction(theta_v, phi_l + 90.0)));
            }
            for _ in 0..40 {
                pairs.push((l, direction(180.0 * uniform(), 360.0 * uniform())));
            }
        }
    }
    // Exact mirror and straight-through pairs built from the vectors.
    let l = DVec3::new(0.3, -0.2, 0.5).normalize();
    pairs.push((l, DVec3::new(-l.x, -l.y, l.z)));
    pairs.push((l, -l));
    pairs
}

fn close(a: f64, b: f64) -> bool {
    (a.is_nan() && b.is_nan()) || (a - b).abs() <= RELATIVE * a.abs().max(b.abs()) + ABSOLUTE
}

fn check(bsdf: &Bsdf, pairs: &[(DVec3, DVec3)]) -> usize {
    let lights: Vec<DVec3> = pairs.iter().map(|p| p.0).collect();
    let views: Vec<DVec3> = pairs.iter().map(|p| p.1).collect();
    let mut out = RgbBatch::default();
    bsdf.eval_batch(
        &Directions::from_vectors(&lights),
        &Directions::from_vectors(&views),
        &mut out,
    );
    assert_eq!(out.len(), pairs.len());
    let mut nonzero = 0;
    for (i, &(l, v)) in pairs.iter().enumerate() {
        let want = bsdf.eval(l, v);
        let got = out.get(i);
        for ch in 0..3 {
            assert!(
                close(got[ch], want[ch]),
                "{} {:?} {:?} args {:?}: l={l} v={v} ch{ch}: batch {} vs eval {}",
                bsdf.kind(),
                bsdf.options().variant,
                bsdf.options(),
                bsdf.material().args(),
                got[ch],
                want[ch]
            );
        }
        nonzero += usize::from(want[1] > 0.0);
    }
    nonzero
}

fn check_kind(kind: MaterialKind) {
    let pairs = direction_pairs();
    let mut nonzero = 0;
    let mut cases = 0;
    for material in materials(kind) {
        for options in option_sets() {
            nonzero += check(&Bsdf::new(&material, &options), &pairs);
            cases += pairs.len();
        }
    }
    // The comparison is not vacuous: most pairs have a value.
    assert!(
        nonzero * 3 > cases,
        "{kind}: only {nonzero} of {cases} non-zero"
    );
}

#[test]
fn plastic_batch_equals_eval() {
    check_kind(MaterialKind::Plastic);
}

#[test]
fn metal_batch_equals_eval() {
    check_kind(MaterialKind::Metal);
}

#[test]
fn trans_batch_equals_eval() {
    check_kind(MaterialKind::Trans);
}

#[test]
fn plastic2_batch_equals_eval() {
    check_kind(MaterialKind::Plastic2);
}

#[test]
fn metal2_batch_equals_eval() {
    check_kind(MaterialKind::Metal2);
}

#[test]
fn trans2_batch_equals_eval() {
    check_kind(MaterialKind::Trans2);
}

#[test]
fn every_length_and_the_slice_form_agree() {
    // Lengths around the vector width exercise the scalar remainder loop.
    let material = Material::new(
        MaterialKind::Trans,
        &[0.6, 0.7, 0.8, 0.04, 0.05, 0.5, 0.5],
        None,
    )
    .unwrap();
    let bsdf = Bsdf::new(&material, &EvalOptions::default());
    let pairs = direction_pairs();
    for n in [0, 1, 7, 8, 9, 15, 16, 17, 33] {
        check(&bsdf, &pairs[..n]);
    }
    let (l, v): (Vec<DVec3>, Vec<DVec3>) = pairs.iter().copied().unzip();
    let (l, v) = (Directions::from_vectors(&l), Directions::from_vectors(&v));
    let mut owned = RgbBatch::default();
    bsdf.eval_batch(&l, &v, &mut owned);
    let n = l.len();
    let (mut r, mut g, mut b) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    bsdf.eval_soa(
        [&l.x, &l.y, &l.z],
        [&v.x, &v.y, &v.z],
        [&mut r, &mut g, &mut b],
    );
    assert_eq!((owned.r, owned.g, owned.b), (r, g, b));
}

#[test]
#[should_panic(expected = "different lengths")]
fn mismatched_lengths_are_refused() {
    let material = Material::new(MaterialKind::Plastic, &[0.5, 0.4, 0.3, 0.05, 0.1], None).unwrap();
    let bsdf = Bsdf::new(&material, &EvalOptions::default());
    let l = Directions::from_vectors(&[DVec3::Z, DVec3::Z]);
    let v = Directions::from_vectors(&[DVec3::Z]);
    bsdf.eval_batch(&l, &v, &mut RgbBatch::default());
}
