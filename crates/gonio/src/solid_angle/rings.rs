//! The ring path: spherical cells for directions on rings of constant θ.
//!
//! Regular scans (ISE `.mpc` grids, brtf's benches and many synthetic
//! layouts) put their directions on rings of constant θ' (the angle from
//! the hemisphere's normal) with many azimuths each. Then each sample can
//! own an exact spherical cell: the band between the mid-θ' of its ring and
//! its neighbouring rings (0° below the first ring, 90° above the last),
//! cut between the mid-φ of its neighbours on the ring. A band from θ₁ to
//! θ₂ over Δφ has the solid angle Δφ (cos θ₁ − cos θ₂), so the cells sum
//! to 2π exactly, and finding them costs one sort instead of a Delaunay
//! triangulation.

use crate::measurement::Hemisphere;

/// Sorted θ' values further apart than this start a new ring (degrees).
/// Ring positions of gonio-photometers repeat far better than this, and
/// ring spacings are tens of times larger.
const RING_JITTER_DEG: f64 = 0.01;

/// A ring wider than this in θ' is no ring: the directions are scattered.
const MAX_RING_SPREAD_DEG: f64 = 0.02;

/// The gap between two rings must be this many times the wider ring's
/// spread, so that mid-ring boundaries are well defined.
const MIN_GAP_OVER_SPREAD: f64 = 4.0;

/// A ring layout has at least this many directions per ring on average;
/// fewer (an in-plane scan, a handful of directions) is left to the
/// Voronoi cells.
const MIN_MEAN_RING_SIZE: usize = 3;

/// Azimuths closer than this (degrees) are one direction and share a cell.
const SAME_PHI_DEG: f64 = 1e-9;

/// A ring whose θ' is below this (degrees) is the pole: one direction.
const POLE_DEG: f64 = 1e-9;

/// One ring: a run of the θ'-sorted directions.
struct Ring {
    start: usize,
    end: usize,
    mean_deg: f64,
}

/// The cell solid angles (sr) of `directions` (θ, φ in degrees, valid and
/// all in `hemisphere`) when they form a ring layout, else `None`.
#[cfg(test)]
pub(crate) fn ring_areas(directions: &[(f64, f64)], hemisphere: Hemisphere) -> Option<Vec<f64>> {
    ring_areas_of(directions.len(), |k| directions[k], hemisphere)
}

/// [`ring_areas`] of the `count` directions `direction(k)`: the run test
/// reads only θ, and the directions are gathered only for a sort.
pub(crate) fn ring_areas_of(
    count: usize,
    direction: impl Fn(usize) -> (f64, f64),
    hemisphere: Hemisphere,
) -> Option<Vec<f64>> {
    if has_wide_run((0..count).map(|k| direction(k).0), hemisphere) {
        return None;
    }
    let directions: Vec<(f64, f64)> = (0..count).map(direction).collect();
    sorted_ring_areas(&directions, hemisphere)
}

/// Width of the θ' bins of [`has_wide_run`], degrees: two values in
/// neighbouring bins are less than `2 · RUN_BIN_DEG = RING_JITTER_DEG`
/// apart, so they fall in one ring.
const RUN_BIN_DEG: f64 = 0.5 * RING_JITTER_DEG;
/// Occupied neighbouring bins that prove a ring wider than
/// `MAX_RING_SPREAD_DEG`: their values chain into one ring spanning more
/// than `(RUN_BINS − 2) · RUN_BIN_DEG` = 0.025° (one bin of margin for
/// the rounding of the bin index).
const RUN_BINS: usize = 7;

/// True when the directions' θ' values (from the hemisphere's normal)
/// occupy [`RUN_BINS`] neighbouring bins of [`RUN_BIN_DEG`]: then they
/// chain into a ring wider than [`MAX_RING_SPREAD_DEG`], and
/// [`sorted_ring_areas`] would find no ring layout. One pass, no sort,
/// stopping at the first such run: the scattered layouts of real scans are
/// refused after a few directions. `false` says nothing.
fn has_wide_run(thetas: impl Iterator<Item = f64>, hemisphere: Hemisphere) -> bool {
    let bins = (90.0 / RUN_BIN_DEG) as usize + 1;
    let mut occupied = vec![false; bins];
    for theta in thetas {
        let from_normal = match hemisphere {
            Hemisphere::Front => theta,
            Hemisphere::Back => 180.0 - theta,
        };
        // Values outside 0..=90 (none for valid directions) are left out:
        // fewer occupied bins only make a proof less likely.
        if !(0.0..=90.0).contains(&from_normal) {
            continue;
        }
        let bin = ((from_normal / RUN_BIN_DEG) as usize).min(bins - 1);
        if occupied[bin] {
            continue;
        }
        occupied[bin] = true;
        // The run through the newly occupied bin: on a scattered layout one
        // is found after a few directions, and the rest are not read.
        let below = occupied[..bin].iter().rev().take_while(|&&o| o).count();
        let above = occupied[bin + 1..].iter().take_while(|&&o| o).count();
        if below + 1 + above >= RUN_BINS {
            return true;
        }
    }
    false
}

/// [`ring_areas`] by sorting all directions by θ'.
fn sorted_ring_areas(directions: &[(f64, f64)], hemisphere: Hemisphere) -> Option<Vec<f64>> {
    let n = directions.len();
    if u32::try_from(n).is_err() {
        return None;
    }
    // (θ', φ in [0, 360), index), sorted by θ' then φ: the order, and so
    // the result, does not depend on the input order.
    let mut sorted: Vec<(f64, f64, u32)> = directions
        .iter()
        .enumerate()
        .map(|(i, &(theta, phi))| {
            let from_normal = match hemisphere {
                Hemisphere::Front => theta,
                Hemisphere::Back => 180.0 - theta,
            };
            // φ in [0, 360), with azimuths just below 360° read as just
            // below 0°, so that they group with 0°.
            let mut phi = phi.rem_euclid(360.0);
            if 360.0 - phi <= SAME_PHI_DEG {
                phi -= 360.0;
            }
            (from_normal, phi, i as u32)
        })
        .collect();
    sorted.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));

    let rings = find_rings(&sorted)?;
    if n < MIN_MEAN_RING_SIZE * rings.len() {
        return None;
    }

    let mut areas = vec![0.0; n];
    let mut by_phi: Vec<(f64, u32)> = Vec::new();
    for (k, ring) in rings.iter().enumerate() {
        let lower = if k == 0 {
            0.0
        } else {
            0.5 * (rings[k - 1].mean_deg + ring.mean_deg)
        };
        let upper = match rings.get(k + 1) {
            Some(next) => 0.5 * (ring.mean_deg + next.mean_deg),
            None => 90.0,
        };
        // Solid angle per radian of azimuth.
        let band = lower.to_radians().cos() - upper.to_radians().cos();
        let members = &sorted[ring.start..ring.end];
        if ring.mean_deg < POLE_DEG {
            // The pole: every member is the same direction.
            let share = std::f64::consts::TAU * band / members.len() as f64;
            for &(_, _, i) in members {
                areas[i as usize] = share;
            }
            continue;
        }
        by_phi.clear();
        by_phi.extend(members.iter().map(|&(_, phi, i)| (phi, i)));
        // Jittered rings are sorted by θ' first: sort by φ again.
        by_phi.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        share_ring(&by_phi, band, &mut areas);
    }
    Some(areas)
}

/// Splits the θ'-sorted directions into rings, or `None` when they do not
/// form rings.
fn find_rings(sorted: &[(f64, f64, u32)]) -> Option<Vec<Ring>> {
    let mut rings: Vec<Ring> = Vec::new();
    let mut start = 0;
    for i in 1..=sorted.len() {
        let ends = i == sorted.len() || sorted[i].0 - sorted[i - 1].0 > RING_JITTER_DEG;
        if !ends {
            continue;
        }
        let members = &sorted[start..i];
        let spread = members[members.len() - 1].0 - members[0].0;
        if spread > MAX_RING_SPREAD_DEG {
            return None;
        }
        let mean_deg = members.iter().map(|m| m.0).sum::<f64>() / members.len() as f64;
        if let Some(previous) = rings.last() {
            let previous_spread = sorted[previous.end - 1].0 - sorted[previous.start].0;
            let gap = members[0].0 - sorted[previous.end - 1].0;
            if gap < MIN_GAP_OVER_SPREAD * spread.max(previous_spread) {
                return None;
            }
        }
        rings.push(Ring {
            start,
            end: i,
            mean_deg,
        });
        start = i;
    }
    Some(rings)
}

/// Gives each direction of one ring (sorted by φ) its cell: `band` times
/// the azimuth from the mid-φ with its previous neighbour to the mid-φ
/// with its next one. Coincident azimuths share one cell.
fn share_ring(by_phi: &[(f64, u32)], band: f64, areas: &mut [f64]) {
    // Groups of coincident azimuths: (first member, end, φ).
    let mut groups: Vec<(usize, usize, f64)> = Vec::new();
    for (j, &(phi, _)) in by_phi.iter().enumerate() {
        match groups.last_mut() {
            Some(group) if phi - group.2 <= SAME_PHI_DEG => group.1 = j + 1,
            _ => groups.push((j, j + 1, phi)),
        }
    }
    let m = groups.len();
    for (g, &(start, end, phi)) in groups.iter().enumerate() {
        let azimuth_deg = if m == 1 {
            360.0
        } else {
            let next = groups[(g + 1) % m].2;
            let previous = groups[(g + m - 1) % m].2;
            0.5 * ((next - phi).rem_euclid(360.0) + (phi - previous).rem_euclid(360.0))
        };
        let share = azimuth_deg.to_radians() * band / (end - start) as f64;
        for &(_, i) in &by_phi[start..end] {
            areas[i as usize] = share;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    #[test]
    fn a_regular_grid_is_rings_and_sums_to_two_pi() {
        let mut directions = vec![(0.0, 0.0)];
        for t in 1..=18 {
            for p in 0..36 {
                directions.push((5.0 * t as f64, 10.0 * p as f64));
            }
        }
        let areas = ring_areas(&directions, Hemisphere::Front).unwrap();
        assert!((areas.iter().sum::<f64>() - TAU).abs() < 1e-12);
        // The pole owns the cap below 2.5°.
        let cap = TAU * (1.0 - 2.5f64.to_radians().cos());
        assert!((areas[0] - cap).abs() < 1e-15);
        // A ring-30° cell: 10° of azimuth between 27.5° and 32.5°.
        let cell = 10f64.to_radians() * (27.5f64.to_radians().cos() - 32.5f64.to_radians().cos());
        assert!((areas[1 + 5 * 36] - cell).abs() < 1e-15);
    }

    #[test]
    fn coincident_azimuths_share_and_wrap() {
        let mut directions = Vec::new();
        for t in [10.0, 20.0] {
            for p in [0.0, 90.0, 180.0, 270.0, 360.0] {
                directions.push((t, p));
            }
        }
        let areas = ring_areas(&directions, Hemisphere::Front).unwrap();
        // 0° and 360° are one direction: they share a quarter ring.
        assert_eq!(areas[0], areas[4]);
        assert!((areas[0] * 2.0 - areas[1]).abs() < 1e-15);
        assert!((areas.iter().sum::<f64>() - TAU).abs() < 1e-12);
    }

    type Directions = Vec<(f64, f64)>;

    /// The run test refuses only what the sort refuses: on both real
    /// scans (both hemispheres), ring grids with jitter, in-plane scans and
    /// scattered sets, `ring_areas` equals `sorted_ring_areas`, and the
    /// real scans are refused by the run test itself.
    #[test]
    fn the_run_test_agrees_with_the_sort() {
        let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../../shared/data/rgl-epfl-pgII-raw");
        let mut sets: Vec<(String, Directions, Hemisphere)> = Vec::new();
        for file in ["golden_paper.txt", "layer_020_030.txt"] {
            let m = crate::read_path(&data.join(file)).unwrap();
            for hemisphere in [Hemisphere::Front, Hemisphere::Back] {
                let directions: Vec<(f64, f64)> = m
                    .samples
                    .iter()
                    .filter(|s| s.hemisphere() == hemisphere)
                    .map(|s| (s.theta_deg, s.phi_deg))
                    .collect();
                if directions.len() > 1000 {
                    assert!(
                        has_wide_run(directions.iter().map(|d| d.0), hemisphere),
                        "{file}"
                    );
                }
                sets.push((format!("{file} {hemisphere:?}"), directions, hemisphere));
            }
        }
        let mut rng = brtf_model::Rng::new(18, 0);
        let mut uniform = move || rng.uniform();
        for jitter in [0.0, 0.0001, 0.004, 0.02] {
            let mut grid = Vec::new();
            for t in 0..=170 {
                for p in 0..60 {
                    let theta = (0.5 * t as f64 + jitter * (uniform() - 0.5)).clamp(0.0, 90.0);
                    grid.push((theta, 6.0 * p as f64));
                }
            }
            sets.push((format!("grid, jitter {jitter}"), grid, Hemisphere::Front));
        }
        let back: Vec<(f64, f64)> = (0..=60)
            .flat_map(|t| (0..24).map(move |p| (180.0 - 1.5 * t as f64, 15.0 * p as f64)))
            .collect();
        sets.push(("back grid".into(), back, Hemisphere::Back));
        let chain: Vec<(f64, f64)> = (0..5000).map(|i| (i as f64 * 0.004, 0.0)).collect();
        sets.push(("chain 0.004°".into(), chain, Hemisphere::Front));
        let random: Vec<(f64, f64)> = (0..20_000)
            .map(|_| (90.0 * uniform(), 360.0 * uniform()))
            .collect();
        sets.push(("random".into(), random, Hemisphere::Front));
        for (name, directions, hemisphere) in &sets {
            assert_eq!(
                ring_areas(directions, *hemisphere),
                sorted_ring_areas(directions, *hemisphere),
                "{name}"
            );
        }
        // Not vacuous: some sets are rings, some are refused by the run test.
        assert!(sets.iter().any(|(_, d, h)| ring_areas(d, *h).is_some()));
        assert!(
            sets.iter()
                .filter(|(_, d, h)| has_wide_run(d.iter().map(|d| d.0), *h))
                .count()
                >= 4
        );
    }

    #[test]
    fn scattered_directions_are_not_rings() {
        // θ' values 0.001° apart chain into one wide "ring".
        let directions: Vec<(f64, f64)> = (0..10_000)
            .map(|i| (i as f64 * 0.001, i as f64 * 7.0))
            .collect();
        assert!(ring_areas(&directions, Hemisphere::Front).is_none());
        // Two directions per ring: an in-plane scan.
        let plane: Vec<(f64, f64)> = (0..90)
            .flat_map(|t| [(t as f64, 0.0), (t as f64, 180.0)])
            .collect();
        assert!(ring_areas(&plane, Hemisphere::Front).is_none());
    }
}
