//! Summaries: the real scans, the `.mpc` excerpt, JSON and text forms.

use approx::assert_relative_eq;
use brtf_gonio::{SolidAngleSource, Summary, read_path};

use crate::common::{MPC_FIXTURE, angle_between_deg, fixture_path, golden};

#[test]
fn golden_paper_summary() {
    let s = golden().summary();
    assert_eq!(s.samples, 127_039);
    let front = s.front.as_ref().unwrap();
    assert_eq!(front.count, 127_039);
    assert!(s.back.is_none());
    assert_eq!(s.negatives, 368);
    assert_eq!(front.negatives, 368);
    assert_eq!(s.unavailable, 0);
    assert_eq!(s.quantity, "raw");
    assert_eq!(s.unit, "uA");
    assert_eq!(s.integral_unit, "uA·sr");
    assert!(s.integral_note.contains("beam integral"));
    assert_eq!(s.solid_angle_source, SolidAngleSource::Computed);
    assert_relative_eq!(s.rho_dh.unwrap(), 0.0263, max_relative = 0.01);
    assert!(s.tau_dh.is_none());
    assert!(front.theta_range_deg[0] < 1.0 && front.theta_range_deg[1] > 89.99);
    assert!(front.phi_range_deg[0] < 0.1 && front.phi_range_deg[1] > 359.9);
    assert_relative_eq!(
        front.solid_angle_sr,
        std::f64::consts::TAU,
        max_relative = 1e-9
    );
    let peak = s.peak.unwrap();
    assert!(angle_between_deg((peak.theta_deg, peak.phi_deg), (26.99, 175.8)) < 0.5);

    let json = serde_json::to_string(&s).unwrap();
    let back: Summary = serde_json::from_str(&json).unwrap();
    // serde_json's default float parser may differ in the last bit.
    assert_relative_eq!(
        back.rho_dh.unwrap(),
        s.rho_dh.unwrap(),
        max_relative = 1e-15
    );
    assert_eq!(back.peak, s.peak);
    assert_eq!(back.front.as_ref().unwrap().count, front.count);
    assert_eq!(back.incidence, s.incidence);

    let text = s.to_string();
    for needle in [
        "theta_in = 26.8421 deg, phi_in = 0 deg (from the header)",
        "raw detector signal [uA]",
        "127039 (front 127039, back 0); 368 negative, 0 not available",
        "rho_dh",
        "front peak",
    ] {
        assert!(text.contains(needle), "missing `{needle}` in\n{text}");
    }
}

#[test]
fn mpc_summary_uses_file_weights_and_reports_the_back() {
    let m = read_path(&fixture_path(MPC_FIXTURE)).unwrap();
    let s = m.summary();
    assert_eq!(s.solid_angle_source, SolidAngleSource::File);
    assert!(s.front.is_none() && s.peak.is_none());
    let back = s.back.as_ref().unwrap();
    assert_eq!(back.count, 6);
    assert_eq!(back.negatives, 5);
    assert_eq!(s.integral_unit, "1");
    let expected: f64 = m
        .samples
        .iter()
        .map(|x| x.values[0] * x.abs_cos_theta() * x.solid_angle_sr.unwrap())
        .sum();
    assert_relative_eq!(s.tau_dh.unwrap(), expected, max_relative = 1e-12);
    assert!(s.rho_dh.is_none());
    assert_eq!(s.beam.as_ref().unwrap().integral, 0.063626);
    assert!(
        s.to_string()
            .contains("beam file     pab-aluA-st1:beam.mpc.refint")
    );
}

#[test]
fn xyz_summary_counts_any_unavailable_channel_and_integrates_y() {
    use brtf_gonio::{Channels, Incidence, Measurement, Quantity, Sample, SourceFormat};
    let mut samples = crate::common::grid(5.0, 10.0, false, 0.0);
    for s in &mut samples {
        s.values = [0.1, 1.0 / std::f64::consts::PI, 0.3];
    }
    samples[10].values[0] = f64::NAN; // X missing, Y fine
    samples.push(Sample::new(120.0, 0.0, [0.0, -0.5, 0.0]));
    let m = Measurement::new(
        SourceFormat::Mountain,
        Incidence::new(10.0, 0.0),
        Quantity::Bsdf,
        Channels::Xyz,
        samples,
    );
    let s = m.summary();
    assert_eq!(s.unavailable, 1);
    assert_eq!(s.front.as_ref().unwrap().unavailable, 1);
    assert_eq!(s.back.as_ref().unwrap().negatives, 1);
    assert_relative_eq!(s.rho_dh.unwrap(), 1.0, max_relative = 0.01);
    assert!(
        s.tau_dh.unwrap() < 0.0,
        "noise integrates to a negative tau"
    );
    assert_eq!(s.peak.unwrap().value, 1.0 / std::f64::consts::PI);
}
