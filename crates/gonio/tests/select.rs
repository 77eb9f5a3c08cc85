//! Selections: hemisphere, θ cap, incident-beam cone, value floors.

use brtf_gonio::{
    Channels, DEFAULT_THETA_CAP_DEG, Hemisphere, Incidence, Measurement, Quantity, Sample,
    SourceFormat, read_path,
};

use crate::common::{MPC_FIXTURE, angle_between_deg, fixture_path, golden, grid};

fn two_sided() -> Measurement {
    Measurement::new(
        SourceFormat::Mountain,
        Incidence::new(30.0, 0.0),
        Quantity::Bsdf,
        Channels::Y,
        grid(5.0, 15.0, true, 1.0),
    )
}

#[test]
fn hemispheres_split_the_samples() {
    let m = two_sided();
    let front = m.select_hemisphere(Hemisphere::Front);
    let back = m.select_hemisphere(Hemisphere::Back);
    assert_eq!(front.measurement.len() + back.measurement.len(), m.len());
    assert_eq!(front.removed, back.measurement.len());
    assert!(
        front
            .measurement
            .samples
            .iter()
            .all(|s| s.theta_deg <= 90.0)
    );
    assert!(back.measurement.samples.iter().all(|s| s.theta_deg > 90.0));
    assert_eq!(front.kept.len(), front.measurement.len());
}

#[test]
fn theta_cap_applies_to_both_hemispheres() {
    let m = two_sided();
    let capped = m.cap_theta(DEFAULT_THETA_CAP_DEG);
    assert!(capped.removed > 0);
    assert!(
        capped
            .measurement
            .samples
            .iter()
            .all(|s| s.theta_deg <= 85.0 || s.theta_deg >= 95.0)
    );
    assert_eq!(capped.measurement.len() + capped.removed, m.len());
}

#[test]
fn incident_cone_removes_only_directions_near_the_beam() {
    let m = golden();
    let masked = m.mask_incident_cone(5.0);
    assert!(
        masked.removed > 0
            || m.samples
                .iter()
                .all(|s| { angle_between_deg((s.theta_deg, s.phi_deg), (26.8421, 0.0)) >= 5.0 })
    );
    for s in &masked.measurement.samples {
        assert!(angle_between_deg((s.theta_deg, s.phi_deg), (26.8421, 0.0)) >= 5.0 - 1e-9);
    }
    let near = m
        .samples
        .iter()
        .filter(|s| angle_between_deg((s.theta_deg, s.phi_deg), (26.8421, 0.0)) < 5.0 - 1e-6)
        .count();
    assert_eq!(masked.removed, near);
    // The specular peak survives.
    assert_eq!(masked.measurement.front_peak(), m.front_peak());
}

#[test]
fn value_floors() {
    let mut m = golden().clone();
    assert!(m.samples[0].values[0] > 0.0);
    m.samples[0].values[0] = f64::NAN;
    let floor = m.drop_below(0.0);
    assert_eq!(
        floor.removed,
        368 + 1,
        "negatives and the unavailable sample"
    );
    let unavailable = m.drop_unavailable();
    assert_eq!(unavailable.removed, 1);
    assert_eq!(unavailable.kept[0], 1);
}

#[test]
fn mpc_columns_follow_their_samples() {
    let m = read_path(&fixture_path(MPC_FIXTURE)).unwrap();
    let sel = m.drop_below(0.0);
    assert_eq!(sel.removed, 5);
    assert_eq!(sel.kept, vec![5]);
    assert_eq!(sel.measurement.mpc_columns.len(), 1);
    assert_eq!(sel.measurement.mpc_columns[0].raw_signal, 0.000205099);
    assert!(sel.measurement.mpc_columns_consistent());
}

#[test]
fn generic_select() {
    let m = Measurement::new(
        SourceFormat::Mountain,
        Incidence::new(0.0, 0.0),
        Quantity::Dsf,
        Channels::Y,
        (0..10)
            .map(|i| Sample::luminance(i as f64, 0.0, i as f64))
            .collect(),
    );
    let sel = m.select(|s| s.values[0] % 2.0 == 0.0);
    assert_eq!(sel.kept, vec![0, 2, 4, 6, 8]);
    assert_eq!(sel.removed, 5);
}
