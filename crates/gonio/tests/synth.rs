//! Synthetic measurements: the data-side integral agrees with the model's
//! albedo, instrument effects are where they should be, output is seeded.

use brtf_gonio::synth::{GroundTruth, Instrument, Layout, SynthSpec, synthesize};
use brtf_gonio::{
    Channels, Hemisphere, Incidence, SourceFormat, hemispherical_integral, read_str,
    to_mountain_string, to_mpc_string,
};
use brtf_model::{Bsdf, EvalOptions, Material, MaterialKind, albedo, direction};

fn metal(args: &[f64]) -> Bsdf {
    let m = Material::new(MaterialKind::Metal, args, None).unwrap();
    Bsdf::new(&m, &EvalOptions::default())
}

fn clean() -> Instrument {
    Instrument {
        source_aperture_deg: 0.0,
        detector_aperture_deg: 0.0,
        noise_relative: 0.0,
        noise_floor: 0.0,
        blind_spot_deg: 0.0,
        holder_gap: false,
        holder_shadow: false,
        back_rows: false,
        aperture_rays: 1,
    }
}

fn spec(truth: GroundTruth, theta: f64, instrument: Instrument, seed: u64) -> SynthSpec {
    SynthSpec {
        truth,
        incidence: Incidence::new(theta, 0.0),
        instrument,
        layout: Layout::default(),
        channels: Channels::Y,
        seed,
        sample_name: "test".into(),
    }
}

#[test]
fn noise_free_data_integrates_to_the_model_albedo_within_one_percent() {
    for (args, theta) in [
        ([0.9, 0.8, 0.7, 0.8, 0.1], 30.0),
        ([0.5, 0.5, 0.5, 0.3, 0.2], 0.0),
        ([0.9, 0.9, 0.9, 0.9, 0.05], 60.0),
    ] {
        let bsdf = metal(&args);
        let m = synthesize(&spec(GroundTruth::Model(bsdf), theta, clean(), 1));
        let weights: Vec<f64> = m
            .samples
            .iter()
            .map(|s| s.solid_angle_sr.unwrap())
            .collect();
        let data = hemispherical_integral(&m, &weights, Hemisphere::Front)
            .unwrap()
            .value;
        let model = albedo(&bsdf, direction(theta, 0.0), 1e-6).rho;
        // The single-channel files hold CIE Y, the luminance.
        let model = brtf_model::luminance(model);
        // The layout stops at θ_out = 88°; the model integral does not.
        let rel = (data - model).abs() / model;
        eprintln!("metal {args:?} θ_in {theta}: data ρ_dh {data:.5}, model {model:.5}");
        assert!(
            rel < 0.01,
            "{args:?} θ={theta}: data ρ_dh {data} vs model {model} ({rel:.4})"
        );
    }
}

#[test]
fn instrument_effects_are_applied() {
    let bsdf = metal(&[0.9, 0.9, 0.9, 0.8, 0.1]);
    let m = synthesize(&spec(
        GroundTruth::Model(bsdf),
        30.0,
        Instrument::default(),
        7,
    ));
    let light = direction(30.0, 0.0);
    // The blind spot: nothing within 3° of the incident beam.
    let closest = m
        .samples
        .iter()
        .map(|s| s.direction().angle_between(light).to_degrees())
        .fold(f64::INFINITY, f64::min);
    assert!(closest >= 3.0, "a sample {closest}° from the beam");
    // The holder gap near grazing around φ_in + 90°.
    assert!(
        !m.samples
            .iter()
            .any(|s| s.theta_deg > 80.0 && s.theta_deg < 90.0 && (s.phi_deg - 90.0).abs() < 10.0)
    );
    // Noise-only back rows around zero, with negatives.
    let back: Vec<f64> = m
        .samples
        .iter()
        .filter(|s| s.theta_deg > 90.0)
        .map(|s| s.values[0])
        .collect();
    assert!(back.len() > 100);
    let mean = back.iter().sum::<f64>() / back.len() as f64;
    assert!(mean.abs() < 3e-4, "back mean {mean}");
    assert!(back.iter().any(|v| *v < 0.0));
    // Dense sampling at the peak: more samples within 5° of the mirror
    // direction than a uniform 2.5° grid would give.
    let mirror = direction(30.0, 180.0);
    let near = m
        .samples
        .iter()
        .filter(|s| s.direction().angle_between(mirror) < 5f64.to_radians())
        .count();
    assert!(near > 150, "only {near} samples near the peak");
}

#[test]
fn seeded_and_deterministic() {
    let bsdf = metal(&[0.9, 0.9, 0.9, 0.8, 0.1]);
    let a = synthesize(&spec(
        GroundTruth::Model(bsdf),
        45.0,
        Instrument::default(),
        3,
    ));
    let b = synthesize(&spec(
        GroundTruth::Model(bsdf),
        45.0,
        Instrument::default(),
        3,
    ));
    let c = synthesize(&spec(
        GroundTruth::Model(bsdf),
        45.0,
        Instrument::default(),
        4,
    ));
    assert_eq!(a, b);
    assert_ne!(a.samples, c.samples);
}

#[test]
fn ggx_truth_peaks_at_the_mirror_and_conserves_energy() {
    let truth = GroundTruth::Ggx {
        f0: [0.91, 0.92, 0.92],
        alpha: 0.12,
        diffuse: [0.02; 3],
    };
    let m = synthesize(&spec(truth, 30.0, clean(), 1));
    let peak = m.front_peak().unwrap();
    assert!(
        (peak.theta_deg - 30.0).abs() < 1.0 && (peak.phi_deg - 180.0).abs() < 1.0,
        "{peak:?}"
    );
    let weights: Vec<f64> = m
        .samples
        .iter()
        .map(|s| s.solid_angle_sr.unwrap())
        .collect();
    let rho = hemispherical_integral(&m, &weights, Hemisphere::Front)
        .unwrap()
        .value;
    assert!(rho > 0.8 && rho < 1.0, "GGX ρ_dh {rho}");
}

#[test]
fn synthetic_files_round_trip_in_both_formats() {
    let bsdf = metal(&[0.9, 0.8, 0.7, 0.8, 0.1]);
    let mut m = synthesize(&spec(
        GroundTruth::Model(bsdf),
        15.0,
        Instrument::default(),
        9,
    ));
    let mpc = to_mpc_string(&m).unwrap();
    let back = read_str(&mpc, "x:+15+0.mpc").unwrap();
    assert_eq!(back.samples, m.samples);
    m.format = SourceFormat::Mountain;
    let mut xyz = spec(GroundTruth::Model(bsdf), 15.0, Instrument::default(), 9);
    xyz.channels = Channels::Xyz;
    let m3 = synthesize(&xyz);
    let text = to_mountain_string(&m3);
    let back = read_str(&text, "x.txt").unwrap();
    assert_eq!(back.channels, Channels::Xyz);
    assert_eq!(back.samples.len(), m3.samples.len());
    for (a, b) in back.samples.iter().zip(&m3.samples) {
        assert_eq!(a.values, b.values);
    }
}
