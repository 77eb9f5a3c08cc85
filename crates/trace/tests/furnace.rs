//! White furnace: a sample in an environment of constant radiance L (no
//! sources, no other geometry) must look like `(ρ_dh + τ_dh)·L`, with
//! ρ_dh and τ_dh from brtf-model's `albedo` (for these reciprocal
//! materials, the hemispherical-directional and directional-hemispherical
//! integrals are equal). Specular lobes are importance-sampled, diffuse
//! parts get the one-bounce rays, roughness-0 surfaces trace their deltas.

use crate::common::{lobe_sum, lobe_sums, mat, mirror_mixture, shader_of, zoo};
use brtf_model::Rng;
use brtf_model::{Bsdf, CompositeBsdf, EvalOptions, MaterialKind, albedo, composite_albedo};
use brtf_trace::{Ray, RayCounts, Scene, Settings, Shader, Shape, Tracer};
use glam::DVec3;

fn furnace_radiance(shader: Shader, v: DVec3, background: f64, rays: u32) -> ([f64; 3], RayCounts) {
    let mut scene = Scene::new();
    let id = scene.add_shader(shader);
    scene.add(
        Shape::Disk {
            center: DVec3::ZERO,
            normal: DVec3::Z,
            radius: 1.0,
        },
        id,
    );
    scene.background = [background; 3];
    let settings = Settings {
        source_samples: 1,
        specular_samples: 16,
        diffuse_samples: 16,
        max_depth: 2,
    };
    let tracer = Tracer::new(&scene, settings);
    let mut counts = RayCounts::default();
    let mut sum = [0.0; 3];
    for i in 0..rays {
        let mut rng = Rng::new(42, i as u64);
        let r = tracer.radiance(
            &Ray {
                origin: v * 5.0,
                dir: -v,
            },
            &mut rng,
            &mut counts,
        );
        for k in 0..3 {
            sum[k] += r[k];
        }
    }
    (sum.map(|s| s / rays as f64), counts)
}

#[test]
fn white_furnace_gives_albedo_times_radiance() {
    use MaterialKind::*;
    let mut materials = zoo();
    materials.push(("pure plastic", mat(Plastic, &[0.5, 0.5, 0.5, 0.05, 0.0])));
    materials.push((
        "pure trans",
        mat(Trans, &[0.8, 0.8, 0.8, 0.05, 0.0, 0.7, 0.5]),
    ));
    materials.push(("white lambert", mat(Plastic, &[1.0, 1.0, 1.0, 0.0, 0.0])));
    let options = EvalOptions::default();
    let background = 2.5;
    let mut worst: (f64, String) = (0.0, String::new());
    for (name, material) in materials {
        let bsdf = Bsdf::new(&material, &options);
        for theta in [0.0, 40.0, 70.0] {
            let v = brtf_model::direction(theta, 25.0);
            let a = albedo(&bsdf, v, 1e-6);
            let (got, _) = furnace_radiance(shader_of(&material, &options), v, background, 4096);
            for k in 0..3 {
                let want = (a.rho[k] + a.tau[k] + a.rho_spike[k] + a.tau_spike[k]) * background;
                let rel = (got[k] - want).abs() / want;
                if rel > worst.0 {
                    worst = (rel, format!("{name} θ_v={theta} ch{k}: {got:?} vs {want}"));
                }
            }
        }
    }
    eprintln!(
        "white furnace: worst relative difference {:.2e} ({})",
        worst.0, worst.1
    );
    assert!(worst.0 < 0.01, "{}", worst.1);
}

#[test]
fn white_furnace_holds_for_the_manual2004_variant() {
    // The 2004 manual's lobes, 1/(4π α² c_i c_o) and 1/(|c_i| c_o), are
    // reciprocal too (and can exceed albedo 1 at grazing: the renderer
    // follows them, it does not fix them).
    use MaterialKind::*;
    let options = EvalOptions::with_variant(brtf_model::Variant::Manual2004);
    for (name, material) in [
        ("plastic", mat(Plastic, &[0.6, 0.5, 0.4, 0.3, 0.2])),
        ("trans", mat(Trans, &[0.8, 0.8, 0.7, 0.04, 0.12, 0.6, 0.5])),
    ] {
        let bsdf = Bsdf::new(&material, &options);
        for theta in [10.0, 60.0] {
            let v = brtf_model::direction(theta, 0.0);
            let a = albedo(&bsdf, v, 1e-6);
            let (got, _) = furnace_radiance(shader_of(&material, &options), v, 1.0, 4096);
            for k in 0..3 {
                let want = a.rho[k] + a.tau[k];
                assert!(
                    (got[k] - want).abs() < 0.01 * want,
                    "manual2004 {name} θ_v={theta} ch{k}: {got:?} vs {want}"
                );
            }
        }
    }
}

/// Lobe sums in the white furnace: the rendered radiance is brtf-model's
/// `composite_albedo` × L (the weighted sum of the lobes' albedos), for
/// two isotropic lobes, two anisotropic lobes (fitted orientation and
/// fixed), three lobes, a mixture of types, a mixture with a mirror
/// (delta) primitive, and a white two-lobe metal, whose energy stays at
/// most 1.
#[test]
fn white_furnace_holds_for_lobe_sums() {
    let options = EvalOptions::default();
    let mut materials = lobe_sums();
    materials.push(("mirror mixture", mirror_mixture()));
    materials.push((
        "white metal ×2",
        lobe_sum(
            MaterialKind::Metal,
            2,
            false,
            &[1.0, 1.0, 1.0, 1.0, 0.5, 0.05, 0.3],
        ),
    ));
    let background = 2.0;
    let mut worst: (f64, String) = (0.0, String::new());
    let mut most: f64 = 0.0;
    for (name, composite) in materials {
        let bsdf = CompositeBsdf::new(&composite, &options);
        let shader = Shader::new(&composite, &options).unwrap();
        for theta in [0.0, 40.0, 70.0] {
            let v = brtf_model::direction(theta, 25.0);
            let a = composite_albedo(&bsdf, v, 1e-6);
            let (got, _) = furnace_radiance(shader.clone(), v, background, 4096);
            for k in 0..3 {
                let want = (a.rho[k] + a.tau[k] + a.rho_spike[k] + a.tau_spike[k]) * background;
                let rel = (got[k] - want).abs() / want;
                if rel > worst.0 {
                    worst = (rel, format!("{name} θ_v={theta} ch{k}: {got:?} vs {want}"));
                }
                most = most.max(got[k] / background);
            }
        }
    }
    eprintln!(
        "white furnace, lobe sums: worst relative difference {:.2e} ({}); largest energy {most:.4}",
        worst.0, worst.1
    );
    assert!(worst.0 < 0.01, "{}", worst.1);
    assert!(most <= 1.0, "a lobe sum reflects {most} of the light");
}
