//! Data-side hemispherical integrals: ρ_dh (front) and τ_dh (back).
//!
//! This module owns the quadrature of the measured values over each
//! hemisphere:
//!
//! ```text
//! ρ_dh = Σ_front BSDF_i · |cos θ_i| · ΔΩ_i      τ_dh = Σ_back (same)
//! ```
//!
//! with ΔΩ_i from [`crate::solid_angle`]. For DSF data the cosine is
//! already in the value (Σ DSF_i · ΔΩ_i). Raw signal is proportional to the
//! DSF: its sum Σ raw_i · ΔΩ_i is in the file's unit × sr and is divided by
//! the beam integral when one is known, giving ρ_dh. Only the CIE-Y value
//! is integrated. Samples with a "not available" value are skipped (their
//! solid angle is not redistributed) and counted.

use serde::{Deserialize, Serialize};

use crate::measurement::{Hemisphere, Measurement, Quantity};

/// The integral over one hemisphere.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct HemisphereIntegral {
    /// Which hemisphere.
    pub hemisphere: Hemisphere,
    /// The integral, in [`HemisphereIntegral::unit`].
    pub value: f64,
    /// `1` (a reflectance or transmittance fraction) or e.g. `uA·sr`.
    pub unit: String,
    /// Samples that contributed.
    pub samples_used: usize,
    /// Samples skipped because their value was not available.
    pub samples_skipped: usize,
    /// Σ ΔΩ over all samples of the hemisphere (2π for full coverage), sr.
    pub solid_angle_sr: f64,
}

/// Integrates one hemisphere of `measurement` with the given per-sample
/// solid angles (parallel to the samples). `None` when the hemisphere has
/// no samples.
pub fn hemispherical_integral(
    measurement: &Measurement,
    solid_angles_sr: &[f64],
    hemisphere: Hemisphere,
) -> Option<HemisphereIntegral> {
    let slot = measurement.channels.luminance_slot();
    let (scale, unit) = match &measurement.quantity {
        Quantity::Bsdf | Quantity::Dsf => (1.0, "1".to_owned()),
        Quantity::Raw {
            beam_integral: Some(b),
            ..
        } if b.is_finite() && *b > 0.0 => (1.0 / b, "1".to_owned()),
        Quantity::Raw { unit, .. } => (1.0, format!("{unit}·sr")),
    };
    let cosine_needed = !measurement.quantity.includes_cosine();
    let mut value = 0.0;
    let mut used = 0;
    let mut skipped = 0;
    let mut solid_angle = 0.0;
    for (sample, &w) in measurement.samples.iter().zip(solid_angles_sr) {
        if sample.hemisphere() != hemisphere {
            continue;
        }
        solid_angle += w;
        let v = sample.values[slot];
        if !v.is_finite() {
            skipped += 1;
            continue;
        }
        let cos = if cosine_needed {
            sample.abs_cos_theta()
        } else {
            1.0
        };
        value += v * cos * w;
        used += 1;
    }
    (used + skipped > 0).then_some(HemisphereIntegral {
        hemisphere,
        value: value * scale,
        unit,
        samples_used: used,
        samples_skipped: skipped,
        solid_angle_sr: solid_angle,
    })
}
