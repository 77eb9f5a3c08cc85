//! Conversions between BSDF, DSF and raw signal.

use approx::assert_relative_eq;
use brtf_gonio::{
    Channels, ConvertError, Incidence, Measurement, Quantity, Sample, SourceFormat, read_path,
};

use crate::common::{MPC_FIXTURE, fixture_path};

fn bsdf(samples: Vec<Sample>) -> Measurement {
    Measurement::new(
        SourceFormat::Mountain,
        Incidence::new(30.0, 0.0),
        Quantity::Bsdf,
        Channels::Xyz,
        samples,
    )
}

#[test]
fn bsdf_to_dsf_and_back() {
    let m = bsdf(vec![
        Sample::new(0.0, 0.0, [1.0, 2.0, 3.0]),
        Sample::new(60.0, 10.0, [1.0, 2.0, 3.0]),
        Sample::new(120.0, 10.0, [0.5, f64::NAN, -1.0]),
    ]);
    let dsf = m.to_dsf().unwrap();
    assert_eq!(dsf.measurement.quantity, Quantity::Dsf);
    assert_eq!(dsf.made_unavailable, 0);
    assert_relative_eq!(dsf.measurement.samples[1].values[2], 1.5, epsilon = 1e-12);
    assert_relative_eq!(dsf.measurement.samples[2].values[0], 0.25, epsilon = 1e-12);
    assert!(dsf.measurement.samples[2].values[1].is_nan());
    let back = dsf.measurement.to_bsdf().unwrap().measurement;
    for (a, b) in back.samples.iter().zip(&m.samples) {
        for k in 0..3 {
            if b.values[k].is_nan() {
                assert!(a.values[k].is_nan());
            } else {
                assert_relative_eq!(a.values[k], b.values[k], max_relative = 1e-12);
            }
        }
    }
    // Converting to what it already is changes nothing.
    let same = m.to_bsdf().unwrap().measurement;
    crate::common::assert_samples_identical(&same.samples, &m.samples);
    assert_eq!(same.quantity, m.quantity);
}

#[test]
fn division_at_grazing_becomes_unavailable() {
    let mut m = bsdf(vec![Sample::new(90.0, 0.0, [1.0, 1.0, 1.0])]);
    m.quantity = Quantity::Dsf;
    let c = m.to_bsdf().unwrap();
    assert_eq!(c.made_unavailable, 1);
    assert!(c.measurement.samples[0].values.iter().all(|v| v.is_nan()));
    assert_eq!(c.measurement.count_unavailable(), 1);
}

#[test]
fn raw_needs_a_beam_integral() {
    let mut m = bsdf(vec![Sample::new(60.0, 0.0, [0.2, 0.4, 0.6])]);
    m.quantity = Quantity::Raw {
        unit: "uA".into(),
        beam_integral: None,
    };
    assert_eq!(
        m.to_bsdf().unwrap_err(),
        ConvertError::MissingBeamIntegral { unit: "uA".into() }
    );
    assert!(matches!(
        m.raw_to_bsdf(0.0),
        Err(ConvertError::InvalidBeamIntegral(_))
    ));
    assert!(matches!(
        m.raw_to_bsdf(f64::NAN),
        Err(ConvertError::InvalidBeamIntegral(_))
    ));
    // raw / beam / |cos|: 0.4 / 0.1 / 0.5 = 8.
    let b = m.raw_to_bsdf(0.1).unwrap().measurement;
    assert_eq!(b.quantity, Quantity::Bsdf);
    assert_relative_eq!(b.samples[0].values[1], 8.0, max_relative = 1e-12);
    let d = m.raw_to_dsf(0.1).unwrap().measurement;
    assert_relative_eq!(d.samples[0].values[1], 4.0, max_relative = 1e-12);
    // With the beam integral stored in the quantity, to_bsdf uses it.
    m.quantity = Quantity::Raw {
        unit: "uA".into(),
        beam_integral: Some(0.1),
    };
    assert_eq!(m.to_bsdf().unwrap().measurement.samples, b.samples);
    // Only raw data is divided by a beam integral.
    assert!(matches!(
        bsdf(vec![]).raw_to_bsdf(1.0),
        Err(ConvertError::WrongQuantity { .. })
    ));
}

/// The `.mpc` columns obey the documented raw rule: column 6 is column 5
/// divided by |cos θ|, and the BRTF is column 6 divided by the beam integral.
#[test]
fn mpc_columns_follow_the_raw_rule() {
    let m = read_path(&fixture_path(MPC_FIXTURE)).unwrap();
    let beam = m.beam.as_ref().unwrap().integral;
    for (s, c) in m.samples.iter().zip(&m.mpc_columns) {
        assert_relative_eq!(c.cosine_corrected / beam, s.values[0], max_relative = 1e-4);
        let cos = s.abs_cos_theta();
        assert_relative_eq!(
            c.minus_background_per_beam_reference / cos,
            c.cosine_corrected,
            max_relative = 2e-3
        );
    }
}
