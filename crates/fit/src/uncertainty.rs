//! Standard errors of the fitted parameters, in the optimiser's
//! (unconstrained) coordinates, from the final pass's compressed Jacobian.
//!
//! * `s² (JᵀJ)⁻¹` with `s² = 2·cost / (m − n)`: right when every residual
//!   has the same variance;
//! * the sandwich `m/(m−n) (JᵀJ)⁻¹ (Σ rᵢ² Jᵢ Jᵢᵀ) (JᵀJ)⁻¹` (HC1), which does
//!   not assume that.
//!
//! The caller maps them to physical units with the bound transform's
//! derivative.

use crate::problem::Compressed;

/// Both standard errors per unconstrained parameter (NaN where `JᵀJ` is
/// singular or the sandwich's middle was not accumulated).
pub(crate) struct UnconstrainedErrors {
    pub plain: Vec<f64>,
    pub robust: Vec<f64>,
}

/// The standard errors at the solution `pass`, whose cost is `cost`, over
/// `m` residuals and `n` parameters.
pub(crate) fn standard_errors(
    pass: &Compressed,
    cost: f64,
    m: usize,
    n: usize,
) -> UnconstrainedErrors {
    let dof = m.saturating_sub(n).max(1) as f64;
    let s2 = 2.0 * cost / dof;
    // JᵀJ = RᵀR for the compressed Jacobian [R; 0].
    let inverse = (pass.jacobian.transpose() * &pass.jacobian).try_inverse();
    let plain = match &inverse {
        Some(inv) => (0..n).map(|i| (s2 * inv[(i, i)]).max(0.0).sqrt()).collect(),
        None => vec![f64::NAN; n],
    };
    let robust = match (&inverse, &pass.meat) {
        (Some(inv), Some(meat)) => {
            let sandwich = inv * meat * inv * (m as f64 / dof);
            (0..n).map(|i| sandwich[(i, i)].max(0.0).sqrt()).collect()
        }
        _ => vec![f64::NAN; n],
    };
    UnconstrainedErrors { plain, robust }
}
