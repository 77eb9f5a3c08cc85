//! Solid angles: constant integrals on the real layouts and on grids,
//! partitions summing to 2π, determinism and degenerate layouts.

use std::f64::consts::{PI, TAU};

use approx::assert_relative_eq;
use brtf_gonio::{
    Hemisphere, Sample, SolidAngleSource, compute_solid_angles, read_path, solid_angles,
};

use crate::common::{MPC_FIXTURE, fixture_path, golden, grid, layer};

/// Σ (1/π) |cos θ| ΔΩ over one hemisphere: 1 for exact quadrature.
fn constant_integral(samples: &[Sample], weights: &[f64], hemisphere: Hemisphere) -> f64 {
    samples
        .iter()
        .zip(weights)
        .filter(|(s, _)| s.hemisphere() == hemisphere)
        .map(|(s, w)| s.abs_cos_theta() / PI * w)
        .sum()
}

fn hemisphere_total(samples: &[Sample], weights: &[f64], hemisphere: Hemisphere) -> f64 {
    samples
        .iter()
        .zip(weights)
        .filter(|(s, _)| s.hemisphere() == hemisphere)
        .map(|(_, w)| w)
        .sum()
}

#[test]
fn constant_integrates_to_one_on_the_real_layouts() {
    for (name, m) in [("golden_paper", golden()), ("layer_020_030", layer())] {
        let w = solid_angles(m);
        assert_eq!(w.source, SolidAngleSource::Computed);
        let one = constant_integral(&m.samples, &w.per_sample_sr, Hemisphere::Front);
        let total = hemisphere_total(&m.samples, &w.per_sample_sr, Hemisphere::Front);
        let largest = w.per_sample_sr.iter().cloned().fold(0.0, f64::max);
        let theta_max = m.samples.iter().map(|s| s.theta_deg).fold(0.0, f64::max);
        let theta_min = m.samples.iter().map(|s| s.theta_deg).fold(90.0, f64::min);
        // Coverage report (visible with --nocapture).
        println!(
            "{name}: constant integral {one:.5}, cells sum {total:.6} sr (2pi = {TAU:.6}), \
             theta {theta_min:.2}..{theta_max:.3} deg, largest cell {largest:.2e} sr"
        );
        assert_relative_eq!(one, 1.0, max_relative = 0.01);
        assert_relative_eq!(total, TAU, max_relative = 1e-9);
        assert!(
            theta_max > 89.99 && theta_min < 1.0,
            "front hemisphere covered"
        );
        assert!(w.per_sample_sr.iter().all(|&a| a > 0.0 && a < 0.02));
    }
}

#[test]
fn constant_integrates_to_one_on_regular_grids() {
    for (theta_step, phi_step) in [(5.0, 10.0), (1.0, 2.0), (15.0, 45.0)] {
        let samples = grid(theta_step, phi_step, true, 1.0);
        let w = compute_solid_angles(&samples);
        for h in [Hemisphere::Front, Hemisphere::Back] {
            assert_relative_eq!(hemisphere_total(&samples, &w, h), TAU, max_relative = 1e-9);
            let one = constant_integral(&samples, &w, h);
            println!("{theta_step} x {phi_step} deg grid, {h:?}: {one:.5}");
            // The 15° x 45° grid is very coarse, and its back half has no
            // ring at 90° (the outer ring at 75° owns the band to 90° with a
            // cosine that is too large): only sanity bounds there.
            let tolerance = match (theta_step > 10.0, h) {
                (false, _) => 0.01,
                (true, Hemisphere::Front) => 0.05,
                (true, Hemisphere::Back) => 0.10,
            };
            assert_relative_eq!(one, 1.0, max_relative = tolerance);
        }
    }
}

#[test]
fn constant_integrates_to_one_on_random_directions() {
    // Uniform on the hemisphere: cos θ uniform in [0, 1].
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut uniform = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let samples: Vec<Sample> = (0..20_000)
        .map(|_| Sample::luminance(uniform().acos().to_degrees(), 360.0 * uniform(), 1.0))
        .collect();
    let w = compute_solid_angles(&samples);
    assert_relative_eq!(
        constant_integral(&samples, &w, Hemisphere::Front),
        1.0,
        max_relative = 0.01
    );
}

#[test]
fn file_weights_are_used_when_present() {
    let m = read_path(&fixture_path(MPC_FIXTURE)).unwrap();
    let w = solid_angles(&m);
    assert_eq!(w.source, SolidAngleSource::File);
    assert_eq!(w.per_sample_sr[0], 0.0351119);
    // One missing or negative weight: compute instead.
    let mut partial = m.clone();
    partial.samples[2].solid_angle_sr = None;
    assert_eq!(solid_angles(&partial).source, SolidAngleSource::Computed);
    partial.samples[2].solid_angle_sr = Some(-1.0);
    assert_eq!(solid_angles(&partial).source, SolidAngleSource::Computed);
}

#[test]
fn fill_solid_angles_keeps_weights_through_selections() {
    let mut m = golden().clone();
    m.samples.truncate(3000);
    assert_eq!(m.fill_solid_angles(), SolidAngleSource::Computed);
    let full = solid_angles(&m);
    assert_eq!(full.source, SolidAngleSource::File);
    let capped = m.cap_theta(60.0);
    let kept = solid_angles(&capped.measurement);
    assert_eq!(kept.source, SolidAngleSource::File);
    for (k, &i) in capped.kept.iter().enumerate() {
        assert_eq!(kept.per_sample_sr[k], full.per_sample_sr[i]);
    }
}

#[test]
fn deterministic_and_order_independent() {
    let mut m = layer().clone();
    m.samples.truncate(20_000);
    let a = compute_solid_angles(&m.samples);
    let b = compute_solid_angles(&m.samples);
    assert_eq!(a, b);
    let mut reversed = m.samples.clone();
    reversed.reverse();
    let mut c = compute_solid_angles(&reversed);
    c.reverse();
    assert_eq!(a, c);
}

#[test]
fn degenerate_layouts() {
    assert!(compute_solid_angles(&[]).is_empty());
    let one = compute_solid_angles(&[Sample::luminance(10.0, 0.0, 1.0)]);
    assert_relative_eq!(one[0], TAU, max_relative = 1e-12);
    // An in-plane scan: every direction at φ = 0 or 180, collinear in the
    // projection.
    let plane: Vec<Sample> = (0..90)
        .flat_map(|t| {
            [
                Sample::luminance(t as f64, 0.0, 1.0),
                Sample::luminance(t as f64, 180.0, 1.0),
            ]
        })
        .collect();
    let w = compute_solid_angles(&plane);
    assert_relative_eq!(w.iter().sum::<f64>(), TAU, max_relative = 1e-9);
    assert!(w.iter().all(|&a| a >= 0.0));
    // Coincident directions (θ = 0 with any φ) share one cell.
    let pole = compute_solid_angles(&[
        Sample::luminance(0.0, 0.0, 1.0),
        Sample::luminance(0.0, 90.0, 1.0),
        Sample::luminance(45.0, 0.0, 1.0),
    ]);
    assert_eq!(pole[0], pole[1]);
    assert_relative_eq!(pole.iter().sum::<f64>(), TAU, max_relative = 1e-9);
    // Non-finite directions get zero weight and do not disturb the rest.
    let odd = compute_solid_angles(&[
        Sample::luminance(f64::NAN, 0.0, 1.0),
        Sample::luminance(30.0, f64::INFINITY, 1.0),
        Sample::luminance(30.0, 0.0, 1.0),
    ]);
    assert_eq!(&odd[..2], &[0.0, 0.0]);
    assert_relative_eq!(odd[2], TAU, max_relative = 1e-12);
}
