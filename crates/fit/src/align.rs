//! Aligning a scan's azimuth with its plane of incidence.
//!
//! An isotropic surface reflects its specular peak into the plane of
//! incidence, at the mirror azimuth φ_in + 180°, and transmits it at the
//! same azimuth. A scan whose peak lies beside that plane was measured
//! with the sample, or the detector's azimuth zero, turned a little: no
//! material can put its peak there, so the fit pays for the misalignment
//! with a wrong lobe. On the pgII golden paper scan the peak lies 1.6°
//! (arc) out of the plane: turning φ_out by 3.4° halves the two-lobe
//! fit's E1.
//!
//! [`AzimuthRule::AlignPeak`] turns every φ_out by the angle that brings
//! the data's peak (the centroid of the brightest samples, as the peak
//! diagnostic finds it) to the mirror azimuth, when the peak lies at least
//! [`MIN_ARC_DEG`] out of the plane. The turn is a function of the file and
//! the recipe alone, so every command that rebuilds the data finds it.

use glam::DVec3;
use serde::{Deserialize, Serialize};

/// The brightest fraction of the fitted samples whose centroid is the peak.
pub(crate) const PEAK_FRACTION: f64 = 0.002;

/// Peaks closer to the plane of incidence than this arc (degrees) are left
/// where they are: within an instrument's positioning and the noise.
pub const MIN_ARC_DEG: f64 = 0.5;

/// The largest turn taken as a misalignment, degrees. A peak further from
/// the mirror azimuth is another feature (retro-reflection, a real
/// asymmetry), not a turned sample.
pub const MAX_TURN_DEG: f64 = 10.0;

/// Peaks nearer the normal than this (degrees) have no reliable azimuth.
const MIN_PEAK_THETA_DEG: f64 = 10.0;

/// How φ_out is aligned with the plane of incidence.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "rule", rename_all = "snake_case")]
pub enum AzimuthRule {
    /// Turn φ_out so that the data's specular peak lies in the plane of
    /// incidence, when it lies at least [`MIN_ARC_DEG`] out of it and at
    /// most [`MAX_TURN_DEG`] from the mirror azimuth.
    AlignPeak,
    /// Turn every φ_out by `degrees` (0: the file's own frame).
    Turn {
        /// The turn, degrees, counter-clockwise seen from the front.
        degrees: f64,
    },
}

impl AzimuthRule {
    /// The file's own frame: what fits written before the rule existed
    /// used.
    pub fn file_frame() -> AzimuthRule {
        AzimuthRule::Turn { degrees: 0.0 }
    }
}

impl std::fmt::Display for AzimuthRule {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            AzimuthRule::AlignPeak => f.write_str("auto"),
            AzimuthRule::Turn { degrees } => write!(f, "{degrees}"),
        }
    }
}

impl std::str::FromStr for AzimuthRule {
    type Err = String;

    fn from_str(s: &str) -> Result<AzimuthRule, String> {
        if s == "auto" {
            return Ok(AzimuthRule::AlignPeak);
        }
        match s.parse::<f64>() {
            Ok(degrees) if degrees.is_finite() && degrees.abs() <= 180.0 => {
                Ok(AzimuthRule::Turn { degrees })
            }
            _ => Err(format!(
                "`{s}`: expected `auto` or a turn in degrees between -180 and 180"
            )),
        }
    }
}

/// Where a scan's peak lies against its plane of incidence.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PeakAzimuth {
    /// The turn that brings the peak to the mirror azimuth, degrees in
    /// (−180, 180].
    pub turn_deg: f64,
    /// The peak's distance from the plane of incidence, degrees of arc.
    pub arc_deg: f64,
}

/// The peak of `samples` (direction, value) against the plane of incidence
/// of a light at azimuth `phi_in_deg`; `None` without a distinct peak (its
/// brightest samples under twice the median) or with one within
/// [`MIN_PEAK_THETA_DEG`] of either normal.
pub(crate) fn peak_azimuth(samples: &[(DVec3, f64)], phi_in_deg: f64) -> Option<PeakAzimuth> {
    let values: Vec<f64> = samples.iter().map(|s| s.1).collect();
    let dirs: Vec<DVec3> = samples.iter().map(|s| s.0).collect();
    let (peak, contrast) = bright_centroid(&dirs, &values)?;
    let theta = peak.z.abs().clamp(0.0, 1.0).acos().to_degrees();
    if contrast < 2.0 || theta < MIN_PEAK_THETA_DEG {
        return None;
    }
    let phi = peak.y.atan2(peak.x).to_degrees();
    let turn = (phi_in_deg + 180.0 - phi + 180.0).rem_euclid(360.0) - 180.0;
    let arc = (theta.to_radians().sin() * turn.to_radians().sin().abs())
        .clamp(0.0, 1.0)
        .asin()
        .to_degrees();
    Some(PeakAzimuth {
        turn_deg: if turn <= -180.0 { 180.0 } else { turn },
        arc_deg: arc,
    })
}

/// The turn [`AzimuthRule::AlignPeak`] takes for `peak` (0 when the peak is
/// close enough to the plane, or too far from the mirror azimuth to be a
/// misalignment).
pub(crate) fn aligning_turn(peak: Option<PeakAzimuth>) -> f64 {
    match peak {
        Some(p) if p.arc_deg >= MIN_ARC_DEG && p.turn_deg.abs() <= MAX_TURN_DEG => p.turn_deg,
        _ => 0.0,
    }
}

/// The value-weighted centroid of the brightest [`PEAK_FRACTION`] of
/// `values` (at least 3) and the contrast of the brightest against the
/// median; `None` for fewer than 10 finite samples or no positive peak.
pub(crate) fn bright_centroid(dirs: &[DVec3], values: &[f64]) -> Option<(DVec3, f64)> {
    if values.len() < 10 {
        return None;
    }
    let count = ((values.len() as f64 * PEAK_FRACTION).ceil() as usize).clamp(3, values.len());
    let top = brightest(values, count);
    let sum: DVec3 = top.iter().map(|&i| dirs[i] * values[i].max(0.0)).sum();
    let brightest = values[top[0]];
    let mut all = values.to_vec();
    let mid = all.len() / 2;
    let median = *all.select_nth_unstable_by(mid, f64::total_cmp).1;
    let centroid = sum.normalize_or_zero();
    (centroid != DVec3::ZERO).then_some((centroid, brightest / median.max(1e-300)))
}

/// The indices of the `count` largest `values`, largest first and in index
/// order among equals: the head of a stable sort by decreasing value,
/// found by a selection and a sort of the head alone. `count` ≥ 1.
pub(crate) fn brightest(values: &[f64], count: usize) -> Vec<usize> {
    let brighter = |a: &usize, b: &usize| values[*b].total_cmp(&values[*a]).then(a.cmp(b));
    let mut order: Vec<usize> = (0..values.len()).collect();
    order.select_nth_unstable_by(count - 1, brighter);
    order.truncate(count);
    order.sort_unstable_by(brighter);
    order
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A narrow lobe of samples around `peak` over a dim floor.
    fn lobe(peak: DVec3) -> Vec<(DVec3, f64)> {
        let mut samples = Vec::new();
        for i in 0..90 {
            for j in 0..360 {
                let (t, p) = ((i as f64).to_radians(), (j as f64).to_radians());
                let d = DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
                let angle = d.dot(peak).clamp(-1.0, 1.0).acos();
                samples.push((d, 0.1 + 50.0 * (-(angle / 0.05).powi(2)).exp()));
            }
        }
        samples
    }

    fn direction(theta: f64, phi: f64) -> DVec3 {
        let (t, p) = (theta.to_radians(), phi.to_radians());
        DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
    }

    #[test]
    fn a_peak_beside_the_plane_is_turned_back_to_the_mirror_azimuth() {
        let p = peak_azimuth(&lobe(direction(30.0, 176.0)), 0.0).unwrap();
        assert!((p.turn_deg - 4.0).abs() < 0.2, "{p:?}");
        let arc = (30f64.to_radians().sin() * 4f64.to_radians().sin()).asin();
        assert!((p.arc_deg - arc.to_degrees()).abs() < 0.1, "{p:?}");
        assert_eq!(aligning_turn(Some(p)), p.turn_deg);
        // The light at φ_in 90°: the mirror azimuth is 270°.
        let q = peak_azimuth(&lobe(direction(30.0, 273.0)), 90.0).unwrap();
        assert!((q.turn_deg + 3.0).abs() < 0.2, "{q:?}");
    }

    #[test]
    fn peaks_in_the_plane_far_from_it_or_near_the_normal_are_left_alone() {
        let inside = peak_azimuth(&lobe(direction(30.0, 180.0)), 0.0).unwrap();
        assert!(inside.turn_deg.abs() < 0.05, "{inside:?}");
        assert_eq!(aligning_turn(Some(inside)), 0.0);
        // 40° off the mirror azimuth: not a misalignment.
        let far = peak_azimuth(&lobe(direction(30.0, 140.0)), 0.0).unwrap();
        assert_eq!(aligning_turn(Some(far)), 0.0);
        assert_eq!(peak_azimuth(&lobe(direction(3.0, 150.0)), 0.0), None);
        // No distinct peak.
        let flat: Vec<(DVec3, f64)> = lobe(DVec3::Z).iter().map(|s| (s.0, 1.0)).collect();
        assert_eq!(peak_azimuth(&flat, 0.0), None);
    }

    #[test]
    fn the_rule_reads_and_prints_its_words() {
        assert_eq!("auto".parse::<AzimuthRule>(), Ok(AzimuthRule::AlignPeak));
        assert_eq!(
            "-2.5".parse::<AzimuthRule>(),
            Ok(AzimuthRule::Turn { degrees: -2.5 })
        );
        assert!("200".parse::<AzimuthRule>().is_err());
        assert!("nan".parse::<AzimuthRule>().is_err());
        assert_eq!(AzimuthRule::Turn { degrees: 3.5 }.to_string(), "3.5");
    }

    #[test]
    fn the_brightest_are_the_head_of_a_stable_sort() {
        // Many ties, negative values and both zeros, in a scrambled order.
        let values: Vec<f64> = (0..5000u64)
            .map(|i| {
                let h = i.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 40;
                match h % 7 {
                    0 => 0.0,
                    1 => -0.0,
                    2 => -((h % 13) as f64),
                    _ => (h % 97) as f64 * 0.25,
                }
            })
            .collect();
        let mut stable: Vec<usize> = (0..values.len()).collect();
        stable.sort_by(|&a, &b| values[b].total_cmp(&values[a]));
        for count in [1, 3, 10, 11, 250, 4999, 5000] {
            assert_eq!(brightest(&values, count), stable[..count], "count {count}");
        }
    }
}
