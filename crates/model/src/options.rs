//! Evaluation settings that are not material arguments: the formula
//! variant, the Fresnel constant, and the light source's solid angle.

use crate::kind::Variant;

/// `e^-5.85`: the classic Fresnel constant (2003-06 → 2023-11 and again
/// from 2026-06-11), which makes `F(1) = 0`.
pub const FRESNEL_K_CLASSIC: f64 = 0.002_879_899_16;

/// `e^-6.2`: the constant in the Radiance 6.0a binary shipped by
/// pyradiance 1.3.1 (2023-11 → 2026-06). Tests against that rtrace use it.
pub const FRESNEL_K_PYRADIANCE: f64 = 0.002_029_430_64;

/// Reads a Fresnel constant: `classic`, `pyradiance` or a number.
pub fn parse_fresnel_k(text: &str) -> Result<f64, String> {
    match text.trim() {
        "classic" => Ok(FRESNEL_K_CLASSIC),
        "pyradiance" => Ok(FRESNEL_K_PYRADIANCE),
        other => other
            .parse::<f64>()
            .map_err(|_| format!("expected classic, pyradiance or a number, found `{other}`")),
    }
}

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

/// A number outside its allowed range, for a one-line error that names
/// the option, the value and the range:
/// `--source-omega 100: out of range; allowed: 0 ≤ ω ≤ 2π sr`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OptionError {
    /// The option (its command-line spelling).
    pub option: &'static str,
    /// The value given, as text.
    pub value: String,
    /// The allowed range, for people.
    pub allowed: &'static str,
}

impl std::fmt::Display for OptionError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} {}: out of range; allowed: {}",
            self.option, self.value, self.allowed
        )
    }
}

impl std::error::Error for OptionError {}

impl OptionError {
    /// `Ok` when `ok`, else the error for `option` = `value`.
    pub fn check(
        option: &'static str,
        value: f64,
        ok: bool,
        allowed: &'static str,
    ) -> Result<(), OptionError> {
        if ok {
            return Ok(());
        }
        Err(OptionError {
            option,
            value: short_number(value),
            allowed,
        })
    }
}

/// `value` as a message shows it: as Rust prints it, but in exponent
/// form when that would take more than a few digits (`1e300`, not 301).
fn short_number(value: f64) -> String {
    let plain = value.to_string();
    if plain.len() > 16 && value.is_finite() {
        format!("{value:e}")
    } else {
        plain
    }
}

impl EvalOptions {
    /// Checks the settings a user gives: `--fresnel-k` in [0, 1),
    /// `--source-omega` in [0, 2π] sr (at most a hemisphere), the jitter
    /// in [0, 1]. NaN fails every check.
    pub fn validate(&self) -> Result<(), OptionError> {
        let k = self.fresnel_k;
        OptionError::check("--fresnel-k", k, (0.0..1.0).contains(&k), "0 ≤ K < 1")?;
        let omega = self.source_omega;
        OptionError::check(
            "--source-omega",
            omega,
            (0.0..=std::f64::consts::TAU).contains(&omega),
            "0 ≤ ω ≤ 2π sr (6.283)",
        )?;
        let dj = self.source_jitter;
        OptionError::check("source jitter", dj, (0.0..=1.0).contains(&dj), "0 to 1")
    }
}

/// Checks an incidence given by a user: θ_in in [0, 180]° but not 90°
/// (grazing light has no irradiance), φ_in finite.
pub fn check_incidence(theta_in: f64, phi_in: f64) -> Result<(), OptionError> {
    OptionError::check(
        "--theta-in",
        theta_in,
        (0.0..=180.0).contains(&theta_in) && theta_in != 90.0,
        "0 ≤ θ_in ≤ 180 degrees, not 90 (grazing)",
    )?;
    OptionError::check(
        "--phi-in",
        phi_in,
        phi_in.is_finite(),
        "a finite angle in degrees",
    )
}

/// Checks a direction seen from, given by a user: θ_out in [0, 180]°
/// (beyond 90°: the back side), φ_out within ±360°.
pub fn check_outgoing(theta_out: f64, phi_out: f64) -> Result<(), OptionError> {
    OptionError::check(
        "theta_out",
        theta_out,
        (0.0..=180.0).contains(&theta_out),
        "0 ≤ θ_out ≤ 180 degrees (beyond 90: the back side)",
    )?;
    OptionError::check(
        "phi_out",
        phi_out,
        (-360.0..=360.0).contains(&phi_out),
        "-360 to 360 degrees",
    )
}

#[cfg(test)]
mod validation_tests {
    use super::*;

    #[test]
    fn huge_values_print_short_in_messages() {
        let e = check_outgoing(30.0, 1e300).unwrap_err().to_string();
        assert_eq!(
            e,
            "phi_out 1e300: out of range; allowed: -360 to 360 degrees"
        );
        let e = check_outgoing(181.5, 0.0).unwrap_err().to_string();
        assert!(e.starts_with("theta_out 181.5: out of range"), "{e}");
        assert!(check_outgoing(f64::NAN, 0.0).is_err());
        assert_eq!(check_outgoing(180.0, -360.0), Ok(()));
    }

    #[test]
    fn out_of_range_settings_name_option_value_and_range() {
        assert_eq!(EvalOptions::default().validate(), Ok(()));
        let bad = EvalOptions {
            source_omega: 100.0,
            ..EvalOptions::default()
        };
        assert_eq!(
            bad.validate().unwrap_err().to_string(),
            "--source-omega 100: out of range; allowed: 0 ≤ ω ≤ 2π sr (6.283)"
        );
        let nan_k = EvalOptions {
            fresnel_k: f64::NAN,
            ..EvalOptions::default()
        };
        assert!(
            nan_k
                .validate()
                .unwrap_err()
                .to_string()
                .contains("--fresnel-k NaN")
        );
        assert!(check_incidence(90.0, 0.0).is_err());
        assert!(check_incidence(f64::NAN, 0.0).is_err());
        assert!(check_incidence(30.0, f64::INFINITY).is_err());
        assert_eq!(check_incidence(120.0, -45.0), Ok(()));
    }
}
