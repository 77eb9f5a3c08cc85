//! What the fitter consumes: per-incidence samples of a measured BSDF,
//! already selected and converted (by [`crate::Recipe`], or by a caller
//! that builds them itself; the fitter does no I/O).

use brtf_gonio::Gate;
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// One measured direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitSample {
    /// Unit direction towards the detector (local frame, z = front normal).
    pub view: DVec3,
    /// Measured value per channel: the BSDF in 1/sr, or a raw signal
    /// proportional to it when the fit has a free scale. Single-channel
    /// data uses index 0 only.
    pub value: [f64; 3],
    /// Quadrature weight, normally the sample's solid angle in sr.
    pub weight: f64,
}

/// A selection step that was applied, and how many samples it removed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GateCount {
    /// The selection.
    #[serde(flatten)]
    pub gate: Gate,
    /// How many samples it removed.
    pub removed: usize,
}

/// Which weights the samples carry.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Weighting {
    /// Solid angles: the file's Voronoi cells.
    FileSolidAngles,
    /// Solid angles computed from the sample directions.
    ComputedSolidAngles,
    /// Every sample weighs 1.
    Uniform,
    /// Weights set by the caller of the library.
    Caller,
}

impl std::fmt::Display for Weighting {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Weighting::FileSolidAngles => "solid angle (the file's Voronoi cells)",
            Weighting::ComputedSolidAngles => "solid angle (computed from the sample directions)",
            Weighting::Uniform => "uniform",
            Weighting::Caller => "set by the caller",
        })
    }
}

/// All samples of one incidence.
#[derive(Debug, Clone, PartialEq)]
pub struct IncidenceData {
    /// Where the data came from (a file name), for reports.
    pub source: String,
    /// Incident polar angle θ_in in degrees.
    pub theta_in: f64,
    /// Incident azimuth φ_in in degrees.
    pub phi_in: f64,
    /// 1 (CIE-Y, fitted grey) or 3 (RGB).
    pub channels: usize,
    /// The samples.
    pub samples: Vec<FitSample>,
    /// The selections applied before fitting.
    pub gates: Vec<GateCount>,
    /// Which weights the samples carry.
    pub weighting: Weighting,
}

impl IncidenceData {
    /// Unit vector towards the light.
    pub fn light(&self) -> DVec3 {
        brtf_model::direction(self.theta_in, self.phi_in)
    }
}
