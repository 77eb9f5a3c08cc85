//! Whether the static material carries the measured energy: its ρ_dh and
//! τ_dh against the data's at every fitted incidence. A static material
//! that puts much more or much less light out than the sample did is not
//! written under the name a scene would pick up (`docs/radiance.md`,
//! "When the static material's energy is off").

use brtf_fit::FitResult;
use brtf_model::{Composite, CompositeBsdf, composite_albedo, luminance};

/// Largest relative difference between the static material's ρ_dh or
/// τ_dh and the data's at any incidence before the file is renamed.
pub const STATIC_ENERGY_TOLERANCE: f64 = 0.10;

/// Below this (absolute), ρ_dh or τ_dh counts as this much when judged:
/// a nearly opaque sample's τ of 0.004 against 0.006 is not a failure.
const ENERGY_FLOOR: f64 = 0.02;

/// The static material's worst energy mismatch.
#[derive(Debug, Clone, PartialEq)]
pub struct EnergyOff {
    /// The incidence, degrees.
    pub theta_in: f64,
    /// `rho_dh` or `tau_dh`.
    pub label: &'static str,
    /// The static material's value there.
    pub model: f64,
    /// The data's (measured directions, the incidence's fit elsewhere).
    pub data: f64,
}

impl EnergyOff {
    /// (model − data) / max(data, floor).
    pub fn deviation(&self) -> f64 {
        (self.model - self.data) / self.data.max(ENERGY_FLOOR)
    }
}

/// The worst mismatch of `material` against the data of `result`'s
/// incidences when it exceeds [`STATIC_ENERGY_TOLERANCE`]; `None` when it
/// does not, or when the fit has no energy diagnostics (`--no-adequacy`)
/// or a free scale (its energy is relative).
pub(crate) fn static_energy_off(result: &FitResult, material: &Composite) -> Option<EnergyOff> {
    if result.config.free_scale {
        return None;
    }
    let bsdf = CompositeBsdf::new(material, &result.options());
    let mut worst: Option<EnergyOff> = None;
    for report in &result.incidences {
        let Some(adequacy) = &report.adequacy else {
            continue;
        };
        let light = brtf_model::direction(report.theta_in, report.phi_in);
        let a = composite_albedo(&bsdf, light, 1e-6);
        let total = |x: [f64; 3], spike: [f64; 3]| luminance([0, 1, 2].map(|c| x[c] + spike[c]));
        let pairs = [
            ("rho_dh", adequacy.rho_data, total(a.rho, a.rho_spike)),
            ("tau_dh", adequacy.tau_data, total(a.tau, a.tau_spike)),
        ];
        for (label, data, model) in pairs {
            let Some(data) = data else { continue };
            let off = EnergyOff {
                theta_in: report.theta_in,
                label,
                model,
                data,
            };
            if worst
                .as_ref()
                .is_none_or(|w| off.deviation().abs() > w.deviation().abs())
            {
                worst = Some(off);
            }
        }
    }
    worst.filter(|w| w.deviation().abs() > STATIC_ENERGY_TOLERANCE)
}
