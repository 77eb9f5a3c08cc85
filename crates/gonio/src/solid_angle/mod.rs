//! Per-sample solid angles (quadrature weights) from the sample directions.
//!
//! This module owns the answer to "how much of the sphere does each sample
//! stand for?". [`solid_angles`] uses the file's Voronoi cell sizes when
//! every sample has a valid one and otherwise calls
//! [`compute_solid_angles`], which works on the directions alone, one
//! hemisphere at a time, and picks one of two exact partitions of the
//! hemisphere by looking at the layout ([`detect_layout`]):
//!
//! * **Rings** ([`DirectionLayout::Rings`], module `rings`): the directions lie on
//!   rings of (near-)constant θ about the hemisphere's normal, as in a
//!   regular (θ, φ) scan. Each sample owns the spherical cell between the
//!   mid-θ of its ring and the neighbouring rings, and between the mid-φ of
//!   its neighbours on the ring. The cells are exact on the sphere, cost one
//!   sort, and sum to 2π.
//! * **Scattered** ([`DirectionLayout::Scattered`], module `voronoi`): anything else,
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

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::measurement::{Hemisphere, Measurement, Sample};

pub use voronoi::{DISK_RADIUS, disk_voronoi_areas, project, reference_disk_voronoi_areas};

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
pub enum DirectionLayout {
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
pub fn detect_layout(samples: &[Sample]) -> [Option<DirectionLayout>; 2] {
    let [front, back] = both_hemispheres(samples);
    [(Hemisphere::Front, front), (Hemisphere::Back, back)].map(|(hemisphere, members)| {
        if members.is_empty() {
            None
        } else if rings::ring_areas_of(members.len(), |k| members.direction(k), hemisphere)
            .is_some()
        {
            Some(DirectionLayout::Rings)
        } else {
            Some(DirectionLayout::Scattered)
        }
    })
}

fn compute(samples: &[Sample], path: Path) -> Vec<f64> {
    let [front, back] = both_hemispheres(samples);
    let mut weights: Option<Vec<f64>> = None;
    for (hemisphere, members) in [(Hemisphere::Front, front), (Hemisphere::Back, back)] {
        if members.is_empty() {
            continue;
        }
        let direction = |k: usize| members.direction(k);
        let rings = match path {
            Path::Detect => rings::ring_areas_of(members.len(), direction, hemisphere),
            Path::Voronoi => None,
        };
        let areas = rings
            .unwrap_or_else(|| voronoi::hemisphere_areas(members.len(), direction, hemisphere));
        match &members.indices {
            // Every sample is in this hemisphere: its areas are the weights.
            None => return areas,
            Some(indices) => {
                let weights = weights.get_or_insert_with(|| vec![0.0; samples.len()]);
                for (&i, area) in indices.iter().zip(areas) {
                    weights[i as usize] = area;
                }
            }
        }
    }
    weights.unwrap_or_else(|| vec![0.0; samples.len()])
}

/// The valid samples of one hemisphere.
struct Members<'a> {
    samples: &'a [Sample],
    /// Their indices in `samples`, in order; `None` when they are all the
    /// samples (a one-sided scan: no index list to build or scatter
    /// through).
    indices: Option<Vec<u32>>,
}

impl Members<'_> {
    fn len(&self) -> usize {
        self.indices.as_ref().map_or(self.samples.len(), Vec::len)
    }

    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// `(θ, φ)` in degrees of the `k`-th member.
    #[inline]
    fn direction(&self, k: usize) -> (f64, f64) {
        let s = match &self.indices {
            None => &self.samples[k],
            Some(indices) => &self.samples[indices[k] as usize],
        };
        (s.theta_deg, s.phi_deg)
    }
}

/// Samples per piece of the parallel hemisphere split.
const SPLIT_CHUNK: usize = 16_384;

/// Which list a sample goes to: 0 front, 1 back, 2 none (not a valid
/// direction).
#[inline]
fn side_of(s: &Sample) -> usize {
    let valid =
        s.theta_deg.is_finite() && (0.0..=180.0).contains(&s.theta_deg) && s.phi_deg.is_finite();
    if !valid {
        2
    } else {
        usize::from(s.hemisphere() == Hemisphere::Back)
    }
}

/// The valid samples of each hemisphere, front then back: counted in
/// parallel pieces, then each piece writes its indices into its share of
/// the lists. A hemisphere holding every sample needs no list.
fn both_hemispheres(samples: &[Sample]) -> [Members<'_>; 2] {
    let all = |indices| Members { samples, indices };
    if samples.len() >= u32::MAX as usize {
        // Beyond u32 indices (never in practice): one sequential pass.
        let mut lists: [Vec<u32>; 2] = Default::default();
        for (i, s) in samples.iter().enumerate() {
            if let Some(list) = lists.get_mut(side_of(s)) {
                list.push(i as u32);
            }
        }
        return lists.map(|list| all(Some(list)));
    }
    let counts: Vec<[usize; 3]> = samples
        .par_chunks(SPLIT_CHUNK)
        .map(|chunk| {
            let mut count = [0; 3];
            for s in chunk {
                count[side_of(s)] += 1;
            }
            count
        })
        .collect();
    let totals = counts
        .iter()
        .fold([0; 3], |t, c| [t[0] + c[0], t[1] + c[1], t[2] + c[2]]);
    for side in 0..2 {
        if totals[side] == samples.len() {
            let mut members = [all(Some(Vec::new())), all(Some(Vec::new()))];
            members[side].indices = None;
            return members;
        }
    }
    let mut lists = [vec![0u32; totals[0]], vec![0u32; totals[1]]];
    // Each piece's share of the two lists.
    let mut shares: Vec<[&mut [u32]; 2]> = Vec::with_capacity(counts.len());
    {
        let [mut front, mut back] = lists.each_mut().map(|list| list.as_mut_slice());
        for count in &counts {
            let (f, rest_f) = front.split_at_mut(count[0]);
            let (b, rest_b) = back.split_at_mut(count[1]);
            shares.push([f, b]);
            (front, back) = (rest_f, rest_b);
        }
    }
    samples
        .par_chunks(SPLIT_CHUNK)
        .zip(shares)
        .enumerate()
        .for_each(|(piece, (chunk, share))| {
            let first = piece * SPLIT_CHUNK;
            let mut next = [0usize; 2];
            for (k, s) in chunk.iter().enumerate() {
                let side = side_of(s);
                if side < 2 {
                    share[side][next[side]] = (first + k) as u32;
                    next[side] += 1;
                }
            }
        });
    lists.map(|list| all(Some(list)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The parallel split gives, per hemisphere, exactly the valid samples
    /// in order, across piece boundaries and with invalid samples mixed in;
    /// a one-sided set needs no index list; and the weights of a mixed set
    /// are each hemisphere's cells, 0 for invalid samples.
    #[test]
    fn hemispheres_are_split_in_order() {
        let mut rng = brtf_model::Rng::new(18, 1);
        let samples: Vec<Sample> = (0..3 * SPLIT_CHUNK + 123)
            .map(|i| {
                let theta = match i % 97 {
                    0 => f64::NAN,
                    1 => 180.5,
                    2 => -0.5,
                    _ => 180.0 * rng.uniform(),
                };
                let phi = if i % 89 == 0 {
                    f64::INFINITY
                } else {
                    360.0 * rng.uniform()
                };
                Sample::luminance(theta, phi, 1.0)
            })
            .collect();
        let expected = |hemisphere: Hemisphere| -> Vec<u32> {
            (0..samples.len() as u32)
                .filter(|&i| {
                    let s = &samples[i as usize];
                    s.theta_deg.is_finite()
                        && (0.0..=180.0).contains(&s.theta_deg)
                        && s.phi_deg.is_finite()
                        && s.hemisphere() == hemisphere
                })
                .collect()
        };
        let [front, back] = both_hemispheres(&samples);
        assert_eq!(front.indices, Some(expected(Hemisphere::Front)));
        assert_eq!(back.indices, Some(expected(Hemisphere::Back)));
        let k = front.len() / 2;
        let i = front.indices.as_ref().unwrap()[k] as usize;
        assert_eq!(
            front.direction(k),
            (samples[i].theta_deg, samples[i].phi_deg)
        );

        let weights = compute_solid_angles(&samples);
        for (hemisphere, members) in [(Hemisphere::Front, &front), (Hemisphere::Back, &back)] {
            let indices = members.indices.as_ref().unwrap();
            let directions: Vec<(f64, f64)> =
                (0..members.len()).map(|k| members.direction(k)).collect();
            let areas = voronoi::hemisphere_areas(directions.len(), |k| directions[k], hemisphere);
            for (&i, area) in indices.iter().zip(&areas) {
                assert_eq!(weights[i as usize], *area);
            }
            let total: f64 = areas.iter().sum();
            assert!((total - std::f64::consts::TAU).abs() < 1e-9);
        }
        let valid = front.len() + back.len();
        assert!(valid < samples.len());
        assert_eq!(
            weights.iter().filter(|w| **w == 0.0).count(),
            samples.len() - valid
        );

        let one_sided: Vec<Sample> = samples
            .iter()
            .filter(|s| side_of(s) == 1)
            .copied()
            .collect();
        let [front, back] = both_hemispheres(&one_sided);
        assert!(front.is_empty() && back.indices.is_none() && back.len() == one_sided.len());
    }
}
