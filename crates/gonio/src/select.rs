//! Sample selections a fitter applies before fitting.
//!
//! This module owns the filters as one typed [`Gate`]: hemisphere, a
//! grazing-angle θ cap, a cone around the incident beam where the detector
//! cannot see, and value floors (below a value, not available,
//! non-finite). A gate is data (serialised into `fit.json`), and
//! [`Gate::keeps`] is the one place that decides whether a sample passes
//! it, for the fitter, the plots and the check alike.
//!
//! The `Measurement` methods return a [`Selection`]: the new measurement,
//! the indices kept (into the input), and how many samples were removed.
//! Samples keep their solid angles; call [`Measurement::fill_solid_angles`]
//! first if the weights should describe the full layout rather than be
//! recomputed after the selection.

use crate::measurement::{Hemisphere, Measurement, Sample};
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// The default θ cap: samples farther than this from the nearer normal
/// (front or back) are grazing and usually unreliable.
pub const DEFAULT_THETA_CAP_DEG: f64 = 85.0;

/// One selection step. Its `Display` is for people only: nothing parses it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "gate", rename_all = "snake_case")]
pub enum Gate {
    /// Drops values that are not available (9.9e+37) or not finite.
    Unavailable,
    /// Keeps one hemisphere (front: θ ≤ 90°, back: θ > 90°).
    Hemisphere {
        /// The hemisphere kept.
        keep: Hemisphere,
    },
    /// Keeps samples within `max_deg` of the nearer normal.
    ThetaCap {
        /// Largest θ_out from the nearer normal, degrees.
        max_deg: f64,
    },
    /// Drops samples within `half_angle_deg` of the incident direction.
    BeamMask {
        /// Half-angle of the masked cone, degrees.
        half_angle_deg: f64,
    },
    /// Drops samples with a used value below `min` (or not finite).
    MinValue {
        /// The smallest value kept, in the data's unit.
        min: f64,
    },
    /// Drops a band of azimuths at grazing angles, where a sample holder
    /// shadows the detector: |φ_out − `center_deg`| ≤ `half_width_deg` and
    /// θ_out (from the nearer normal) ≥ `min_theta_deg`; with
    /// `from_incidence` the centre is measured from φ_in (the instrument's
    /// frame, in which the holder stays put while the sample turns).
    AzimuthBand {
        /// Centre azimuth, degrees.
        center_deg: f64,
        /// Half-width in azimuth, degrees.
        half_width_deg: f64,
        /// Smallest θ_out dropped, degrees.
        min_theta_deg: f64,
        /// The centre is φ_in + `center_deg` (fits saved before the field
        /// had an absolute centre).
        #[serde(default)]
        from_incidence: bool,
    },
    /// Drops the samples of connected regions that read far below their
    /// mirror across the plane of incidence (a shadow, such as the
    /// holder's): see [`crate::shadow`]. Decided over all samples at once
    /// by [`crate::shadow::detect`], not sample by sample.
    Shadow {
        /// A region's median ratio to its mirror must be below this.
        max_ratio: f64,
        /// Only samples at least this far from the nearer normal, degrees.
        min_theta_deg: f64,
    },
}

/// The pgII holder's shadow (`brtf fit --mask-holder`): φ_out − φ_in in
/// 270 ± 45° at θ_out ≥ 73°, where both real pgII scans read 5× (glossy
/// paper) to 300× (layered sample) below their mirror azimuth, from
/// θ_out 73.5° on.
pub const PGII_HOLDER_BAND: Gate = Gate::AzimuthBand {
    center_deg: 270.0,
    half_width_deg: 45.0,
    min_theta_deg: 73.0,
    from_incidence: true,
};

/// `brtf fit --mask-holder auto`: regions at θ_out ≥ 60° whose median
/// is below half their mirror's.
pub const DETECTED_SHADOW: Gate = Gate::Shadow {
    max_ratio: 0.5,
    min_theta_deg: 60.0,
};

/// What a gate needs to know about the measurement it filters.
#[derive(Clone, Copy, Debug)]
pub struct GateContext {
    /// Values per sample that are used (1 or 3).
    channels: usize,
    /// Towards the light.
    light: DVec3,
    /// φ_in, degrees.
    phi_in: f64,
}

impl GateContext {
    /// The context of `measurement`.
    pub fn of(measurement: &Measurement) -> GateContext {
        GateContext {
            channels: measurement.channels.count(),
            light: measurement.incident_direction(),
            phi_in: measurement.incidence.phi_deg,
        }
    }
}

impl Gate {
    /// The gate's name in `fit.json` (its `gate` tag), for tables.
    pub fn name(&self) -> &'static str {
        match self {
            Gate::Unavailable => "unavailable",
            Gate::Hemisphere { .. } => "hemisphere",
            Gate::ThetaCap { .. } => "theta_cap",
            Gate::BeamMask { .. } => "beam_mask",
            Gate::MinValue { .. } => "min_value",
            Gate::AzimuthBand { .. } => "azimuth_band",
            Gate::Shadow { .. } => "shadow",
        }
    }

    /// Checks a gate's number, named by its `brtf fit` option:
    /// `--theta-cap` in (0, 90], `--beam-mask` in [0, 90), `--min-value`
    /// finite.
    pub fn validate(&self) -> Result<(), brtf_model::OptionError> {
        use brtf_model::OptionError;
        match *self {
            Gate::Unavailable | Gate::Hemisphere { .. } => Ok(()),
            Gate::ThetaCap { max_deg } => OptionError::check(
                "--theta-cap",
                max_deg,
                max_deg > 0.0 && max_deg <= 90.0,
                "0 < θ ≤ 90 degrees",
            ),
            Gate::BeamMask { half_angle_deg: a } => OptionError::check(
                "--beam-mask",
                a,
                (0.0..90.0).contains(&a),
                "0 ≤ half-angle < 90 degrees",
            ),
            Gate::MinValue { min } => {
                OptionError::check("--min-value", min, min.is_finite(), "a finite number")
            }
            Gate::Shadow {
                max_ratio,
                min_theta_deg,
            } => OptionError::check(
                "--mask-holder",
                max_ratio,
                max_ratio > 0.0 && max_ratio < 1.0 && (0.0..90.0).contains(&min_theta_deg),
                "a ratio in (0, 1) and 0 ≤ θ < 90 degrees",
            ),
            Gate::AzimuthBand {
                center_deg,
                half_width_deg,
                min_theta_deg,
                ..
            } => OptionError::check(
                "--mask-band",
                half_width_deg,
                center_deg.is_finite() && half_width_deg > 0.0 && half_width_deg <= 180.0,
                "a finite centre and 0 < half-width ≤ 180 degrees",
            )
            .and_then(|()| {
                OptionError::check(
                    "--mask-band",
                    min_theta_deg,
                    (0.0..=90.0).contains(&min_theta_deg),
                    "0 ≤ θ ≤ 90 degrees",
                )
            }),
        }
    }

    /// True when `sample` passes the gate.
    pub fn keeps(&self, sample: &Sample, context: &GateContext) -> bool {
        self.keeps_at(sample, || sample.direction(), context)
    }

    /// [`Gate::keeps`] with the sample's direction from `direction`
    /// (called only by the gates that need it), for a caller that has the
    /// directions already.
    pub fn keeps_at(
        &self,
        sample: &Sample,
        direction: impl FnOnce() -> DVec3,
        context: &GateContext,
    ) -> bool {
        let values = &sample.values[..context.channels];
        match *self {
            Gate::Unavailable => values.iter().all(|v| v.is_finite()),
            Gate::Hemisphere { keep } => sample.hemisphere() == keep,
            Gate::ThetaCap { max_deg } => sample.theta_deg.min(180.0 - sample.theta_deg) <= max_deg,
            Gate::BeamMask { half_angle_deg } => {
                direction().dot(context.light) < brtf_model::cos_degrees(half_angle_deg)
            }
            Gate::MinValue { min } => values.iter().all(|&v| v.is_finite() && v >= min),
            // Decided for all samples at once (`crate::shadow::detect`).
            Gate::Shadow { .. } => true,
            Gate::AzimuthBand {
                center_deg,
                half_width_deg,
                min_theta_deg,
                from_incidence,
            } => {
                let center = if from_incidence {
                    context.phi_in + center_deg
                } else {
                    center_deg
                };
                let dphi = sample.phi_deg - center;
                // rem_euclid is a slow fmod; in range it is the identity.
                let dphi = if (0.0..360.0).contains(&dphi) {
                    dphi
                } else {
                    dphi.rem_euclid(360.0)
                };
                let dphi = dphi.min(360.0 - dphi);
                let theta = sample.theta_deg.min(180.0 - sample.theta_deg);
                !(dphi <= half_width_deg && theta >= min_theta_deg)
            }
        }
    }
}

impl std::fmt::Display for Gate {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Gate::Unavailable => f.write_str("not available or not finite"),
            Gate::Hemisphere {
                keep: Hemisphere::Front,
            } => f.write_str("front hemisphere only"),
            Gate::Hemisphere {
                keep: Hemisphere::Back,
            } => f.write_str("back hemisphere only"),
            Gate::ThetaCap { max_deg } => write!(f, "theta_out <= {max_deg}°"),
            Gate::BeamMask { half_angle_deg } => write!(f, "{half_angle_deg}° beam mask"),
            Gate::MinValue { min } => write!(f, "value >= {min}"),
            Gate::AzimuthBand {
                center_deg,
                half_width_deg,
                min_theta_deg,
                from_incidence: false,
            } => write!(
                f,
                "holder band φ_out {center_deg}±{half_width_deg}° at θ_out >= {min_theta_deg}°"
            ),
            Gate::AzimuthBand {
                center_deg,
                half_width_deg,
                min_theta_deg,
                from_incidence: true,
            } => write!(
                f,
                "holder band φ_out − φ_in {center_deg}±{half_width_deg}° at θ_out >= {min_theta_deg}°"
            ),
            Gate::Shadow {
                max_ratio,
                min_theta_deg,
            } => write!(
                f,
                "shadows below {max_ratio}× their mirror at θ_out >= {min_theta_deg}°"
            ),
        }
    }
}

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

    /// Keeps the samples that pass `gate`.
    pub fn apply_gate(&self, gate: Gate) -> Selection {
        let context = GateContext::of(self);
        self.select(|s| gate.keeps(s, &context))
    }

    /// Keeps one hemisphere (front: θ ≤ 90°, back: θ > 90°).
    pub fn select_hemisphere(&self, hemisphere: Hemisphere) -> Selection {
        self.apply_gate(Gate::Hemisphere { keep: hemisphere })
    }

    /// Keeps samples within `max_theta_deg` of the nearer normal: θ ≤ cap in
    /// front, 180° − θ ≤ cap in back. See [`DEFAULT_THETA_CAP_DEG`].
    pub fn cap_theta(&self, max_theta_deg: f64) -> Selection {
        self.apply_gate(Gate::ThetaCap {
            max_deg: max_theta_deg,
        })
    }

    /// Removes samples within `half_angle_deg` of the incident direction
    /// (θ_in, φ_in), where the detector would block the beam.
    pub fn mask_incident_cone(&self, half_angle_deg: f64) -> Selection {
        self.apply_gate(Gate::BeamMask { half_angle_deg })
    }

    /// Removes samples with a used value below `floor`, not available or
    /// not finite (for CIE-XYZ: if any of X, Y, Z is).
    pub fn drop_below(&self, floor: f64) -> Selection {
        self.apply_gate(Gate::MinValue { min: floor })
    }

    /// Removes samples with a value that is not available or not finite.
    pub fn drop_unavailable(&self) -> Selection {
        self.apply_gate(Gate::Unavailable)
    }
}
