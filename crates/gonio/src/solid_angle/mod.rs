//! Per-sample solid angles (quadrature weights) from the sample directions.
//!
//! This module owns the answer to "how much of the sphere does each sample
//! stand for?". [`solid_angles`] uses the file's Voronoi cell sizes when
//! every sample has a valid one and otherwise calls
//! [`compute_solid_angles`], which works on the directions alone, one
//! hemisphere at a time, and picks one of two exact partitions of the
//! hemisphere by looking at the layout ([`detect_layout`]):
//!
//! * **Rings** ([`Layout::Rings`], module `rings`): the directions lie on
//!   rings of (near-)constant θ about the hemisphere's normal, as in a
//!   regular (θ, φ) scan. Each sample owns the spherical cell between the
//!   mid-θ of its ring and the neighbouring rings, and between the mid-φ of
//!   its neighbours on the ring. The cells are exact on the sphere, cost one
//!   sort, and sum to 2π.
//! * **Scattered** ([`Layout::Scattered`], module `voronoi`): anything else,
//!   such as the adaptive paths of the real pgII scans. Each sample owns
//!   its equal-area Voronoi cell (Lambert projection, Delaunay
//!   triangulation, cells clipped to the disk), which also sums to 2π.
//!
//! On ring layouts both give the same total and, for rings sampled densely
//! in φ, the same cells to well under 1 % (the test `solid_angle_paths`).
//! Non-finite directions get weight 0. Coincident directions share one cell
//! equally. The result is deterministic and independent of the sample
//! order.

mod delaunay;
mod rings;
mod voronoi;

use serde::{Deserialize, Serialize};

use crate::measurement::{Hemisphere, Measurement, Sample};

pub use voronoi::{
    DISK_RADIUS, disk_polygon_area, disk_voronoi_areas, project, reference_disk_voronoi_areas,
};

/// Where a set of solid angles came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SolidAngleSource {
    /// The file's Voronoi cell sizes (`.mpc` column 8, or
    /// [`Sample::solid_angle_sr`] set by code).
    File,
    /// Computed from the sample directions by [`compute_solid_angles`].
    Computed,
}

/// Per-sample solid angles, parallel to [`Measurement::samples`].
#[derive(Clone, Debug, PartialEq)]
pub struct SolidAngles {
    /// Solid angle of each sample, sr.
    pub per_sample_sr: Vec<f64>,
    /// Where they came from.
    pub source: SolidAngleSource,
}

/// How the directions of one hemisphere are laid out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// Rings of near-constant θ about the hemisphere's normal.
    Rings,
    /// Anything else.
    Scattered,
}

/// The solid angles to use for `measurement`: the file's when every sample
/// has a finite, non-negative one, computed ones otherwise.
pub fn solid_angles(measurement: &Measurement) -> SolidAngles {
    let from_file: Option<Vec<f64>> = measurement
        .samples
        .iter()
        .map(|s| s.solid_angle_sr.filter(|w| w.is_finite() && *w >= 0.0))
        .collect();
    match from_file {
        Some(per_sample_sr) if !per_sample_sr.is_empty() => SolidAngles {
            per_sample_sr,
            source: SolidAngleSource::File,
        },
        _ => SolidAngles {
            per_sample_sr: compute_solid_angles(&measurement.samples),
            source: SolidAngleSource::Computed,
        },
    }
}

impl Measurement {
    /// Sets every sample's [`Sample::solid_angle_sr`] from
    /// [`solid_angles`], so the weights survive later selections.
    pub fn fill_solid_angles(&mut self) -> SolidAngleSource {
        let weights = solid_angles(self);
        self.set_solid_angles(&weights);
        weights.source
    }

    /// Sets every sample's [`Sample::solid_angle_sr`] from `weights`
    /// (computed for the same samples, in the same order).
    pub fn set_solid_angles(&mut self, weights: &SolidAngles) {
        debug_assert_eq!(self.samples.len(), weights.per_sample_sr.len());
        for (sample, w) in self.samples.iter_mut().zip(&weights.per_sample_sr) {
            sample.solid_angle_sr = Some(*w);
        }
    }
}

/// Which path [`compute_solid_angles`] forces, for comparing them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Path {
    /// Rings where detected, Voronoi otherwise.
    Detect,
    /// Always the Voronoi cells.
    Voronoi,
}

/// Solid angles (sr) computed from the sample directions alone; see the
/// module docs. Each hemisphere's weights sum to 2π when it has samples.
pub fn compute_solid_angles(samples: &[Sample]) -> Vec<f64> {
    compute(samples, Path::Detect)
}

/// Solid angles from the equal-area Voronoi cells whatever the layout (the
/// general path of [`compute_solid_angles`]).
pub fn voronoi_solid_angles(samples: &[Sample]) -> Vec<f64> {
    compute(samples, Path::Voronoi)
}

/// The layout of each hemisphere's valid directions, front then back
/// (`None` for a hemisphere without samples).
pub fn detect_layout(samples: &[Sample]) -> [Option<Layout>; 2] {
    let [front, back] = both_hemispheres(samples);
    [(Hemisphere::Front, front), (Hemisphere::Back, back)].map(|(hemisphere, (_, directions))| {
        if directions.is_empty() {
            None
        } else if rings::ring_areas(&directions, hemisphere).is_some() {
            Some(Layout::Rings)
        } else {
            Some(Layout::Scattered)
        }
    })
}

fn compute(samples: &[Sample], path: Path) -> Vec<f64> {
    let mut weights = vec![0.0; samples.len()];
    let [front, back] = both_hemispheres(samples);
    for (hemisphere, (indices, directions)) in
        [(Hemisphere::Front, front), (Hemisphere::Back, back)]
    {
        if directions.is_empty() {
            continue;
        }
        let rings = match path {
            Path::Detect => rings::ring_areas(&directions, hemisphere),
            Path::Voronoi => None,
        };
        let areas = rings.unwrap_or_else(|| voronoi::hemisphere_areas(&directions, hemisphere));
        for (i, area) in indices.into_iter().zip(areas) {
            weights[i] = area;
        }
    }
    weights
}

/// Sample indices and their `(θ, φ)` in degrees.
type Directions = (Vec<usize>, Vec<(f64, f64)>);

/// The indices and `(θ, φ)` of the valid samples in each hemisphere, front
/// then back, in one pass.
fn both_hemispheres(samples: &[Sample]) -> [Directions; 2] {
    let mut split: [Directions; 2] = Default::default();
    for (i, s) in samples.iter().enumerate() {
        let valid = s.theta_deg.is_finite()
            && (0.0..=180.0).contains(&s.theta_deg)
            && s.phi_deg.is_finite();
        if valid {
            let side = &mut split[usize::from(s.hemisphere() == Hemisphere::Back)];
            side.0.push(i);
            side.1.push((s.theta_deg, s.phi_deg));
        }
    }
    split
}
