//! What the fitter consumes: per-incidence samples of a measured BSDF,
//! already selected and converted by the caller (the fitter does no I/O).

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

/// A selection step the caller applied, for the report.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GateReport {
    /// What was applied, e.g. `theta_out <= 85`.
    pub gate: String,
    /// How many samples it removed.
    pub removed: usize,
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
    pub gates: Vec<GateReport>,
    /// Which weights the samples carry (e.g. `voronoi (file)`).
    pub weighting: String,
}

impl IncidenceData {
    /// Unit vector towards the light.
    pub fn light(&self) -> DVec3 {
        brtf_model::direction(self.theta_in, self.phi_in)
    }
}
