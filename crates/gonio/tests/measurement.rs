//! The data model: directions, constructors, serde.

use brtf_gonio::{
    Channels, Hemisphere, Incidence, Measurement, Quantity, Sample, SourceFormat,
    direction_from_degrees, read_path,
};

use crate::common::{MPC_FIXTURE, fixture_path};

#[test]
fn directions_use_z_as_the_front_normal() {
    let s = Sample::luminance(90.0, 0.0, 1.0);
    assert!((s.direction() - glam::DVec3::X).length() < 1e-12);
    let up = Sample::luminance(0.0, 123.0, 1.0);
    assert!((up.direction() - glam::DVec3::Z).length() < 1e-12);
    let down = Sample::luminance(180.0, 0.0, 1.0);
    assert!((down.direction() + glam::DVec3::Z).length() < 1e-12);
    assert_eq!(down.hemisphere(), Hemisphere::Back);
    assert_eq!(s.hemisphere(), Hemisphere::Front);
    let m = Measurement::new(
        SourceFormat::Mountain,
        Incidence::new(30.0, 90.0),
        Quantity::Bsdf,
        Channels::Y,
        vec![],
    );
    let d = m.incident_direction();
    assert!((d - direction_from_degrees(30.0, 90.0)).length() < 1e-15);
    assert!(d.y > 0.0 && d.z > 0.0);
    assert!((d.length() - 1.0).abs() < 1e-15);
}

#[test]
fn serde_round_trip_keeps_unavailable_values() {
    let m = read_path(&fixture_path(MPC_FIXTURE)).unwrap();
    let json = serde_json::to_string(&m).unwrap();
    assert!(json.contains("\"beam_reference\":null"));
    let back: Measurement = serde_json::from_str(&json).unwrap();
    assert!(back.mpc_columns[0].beam_reference.is_nan());
    assert_eq!(back.samples, m.samples);
    assert_eq!(back.header, m.header);
    let mut s = Sample::new(1.0, 2.0, [f64::NAN, 1.0, 0.0]);
    s.solid_angle_sr = Some(0.5);
    let j = serde_json::to_string(&s).unwrap();
    let t: Sample = serde_json::from_str(&j).unwrap();
    assert!(t.values[0].is_nan());
    assert_eq!(t.values[1..], s.values[1..]);
    assert_eq!(t.solid_angle_sr, Some(0.5));
}

#[test]
fn quantity_names_and_units() {
    let raw = Quantity::Raw {
        unit: "uA".into(),
        beam_integral: None,
    };
    assert_eq!(raw.unit(), "uA");
    assert_eq!(raw.name(), "raw");
    assert!(raw.includes_cosine() && Quantity::Dsf.includes_cosine());
    assert!(!Quantity::Bsdf.includes_cosine());
    assert_eq!(Quantity::Bsdf.unit(), "1/sr");
    assert_eq!(Channels::Xyz.luminance_slot(), 1);
    assert_eq!(Channels::Y.count(), 1);
}
