//! The equal-area Voronoi cells from brtf's own Delaunay triangulation
//! (`disk_voronoi_areas`) against the delaunator-based reference
//! (`reference_disk_voronoi_areas`): the Voronoi diagram is unique, so the
//! cells must agree to rounding (1e-9 relative per cell) on both real pgII
//! scans and on synthetic layouts that stress the triangulation (uniform,
//! clustered, near-collinear paths, grids and rings full of cocircular
//! points, duplicates).

use std::f64::consts::{PI, TAU};

use brtf_gonio::{DISK_RADIUS, disk_voronoi_areas, project, reference_disk_voronoi_areas};
use brtf_gonio::{Hemisphere, Measurement, compute_solid_angles};

use crate::common::{golden, layer};

/// Per-cell agreement demanded: rounding only, 5e-9 relative or 1e-16 sr
/// absolute (one rounding of a coordinate of size 1). Both methods compute
/// the Voronoi corners with the same formula, but from each triangle's
/// vertices in whatever rotation its triangulation stores them; for
/// near-flat triangles (near-collinear paths, tight clusters) the corner's
/// rounding is amplified. Worst seen (24 November 2026): 1.1e-9 relative on
/// golden_paper and 1.5e-9 on layer_020_030 (1.4e-17 and 2.8e-17 sr, one
/// cell each above 1e-9; around the golden_paper one both triangulations
/// have the same triangles), 2.1e-9 on the synthetic paths, and 6.5e-8
/// relative but 6.9e-18 sr absolute on a 1e-10 sr cell of a tight cluster.
const TOLERANCE: f64 = 5e-9;
const ABSOLUTE_TOLERANCE_SR: f64 = 1e-16;

/// A small deterministic generator (xorshift64*), uniform in [0, 1).
struct Rng(u64);

impl Rng {
    fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }

    fn normal(&mut self) -> f64 {
        let (u, v) = (self.uniform().max(1e-300), self.uniform());
        (-2.0 * u.ln()).sqrt() * (TAU * v).cos()
    }
}

/// The largest relative difference between the two methods' cells, after
/// checking that both sum to 2π.
fn compare(name: &str, points: &[[f64; 2]]) -> f64 {
    let fast = disk_voronoi_areas(points);
    let reference = reference_disk_voronoi_areas(points);
    assert_eq!(fast.len(), points.len());
    let total: f64 = fast.iter().sum();
    assert!(
        (total - TAU).abs() < 1e-9,
        "{name}: cells sum to {total}, not 2π"
    );
    let mut worst = 0.0f64;
    for (i, (f, r)) in fast.iter().zip(&reference).enumerate() {
        let difference = (f - r).abs() / r.abs().max(1e-300);
        assert!(
            difference <= TOLERANCE || (f - r).abs() <= ABSOLUTE_TOLERANCE_SR,
            "{name}: point {i} {:?}: cell {f} against the reference's {r} ({difference:e})",
            points[i]
        );
        worst = worst.max(difference);
    }
    worst
}

/// The projected directions of `m`'s valid samples in `hemisphere`.
fn projected(m: &Measurement, hemisphere: Hemisphere) -> Vec<[f64; 2]> {
    m.samples
        .iter()
        .filter(|s| {
            s.theta_deg.is_finite()
                && (0.0..=180.0).contains(&s.theta_deg)
                && s.phi_deg.is_finite()
                && s.hemisphere() == hemisphere
        })
        .map(|s| project(s.theta_deg, s.phi_deg, hemisphere))
        .collect()
}

fn snap(v: f64) -> f64 {
    let grid = 1.0 / (1u64 << 30) as f64;
    (v / grid).round() * grid
}

/// `n` uniform points in the disk, snapped to the projection's grid.
fn uniform_disk(rng: &mut Rng, n: usize) -> Vec<[f64; 2]> {
    (0..n)
        .map(|_| {
            let r = DISK_RADIUS * rng.uniform().sqrt();
            let a = TAU * rng.uniform();
            [snap(r * a.cos()), snap(r * a.sin())]
        })
        .collect()
}

#[test]
fn real_scans_give_the_reference_cells() {
    for (name, m) in [("golden_paper", golden()), ("layer_020_030", layer())] {
        let points = projected(m, Hemisphere::Front);
        assert!(points.len() > 100_000, "{name}: {} points", points.len());
        let worst = compare(name, &points);
        eprintln!("{name}: worst relative cell difference {worst:e}");
        // The whole path, samples to weights, also matches the reference.
        let weights = compute_solid_angles(&m.samples);
        let reference = reference_disk_voronoi_areas(&points);
        let front: Vec<f64> = m
            .samples
            .iter()
            .zip(&weights)
            .filter(|(s, _)| s.hemisphere() == Hemisphere::Front)
            .map(|(_, w)| *w)
            .collect();
        assert_eq!(front.len(), reference.len());
        for (w, r) in front.iter().zip(&reference) {
            assert!(
                (w - r).abs() <= TOLERANCE * r || (w - r).abs() <= ABSOLUTE_TOLERANCE_SR,
                "{name}: {w} against {r}"
            );
        }
    }
}

#[test]
fn synthetic_layouts_give_the_reference_cells() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);

    compare("uniform 50k", &uniform_disk(&mut rng, 50_000));

    // Gaussian clusters of very different sizes.
    let mut clustered = Vec::new();
    for c in 0..40 {
        let centre = uniform_disk(&mut rng, 1)[0];
        let spread = 1e-4 * 10f64.powi(c % 4);
        for _ in 0..500 {
            let p = [
                centre[0] + spread * rng.normal(),
                centre[1] + spread * rng.normal(),
            ];
            if p[0].hypot(p[1]) <= DISK_RADIUS {
                clustered.push([snap(p[0]), snap(p[1])]);
            }
        }
    }
    compare("clusters", &clustered);

    // Near-collinear paths 0.04° apart, like the instrument's adaptive runs.
    let mut paths = Vec::new();
    for _ in 0..100 {
        let theta0 = 85.0 * rng.uniform();
        let phi0 = 360.0 * rng.uniform();
        let (dtheta, dphi) = (0.04 * rng.normal(), 0.04 * rng.normal());
        for k in 0..300 {
            let theta = theta0 + dtheta * k as f64;
            if (0.0..=90.0).contains(&theta) {
                paths.push(project(theta, phi0 + dphi * k as f64, Hemisphere::Front));
            }
        }
    }
    compare("paths", &paths);

    // A square grid (every cell's corners cocircular) and rings of constant
    // θ (cocircular by construction), both full of degenerate Delaunay cases.
    let mut grid = Vec::new();
    for i in -60..=60 {
        for j in -60..=60 {
            let p = [i as f64 / 45.0, j as f64 / 45.0];
            if p[0].hypot(p[1]) <= DISK_RADIUS {
                grid.push(p);
            }
        }
    }
    compare("grid", &grid);
    let mut rings = Vec::new();
    for i in 0..60 {
        for j in 0..120 {
            rings.push(project(1.5 * i as f64, 3.0 * j as f64, Hemisphere::Front));
        }
    }
    compare("rings with the pole repeated", &rings);

    // Points on the rim of the disk.
    let rim: Vec<[f64; 2]> = (0..1000)
        .map(|k| {
            let a = TAU * k as f64 / 1000.0;
            [DISK_RADIUS * a.cos(), DISK_RADIUS * a.sin()]
        })
        .collect();
    compare("rim", &rim);

    // Small and degenerate sets.
    compare("one", &[[0.3, -0.2]]);
    compare("two", &[[0.3, -0.2], [-0.1, 0.4]]);
    compare(
        "collinear",
        &[[0.1, 0.1], [0.2, 0.2], [0.3, 0.3], [0.5, 0.5]],
    );
    compare("all the same", &[[0.2, 0.1]; 7]);
}

#[test]
fn duplicates_share_their_cell_and_order_does_not_matter() {
    let mut rng = Rng(0x0123_4567_89ab_cdef);
    let mut points = uniform_disk(&mut rng, 5_000);
    // Every tenth point twice more, every hundredth four times more.
    for i in 0..500 {
        points.push(points[10 * i]);
        points.push(points[10 * i]);
    }
    for i in 0..50 {
        for _ in 0..4 {
            points.push(points[100 * i]);
        }
    }
    compare("duplicates", &points);
    let areas = disk_voronoi_areas(&points);
    assert_eq!(areas[10], areas[5_000 + 2]);
    assert_eq!(areas[100], areas[6_000 + 4]);
    // Reversed input: the same cells, bit for bit.
    let reversed: Vec<[f64; 2]> = points.iter().rev().copied().collect();
    let mut areas_reversed = disk_voronoi_areas(&reversed);
    areas_reversed.reverse();
    assert_eq!(areas, areas_reversed);
}

#[test]
fn points_beyond_the_fast_path_use_the_reference() {
    // Beyond radius 2√2 (never produced by the projection) the reference
    // computes the cells, so both agree exactly.
    let points = [[0.0, 0.0], [0.5, 0.5], [3.5, 0.0]];
    assert_eq!(
        disk_voronoi_areas(&points),
        reference_disk_voronoi_areas(&points)
    );
    let total: f64 = disk_voronoi_areas(&points).iter().sum();
    assert!((total - 2.0 * PI).abs() < 1e-9);
}

#[test]
fn one_thread_and_two_give_the_same_cells() {
    // Two threads split the points at a median abscissa, sort and
    // triangulate each half on its own thread and re-triangulate the seam;
    // one thread triangulates everything at once. The Voronoi diagram is
    // the same, so the cells agree to rounding, on both real scans.
    for (name, m) in [("golden_paper", golden()), ("layer_020_030", layer())] {
        let points = projected(m, Hemisphere::Front);
        let with = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| disk_voronoi_areas(&points))
        };
        let (one, two) = (with(1), with(2));
        assert_eq!(one.len(), two.len());
        // Not bit for bit: otherwise the split path gave up and fell back to
        // the single triangulation, and this test compares nothing.
        assert_ne!(one, two, "{name}: two threads did not take the split path");
        for (i, (a, b)) in one.iter().zip(&two).enumerate() {
            assert!(
                (a - b).abs() <= TOLERANCE * b.abs() || (a - b).abs() <= ABSOLUTE_TOLERANCE_SR,
                "{name}: point {i}: {a} with one thread, {b} with two"
            );
        }
        let total: f64 = two.iter().sum();
        assert!((total - TAU).abs() < 1e-9, "{name}: {total}");
    }
}
