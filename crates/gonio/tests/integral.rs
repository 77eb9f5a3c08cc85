//! Data-side hemispherical integrals.

use approx::assert_relative_eq;
use brtf_gonio::{
    Channels, Hemisphere, Incidence, Measurement, Quantity, SourceFormat, compute_solid_angles,
    hemispherical_integral, solid_angles,
};

use crate::common::{golden, grid, layer};

fn lambertian(quantity: Quantity, rho: f64, tau: f64) -> Measurement {
    let mut samples = grid(2.0, 4.0, true, 0.0);
    for s in &mut samples {
        let bsdf = if s.theta_deg <= 90.0 { rho } else { tau } / std::f64::consts::PI;
        s.values[0] = match quantity {
            Quantity::Bsdf => bsdf,
            _ => bsdf * s.abs_cos_theta() * 0.2, // raw with beam integral 0.2, or DSF × 0.2
        };
    }
    Measurement::new(
        SourceFormat::Mountain,
        Incidence::new(20.0, 0.0),
        quantity,
        Channels::Y,
        samples,
    )
}

#[test]
fn lambertian_bsdf_integrates_to_its_albedo() {
    let m = lambertian(Quantity::Bsdf, 0.7, 0.2);
    let w = compute_solid_angles(&m.samples);
    let rho = hemispherical_integral(&m, &w, Hemisphere::Front).unwrap();
    let tau = hemispherical_integral(&m, &w, Hemisphere::Back).unwrap();
    assert_relative_eq!(rho.value, 0.7, max_relative = 0.01);
    assert_relative_eq!(tau.value, 0.2, max_relative = 0.01);
    assert_eq!(rho.unit, "1");
    assert_relative_eq!(
        rho.solid_angle_sr,
        std::f64::consts::TAU,
        max_relative = 1e-9
    );
}

#[test]
fn raw_integral_uses_the_beam_integral_when_known() {
    let m = lambertian(
        Quantity::Raw {
            unit: "uA".into(),
            beam_integral: Some(0.2),
        },
        0.5,
        0.0,
    );
    let w = compute_solid_angles(&m.samples);
    let rho = hemispherical_integral(&m, &w, Hemisphere::Front).unwrap();
    assert_relative_eq!(rho.value, 0.5, max_relative = 0.01);
    assert_eq!(rho.unit, "1");
    let mut unknown = m.clone();
    unknown.quantity = Quantity::Raw {
        unit: "uA".into(),
        beam_integral: None,
    };
    let raw = hemispherical_integral(&unknown, &w, Hemisphere::Front).unwrap();
    assert_relative_eq!(raw.value, 0.1, max_relative = 0.01);
    assert_eq!(raw.unit, "uA·sr");
}

#[test]
fn unavailable_values_are_skipped_and_counted() {
    let mut m = lambertian(Quantity::Bsdf, 0.5, 0.5);
    m.samples[3].values[0] = f64::NAN;
    let w = compute_solid_angles(&m.samples);
    let rho = hemispherical_integral(&m, &w, Hemisphere::Front).unwrap();
    assert_eq!(rho.samples_skipped, 1);
    assert!(rho.value.is_finite());
    let front_only = m.select_hemisphere(Hemisphere::Front).measurement;
    let w = compute_solid_angles(&front_only.samples);
    assert!(hemispherical_integral(&front_only, &w, Hemisphere::Back).is_none());
}

/// The pgII header's `#front_integral` is the instrument's own integral of
/// the raw signal; the computed equal-area cells reproduce it.
#[test]
fn real_scans_match_the_instruments_front_integral() {
    for (m, front_integral) in [(golden(), 0.0263), (layer(), 0.221)] {
        let w = solid_angles(m);
        let raw = hemispherical_integral(m, &w.per_sample_sr, Hemisphere::Front).unwrap();
        assert_eq!(raw.unit, "uA·sr");
        assert_relative_eq!(raw.value, front_integral, max_relative = 0.01);
    }
}
