//! Shadows found in a scan: connected regions that read far below their
//! mirror across the plane of incidence.
//!
//! An isotropic sample scatters the same light to (θ, φ_in + δ) as to
//! (θ, φ_in − δ). Something between the sample and the detector on one
//! side (the pgII sample holder, at φ_out − φ_in ≈ 270° beyond θ_out 73°)
//! breaks that symmetry: those directions read a fraction of their
//! mirror's value. [`detect`] compares each sample with the sample nearest
//! its mirror direction, marks the cells of a 3° × 3° grid whose median
//! ratio is below the threshold, joins touching marked cells into regions
//! and flags the samples of each region of 20 or more that read below
//! their mirror (and in the cells around it, which the shadow's edge
//! crosses, those below the threshold). A real asymmetry of the material (an anisotropic lobe
//! turned in the plane) is found the same way: the detection is for
//! scans of isotropic samples (`brtf fit --mask-holder auto`).

use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;

/// Side of the grid's cells, degrees.
const CELL_DEG: f64 = 3.0;
/// The most a mirror sample may lie from the exact mirror direction, degrees.
const MIRROR_TOLERANCE_DEG: f64 = 1.5;
/// The fewest samples of a region.
const MIN_REGION_SAMPLES: usize = 20;
/// The fewest samples with a ratio in a marked cell.
const MIN_CELL_SAMPLES: usize = 1;

/// One shadow found.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ShadowRegion {
    /// Samples flagged.
    pub samples: usize,
    /// Solid angle of the region's grid cells, sr.
    pub solid_angle_sr: f64,
    /// Median ratio of the flagged samples to their mirrors.
    pub median_ratio: f64,
    /// θ_out range of the flagged samples (from the nearer normal), degrees.
    pub theta_deg: [f64; 2],
    /// φ_out − φ_in range of the flagged samples, degrees in [0, 360)
    /// (the first may exceed the second when the range wraps through 0).
    pub phi_from_incidence_deg: [f64; 2],
}

impl std::fmt::Display for ShadowRegion {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} samples, {:.3} sr, median {:.3} of their mirror, φ_out − φ_in {:.0}–{:.0}°, θ_out {:.1}–{:.1}°",
            self.samples,
            self.solid_angle_sr,
            self.median_ratio,
            self.phi_from_incidence_deg[0],
            self.phi_from_incidence_deg[1],
            self.theta_deg[0],
            self.theta_deg[1]
        )
    }
}

/// What [`detect`] found: per sample whether it lies in a shadow, and the
/// regions.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ShadowScan {
    /// Per sample (in the order given): in a shadow.
    pub flagged: Vec<bool>,
    /// The regions, largest first.
    pub regions: Vec<ShadowRegion>,
}

/// Finds the shadows among the `candidates` of a scan whose light lies at
/// azimuth `phi_in_deg`: `directions` (unit vectors) and `values` (one per
/// sample, NaN when not available) of every sample, the candidates those
/// still in the fit. Only candidates at least `min_theta_deg` from the
/// nearer normal are judged; any sample with a positive value may be a
/// mirror. A region's cells must have a median ratio below `max_ratio`.
pub fn detect(
    directions: &[DVec3],
    values: &[f64],
    candidates: &[bool],
    phi_in_deg: f64,
    max_ratio: f64,
    min_theta_deg: f64,
) -> ShadowScan {
    let n = directions.len();
    let mut scan = ShadowScan {
        flagged: vec![false; n],
        regions: Vec::new(),
    };
    // Every usable mirror, hashed by a cube grid of about the tolerance.
    let step = MIRROR_TOLERANCE_DEG.to_radians();
    let key = |d: DVec3| {
        (
            (d.x / step).floor() as i32,
            (d.y / step).floor() as i32,
            (d.z / step).floor() as i32,
        )
    };
    let mut grid: HashMap<(i32, i32, i32), Vec<u32>> = HashMap::new();
    for (i, (&d, &v)) in directions.iter().zip(values).enumerate() {
        if v.is_finite() && v > 0.0 {
            grid.entry(key(d)).or_default().push(i as u32);
        }
    }
    // The mirror across the plane of incidence: the plane through the
    // normal and the light's azimuth.
    let (sin2, cos2) = (2.0 * phi_in_deg.to_radians()).sin_cos();
    let mirror = |d: DVec3| DVec3::new(cos2 * d.x + sin2 * d.y, sin2 * d.x - cos2 * d.y, d.z);
    let min_cos = MIRROR_TOLERANCE_DEG.to_radians().cos();
    let columns = (360.0 / CELL_DEG).round() as i64;
    let mut cells: HashMap<(i64, i64), Vec<(usize, f64)>> = HashMap::new();
    for i in 0..n {
        let d = directions[i];
        let theta = d.z.abs().clamp(0.0, 1.0).acos().to_degrees();
        if !candidates[i] || theta < min_theta_deg || !values[i].is_finite() {
            continue;
        }
        let m = mirror(d);
        let (kx, ky, kz) = key(m);
        let mut best: Option<(f64, u32)> = None;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    for &j in grid.get(&(kx + dx, ky + dy, kz + dz)).into_iter().flatten() {
                        let c = directions[j as usize].dot(m);
                        if c >= min_cos && best.is_none_or(|(b, _)| c > b) {
                            best = Some((c, j));
                        }
                    }
                }
            }
        }
        let Some((_, j)) = best else { continue };
        if j as usize == i {
            continue;
        }
        let ratio = values[i] / values[j as usize];
        let phi = d.y.atan2(d.x).to_degrees().rem_euclid(360.0);
        let cell = (
            (theta / CELL_DEG).floor() as i64,
            ((phi / CELL_DEG).floor() as i64).rem_euclid(columns),
        );
        cells.entry(cell).or_default().push((i, ratio));
    }
    let dark: Vec<(i64, i64)> = cells
        .iter()
        .filter(|(_, members)| {
            members.len() >= MIN_CELL_SAMPLES && median(members.iter().map(|m| m.1)) < max_ratio
        })
        .map(|(&c, _)| c)
        .collect();
    let mut unvisited: std::collections::HashSet<(i64, i64)> = dark.iter().copied().collect();
    let mut order = dark;
    order.sort_unstable();
    for start in order {
        if !unvisited.remove(&start) {
            continue;
        }
        let mut region = vec![start];
        let mut next = 0;
        while next < region.len() {
            let (row, column) = region[next];
            next += 1;
            for dr in -1..=1 {
                for dc in -1..=1 {
                    let neighbour = (row + dr, (column + dc).rem_euclid(columns));
                    if unvisited.remove(&neighbour) {
                        region.push(neighbour);
                    }
                }
            }
        }
        // The region's samples below their mirror, and in the cells around
        // it (which the shadow's edge crosses) those below the threshold.
        let inside: std::collections::HashSet<(i64, i64)> = region.iter().copied().collect();
        let mut rim: Vec<(i64, i64)> = region
            .iter()
            .flat_map(|&(row, column)| {
                (-1..=1).flat_map(move |dr| {
                    (-1..=1).map(move |dc| (row + dr, (column + dc).rem_euclid(columns)))
                })
            })
            .filter(|c| !inside.contains(c) && cells.contains_key(c))
            .collect();
        rim.sort_unstable();
        rim.dedup();
        let members: Vec<(usize, f64)> = region
            .iter()
            .flat_map(|c| cells[c].iter().copied())
            .filter(|&(_, ratio)| ratio < 1.0)
            .chain(
                rim.iter()
                    .flat_map(|c| cells[c].iter().copied())
                    .filter(|&(_, ratio)| ratio < max_ratio),
            )
            .collect();
        if members.len() < MIN_REGION_SAMPLES {
            continue;
        }
        for &(i, _) in &members {
            scan.flagged[i] = true;
        }
        scan.regions
            .push(describe(&region, &members, directions, phi_in_deg));
    }
    scan.regions.sort_by_key(|r| std::cmp::Reverse(r.samples));
    scan
}

/// A region's record from its grid cells and flagged members.
fn describe(
    cells: &[(i64, i64)],
    members: &[(usize, f64)],
    directions: &[DVec3],
    phi_in_deg: f64,
) -> ShadowRegion {
    let solid_angle_sr = cells
        .iter()
        .map(|&(row, _)| {
            let (a, b) = ((row as f64) * CELL_DEG, (row as f64 + 1.0) * CELL_DEG);
            CELL_DEG.to_radians()
                * (a.to_radians().cos() - b.to_radians().min(90f64.to_radians()).cos())
        })
        .sum();
    let thetas: Vec<f64> = members
        .iter()
        .map(|&(i, _)| directions[i].z.abs().clamp(0.0, 1.0).acos().to_degrees())
        .collect();
    let phis: Vec<f64> = members
        .iter()
        .map(|&(i, _)| {
            let d = directions[i];
            (d.y.atan2(d.x).to_degrees() - phi_in_deg).rem_euclid(360.0)
        })
        .collect();
    // The azimuth range about the circular mean, so that it may wrap.
    let (s, c) = phis.iter().fold((0.0, 0.0), |(s, c), p| {
        (s + p.to_radians().sin(), c + p.to_radians().cos())
    });
    let centre = f64::atan2(s, c).to_degrees();
    let offsets = phis
        .iter()
        .map(|p| (p - centre + 180.0).rem_euclid(360.0) - 180.0);
    let (lo, hi) = offsets.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), o| {
        (lo.min(o), hi.max(o))
    });
    ShadowRegion {
        samples: members.len(),
        solid_angle_sr,
        median_ratio: median(members.iter().map(|m| m.1)),
        theta_deg: [
            thetas.iter().copied().fold(f64::INFINITY, f64::min),
            thetas.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        ],
        phi_from_incidence_deg: [
            (centre + lo).rem_euclid(360.0),
            (centre + hi).rem_euclid(360.0),
        ],
    }
}

/// The median of `values` (NaN for none).
fn median(values: impl Iterator<Item = f64>) -> f64 {
    let mut v: Vec<f64> = values.collect();
    if v.is_empty() {
        return f64::NAN;
    }
    let mid = v.len() / 2;
    *v.select_nth_unstable_by(mid, f64::total_cmp).1
}

#[cfg(test)]
mod tests {
    use super::*;

    fn direction(theta: f64, phi: f64) -> DVec3 {
        let (t, p) = (theta.to_radians(), phi.to_radians());
        DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
    }

    /// A symmetric scan on a 1° grid, darkened 100× where `shadow` says.
    fn scan(phi_in: f64, shadow: impl Fn(f64, f64) -> bool) -> (Vec<DVec3>, Vec<f64>) {
        let mut dirs = Vec::new();
        let mut values = Vec::new();
        for t in 0..86 {
            for p in 0..360 {
                let (theta, phi) = (t as f64 + 0.5, p as f64 + 0.25);
                let d = direction(theta, phi);
                // Symmetric about the plane of incidence, varying with both.
                let rel = (phi - phi_in).to_radians();
                let mut v = 1.0 + 0.5 * rel.cos() + 0.01 * theta;
                if shadow(theta, (phi - phi_in).rem_euclid(360.0)) {
                    v *= 0.01;
                }
                dirs.push(d);
                values.push(v);
            }
        }
        (dirs, values)
    }

    #[test]
    fn a_shadow_beside_the_plane_of_incidence_is_found_where_it_is() {
        let inside = |theta: f64, rel: f64| theta >= 74.0 && (225.0..=315.0).contains(&rel);
        let (dirs, values) = scan(210.0, inside);
        let all = vec![true; dirs.len()];
        let found = detect(&dirs, &values, &all, 210.0, 0.5, 60.0);
        assert_eq!(found.regions.len(), 1, "{:?}", found.regions);
        let r = &found.regions[0];
        assert!(r.median_ratio < 0.02, "{r}");
        assert!(r.theta_deg[0] >= 73.5 && r.theta_deg[1] <= 86.0, "{r}");
        assert!((r.phi_from_incidence_deg[0] - 225.0).abs() < 2.0, "{r}");
        assert!((r.phi_from_incidence_deg[1] - 315.0).abs() < 2.0, "{r}");
        // Every shadowed sample is flagged, no other.
        let mut missed = 0;
        let mut wrong = 0;
        for (i, d) in dirs.iter().enumerate() {
            let theta = d.z.acos().to_degrees();
            let rel = (d.y.atan2(d.x).to_degrees() - 210.0).rem_euclid(360.0);
            match (inside(theta, rel), found.flagged[i]) {
                (true, false) => missed += 1,
                (false, true) => wrong += 1,
                _ => {}
            }
        }
        assert_eq!((missed, wrong), (0, 0));
    }

    #[test]
    fn a_symmetric_scan_has_no_shadow() {
        let (dirs, values) = scan(0.0, |_, _| false);
        let all = vec![true; dirs.len()];
        let found = detect(&dirs, &values, &all, 0.0, 0.5, 60.0);
        assert!(found.regions.is_empty(), "{:?}", found.regions);
        assert!(!found.flagged.iter().any(|&f| f));
    }
}
