//! The virtual gonio-photometer against brtf-model.
//!
//! * Point-like source and detector (0.01° apertures): the rendered BSDF
//!   equals `Bsdf::eval(l, v)` within Monte Carlo noise: at most 1% of the
//!   values outside 3σ, none outside 5σ, and all within 1%.
//! * Finite apertures (2°): it equals the quadrature cone average
//!   ([`brtf_trace::cone_average`]) within 1% and within noise.
//! * Roughness 0: the mirror spike has the analytic height.

use crate::common::{lobe_sums, mat, shader_of, zoo};
use brtf_model::{Bsdf, CompositeBsdf, EvalOptions, MaterialKind, Rgb, cone_solid_angle};
use brtf_trace::{GonioSetup, Shader, VirtualGonio, cone_average};
use glam::DVec3;

/// Detector directions: a θ/φ grid on the front, and on the back for
/// transmitting types.
fn directions(kind: MaterialKind, phi_in: f64) -> Vec<DVec3> {
    let mut dirs = Vec::new();
    let back = kind.is_transmitting();
    for t in (0..=85).step_by(17) {
        for dp in [0.0, 60.0, 150.0, 180.0, 195.0, 270.0] {
            dirs.push(brtf_model::direction(t as f64, phi_in + dp));
            if back {
                dirs.push(brtf_model::direction(180.0 - t as f64, phi_in + dp));
            }
        }
    }
    dirs
}

#[derive(Default)]
struct Tally {
    values: usize,
    beyond3: usize,
    beyond5: usize,
    worst_rel: f64,
    worst_at: String,
}

impl Tally {
    /// `allowance`: relative difference allowed on top of the noise.
    fn add(
        &mut self,
        got: Rgb,
        sigma: Rgb,
        want: Rgb,
        peak: f64,
        allowance: f64,
        what: &dyn Fn() -> String,
    ) {
        for k in 0..3 {
            let d = (got[k] - want[k]).abs();
            let tol = allowance * want[k].abs() + 1e-12 * peak;
            self.values += 1;
            if d > 3.0 * sigma[k] + tol {
                self.beyond3 += 1;
            }
            if d > 5.0 * sigma[k] + tol {
                self.beyond5 += 1;
            }
            // Relative error where the value matters (≥ 1% of the peak).
            if want[k] >= 0.01 * peak {
                let rel = d / want[k];
                if rel > self.worst_rel {
                    self.worst_rel = rel;
                    self.worst_at = format!(
                        "{} ch{k}: {} vs {} (σ {})",
                        what(),
                        got[k],
                        want[k],
                        sigma[k]
                    );
                }
            }
        }
    }
}

#[test]
fn point_like_apertures_give_the_model_within_noise() {
    let omega = cone_solid_angle(0.01);
    let options = EvalOptions::default();
    let mut tally = Tally::default();
    for (name, material) in zoo() {
        let bsdf = Bsdf::new(&material, &options);
        let shader = shader_of(&material, &options);
        for (theta_in, phi_in) in [(0.0, 0.0), (35.0, 20.0), (65.0, 0.0)] {
            let setup = GonioSetup {
                theta_in,
                phi_in,
                source_omega: omega,
                detector_omega: omega,
                samples: 256,
                seed: 7,
            };
            let gonio = VirtualGonio::new(shader.clone(), setup);
            let dirs = directions(material.kind(), phi_in);
            let (values, _) = gonio.render(&dirs);
            let l = setup.light();
            let model: Vec<Rgb> = dirs.iter().map(|&v| bsdf.eval(l, v)).collect();
            let peak = model.iter().flatten().fold(0.0f64, |a, &b| a.max(b));
            for ((v, got), want) in dirs.iter().zip(&values).zip(&model) {
                // Allowance: the 0.01° apertures' own smoothing, second order
                // in the aperture (≤ 1e-6 relative), where the noise (first
                // order) vanishes: at a lobe's peak or on a constant BSDF.
                tally.add(got.bsdf, got.std_err, *want, peak, 1e-5, &|| {
                    format!("{name} θ_in={theta_in} v={v:.3}")
                });
            }
        }
    }
    eprintln!(
        "point-like gonio vs model: {} values, {} beyond 3σ ({:.2}%), {} beyond 5σ, worst relative {:.2e} ({})",
        tally.values,
        tally.beyond3,
        100.0 * tally.beyond3 as f64 / tally.values as f64,
        tally.beyond5,
        tally.worst_rel,
        tally.worst_at
    );
    assert!(tally.beyond3 as f64 <= 0.01 * tally.values as f64);
    assert_eq!(tally.beyond5, 0);
    assert!(tally.worst_rel < 0.01, "{}", tally.worst_at);
}

#[test]
fn finite_apertures_give_the_cone_average() {
    // 2° source and detector, as in a real instrument.
    let omega = cone_solid_angle(2.0);
    let options = EvalOptions::default();
    let mut tally = Tally::default();
    for (name, material) in zoo() {
        let shader = shader_of(&material, &options);
        for (theta_in, phi_in) in [(20.0, 0.0), (60.0, 45.0)] {
            let setup = GonioSetup {
                theta_in,
                phi_in,
                source_omega: omega,
                detector_omega: omega,
                samples: 4096,
                seed: 3,
            };
            let gonio = VirtualGonio::new(shader.clone(), setup);
            let dirs = directions(material.kind(), phi_in);
            let (values, _) = gonio.render(&dirs);
            let l = setup.light();
            let reference: Vec<Rgb> = dirs
                .iter()
                .map(|&v| cone_average(&shader, l, omega, v, omega, (8, 16)))
                .collect();
            let peak = reference.iter().flatten().fold(0.0f64, |a, &b| a.max(b));
            for ((v, got), want) in dirs.iter().zip(&values).zip(&reference) {
                tally.add(got.bsdf, got.std_err, *want, peak, 1e-6, &|| {
                    format!("{name} θ_in={theta_in} v={v:.3}")
                });
            }
        }
    }
    eprintln!(
        "2° gonio vs cone average: {} values, {} beyond 3σ ({:.2}%), {} beyond 5σ, worst relative {:.2e} ({})",
        tally.values,
        tally.beyond3,
        100.0 * tally.beyond3 as f64 / tally.values as f64,
        tally.beyond5,
        tally.worst_rel,
        tally.worst_at
    );
    assert!(tally.worst_rel < 0.01, "{}", tally.worst_at);
    assert!(tally.beyond3 as f64 <= 0.02 * tally.values as f64);
}

#[test]
fn mirror_spike_of_a_roughness_0_metal_has_the_analytic_height() {
    let material = mat(MaterialKind::Metal, &[0.9, 0.8, 0.6, 0.9, 0.0]);
    let options = EvalOptions::default();
    let bsdf = Bsdf::new(&material, &options);
    let (source_apex, detector_apex) = (2.0f64, 1.0f64);
    let theta_in = 30.0f64;
    let setup = GonioSetup {
        theta_in,
        phi_in: 0.0,
        source_omega: cone_solid_angle(source_apex),
        detector_omega: cone_solid_angle(detector_apex),
        samples: 64,
        seed: 1,
    };
    let gonio = VirtualGonio::new(shader_of(&material, &options), setup);
    let mirror = brtf_model::direction(theta_in, 180.0);
    let (values, _) = gonio.render(&[mirror, brtf_model::direction(10.0, 0.0)]);
    // Every detector direction's mirror lies inside the source cone, so
    // L_r = coef·L + diffuse, and E = L π sin²a cos θ_in.
    let a = 0.5 * source_apex.to_radians();
    let (coef, _) = bsdf.delta_coefficients(theta_in.to_radians().cos());
    let diffuse = bsdf.eval(setup.light(), mirror);
    for k in 0..3 {
        let want = coef[k] / (std::f64::consts::PI * a.sin().powi(2) * theta_in.to_radians().cos())
            + diffuse[k];
        let got = values[0].bsdf[k];
        assert!((got - want).abs() < 2e-3 * want, "ch{k}: {got} vs {want}");
        // Away from the spike only the diffuse part is left.
        let off = bsdf.eval(setup.light(), brtf_model::direction(10.0, 0.0))[k];
        assert!((values[1].bsdf[k] - off).abs() < 1e-3 * off.max(1e-9) + 1e-12);
    }
}

#[test]
fn renders_are_deterministic_and_thread_independent() {
    let (_, material) = zoo()[3];
    let options = EvalOptions::default();
    let setup = GonioSetup {
        theta_in: 30.0,
        phi_in: 0.0,
        source_omega: cone_solid_angle(1.0),
        detector_omega: cone_solid_angle(1.0),
        samples: 32,
        seed: 9,
    };
    let gonio = VirtualGonio::new(shader_of(&material, &options), setup);
    let dirs = directions(material.kind(), 0.0);
    let (a, _) = gonio.render(&dirs);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let (b, _) = pool.install(|| gonio.render(&dirs));
    assert_eq!(a, b);
}

#[test]
fn table_materials_render_with_the_parameters_of_the_incidence() {
    use brtf_fit::{Interpolation, ParamTable};
    let table = ParamTable {
        azimuth: None,
        kind: MaterialKind::Metal,
        lobes: 1,
        oriented: false,
        orientation: [1.0, 0.0, 0.0],
        method: Interpolation::Pchip,
        theta_in: vec![0.0, 30.0, 60.0],
        args: vec![
            vec![0.9, 0.9, 0.9, 0.80, 0.08],
            vec![0.9, 0.9, 0.9, 0.85, 0.10],
            vec![0.9, 0.9, 0.9, 0.90, 0.14],
        ],
    };
    let options = EvalOptions::default();
    let shader = Shader::from_table(&table, &options).unwrap();
    let omega = cone_solid_angle(0.01);
    for theta_in in [0.0, 17.3, 30.0, 48.0, 60.0] {
        let setup = GonioSetup {
            theta_in,
            phi_in: 0.0,
            source_omega: omega,
            detector_omega: omega,
            samples: 16,
            seed: 2,
        };
        let gonio = VirtualGonio::new(shader.clone(), setup);
        let bsdf = Bsdf::new(&table.at(theta_in).unwrap().material, &options);
        let dirs = directions(MaterialKind::Metal, 0.0);
        let (values, _) = gonio.render(&dirs);
        let peak = dirs
            .iter()
            .map(|&v| bsdf.eval(setup.light(), v)[0])
            .fold(0.0, f64::max);
        for (v, got) in dirs.iter().zip(&values) {
            let want = bsdf.eval(setup.light(), *v)[0];
            if want > 0.01 * peak {
                assert!(
                    (got.bsdf[0] - want).abs() < 5e-3 * want,
                    "θ_in {theta_in}, v {v}: {} vs {want}",
                    got.bsdf[0]
                );
            }
        }
    }
}

/// A lobe sum through the virtual gonio-photometer with a point-like
/// beam and detector: the rendered BSDF is brtf-model's
/// `CompositeBsdf::eval` (the weighted sum of the lobes) within the
/// Monte Carlo error, as for one primitive.
#[test]
fn point_like_apertures_give_lobe_sums_within_noise() {
    let omega = cone_solid_angle(0.01);
    let options = EvalOptions::default();
    let mut tally = Tally::default();
    for (name, composite) in lobe_sums() {
        let bsdf = CompositeBsdf::new(&composite, &options);
        let shader = Shader::new(&composite, &options).unwrap();
        let transmitting = shader.is_transmitting();
        for (theta_in, phi_in) in [(0.0, 0.0), (35.0, 20.0), (65.0, 0.0)] {
            let setup = GonioSetup {
                theta_in,
                phi_in,
                source_omega: omega,
                detector_omega: omega,
                samples: 256,
                seed: 11,
            };
            let gonio = VirtualGonio::new(shader.clone(), setup);
            let kind = if transmitting {
                MaterialKind::Trans
            } else {
                MaterialKind::Metal
            };
            let dirs = directions(kind, phi_in);
            let (values, _) = gonio.render(&dirs);
            let l = setup.light();
            let model: Vec<Rgb> = dirs.iter().map(|&v| bsdf.eval(l, v)).collect();
            let peak = model.iter().flatten().fold(0.0f64, |a, &b| a.max(b));
            for ((v, got), want) in dirs.iter().zip(&values).zip(&model) {
                tally.add(got.bsdf, got.std_err, *want, peak, 1e-5, &|| {
                    format!("{name} θ_in={theta_in} v={v:.3}")
                });
            }
        }
    }
    eprintln!(
        "point-like gonio vs lobe sums: {} values, {} beyond 3σ ({:.2}%), {} beyond 5σ, worst relative {:.2e} ({})",
        tally.values,
        tally.beyond3,
        100.0 * tally.beyond3 as f64 / tally.values as f64,
        tally.beyond5,
        tally.worst_rel,
        tally.worst_at
    );
    assert!(tally.beyond3 as f64 <= 0.01 * tally.values as f64);
    assert_eq!(tally.beyond5, 0);
    assert!(tally.worst_rel < 0.01, "{}", tally.worst_at);
}

/// With finite (2°) apertures a lobe sum renders as the quadrature cone
/// average of its shader, within 1% and the noise.
#[test]
fn finite_apertures_give_the_cone_average_of_lobe_sums() {
    let omega = cone_solid_angle(2.0);
    let options = EvalOptions::default();
    let mut tally = Tally::default();
    for (name, composite) in lobe_sums() {
        let shader = Shader::new(&composite, &options).unwrap();
        let setup = GonioSetup {
            theta_in: 40.0,
            phi_in: 30.0,
            source_omega: omega,
            detector_omega: omega,
            samples: 4096,
            seed: 5,
        };
        let gonio = VirtualGonio::new(shader.clone(), setup);
        let dirs = directions(MaterialKind::Metal, 30.0);
        let (values, _) = gonio.render(&dirs);
        let l = setup.light();
        let reference: Vec<Rgb> = dirs
            .iter()
            .map(|&v| cone_average(&shader, l, omega, v, omega, (8, 16)))
            .collect();
        let peak = reference.iter().flatten().fold(0.0f64, |a, &b| a.max(b));
        for ((v, got), want) in dirs.iter().zip(&values).zip(&reference) {
            tally.add(got.bsdf, got.std_err, *want, peak, 1e-6, &|| {
                format!("{name} v={v:.3}")
            });
        }
    }
    eprintln!(
        "2° gonio vs cone average, lobe sums: {} values, {} beyond 3σ, worst relative {:.2e} ({})",
        tally.values, tally.beyond3, tally.worst_rel, tally.worst_at
    );
    assert!(tally.worst_rel < 0.01, "{}", tally.worst_at);
    assert!(tally.beyond3 as f64 <= 0.02 * tally.values as f64);
}
