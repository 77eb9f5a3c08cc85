//! Evaluation settings that are not material arguments: the formula
//! variant, the Fresnel constant, and the light source's solid angle.

use crate::kind::Variant;

/// `e^-5.85`: the classic Fresnel constant (2003-06 → 2023-11 and again
/// from 2026-06-11), which makes `F(1) = 0`.
pub const FRESNEL_K_CLASSIC: f64 = 0.002_879_899_16;

/// `e^-6.2`: the constant in the Radiance 6.0a binary shipped by
/// pyradiance 1.3.1 (2023-11 → 2026-06). Tests against that rtrace use it.
pub const FRESNEL_K_PYRADIANCE: f64 = 0.002_029_430_64;

/// How to evaluate a material.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EvalOptions {
    /// Which formula set.
    pub variant: Variant,
    /// `K` in the Fresnel estimate `exp(-5.85 c) - K` (radiance variant only).
    pub fresnel_k: f64,
    /// Solid angle ω of the light source sample, in sr (0 = a point).
    pub source_omega: f64,
    /// The lit primitive is flat (polygon or ring), so rtrace widens the
    /// reflected lobe by the source size. True for a gonio sample.
    pub flat: bool,
    /// rtrace's `-dj` source jitter; the flat widening is scaled by `1 - dj`.
    pub source_jitter: f64,
}

impl Default for EvalOptions {
    fn default() -> Self {
        EvalOptions {
            variant: Variant::Radiance,
            fresnel_k: FRESNEL_K_CLASSIC,
            source_omega: 0.0,
            flat: true,
            source_jitter: 0.0,
        }
    }
}

impl EvalOptions {
    /// Default options with another variant.
    pub fn with_variant(variant: Variant) -> Self {
        EvalOptions {
            variant,
            ..EvalOptions::default()
        }
    }
}
