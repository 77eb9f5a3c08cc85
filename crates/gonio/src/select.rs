//! Sample selections a fitter applies before fitting.
//!
//! This module owns the filters: hemisphere, a grazing-angle θ cap, a cone
//! around the incident beam where the detector cannot see, and value floors
//! (below a value, not available, non-finite). Each returns a
//! [`Selection`]: the new measurement, the indices kept (into the input),
//! and how many samples were removed. Samples keep their solid angles; call
//! [`Measurement::fill_solid_angles`] first if the weights should describe
//! the full layout rather than be recomputed after the selection.

use crate::measurement::{Hemisphere, Measurement, Sample};

/// The default θ cap: samples farther than this from the nearer normal
/// (front or back) are grazing and usually unreliable.
pub const DEFAULT_THETA_CAP_DEG: f64 = 85.0;

/// The result of a selection.
#[derive(Clone, Debug, PartialEq)]
pub struct Selection {
    /// The measurement with only the kept samples (and their `.mpc` columns).
    pub measurement: Measurement,
    /// Indices of the kept samples in the input measurement, ascending.
    pub kept: Vec<usize>,
    /// Number of samples removed.
    pub removed: usize,
}

impl Measurement {
    /// Keeps the samples for which `keep` returns true.
    pub fn select(&self, mut keep: impl FnMut(&Sample) -> bool) -> Selection {
        let kept: Vec<usize> = self
            .samples
            .iter()
            .enumerate()
            .filter(|(_, s)| keep(s))
            .map(|(i, _)| i)
            .collect();
        Selection {
            measurement: self.with_samples_at(&kept),
            removed: self.samples.len() - kept.len(),
            kept,
        }
    }

    /// Keeps one hemisphere (front: θ ≤ 90°, back: θ > 90°).
    pub fn select_hemisphere(&self, hemisphere: Hemisphere) -> Selection {
        self.select(|s| s.hemisphere() == hemisphere)
    }

    /// Keeps samples within `max_theta_deg` of the nearer normal: θ ≤ cap in
    /// front, 180° − θ ≤ cap in back. See [`DEFAULT_THETA_CAP_DEG`].
    pub fn cap_theta(&self, max_theta_deg: f64) -> Selection {
        self.select(|s| s.theta_deg.min(180.0 - s.theta_deg) <= max_theta_deg)
    }

    /// Removes samples within `half_angle_deg` of the incident direction
    /// (θ_in, φ_in), where the detector would block the beam.
    pub fn mask_incident_cone(&self, half_angle_deg: f64) -> Selection {
        let towards_light = self.incident_direction();
        let cos_limit = half_angle_deg.to_radians().cos();
        self.select(|s| s.direction().dot(towards_light) < cos_limit)
    }

    /// Removes samples with a used value below `floor`, not available or
    /// not finite (for CIE-XYZ: if any of X, Y, Z is).
    pub fn drop_below(&self, floor: f64) -> Selection {
        let n = self.channels.count();
        self.select(|s| s.values[..n].iter().all(|&v| v.is_finite() && v >= floor))
    }

    /// Removes samples with a value that is not available or not finite.
    pub fn drop_unavailable(&self) -> Selection {
        let channels = self.channels;
        self.select(|s| s.is_available(channels))
    }
}
