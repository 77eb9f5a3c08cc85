//! What the adequacy diagnostics found for one incidence (computed by
//! `diagnose`), and the tolerances beyond which they warn.

use serde::{Deserialize, Serialize};

/// Energy ratio (data ÷ model) outside [1/(1+t), 1+t] warns.
pub const ENERGY_TOLERANCE: f64 = 0.05;
/// A model peak farther than this from the data's warns, degrees.
pub const PEAK_TOLERANCE_DEG: f64 = 5.0;
/// A model peak wider or narrower than the data's by more than this
/// fraction (of the data's half-maximum width) is not trusted for gloss.
pub const GLOSS_WIDTH_TOLERANCE: f64 = 0.2;
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
    /// The peak's width, data and model: the full apex angle of the cone
    /// as large as the directions brighter than half the peak's height
    /// over the median, degrees (`None` without a distinct peak).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gloss_width_deg: Option<[f64; 2]>,
    /// The fit with the other residual kind, when it was made.
    pub residual_check: Option<ResidualCheck>,
    /// A free-scale fit's energy in the file's own unit, in place of
    /// `rho_data`/`tau_data` (which would depend on the fitted scale).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub raw_energy: Option<RawEnergy>,
}

/// `Σ Ω |cos θ_out| y` over a free-scale fit's fitted samples of one side,
/// in the file's unit × sr: the data's (which no fit changes) and the
/// fitted model's (× its scale).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RawEnergy {
    /// The file's unit, e.g. `uA`.
    pub unit: String,
    /// Transmission side (else reflection).
    pub back: bool,
    /// The data's sum.
    pub data: f64,
    /// The model's sum, at the fitted scale.
    pub model: f64,
}

/// The energy the diagnostics compare, whatever its kind.
#[derive(Debug, Clone, PartialEq)]
pub struct EnergyFigure {
    /// `ρ_dh`, `τ_dh`, or for a free scale `∫ reflected` / `∫ transmitted`.
    pub label: &'static str,
    /// The data's.
    pub data: f64,
    /// The model's.
    pub model: f64,
    /// `uA·sr` and the like for a free scale; `None` for ρ/τ.
    pub unit: Option<String>,
}

impl std::fmt::Display for EnergyFigure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let unit = self
            .unit
            .as_deref()
            .map_or_else(String::new, |u| format!(" {u}"));
        write!(
            f,
            "{} data {:.4}{unit}, model {:.4}{unit}",
            self.label, self.data, self.model
        )?;
        if self.unit.is_some() {
            f.write_str(" over the measured directions (free scale: the file's unit)")?;
        }
        Ok(())
    }
}

impl Adequacy {
    /// Data ÷ model reflectance (or transmittance when there is no
    /// reflection data).
    pub fn energy_ratio(&self) -> Option<f64> {
        self.energy().map(|e| e.data / e.model)
    }

    /// The data's and the model's energy: ρ_dh where there is reflection
    /// data (and model), else τ_dh; a free scale's sums in the file's unit.
    pub fn energy(&self) -> Option<EnergyFigure> {
        if let Some(raw) = &self.raw_energy {
            return (raw.model > 0.0).then(|| EnergyFigure {
                label: if raw.back {
                    "∫ transmitted"
                } else {
                    "∫ reflected"
                },
                data: raw.data,
                model: raw.model,
                unit: Some(format!("{}·sr", raw.unit)),
            });
        }
        let figure = |label, data, model| EnergyFigure {
            label,
            data,
            model,
            unit: None,
        };
        match (self.rho_data, self.tau_data) {
            (Some(d), _) if self.rho_model > 0.0 => Some(figure("ρ_dh", d, self.rho_model)),
            (_, Some(d)) if self.tau_model > 0.0 => Some(figure("τ_dh", d, self.tau_model)),
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
