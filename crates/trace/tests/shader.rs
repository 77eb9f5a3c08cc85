//! The shader's split of brtf-model's BSDF into diffuse and specular parts,
//! its frames, and θ_in-table shaders.

use crate::common::{lobe_sums, mat, mirror_mixture, shader_of, zoo};
use brtf_fit::{Interpolation, ParamTable};
use brtf_model::Rng;
use brtf_model::{Bsdf, Composite, CompositeBsdf, EvalOptions, MaterialKind, Variant};
use brtf_trace::{LobeMix, ReflectionLobe, Shader, ShaderError};
use glam::DVec3;

fn random_dir(rng: &mut Rng) -> DVec3 {
    let [a, b] = rng.uniform2();
    let z = 1.0 - 2.0 * a;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * std::f64::consts::PI * b;
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Materials of every type, plus pure and spec-0 ones.
fn all_materials() -> Vec<(&'static str, brtf_model::Material)> {
    use MaterialKind::*;
    let mut m = zoo();
    m.push(("pure plastic", mat(Plastic, &[0.5, 0.5, 0.5, 0.05, 0.0])));
    m.push(("pure metal", mat(Metal, &[0.9, 0.8, 0.6, 0.9, 0.0])));
    m.push((
        "pure trans",
        mat(Trans, &[0.8, 0.8, 0.8, 0.05, 0.0, 0.7, 0.5]),
    ));
    m.push(("lambert", mat(Plastic, &[0.7, 0.6, 0.5, 0.0, 0.2])));
    m
}

#[test]
fn diffuse_part_is_below_f_and_specular_vanishes_without_lobes() {
    let mut rng = Rng::new(11, 0);
    for variant in Variant::ALL {
        let options = EvalOptions::with_variant(variant);
        for (name, material) in all_materials() {
            let shader = shader_of(&material, &options);
            // Ward 1992's Fresnel term gives even a spec-0 surface a lobe.
            let pure = !material.kind().is_anisotropic() && material.args()[4] == 0.0;
            let no_lobe = pure || (material.spec() == 0.0 && variant != Variant::Ward1992);
            let (frame, degenerate) = shader.frame(DVec3::Z);
            for _ in 0..2000 {
                let l = random_dir(&mut rng);
                let mut v = random_dir(&mut rng);
                v.z = v.z.abs();
                let (l, v) = (frame.to_local(l), frame.to_local(v));
                let f = shader.eval(l, v, degenerate);
                let d = shader.diffuse(l, v);
                for k in 0..3 {
                    assert!(
                        d[k] <= f[k] * (1.0 + 1e-12) + 1e-15,
                        "{variant} {name}: f_d {d:?} > f {f:?} at l={l} v={v}"
                    );
                    if no_lobe {
                        assert!(
                            (d[k] - f[k]).abs() <= 1e-12 * f[k].abs(),
                            "{variant} {name}: f_d {d:?} != f {f:?}"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn diffuse_part_equals_f_far_from_the_lobes() {
    // Radiance variant: lobe values below 1e-6 are cut off, so far from a
    // narrow lobe f is exactly the diffuse part.
    let options = EvalOptions::default();
    for args in [
        [0.6, 0.5, 0.4, 0.05, 0.05, 0.0, 0.0],
        [0.8, 0.8, 0.7, 0.04, 0.05, 0.6, 0.5],
    ] {
        let kind = if args[5] > 0.0 {
            MaterialKind::Trans
        } else {
            MaterialKind::Plastic
        };
        let material = mat(kind, &args[..kind.n_args()]);
        let shader = shader_of(&material, &options);
        let v = brtf_model::direction(20.0, 0.0);
        for (t, p) in [(60.0, 0.0), (30.0, 90.0), (120.0, 0.0), (150.0, 90.0)] {
            let l = brtf_model::direction(t, p);
            assert_eq!(
                shader.eval(l, v, false),
                shader.diffuse(l, v),
                "{kind} l=({t},{p})"
            );
        }
    }
}

#[test]
fn shading_frames_reproduce_the_model_in_the_measurement_frame() {
    // The gonio sample: normal +z, local frame = world. The shader builds
    // its own tangent frame from the orientation; f must not change, on
    // either side of the surface.
    let mut rng = Rng::new(5, 1);
    for (name, material) in zoo() {
        for orientation in [
            DVec3::new(1.0, 0.3, 0.0),
            DVec3::new(0.2, 1.0, 0.5),
            DVec3::Z,
        ] {
            let material =
                brtf_model::Material::new(material.kind(), material.args(), Some(orientation))
                    .unwrap();
            let options = EvalOptions::default();
            let bsdf = Bsdf::new(&material, &options);
            let shader = shader_of(&material, &options);
            for _ in 0..500 {
                let l = random_dir(&mut rng);
                let v = random_dir(&mut rng);
                let n = if v.z >= 0.0 { DVec3::Z } else { -DVec3::Z };
                let (frame, degenerate) = shader.frame(n);
                let got = shader.eval(frame.to_local(l), frame.to_local(v), degenerate);
                let want = bsdf.eval(l, v);
                for k in 0..3 {
                    assert!(
                        (got[k] - want[k]).abs() <= 1e-9 * want[k].abs() + 1e-12,
                        "{name} u={orientation}: {got:?} vs {want:?} at l={l} v={v}"
                    );
                }
            }
        }
    }
}

#[test]
fn table_shader_uses_the_light_angle() {
    let table = ParamTable {
        azimuth: None,
        kind: MaterialKind::Plastic,
        lobes: 1,
        oriented: false,
        orientation: [1.0, 0.0, 0.0],
        method: Interpolation::Linear,
        theta_in: vec![0.0, 40.0, 80.0],
        args: vec![
            vec![0.5, 0.5, 0.5, 0.05, 0.05],
            vec![0.4, 0.4, 0.4, 0.10, 0.10],
            vec![0.3, 0.3, 0.3, 0.20, 0.20],
        ],
    };
    let options = EvalOptions::default();
    let shader = Shader::from_table(&table, &options).unwrap();
    assert!(shader.is_table());
    let v = brtf_model::direction(25.0, 180.0);
    for theta in [0.0, 10.0, 25.0, 40.0, 55.5, 80.0, 89.0] {
        let l = brtf_model::direction(theta, 0.0);
        let bsdf = Bsdf::new(&table.at(theta).unwrap().material, &options);
        let want = bsdf.eval(l, v);
        let got = shader.eval(l, v, false);
        for k in 0..3 {
            // Between grid nodes f is interpolated linearly over 0.25°.
            assert!(
                (got[k] - want[k]).abs() <= 2e-3 * want[k],
                "θ_l = {theta}: {got:?} vs {want:?}"
            );
        }
    }
}

/// A table that follows φ_in (an anisotropic type fitted to rings of
/// azimuths) is shaded with the parameters at the light's (θ_l, φ_l),
/// φ_l counted from u in the frame whose normal is on the light's side:
/// equal to brtf-model with `ParamTable::at_direction`, for reflection
/// and transmission, and different from the φ_in-averaged rows.
#[test]
fn azimuth_table_shader_uses_the_light_azimuth() {
    let rings: [(f64, usize); 4] = [(0.0, 1), (20.0, 8), (40.0, 12), (60.0, 8)];
    let args_at = |theta: f64, phi: f64| -> Vec<f64> {
        let (c, x) = (phi.to_radians().cos(), theta / 60.0);
        vec![
            0.3,
            0.3,
            0.3,
            0.02 + 0.01 * x * (1.0 + c),
            0.08 + 0.03 * x * (1.0 + c),
            0.12,
            0.2 + 0.1 * x * c,
            0.5 + 0.2 * x * (2.0 * phi).to_radians().sin(),
        ]
    };
    let mut table = ParamTable {
        azimuth: None,
        kind: MaterialKind::Trans2,
        lobes: 1,
        oriented: false,
        orientation: [1.0, 0.0, 0.0],
        method: Interpolation::Pchip,
        theta_in: Vec::new(),
        args: Vec::new(),
    };
    let mut azimuth = Vec::new();
    for (theta, count) in rings {
        let phi_in: Vec<f64> = (0..count)
            .map(|k| 360.0 * k as f64 / count as f64)
            .collect();
        let args: Vec<Vec<f64>> = phi_in.iter().map(|&p| args_at(theta, p)).collect();
        let mean = (0..8)
            .map(|j| args.iter().map(|a| a[j]).sum::<f64>() / count as f64)
            .collect();
        table.theta_in.push(theta);
        table.args.push(mean);
        azimuth.push(brtf_fit::AzimuthRing { phi_in, args });
    }
    table.azimuth = Some(azimuth);
    table.validate().unwrap();
    let options = EvalOptions::default();
    let shader = Shader::from_table(&table, &options).unwrap();
    let mut differs = 0;
    for (theta, phi) in [(20.0, 45.0), (33.0, 100.0), (40.0, 357.0), (55.0, 210.0)] {
        for light_below in [false, true] {
            let mut l = brtf_model::direction(theta, phi);
            if light_below {
                // Through the surface: the same azimuth in the light's frame.
                l = DVec3::new(l.x, -l.y, -l.z);
            }
            for v in [
                brtf_model::direction(theta, phi + 180.0),
                brtf_model::direction(30.0, 10.0),
                brtf_model::direction(70.0, 250.0),
            ] {
                let material = table.at_direction(theta, phi).unwrap().material;
                let want = Bsdf::new(&material, &options).eval(l, v);
                let got = shader.eval(l, v, false);
                let mean = Bsdf::new(&table.at(theta).unwrap().material, &options).eval(l, v);
                for k in 0..3 {
                    // Bilinear between grid materials 1° × 2.5° apart.
                    assert!(
                        (got[k] - want[k]).abs() <= 1e-2 * want[k] + 1e-6,
                        "({theta}, {phi}) below {light_below}: {got:?} vs {want:?}"
                    );
                }
                if (mean[0] - want[0]).abs() > 0.02 * want[0] {
                    differs += 1;
                }
            }
        }
    }
    assert!(differs >= 8, "only {differs} values depend on φ_l");
}

/// A lobe sum shades as the weighted sum of its lobes, each shaded alone:
/// the whole `f` (the direct term), the diffuse part and the specular
/// part, in tilted frames too, and `f` is brtf-model's `CompositeBsdf`
/// in the measurement frame.
#[test]
fn lobe_sums_shade_as_the_weighted_sum_of_their_lobes() {
    let options = EvalOptions::default();
    let mut rng = Rng::new(17, 3);
    let mut materials = lobe_sums();
    materials.push(("mirror mixture", mirror_mixture()));
    for (name, composite) in materials {
        let shader = Shader::new(&composite, &options).unwrap();
        assert_eq!(shader.lobe_count(), composite.components().len(), "{name}");
        let lobes: Vec<(f64, Shader)> = composite
            .components()
            .iter()
            .map(|(w, m)| (*w, shader_of(m, &options)))
            .collect();
        let bsdf = CompositeBsdf::new(&composite, &options);
        let sum = |value: &dyn Fn(&Shader) -> [f64; 3]| -> [f64; 3] {
            let mut s = [0.0; 3];
            for (w, lobe) in &lobes {
                let x = value(lobe);
                for k in 0..3 {
                    s[k] += w * x[k];
                }
            }
            s
        };
        let close = |got: [f64; 3], want: [f64; 3], what: &str| {
            for k in 0..3 {
                assert!(
                    (got[k] - want[k]).abs() <= 1e-12 * want[k].abs() + 1e-15,
                    "{name} {what}: {got:?} vs {want:?}"
                );
            }
        };
        for normal in [DVec3::Z, DVec3::new(0.3, -0.5, 0.8).normalize()] {
            let (frame, degenerate) = shader.frame(normal);
            for (w, lobe) in &lobes {
                // Every lobe has the mixture's frame.
                let (f, d) = lobe.frame(normal);
                assert!(
                    (f.x - frame.x).length() < 1e-15 || !lobe.is_anisotropic(),
                    "{name} w={w}"
                );
                assert_eq!(d, degenerate);
            }
            for _ in 0..500 {
                let l = frame.to_local(random_dir(&mut rng));
                let mut v = frame.to_local(random_dir(&mut rng));
                v.z = v.z.abs();
                let f = shader.eval(l, v, degenerate);
                close(f, sum(&|s| s.eval(l, v, degenerate)), "f");
                close(shader.diffuse(l, v), sum(&|s| s.diffuse(l, v)), "f_d");
                close(
                    shader.specular(l, v, degenerate),
                    sum(&|s| s.specular(l, v, degenerate)),
                    "f_s",
                );
                if normal == DVec3::Z {
                    let want = bsdf.eval(frame.to_world(l), frame.to_world(v));
                    for k in 0..3 {
                        assert!(
                            (f[k] - want[k]).abs() <= 1e-9 * want[k].abs() + 1e-12,
                            "{name}: {f:?} vs CompositeBsdf {want:?}"
                        );
                    }
                }
            }
        }
    }
}

/// The lobes a lobe sum samples: its rough lobes as one mixture (picked
/// with the lobe weights when they share the specularity), the weighted
/// sum of the roughness-0 primitives' deltas, and the diffuse parts of
/// any primitive.
#[test]
fn lobe_sums_sample_their_lobes_as_a_mixture() {
    let options = EvalOptions::default();
    let v = brtf_model::direction(35.0, 20.0);
    let (_, metal) = &lobe_sums()[0];
    let shader = Shader::new(metal, &options).unwrap();
    let lobes = shader.lobes(v, false);
    let Some(LobeMix::Many(mixture)) = lobes.reflect else {
        panic!("metal ×2: {:?}", lobes.reflect);
    };
    let picks: Vec<(f64, ReflectionLobe)> = mixture.lobes().map(|(p, l)| (p, *l)).collect();
    assert_eq!(picks.len(), 2);
    for ((p, lobe), (w, m)) in picks.iter().zip(metal.components()) {
        assert!((p - w).abs() < 1e-12, "probability {p} vs weight {w}");
        let alpha = m.args()[4];
        assert_eq!(*lobe, ReflectionLobe::isotropic(alpha));
    }
    assert!(lobes.transmit.is_none() && lobes.delta.is_none());
    assert!(lobes.diffuse_reflect && !lobes.diffuse_transmit);

    let mirror = mirror_mixture();
    let shader = Shader::new(&mirror, &options).unwrap();
    assert!(shader.has_delta());
    let lobes = shader.lobes(v, false);
    // The rough metal alone is sampled (the pure plastic is a delta).
    assert!(matches!(lobes.reflect, Some(LobeMix::Many(m)) if m.lobes().count() == 1));
    let (w, pure) = mirror.components()[1];
    let (mirror_want, through_want) = shader_of(&pure, &options).lobes(v, false).delta.unwrap();
    let (m, t) = lobes.delta.unwrap();
    for k in 0..3 {
        assert!((m[k] - w * mirror_want[k]).abs() < 1e-15);
        assert!((t[k] - w * through_want[k]).abs() < 1e-15);
    }
    // A trans lobe in a mixture brings a transmitted lobe.
    let (_, mixture) = &lobe_sums()[4];
    let shader = Shader::new(mixture, &options).unwrap();
    let lobes = shader.lobes(v, false);
    assert!(lobes.transmit.is_some() && lobes.diffuse_transmit);
}

/// A mixture of anisotropic primitives with different orientation
/// vectors is refused with a clear error.
#[test]
fn mixtures_of_two_orientations_are_refused() {
    let kind = MaterialKind::Plastic2;
    let args = [0.5, 0.5, 0.5, 0.05, 0.1, 0.2];
    let a = brtf_model::Material::new(kind, &args, Some(DVec3::X)).unwrap();
    let b = brtf_model::Material::new(kind, &args, Some(DVec3::Y)).unwrap();
    let mixture = Composite::mixture(vec![(0.5, a), (0.5, b)]).unwrap();
    let err = Shader::new(&mixture, &EvalOptions::default()).unwrap_err();
    assert!(matches!(err, ShaderError::Orientations(..)), "{err}");
    assert!(err.to_string().contains("orientation"), "{err}");
}

/// A table with a fitted orientation (`orient` per θ_in row) turns the
/// tangent frame with θ_l: on the gonio-photometer's flat sample the
/// shader equals brtf-model's `CompositeBsdf` of the table's material at
/// θ_l, exactly at the grid's nodes and within the interpolation between
/// them, for one lobe and for a lobe sum.
#[test]
fn fitted_orientation_tables_turn_with_the_incidence() {
    let one = ParamTable {
        azimuth: None,
        kind: MaterialKind::Metal2,
        lobes: 1,
        oriented: true,
        orientation: [1.0, 0.0, 0.0],
        method: Interpolation::Linear,
        theta_in: vec![0.0, 40.0, 80.0],
        args: vec![
            vec![0.9, 0.9, 0.9, 0.8, 0.3, 0.06, 10.0],
            vec![0.9, 0.9, 0.9, 0.8, 0.25, 0.08, 60.0],
            vec![0.9, 0.9, 0.9, 0.8, 0.2, 0.1, 130.0],
        ],
    };
    let two = ParamTable {
        kind: MaterialKind::Plastic2,
        lobes: 2,
        method: Interpolation::Pchip,
        args: vec![
            vec![0.5, 0.5, 0.5, 0.1, 0.3, 0.05, 0.2, 0.3, 0.1, -20.0],
            vec![0.5, 0.5, 0.5, 0.1, 0.5, 0.06, 0.2, 0.25, 0.1, 15.0],
            vec![0.5, 0.5, 0.5, 0.1, 0.6, 0.08, 0.2, 0.2, 0.1, 70.0],
        ],
        ..one.clone()
    };
    let options = EvalOptions::default();
    let mut rng = Rng::new(8, 8);
    for table in [one, two] {
        table.validate().unwrap();
        let shader = Shader::from_table(&table, &options).unwrap();
        let (frame, degenerate) = shader.frame(DVec3::Z);
        let mut turned = 0;
        for theta in [0.0, 12.5, 23.3, 40.0, 61.7, 80.0] {
            let l = brtf_model::direction(theta, 30.0);
            let (material, _) = table.composite_at(theta).unwrap();
            let bsdf = CompositeBsdf::new(&material, &options);
            let (fixed, _) = table.composite_at(40.0).unwrap();
            let fixed = CompositeBsdf::new(&fixed, &options);
            let on_node = (theta / 0.25f64).fract() == 0.0 && theta % 1.0 == 0.0;
            for _ in 0..200 {
                let mut v = random_dir(&mut rng);
                v.z = v.z.abs();
                let want = bsdf.eval(l, v);
                let got = shader.eval(frame.to_local(l), frame.to_local(v), degenerate);
                let tol = if on_node { 1e-9 } else { 2e-3 };
                for k in 0..3 {
                    assert!(
                        (got[k] - want[k]).abs() <= tol * want[k] + 1e-12,
                        "{} θ_l {theta}: {got:?} vs {want:?}",
                        table.shape()
                    );
                }
                if (fixed.eval(l, v)[0] - want[0]).abs() > 0.05 * want[0] {
                    turned += 1;
                }
            }
        }
        // The orientation matters: the 40° row's material differs elsewhere.
        assert!(
            turned > 100,
            "{}: only {turned} values turned",
            table.shape()
        );
    }
}
