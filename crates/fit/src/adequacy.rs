//! What the adequacy diagnostics found for one incidence (computed by
//! `diagnose`), and the tolerances beyond which they warn.

use serde::{Deserialize, Serialize};

/// Energy ratio (data ÷ model) outside [1/(1+t), 1+t] warns.
pub const ENERGY_TOLERANCE: f64 = 0.05;
/// A model peak farther than this from the data's warns, degrees.
pub const PEAK_TOLERANCE_DEG: f64 = 5.0;
/// A parameter that moves by more than this fraction between residual
/// kinds warns.
pub const RESIDUAL_KIND_TOLERANCE: f64 = 0.2;

/// The adequacy diagnostics of one incidence.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Adequacy {
    /// The data's ρ_dh (front), measured part plus the model's for the
    /// unmeasured directions; `None` without fitted front samples.
    pub rho_data: Option<f64>,
    /// The model's ρ_dh.
    pub rho_model: f64,
    /// The data's τ_dh (back), as `rho_data`; `None` without back samples.
    pub tau_data: Option<f64>,
    /// The model's τ_dh.
    pub tau_model: f64,
    /// Angle between the data's and the model's peak directions, degrees
    /// (`None` when the data have no distinct peak).
    pub peak_offset_deg: Option<f64>,
    /// The fit with the other residual kind, when it was made.
    pub residual_check: Option<ResidualCheck>,
}

impl Adequacy {
    /// Data ÷ model reflectance (or transmittance when there is no
    /// reflection data).
    pub fn energy_ratio(&self) -> Option<f64> {
        match (self.rho_data, self.tau_data) {
            (Some(d), _) if self.rho_model > 0.0 => Some(d / self.rho_model),
            (_, Some(d)) if self.tau_model > 0.0 => Some(d / self.tau_model),
            _ => None,
        }
    }
}

/// The parameters fitted with another residual kind.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ResidualCheck {
    /// The other residual kind.
    pub residual: crate::ResidualKind,
    /// The parameter that moved most.
    pub param: String,
    /// Its value in the main fit and in the other one.
    pub values: [f64; 2],
    /// |difference| ÷ the larger magnitude.
    pub relative_change: f64,
}
