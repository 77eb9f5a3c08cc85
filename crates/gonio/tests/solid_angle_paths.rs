//! The two solid-angle paths: rings for ring layouts, equal-area Voronoi
//! cells for the rest. DirectionLayout detection on the real pgII scans (scattered)
//! and on synthetic ring layouts; on ring layouts both paths give the same
//! totals and the same cells to 1 %.

use std::f64::consts::TAU;

use brtf_gonio::synth::{GroundTruth, Instrument, SynthSpec, synthesize};
use brtf_gonio::{Channels, Hemisphere, Incidence, Sample, compute_solid_angles};
use brtf_gonio::{DirectionLayout, detect_layout, voronoi_solid_angles};

use crate::common::{golden, layer};

fn total(samples: &[Sample], weights: &[f64], hemisphere: Hemisphere) -> f64 {
    samples
        .iter()
        .zip(weights)
        .filter(|(s, _)| s.hemisphere() == hemisphere)
        .map(|(_, w)| w)
        .sum()
}

/// `rings` rings of `azimuths` directions each, θ' from `first` to `last`
/// degrees, φ offset by `stagger` of a step on every other ring, with
/// `theta_jitter` degrees of alternating θ jitter; on both hemispheres
/// when `both`.
fn ring_layout(
    rings: usize,
    azimuths: usize,
    (first, last): (f64, f64),
    stagger: f64,
    theta_jitter: f64,
    both: bool,
) -> Vec<Sample> {
    let mut samples = Vec::new();
    for i in 0..rings {
        let theta = first + (last - first) * i as f64 / (rings - 1) as f64;
        for j in 0..azimuths {
            let offset = if i % 2 == 1 { stagger } else { 0.0 };
            let phi = 360.0 * (j as f64 + offset) / azimuths as f64;
            let jitter = if j % 2 == 0 {
                theta_jitter
            } else {
                -theta_jitter
            };
            samples.push(Sample::luminance(theta + jitter, phi, 1.0));
            if both {
                samples.push(Sample::luminance(180.0 - theta - jitter, phi, 1.0));
            }
        }
    }
    samples
}

fn with_pole(mut samples: Vec<Sample>) -> Vec<Sample> {
    samples.push(Sample::luminance(0.0, 0.0, 1.0));
    samples
}

/// Largest relative difference of the two paths' cells.
fn worst_cell_difference(rings: &[f64], voronoi: &[f64]) -> f64 {
    rings
        .iter()
        .zip(voronoi)
        .map(|(r, v)| (r - v).abs() / v)
        .fold(0.0, f64::max)
}

#[test]
fn real_scans_are_scattered_and_keep_the_voronoi_cells() {
    for m in [golden(), layer()] {
        assert_eq!(
            detect_layout(&m.samples),
            [Some(DirectionLayout::Scattered), None],
            "the pgII scans follow adaptive paths, not rings"
        );
        assert_eq!(
            compute_solid_angles(&m.samples),
            voronoi_solid_angles(&m.samples)
        );
    }
}

#[test]
fn both_paths_agree_on_ring_layouts() {
    let layouts = [
        // The fit bench's layout: 200 rings x 600 azimuths to 85°.
        (
            "200 x 600 to 85°",
            ring_layout(200, 600, (0.2125, 84.7875), 0.0, 0.0, false),
        ),
        // 1° x 2° on both hemispheres, from 1° (no pole sample).
        (
            "90 x 180, both",
            ring_layout(90, 180, (1.0, 90.0), 0.0, 0.0, true),
        ),
        // Rings with 0.0001° of alternating θ jitter and a pole sample.
        // Larger jitter tilts the Voronoi edge between azimuth neighbours
        // by about jitter / spacing, which over a cell's radial extent
        // moves it by a sizeable part of its width (0.0005° here gives
        // 3.4 %, 0.004° 35 %): the bands are then the better cells, and the paths differ.
        (
            "jittered",
            with_pole(ring_layout(60, 120, (5.0, 80.0), 0.0, 0.0001, false)),
        ),
    ];
    for (name, samples) in layouts {
        let layout = detect_layout(&samples);
        assert_eq!(layout[0], Some(DirectionLayout::Rings), "{name}");
        let rings = compute_solid_angles(&samples);
        let voronoi = voronoi_solid_angles(&samples);
        for h in [Hemisphere::Front, Hemisphere::Back] {
            let (a, b) = (total(&samples, &rings, h), total(&samples, &voronoi, h));
            if layout[h as usize].is_some() {
                assert!((a - TAU).abs() < 1e-9 && (b - TAU).abs() < 1e-9, "{name}");
            }
        }
        let worst = worst_cell_difference(&rings, &voronoi);
        println!("{name}: worst cell difference {:.3} %", 100.0 * worst);
        assert!(worst < 0.01, "{name}: {worst}");
    }
}

#[test]
fn staggered_rings_keep_the_total_and_the_mean_cell() {
    // Every other ring turned by half a step: the Voronoi cells become
    // hexagons, the ring cells stay bands; per cell they differ, but the
    // totals agree and both are exact partitions.
    let samples = ring_layout(45, 90, (2.0, 90.0), 0.5, 0.0, false);
    assert_eq!(detect_layout(&samples)[0], Some(DirectionLayout::Rings));
    let rings = compute_solid_angles(&samples);
    let voronoi = voronoi_solid_angles(&samples);
    assert!((rings.iter().sum::<f64>() - TAU).abs() < 1e-9);
    assert!((voronoi.iter().sum::<f64>() - TAU).abs() < 1e-9);
    println!(
        "staggered: worst cell difference {:.2} %",
        100.0 * worst_cell_difference(&rings, &voronoi)
    );
}

#[test]
fn ring_path_is_order_independent() {
    let samples = ring_layout(30, 40, (3.0, 87.0), 0.0, 0.003, true);
    let forward = compute_solid_angles(&samples);
    let mut reversed = samples.clone();
    reversed.reverse();
    let mut backward = compute_solid_angles(&reversed);
    backward.reverse();
    assert_eq!(forward, backward);
}

#[test]
fn synthetic_files_take_the_path_their_layout_asks_for() {
    // brtf synth: coarse rings plus concentric rings about the peak, which
    // together are not rings about the normal.
    let spec = SynthSpec {
        truth: GroundTruth::Ggx {
            f0: [0.9; 3],
            alpha: 0.12,
            diffuse: [0.02; 3],
        },
        incidence: Incidence::new(30.0, 0.0),
        instrument: Instrument::default(),
        layout: brtf_gonio::synth::Layout::default(),
        channels: Channels::Y,
        seed: 1,
        sample_name: "rings".into(),
    };
    let m = synthesize(&spec);
    let layout = detect_layout(&m.samples);
    assert_eq!(layout[0], Some(DirectionLayout::Scattered));
}
