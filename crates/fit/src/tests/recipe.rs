//! `Recipe::prepare` on small hand-built measurements: the conversion to
//! the fitted quantity, the colour conversion, each selection gate (what
//! it removes and how many), and the weights.

use super::{angle_between_deg, measurement, ring_directions};
use crate::data::Weighting;
use crate::recipe::{
    BeamOrigin, ColourConversion, Conversion, DataUnit, PreparedMeasurement, RawScale, Recipe,
    RecipeError, ScaleRule, SelectionOptions, WeightRule,
};
use brtf_gonio::{
    Channels, ConvertError, Gate, Hemisphere, Measurement, PGII_HOLDER_BAND, Quantity, Sample,
};
use std::f64::consts::PI;

/// A recipe with these selections: scale from the files, XYZ → RGB,
/// uniform weights (unless changed by the test).
fn recipe(selections: Vec<Gate>) -> Recipe {
    Recipe {
        scale: ScaleRule::FromFiles,
        colour: ColourConversion::XyzToRadianceRgb,
        selections,
        weights: WeightRule::Uniform,
        patch_average: None,
        azimuth: crate::AzimuthRule::file_frame(),
    }
}

fn prepare(recipe: &Recipe, m: Measurement) -> PreparedMeasurement {
    recipe.prepare(m, "test.txt").expect("prepared")
}

/// A smooth, positive, direction-dependent test function (1/sr).
fn f(theta: f64, phi: f64) -> f64 {
    0.2 + 0.1 * theta.to_radians().cos() + 0.05 * phi.to_radians().sin()
}

/// One-channel samples at `directions`, valued `value(θ, φ)`.
fn samples(directions: &[(f64, f64)], value: impl Fn(f64, f64) -> f64) -> Vec<Sample> {
    directions
        .iter()
        .map(|&(t, p)| Sample::luminance(t, p, value(t, p)))
        .collect()
}

/// Front rings θ = 5, 15, …, 85 with 12 azimuths each.
fn front_rings() -> Vec<(f64, f64)> {
    let thetas: Vec<f64> = (0..9).map(|k| 5.0 + 10.0 * k as f64).collect();
    ring_directions(&thetas, 12)
}

fn raw(beam_integral: Option<f64>) -> Quantity {
    Quantity::Raw {
        unit: "uA".into(),
        beam_integral,
    }
}

fn cos_deg(theta: f64) -> f64 {
    theta.to_radians().cos().abs()
}

fn assert_close(got: f64, want: f64, rel: f64, what: &str) {
    assert!(
        (got - want).abs() <= rel * want.abs().max(1e-300),
        "{what}: {got} vs {want}"
    );
}

// ---------------------------------------------------------------- conversions

#[test]
fn a_bsdf_file_is_fitted_as_it_is() {
    let dirs = front_rings();
    let m = measurement(30.0, Quantity::Bsdf, Channels::Y, samples(&dirs, f));
    let p = prepare(&recipe(Vec::new()), m);
    assert_eq!(p.conversion, Conversion::Bsdf);
    assert_eq!(p.conversion.unit(), DataUnit::Bsdf);
    assert!(!p.conversion.is_free_scale());
    assert_eq!(p.measurement.samples.len(), dirs.len());
    for (s, &(t, ph)) in p.measurement.samples.iter().zip(&dirs) {
        assert_eq!(s.values[0], f(t, ph));
    }
}

#[test]
fn a_dsf_file_is_divided_by_the_cosine_of_theta_out() {
    let dirs = front_rings();
    let m = measurement(30.0, Quantity::Dsf, Channels::Y, samples(&dirs, f));
    let p = prepare(&recipe(Vec::new()), m);
    assert_eq!(p.conversion, Conversion::Dsf);
    assert_eq!(p.conversion.unit(), DataUnit::Bsdf);
    for (s, &(t, ph)) in p.measurement.samples.iter().zip(&dirs) {
        assert_close(
            s.values[0],
            f(t, ph) / cos_deg(t),
            1e-12,
            "BSDF = DSF / cos",
        );
    }
}

#[test]
fn a_dsf_sample_at_theta_90_becomes_unavailable_and_is_counted() {
    // DSF / |cos 90°| is undefined: the conversion makes it NaN, and the
    // Unavailable gate removes it (and only it).
    let dirs = vec![(30.0, 180.0), (90.0, 0.0), (60.0, 90.0)];
    let m = measurement(30.0, Quantity::Dsf, Channels::Y, samples(&dirs, f));
    let p = prepare(&recipe(vec![Gate::Unavailable]), m);
    assert!(p.measurement.samples[1].values[0].is_nan());
    assert_eq!(p.removed_by, vec![None, Some(0), None]);
    assert_eq!(p.gates[0].removed, 1);
    assert_eq!(p.fitted_count(), 2);
}

/// Raw signal of a BSDF `f`: beam · f · |cos θ_out|.
fn raw_samples(dirs: &[(f64, f64)], beam: f64) -> Vec<Sample> {
    samples(dirs, |t, ph| beam * f(t, ph) * cos_deg(t))
}

#[test]
fn raw_signal_with_the_files_beam_integral_becomes_the_absolute_bsdf() {
    let dirs = front_rings();
    let m = measurement(
        30.0,
        raw(Some(250.0)),
        Channels::Y,
        raw_samples(&dirs, 250.0),
    );
    let p = prepare(&recipe(Vec::new()), m);
    assert_eq!(
        p.conversion,
        Conversion::Raw {
            unit: "uA".into(),
            scale: RawScale::BeamIntegral {
                value: 250.0,
                origin: BeamOrigin::File,
            },
        }
    );
    assert!(!p.conversion.is_free_scale());
    assert_eq!(p.conversion.unit(), DataUnit::Bsdf);
    for (s, &(t, ph)) in p.measurement.samples.iter().zip(&dirs) {
        assert_close(s.values[0], f(t, ph), 1e-12, "raw / beam / cos");
    }
}

#[test]
fn a_beam_integral_option_overrides_the_files() {
    let dirs = front_rings();
    let m = measurement(
        30.0,
        raw(Some(250.0)),
        Channels::Y,
        raw_samples(&dirs, 250.0),
    );
    let mut r = recipe(Vec::new());
    r.scale = ScaleRule::BeamIntegral { value: 500.0 };
    let p = prepare(&r, m);
    assert!(matches!(
        p.conversion,
        Conversion::Raw {
            scale: RawScale::BeamIntegral {
                value: 500.0,
                origin: BeamOrigin::Option
            },
            ..
        }
    ));
    // Twice the file's beam integral: half the BSDF.
    for (s, &(t, ph)) in p.measurement.samples.iter().zip(&dirs) {
        assert_close(s.values[0], 0.5 * f(t, ph), 1e-12, "raw / 500 / cos");
    }
}

#[test]
fn raw_signal_without_a_beam_integral_keeps_a_free_scale() {
    let dirs = front_rings();
    let m = measurement(30.0, raw(None), Channels::Y, raw_samples(&dirs, 7.0));
    let p = prepare(&recipe(Vec::new()), m);
    assert_eq!(
        p.conversion,
        Conversion::Raw {
            unit: "uA".into(),
            scale: RawScale::Free,
        }
    );
    assert!(p.conversion.is_free_scale());
    assert_eq!(p.conversion.unit(), DataUnit::RawPerCos("uA".into()));
    // Only the cosine is divided out: the unknown factor 7 stays.
    for (s, &(t, ph)) in p.measurement.samples.iter().zip(&dirs) {
        assert_close(s.values[0], 7.0 * f(t, ph), 1e-12, "raw / cos");
    }
}

#[test]
fn a_known_reflectance_divides_by_k_and_rescaling_later_gives_the_same_numbers() {
    let dirs = front_rings();
    let m = measurement(30.0, raw(None), Channels::Y, raw_samples(&dirs, 40.0));
    let mut r = recipe(Vec::new());
    r.scale = ScaleRule::KnownReflectance {
        rho: 0.8,
        theta_in: 30.0,
        k: 40.0,
    };
    let known = prepare(&r, m.clone());
    assert_eq!(
        known.conversion,
        Conversion::Raw {
            unit: "uA".into(),
            scale: RawScale::KnownReflectance {
                k: 40.0,
                rho: 0.8,
                theta_in: 30.0,
            },
        }
    );
    assert!(!known.conversion.is_free_scale());
    for (s, &(t, ph)) in known.measurement.samples.iter().zip(&dirs) {
        assert_close(s.values[0], f(t, ph), 1e-12, "raw / cos / K");
    }
    // The free-scale preparation rescaled afterwards: the same operations,
    // so bit for bit the same values and the same conversion.
    let mut later = prepare(&recipe(Vec::new()), m);
    assert!(later.rescale_known_reflectance(40.0, 0.8, 30.0));
    assert_eq!(later.conversion, known.conversion);
    assert_eq!(later.measurement.samples, known.measurement.samples);
    // Only free-scale data can be rescaled (and only once).
    assert!(!later.rescale_known_reflectance(40.0, 0.8, 30.0));
}

#[test]
fn raw_scales_are_refused_for_files_that_are_not_raw_and_bad_beams_are_errors() {
    let dirs = front_rings();
    let bsdf = measurement(30.0, Quantity::Bsdf, Channels::Y, samples(&dirs, f));
    let mut r = recipe(Vec::new());
    r.scale = ScaleRule::BeamIntegral { value: 2.0 };
    match r.prepare(bsdf.clone(), "a.txt") {
        Err(RecipeError::ScaleNotRaw {
            origin,
            what,
            quantity,
        }) => {
            assert_eq!(origin, "a.txt");
            assert_eq!(what, "--beam-integral");
            assert_eq!(quantity, "BSDF");
        }
        other => panic!("expected ScaleNotRaw, got {other:?}"),
    }
    r.scale = ScaleRule::KnownReflectance {
        rho: 0.5,
        theta_in: 0.0,
        k: 1.0,
    };
    assert!(matches!(
        r.prepare(bsdf, "a.txt"),
        Err(RecipeError::ScaleNotRaw { what: "--rho", .. })
    ));
    for bad in [0.0, -3.0, f64::INFINITY] {
        r.scale = ScaleRule::BeamIntegral { value: bad };
        let m = measurement(30.0, raw(None), Channels::Y, raw_samples(&dirs, 1.0));
        match r.prepare(m, "b.txt") {
            Err(RecipeError::Convert {
                source: ConvertError::InvalidBeamIntegral(v),
                ..
            }) => assert!(v == bad || (v.is_infinite() && bad.is_infinite())),
            other => panic!("beam {bad}: expected InvalidBeamIntegral, got {other:?}"),
        }
    }
}

// ------------------------------------------------------------------- colour

/// CIE XYZ of luminance `y` at chromaticity (x, y).
fn xyz_at(chromaticity: [f64; 2], luminance: f64) -> [f64; 3] {
    let [x, y] = chromaticity;
    [x / y * luminance, luminance, (1.0 - x - y) / y * luminance]
}

#[test]
fn xyz_files_become_radiance_rgb() {
    // Radiance's primaries (color.h) and rtrace's luminance weights:
    // XYZ on a primary's chromaticity is pure that primary, with
    // luminance = weight × value; the equal-energy white is RGB ≈ (1,1,1)
    // (Radiance's white is 0.3333, 0.3333).
    let primaries = [[0.640, 0.330], [0.290, 0.600], [0.150, 0.060]];
    let weights = [0.265_074_126, 0.670_114_631, 0.064_811_243];
    let dirs = [(10.0, 0.0), (20.0, 0.0), (30.0, 0.0), (40.0, 0.0)];
    let mut values: Vec<[f64; 3]> = primaries.iter().map(|c| xyz_at(*c, 0.3)).collect();
    values.push([0.7, 0.7, 0.7]);
    let samples: Vec<Sample> = dirs
        .iter()
        .zip(&values)
        .map(|(&(t, p), &v)| Sample::new(t, p, v))
        .collect();
    let m = measurement(30.0, Quantity::Bsdf, Channels::Xyz, samples);
    let rgb = prepare(&recipe(Vec::new()), m.clone());
    assert_eq!(rgb.channels(), 3);
    for (c, s) in rgb.measurement.samples[..3].iter().enumerate() {
        for k in 0..3 {
            let want = if k == c { 0.3 / weights[c] } else { 0.0 };
            assert!(
                (s.values[k] - want).abs() < 1e-6,
                "primary {c}: RGB {:?}, want channel {k} = {want}",
                s.values
            );
        }
    }
    for v in rgb.measurement.samples[3].values {
        assert!(
            (v - 0.7).abs() < 1e-3,
            "white: {:?}",
            rgb.measurement.samples[3]
        );
    }
    // As recorded: the three values are taken as RGB unchanged.
    let mut r = recipe(Vec::new());
    r.colour = ColourConversion::AsRecorded;
    let kept = prepare(&r, m);
    for (s, v) in kept.measurement.samples.iter().zip(&values) {
        assert_eq!(s.values, *v);
    }
    // The fitter sees the converted values.
    let data = rgb.incidence_data();
    assert_eq!(data.channels, 3);
    assert_eq!(data.samples[0].value, rgb.measurement.samples[0].values);
}

#[test]
fn one_channel_files_are_not_colour_converted() {
    let dirs = front_rings();
    let m = measurement(30.0, Quantity::Bsdf, Channels::Y, samples(&dirs, f));
    let p = prepare(&recipe(Vec::new()), m);
    assert_eq!(p.channels(), 1);
    assert_eq!(p.incidence_data().channels, 1);
    for (s, &(t, ph)) in p.measurement.samples.iter().zip(&dirs) {
        assert_eq!(s.values, [f(t, ph), 0.0, 0.0]);
    }
}

// -------------------------------------------------------------------- gates

/// Prepares one-channel BSDF `samples` at incidence (`theta_in`, 0)
/// through `gates` and checks that exactly the samples `expected_removed`
/// says are removed, by the gate it names, and that the counts and the
/// fitter's samples agree.
fn check_gates(
    theta_in: f64,
    samples: Vec<Sample>,
    gates: Vec<Gate>,
    expected_removed: impl Fn(&Sample) -> Option<usize>,
) -> PreparedMeasurement {
    let expected: Vec<Option<usize>> = samples.iter().map(expected_removed).collect();
    check_gates_listed(theta_in, samples, gates, expected)
}

/// [`check_gates`] with the expected gate of each sample listed.
fn check_gates_listed(
    theta_in: f64,
    samples: Vec<Sample>,
    gates: Vec<Gate>,
    expected: Vec<Option<usize>>,
) -> PreparedMeasurement {
    let m = measurement(theta_in, Quantity::Bsdf, Channels::Y, samples);
    let p = prepare(&recipe(gates.clone()), m);
    for (i, (got, want)) in p.removed_by.iter().zip(&expected).enumerate() {
        let s = &p.measurement.samples[i];
        assert_eq!(
            got, want,
            "sample {i} at ({}, {}) value {}",
            s.theta_deg, s.phi_deg, s.values[0]
        );
    }
    assert_eq!(p.gates.len(), gates.len());
    for (g, (count, gate)) in p.gates.iter().zip(gates.iter()).enumerate() {
        assert_eq!(count.gate, *gate);
        let want = expected.iter().filter(|r| **r == Some(g)).count();
        assert_eq!(count.removed, want, "gate {gate}");
    }
    let kept: Vec<usize> = (0..expected.len())
        .filter(|&i| expected[i].is_none())
        .collect();
    assert_eq!(p.fitted_count(), kept.len());
    let data = p.incidence_data();
    assert_eq!(data.samples.len(), kept.len());
    for (fs, &i) in data.samples.iter().zip(&kept) {
        let s = &p.measurement.samples[i];
        assert!((fs.view - s.direction()).length() < 1e-15);
        assert_eq!(fs.value, s.values);
    }
    assert_eq!(data.gates, p.gates);
    p
}

#[test]
fn the_theta_cap_removes_samples_beyond_it_from_the_nearer_normal() {
    // Front θ 5…85 and back θ 95…175: the cap counts from the nearer
    // normal, so θ = 170° is 10° from the back normal.
    let thetas: Vec<f64> = (0..18).map(|k| 5.0 + 10.0 * k as f64).collect();
    let dirs = ring_directions(&thetas, 6);
    let p = check_gates(
        30.0,
        samples(&dirs, f),
        vec![Gate::ThetaCap { max_deg: 60.0 }],
        |s| (s.theta_deg.min(180.0 - s.theta_deg) > 60.0).then_some(0),
    );
    // 65, 75, 85 and 95, 105, 115: six rings of six.
    assert_eq!(p.gates[0].removed, 36);
}

#[test]
fn the_beam_mask_removes_the_cone_around_the_incident_direction() {
    // Samples at known angles from the light at (30°, 0°), none within
    // 0.05° of the 3° edge, plus the mirror direction (60° away) and
    // far samples.
    let mut dirs = Vec::new();
    for dt in [-4.0, -3.2, -2.8, -1.0, 0.0, 0.5, 2.9, 3.1, 6.0] {
        dirs.push((30.0 + dt, 0.0));
    }
    for dp in [1.0, 3.0, 5.0, 6.2, 7.0, 359.0, 355.0] {
        dirs.push((30.0, dp));
    }
    dirs.extend([(30.0, 180.0), (60.0, 90.0), (10.0, 270.0)]);
    let light = (30.0, 0.0);
    for &d in &dirs {
        assert!((angle_between_deg(d, light) - 3.0).abs() > 0.05, "{d:?}");
    }
    let p = check_gates(
        30.0,
        samples(&dirs, f),
        vec![Gate::BeamMask {
            half_angle_deg: 3.0,
        }],
        |s| (angle_between_deg((s.theta_deg, s.phi_deg), light) < 3.0).then_some(0),
    );
    // Inside: θ 27.2, 29, 30, 30.5, 32.9; at θ = 30° an azimuth step Δφ
    // is 2 asin(sin 30° sin(Δφ/2)) ≈ Δφ/2 away: φ = 1, 3, 5, 359, 355.
    assert_eq!(p.gates[0].removed, 10);
}

#[test]
fn the_hemisphere_gate_keeps_one_side_and_theta_90_is_front() {
    let dirs = vec![
        (0.0, 0.0),
        (45.0, 90.0),
        (90.0, 0.0),
        (90.5, 0.0),
        (135.0, 270.0),
        (180.0, 0.0),
    ];
    let front = check_gates(
        30.0,
        samples(&dirs, f),
        vec![Gate::Hemisphere {
            keep: Hemisphere::Front,
        }],
        |s| (s.theta_deg > 90.0).then_some(0),
    );
    assert_eq!(front.gates[0].removed, 3);
    let back = check_gates(
        30.0,
        samples(&dirs, f),
        vec![Gate::Hemisphere {
            keep: Hemisphere::Back,
        }],
        |s| (s.theta_deg <= 90.0).then_some(0),
    );
    assert_eq!(back.gates[0].removed, 3);
}

#[test]
fn the_min_value_gate_removes_low_values_and_unavailable_comes_first() {
    let dirs = front_rings();
    // Values 0, 0.01, …: every fifth sample below 0.05, one NaN, one
    // negative.
    let mut s: Vec<Sample> = dirs
        .iter()
        .enumerate()
        .map(|(i, &(t, p))| Sample::luminance(t, p, 0.01 * (i % 10) as f64))
        .collect();
    s[7].values[0] = f64::NAN;
    s[8].values[0] = -1.0;
    let p = check_gates(
        30.0,
        s,
        vec![Gate::Unavailable, Gate::MinValue { min: 0.05 }],
        |s| {
            if s.values[0].is_nan() {
                Some(0)
            } else if s.values[0] < 0.05 {
                Some(1)
            } else {
                None
            }
        },
    );
    assert_eq!(p.gates[0].removed, 1);
    // 108 samples, i % 10 < 5 for 55 of them; sample 7 (NaN) is taken by
    // the first gate, sample 8 (−1, i % 10 = 8) joins the low ones.
    assert_eq!(p.gates[1].removed, 55 + 1);
}

#[test]
fn the_holder_mask_removes_its_azimuth_band_at_grazing_angles() {
    // PGII_HOLDER_BAND: φ_out − φ_in 270 ± 45° at θ_out ≥ 73° (edges
    // included), from the nearer normal; the light at φ_in 0.
    let dirs = vec![
        (75.0, 270.0),
        (75.0, 230.0),
        (80.0, 315.0),
        (80.0, 225.0),
        (80.0, 316.0),
        (75.0, 224.0),
        (72.0, 270.0),
        (73.0, 270.0),
        (75.0, 90.0),
        (110.0, 270.0),
        (30.0, 270.0),
    ];
    let p = check_gates(30.0, samples(&dirs, f), vec![PGII_HOLDER_BAND], |s| {
        let theta = s.theta_deg.min(180.0 - s.theta_deg);
        ((s.phi_deg - 270.0).abs() <= 45.0 && theta >= 73.0).then_some(0)
    });
    assert_eq!(p.gates[0].removed, 5);
}

#[test]
fn each_sample_is_removed_by_the_first_gate_it_fails() {
    let gates = SelectionOptions {
        hemisphere: Some(Hemisphere::Front),
        theta_cap: 60.0,
        beam_mask: 3.0,
        min_value: Some(0.1),
        mask_holder: Some(crate::HolderMask::Band),
    }
    .gates(false);
    assert_eq!(
        gates,
        vec![
            Gate::Unavailable,
            Gate::Hemisphere {
                keep: Hemisphere::Front
            },
            Gate::ThetaCap { max_deg: 60.0 },
            Gate::BeamMask {
                half_angle_deg: 3.0
            },
            Gate::MinValue { min: 0.1 },
            PGII_HOLDER_BAND,
        ]
    );
    // Each sample fails the gates listed; the first one takes it.
    let cases: Vec<(Sample, Option<usize>)> = vec![
        (Sample::luminance(100.0, 270.0, f64::NAN), Some(0)), // NaN, back, band
        (Sample::luminance(100.0, 270.0, 0.0), Some(1)),      // back, cap, min, band
        (Sample::luminance(75.0, 270.0, 0.0), Some(2)),       // cap, min, band
        (Sample::luminance(30.0, 0.0, 0.0), Some(3)),         // beam, min
        (Sample::luminance(40.0, 180.0, 0.05), Some(4)),      // min
        (Sample::luminance(40.0, 180.0, 0.5), None),
        (Sample::luminance(60.0, 270.0, 0.5), None), // below the band's 73°
    ];
    let (samples, expected): (Vec<Sample>, Vec<Option<usize>>) = cases.into_iter().unzip();
    let p = check_gates_listed(30.0, samples, gates, expected);
    assert_eq!(
        p.gates.iter().map(|g| g.removed).collect::<Vec<_>>(),
        vec![1, 1, 1, 1, 1, 0]
    );
}

#[test]
fn selection_options_leave_out_what_is_off_and_what_klems_data_cannot_use() {
    let options = SelectionOptions {
        hemisphere: None,
        theta_cap: 85.0,
        beam_mask: 0.0,
        min_value: None,
        mask_holder: None,
    };
    assert_eq!(
        options.gates(false),
        vec![Gate::Unavailable, Gate::ThetaCap { max_deg: 85.0 }]
    );
    let klems = SelectionOptions {
        hemisphere: Some(Hemisphere::Front),
        beam_mask: 3.0,
        min_value: Some(0.0),
        ..options
    };
    assert_eq!(
        klems.gates(true),
        vec![
            Gate::Unavailable,
            Gate::Hemisphere {
                keep: Hemisphere::Front
            },
            Gate::MinValue { min: 0.0 },
        ]
    );
}

// ------------------------------------------------------------------ weights

#[test]
fn computed_solid_angles_are_the_ring_cells_of_the_full_layout() {
    // Rings θ = 10, 30, 50, 70 with 12 azimuths: each sample owns the band
    // between the mid-θ of its ring and its neighbours' (0° below the
    // first, 90° above the last) over 30° of azimuth:
    // Ω = (2π/12)(cos θ_lo − cos θ_hi), summing to 2π.
    let dirs = ring_directions(&[10.0, 30.0, 50.0, 70.0], 12);
    let bands = [(0.0, 20.0), (20.0, 40.0), (40.0, 60.0), (60.0, 90.0)];
    let cell = |ring: usize| {
        let (lo, hi): (f64, f64) = bands[ring];
        2.0 * PI / 12.0 * (lo.to_radians().cos() - hi.to_radians().cos())
    };
    let m = measurement(30.0, Quantity::Bsdf, Channels::Y, samples(&dirs, f));
    let mut r = recipe(vec![Gate::ThetaCap { max_deg: 60.0 }]);
    r.weights = WeightRule::SolidAngle;
    let p = prepare(&r, m);
    assert_eq!(p.weighting, Weighting::ComputedSolidAngles);
    let total: f64 = p
        .measurement
        .samples
        .iter()
        .map(|s| s.solid_angle_sr.unwrap())
        .sum();
    assert_close(total, 2.0 * PI, 1e-12, "the cells cover the hemisphere");
    for (i, s) in p.measurement.samples.iter().enumerate() {
        assert_close(s.solid_angle_sr.unwrap(), cell(i / 12), 1e-9, "cell");
    }
    // The cap removed the 70° ring; the others keep the cells of the full
    // layout (not recomputed for the selection).
    let data = p.incidence_data();
    assert_eq!(data.weighting, Weighting::ComputedSolidAngles);
    assert_eq!(data.samples.len(), 36);
    for (k, s) in data.samples.iter().enumerate() {
        assert_close(s.weight, cell(k / 12), 1e-9, "fitted weight");
    }
}

#[test]
fn the_files_solid_angles_are_used_when_every_sample_has_one() {
    let dirs = front_rings();
    let mut s = samples(&dirs, f);
    for (i, sample) in s.iter_mut().enumerate() {
        sample.solid_angle_sr = Some(0.001 * (i + 1) as f64);
    }
    let mut r = recipe(Vec::new());
    r.weights = WeightRule::SolidAngle;
    let p = prepare(
        &r,
        measurement(30.0, Quantity::Bsdf, Channels::Y, s.clone()),
    );
    assert_eq!(p.weighting, Weighting::FileSolidAngles);
    for (i, fs) in p.incidence_data().samples.iter().enumerate() {
        assert_eq!(fs.weight, 0.001 * (i + 1) as f64);
    }
    // One sample without a cell: all are computed (and then sum to 2π).
    s[3].solid_angle_sr = None;
    let p = prepare(&r, measurement(30.0, Quantity::Bsdf, Channels::Y, s));
    assert_eq!(p.weighting, Weighting::ComputedSolidAngles);
    let total: f64 = p.incidence_data().samples.iter().map(|s| s.weight).sum();
    assert_close(total, 2.0 * PI, 1e-9, "computed cells");
}

#[test]
fn uniform_weights_are_one_whatever_the_solid_angles() {
    let dirs = front_rings();
    let mut s = samples(&dirs, f);
    for sample in &mut s {
        sample.solid_angle_sr = Some(0.25);
    }
    let p = prepare(
        &recipe(vec![Gate::ThetaCap { max_deg: 50.0 }]),
        measurement(30.0, Quantity::Bsdf, Channels::Y, s),
    );
    assert_eq!(p.weighting, Weighting::Uniform);
    let data = p.incidence_data();
    assert_eq!(data.weighting, Weighting::Uniform);
    // θ 5…45: five rings of twelve.
    assert_eq!(data.samples.len(), 60);
    assert!(data.samples.iter().all(|s| s.weight == 1.0));
}

#[test]
fn a_real_mpc_file_keeps_its_bsdf_column_and_voronoi_cells() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../data/alu-ggx/alu-ggx:+30+0.mpc"
    );
    let m = brtf_gonio::read_path(std::path::Path::new(path)).expect("read the .mpc");
    assert_eq!(m.incidence.theta_deg, 30.0);
    let original = m.clone();
    let mut r = Recipe::for_kind(brtf_model::MaterialKind::Metal);
    r.weights = WeightRule::SolidAngle;
    let p = r.prepare(m, path).expect("prepared");
    assert_eq!(p.conversion, Conversion::Bsdf);
    assert_eq!(p.weighting, Weighting::FileSolidAngles);
    // Every sample is still there, in file order, with its value and cell.
    assert_eq!(p.measurement.samples, original.samples);
    let fitted: Vec<usize> = p.fitted().map(|(i, _)| i).collect();
    for (fs, &i) in p.incidence_data().samples.iter().zip(&fitted) {
        let s = &original.samples[i];
        assert_eq!(fs.value, s.values);
        assert_eq!(Some(fs.weight), s.solid_angle_sr);
        // The default gates: front, θ_out ≤ 85°, 3° around the beam.
        assert!(s.theta_deg <= 85.0);
        assert!(angle_between_deg((s.theta_deg, s.phi_deg), (30.0, 0.0)) > 3.0 - 1e-9);
    }
    let removed: usize = p.gates.iter().map(|g| g.removed).sum();
    assert_eq!(removed + fitted.len(), original.samples.len());
}
