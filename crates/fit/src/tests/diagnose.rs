//! The adequacy diagnostics: the energy ratio of data and model (with the
//! unmeasured directions from the model, and a free scale divided out),
//! the peak offset of data whose lobe is turned by a known angle, the
//! residual-kind comparison, and the warnings at each tolerance.

use super::{measurement, report, ring_directions};
use crate::adequacy::{
    Adequacy, ENERGY_TOLERANCE, PEAK_TOLERANCE_DEG, RESIDUAL_KIND_TOLERANCE, ResidualCheck,
};
use crate::config::FitConfig;
use crate::diagnose::{compare, diagnose, other_residual, warnings};
use crate::problem::ResidualKind;
use crate::recipe::{ColourConversion, PreparedMeasurement, Recipe, ScaleRule, WeightRule};
use crate::report::FitWarning;
use brtf_gonio::{Channels, Gate, Quantity, Sample};
use brtf_model::{Bsdf, EvalOptions, MaterialKind, direction};

/// An adequacy with nothing to warn about; tests change one field.
fn adequate() -> Adequacy {
    Adequacy {
        rho_data: Some(0.5),
        rho_model: 0.5,
        tau_data: None,
        tau_model: 0.0,
        peak_offset_deg: Some(1.0),
        residual_check: None,
        raw_energy: None,
        gloss_width_deg: None,
    }
}

fn check(relative_change: f64) -> ResidualCheck {
    ResidualCheck {
        residual: ResidualKind::Log,
        param: "rough".into(),
        values: [0.1, 0.1 * (1.0 + relative_change)],
        relative_change,
    }
}

#[test]
fn the_tolerances_are_the_documented_ones() {
    assert_eq!(ENERGY_TOLERANCE, 0.05);
    assert_eq!(PEAK_TOLERANCE_DEG, 5.0);
    assert_eq!(RESIDUAL_KIND_TOLERANCE, 0.2);
}

#[test]
fn an_energy_ratio_outside_one_over_one_plus_t_to_one_plus_t_warns() {
    assert!(warnings(&adequate()).is_empty());
    let t = ENERGY_TOLERANCE;
    for (ratio, warns) in [
        (1.0, false),
        (1.0 + t - 1e-3, false),
        (1.0 + t + 1e-3, true),
        (1.0 / (1.0 + t) + 1e-3, false),
        (1.0 / (1.0 + t) - 1e-3, true),
        // Not symmetric about 1: 0.95 is below 1/1.05 = 0.952.
        (0.95, true),
        (0.3, true),
    ] {
        let a = Adequacy {
            rho_data: Some(0.8 * ratio),
            rho_model: 0.8,
            ..adequate()
        };
        assert!((a.energy_ratio().unwrap() - ratio).abs() < 1e-12);
        let w = warnings(&a);
        if warns {
            assert_eq!(
                w,
                vec![FitWarning::EnergyMismatch {
                    data: 0.8 * ratio,
                    model: 0.8,
                    unit: None,
                }],
                "ratio {ratio}"
            );
        } else {
            assert!(w.is_empty(), "ratio {ratio}: {w:?}");
        }
    }
}

#[test]
fn without_reflection_the_energy_is_the_transmissions() {
    // No front data (or a model without reflection): τ decides.
    for (rho_data, rho_model) in [(None, 0.4), (Some(0.4), 0.0)] {
        let a = Adequacy {
            rho_data,
            rho_model,
            tau_data: Some(0.3),
            tau_model: 0.2,
            ..adequate()
        };
        assert!((a.energy_ratio().unwrap() - 1.5).abs() < 1e-12);
        assert_eq!(
            warnings(&a),
            vec![FitWarning::EnergyMismatch {
                data: 0.3,
                model: 0.2,
                unit: None,
            }]
        );
    }
    // Neither: no ratio, no warning.
    let a = Adequacy {
        rho_data: None,
        tau_data: None,
        ..adequate()
    };
    assert_eq!(a.energy_ratio(), None);
    assert!(warnings(&a).is_empty());
}

#[test]
fn peak_offsets_and_residual_kind_changes_warn_beyond_their_tolerances() {
    for (offset, warns) in [(None, false), (Some(4.99), false), (Some(5.01), true)] {
        let a = Adequacy {
            peak_offset_deg: offset,
            ..adequate()
        };
        let want = if warns {
            vec![FitWarning::PeakOffset {
                degrees: offset.unwrap(),
            }]
        } else {
            Vec::new()
        };
        assert_eq!(warnings(&a), want, "{offset:?}");
    }
    for (change, warns) in [(0.19, false), (0.21, true)] {
        let a = Adequacy {
            residual_check: Some(check(change)),
            ..adequate()
        };
        let want = if warns {
            vec![FitWarning::ResidualKindSensitive {
                check: check(change),
            }]
        } else {
            Vec::new()
        };
        assert_eq!(warnings(&a), want, "{change}");
    }
    // All three at once, in that order.
    let a = Adequacy {
        rho_data: Some(1.0),
        rho_model: 0.5,
        peak_offset_deg: Some(10.0),
        residual_check: Some(check(0.5)),
        ..adequate()
    };
    let w = warnings(&a);
    assert_eq!(w.len(), 3);
    assert!(matches!(w[0], FitWarning::EnergyMismatch { .. }));
    assert!(matches!(w[1], FitWarning::PeakOffset { .. }));
    assert!(matches!(w[2], FitWarning::ResidualKindSensitive { .. }));
}

#[test]
fn the_comparison_picks_the_parameter_that_moved_most_on_an_absolute_floor() {
    let kind = MaterialKind::Plastic;
    let main = report(kind, 30.0, &[0.5, 0.5, 0.5, 0.001, 0.10], 1.0);
    // red: 0.02/0.52 = 0.038; spec: 0.002 on the 0.02 floor = 0.1 (not
    // 0.002/0.003 = 0.67); rough: 0.03/0.13 = 0.23.
    let other = report(kind, 30.0, &[0.52, 0.5, 0.5, 0.003, 0.13], 1.0);
    let c = compare(&main, &other, ResidualKind::Log).unwrap();
    assert_eq!(c.param, "rough");
    assert_eq!(c.values, [0.10, 0.13]);
    assert_eq!(c.residual, ResidualKind::Log);
    assert!((c.relative_change - 0.03 / 0.13).abs() < 1e-12);
    let a = Adequacy {
        residual_check: Some(c),
        ..adequate()
    };
    assert_eq!(warnings(&a).len(), 1);

    // rough 0.10 → 0.12 is 0.167: the spec's 0.1 is smaller; no warning.
    let other = report(kind, 30.0, &[0.5, 0.5, 0.5, 0.003, 0.12], 1.0);
    let c = compare(&main, &other, ResidualKind::Log).unwrap();
    assert_eq!(c.param, "rough");
    assert!((c.relative_change - 0.02 / 0.12).abs() < 1e-12);
    assert!(c.relative_change < RESIDUAL_KIND_TOLERANCE);

    // Fixed parameters and the free scale are not compared.
    let mut main = report(kind, 30.0, &[1.0, 1.0, 1.0, 0.2, 0.10], 5.0);
    let mut other = report(kind, 30.0, &[1.0, 1.0, 1.0, 0.2, 0.11], 50.0);
    for r in [&mut main, &mut other] {
        for p in &mut r.params[..3] {
            p.fixed = true;
        }
        let mut scale = r.params[0].clone();
        scale.name = "scale".into();
        scale.value = r.scale;
        scale.fixed = false;
        r.params.push(scale);
        r.params[0].value = r.scale; // a fixed value that differs
    }
    let c = compare(&main, &other, ResidualKind::Absolute).unwrap();
    assert_eq!(c.param, "rough");
    assert!((c.relative_change - 0.01 / 0.11).abs() < 1e-12);
}

#[test]
fn the_second_fit_uses_log_residuals_for_absolute_and_absolute_otherwise() {
    assert_eq!(other_residual(ResidualKind::Absolute), ResidualKind::Log);
    assert_eq!(
        other_residual(ResidualKind::Relative),
        ResidualKind::Absolute
    );
    assert_eq!(other_residual(ResidualKind::Log), ResidualKind::Absolute);
}

// ------------------------------------------------------- on prepared data

/// One-channel BSDF data of the `args` plastic at θ_in (φ_in = 0) but
/// lit from (θ_in, `light_phi`), times `factor`, on rings θ = 1°, 3°, …,
/// 89° every `phi_step` degrees, through `gates` with computed (ring)
/// solid angles.
fn prepared(
    args: &[f64],
    theta_in: f64,
    light_phi: f64,
    factor: f64,
    phi_step: f64,
    gates: Vec<Gate>,
) -> PreparedMeasurement {
    let m = super::material(MaterialKind::Plastic, args);
    let bsdf = Bsdf::new(&m, &EvalOptions::default());
    let light = direction(theta_in, light_phi);
    let thetas: Vec<f64> = (0..45).map(|k| 1.0 + 2.0 * k as f64).collect();
    let per_ring = (360.0 / phi_step).round() as usize;
    let samples = ring_directions(&thetas, per_ring)
        .into_iter()
        .map(|(t, p)| Sample::luminance(t, p, factor * bsdf.eval(light, direction(t, p))[0]))
        .collect();
    let recipe = Recipe {
        scale: ScaleRule::FromFiles,
        colour: ColourConversion::XyzToRadianceRgb,
        selections: gates,
        weights: WeightRule::SolidAngle,
        patch_average: None,
        azimuth: crate::AzimuthRule::file_frame(),
    };
    recipe
        .prepare(
            measurement(theta_in, Quantity::Bsdf, Channels::Y, samples),
            "synthetic",
        )
        .unwrap()
}

fn adequacy(p: &PreparedMeasurement, args: &[f64], scale: f64) -> Adequacy {
    let config = FitConfig::new(MaterialKind::Plastic);
    let r = report(
        MaterialKind::Plastic,
        p.measurement.incidence.theta_deg,
        args,
        scale,
    );
    diagnose(p, &p.incidence_data(), &r, &config).expect("diagnostics")
}

#[test]
fn data_equal_to_the_model_carry_the_models_energy() {
    let args = [0.4, 0.4, 0.4, 0.05, 0.1];
    let p = prepared(
        &args,
        30.0,
        0.0,
        1.0,
        10.0,
        vec![Gate::ThetaCap { max_deg: 60.0 }],
    );
    let a = adequacy(&p, &args, 1.0);
    let rho = a.rho_data.unwrap();
    assert!((rho - a.rho_model).abs() < 1e-9 * a.rho_model, "{a:?}");
    assert_eq!(a.tau_data, None);
    assert!((a.energy_ratio().unwrap() - 1.0).abs() < 1e-9);
    // The plastic's ρ_dh is about its diffuse part plus its specularity.
    assert!(a.rho_model > 0.35 && a.rho_model < 0.46, "{a:?}");
    assert!(warnings(&a).is_empty(), "{:?}", warnings(&a));
}

#[test]
fn a_lambertian_measured_twenty_percent_high_over_theta_60_gives_the_expected_ratio() {
    // f = ρ/π with ρ = 0.6 (spec 0), data 1.2 f over θ_out ≤ 60°, the rest
    // from the model: ρ_data = ρ + 0.2 ∫_{θ≤60°} (ρ/π) cos θ dΩ
    // = ρ (1 + 0.2 sin² 60°) = 0.6 × 1.15.
    let args = [0.6, 0.6, 0.6, 0.0, 0.1];
    let p = prepared(
        &args,
        30.0,
        0.0,
        1.2,
        10.0,
        vec![Gate::ThetaCap { max_deg: 60.0 }],
    );
    let a = adequacy(&p, &args, 1.0);
    assert!((a.rho_model - 0.6).abs() < 1e-6, "{a:?}");
    let ratio = a.energy_ratio().unwrap();
    assert!((ratio - 1.15).abs() < 2e-3, "ratio {ratio}");
    assert_eq!(
        warnings(&a),
        vec![FitWarning::EnergyMismatch {
            data: a.rho_data.unwrap(),
            model: a.rho_model,
            unit: None,
        }]
    );
    // Raw data of a free scale s: the measured part is divided by s, so
    // the same data in 7× the unit with scale 7 give the same ratio, and
    // data that are exactly s × the model give 1.
    let scaled = prepared(
        &args,
        30.0,
        0.0,
        7.0 * 1.2,
        10.0,
        vec![Gate::ThetaCap { max_deg: 60.0 }],
    );
    let b = adequacy(&scaled, &args, 7.0);
    assert!((b.energy_ratio().unwrap() - ratio).abs() < 1e-9);
    let exact = prepared(
        &args,
        30.0,
        0.0,
        7.0,
        10.0,
        vec![Gate::ThetaCap { max_deg: 60.0 }],
    );
    let c = adequacy(&exact, &args, 7.0);
    assert!((c.energy_ratio().unwrap() - 1.0).abs() < 1e-9);
}

/// The angle between a direction at polar angle `theta` (degrees) and
/// the same direction turned by `turn` degrees about the normal.
fn turned_angle(theta: f64, turn: f64) -> f64 {
    2.0 * (theta.to_radians().sin() * (0.5 * turn.to_radians()).sin())
        .asin()
        .to_degrees()
}

#[test]
fn a_lobe_turned_about_the_normal_is_offset_by_the_turns_chord_angle() {
    // The data's lobe is the model's turned by Δφ about the normal (the
    // light at φ = Δφ instead of 0; the ring grid, every 1°, maps onto
    // itself). Then the data's peak is the model's turned by Δφ, and the
    // angle between them is 2 asin(sin θ_p sin(Δφ/2)), θ_p the peak's
    // polar angle: near the mirror direction's 40° for a narrow lobe
    // (within 3°).
    let args = [0.3, 0.3, 0.3, 0.1, 0.05];
    let at = |turn: f64| {
        let p = prepared(&args, 40.0, turn, 1.0, 1.0, Vec::new());
        adequacy(&p, &args, 1.0)
    };
    let same = at(0.0);
    assert!(same.peak_offset_deg.unwrap() < 1e-5, "{same:?}");

    let far = at(20.0);
    let offset = far.peak_offset_deg.unwrap();
    let (lo, hi) = (turned_angle(37.0, 20.0), turned_angle(43.0, 20.0));
    assert!((lo..=hi).contains(&offset), "{offset} not in [{lo}, {hi}]");
    assert!(offset > PEAK_TOLERANCE_DEG);
    assert!(warnings(&far).contains(&FitWarning::PeakOffset { degrees: offset }));

    let near = at(4.0);
    let offset = near.peak_offset_deg.unwrap();
    let (lo, hi) = (turned_angle(37.0, 4.0), turned_angle(43.0, 4.0));
    assert!((lo..=hi).contains(&offset), "{offset} not in [{lo}, {hi}]");
    assert!(
        !warnings(&near)
            .iter()
            .any(|w| matches!(w, FitWarning::PeakOffset { .. }))
    );
}

#[test]
fn data_without_a_distinct_peak_have_no_peak_offset() {
    // A Lambertian: the brightest samples are not twice the median.
    let args = [0.6, 0.6, 0.6, 0.0, 0.1];
    let p = prepared(&args, 30.0, 0.0, 1.0, 10.0, Vec::new());
    assert_eq!(adequacy(&p, &args, 1.0).peak_offset_deg, None);
}
