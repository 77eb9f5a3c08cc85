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
use nalgebra::DMatrix;

/// Both standard errors per unconstrained parameter (NaN where `JᵀJ` is
/// singular or the sandwich's middle was not accumulated).
pub(crate) struct UnconstrainedErrors {
    pub plain: Vec<f64>,
    pub robust: Vec<f64>,
}

/// The standard errors at the solution `pass`, whose cost is `cost`, over
/// `m` residuals and `n` parameters.
///
/// A parameter whose row of `R` is zero (its column is zero, because it
/// has stopped at a bound — see `ParamMap::to_physical` — or it depends on
/// the others, see `augmented_cholesky`) is held fixed: it gets no error,
/// and the errors of the others come from the rest of `JᵀJ`. Inverting
/// the whole of it, singular then, gave errors of exactly 0 or 10⁵.
pub(crate) fn standard_errors(
    pass: &Compressed,
    cost: f64,
    m: usize,
    n: usize,
) -> UnconstrainedErrors {
    let dof = m.saturating_sub(n).max(1) as f64;
    let s2 = 2.0 * cost / dof;
    // JᵀJ = RᵀR for the compressed Jacobian [R; 0].
    let gram = pass.jacobian.transpose() * &pass.jacobian;
    let free: Vec<usize> = (0..n).filter(|&i| pass.jacobian[(i, i)] != 0.0).collect();
    let k = free.len();
    let inverse = DMatrix::from_fn(k, k, |a, b| gram[(free[a], free[b])]).try_inverse();
    let mut plain = vec![f64::NAN; n];
    let mut robust = vec![f64::NAN; n];
    if let Some(inv) = &inverse {
        for (a, &i) in free.iter().enumerate() {
            plain[i] = (s2 * inv[(a, a)]).max(0.0).sqrt();
        }
        if let Some(meat) = &pass.meat {
            let meat = DMatrix::from_fn(k, k, |a, b| meat[(free[a], free[b])]);
            let sandwich = inv * meat * inv * (m as f64 / dof);
            for (a, &i) in free.iter().enumerate() {
                robust[i] = sandwich[(a, a)].max(0.0).sqrt();
            }
        }
    }
    UnconstrainedErrors { plain, robust }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DVector;

    /// `R` (4 × 3, upper triangular) with parameter 1 stopped at a bound:
    /// its row is zero. Parameters 0 and 2 get the errors of the problem
    /// without it; parameter 1 gets none. Inverting the whole `JᵀJ` would
    /// fail (or, with rounding, give nonsense).
    #[test]
    fn a_parameter_with_a_zero_row_is_held_fixed() {
        let r = DMatrix::from_row_slice(
            4,
            3,
            &[
                2.0, 0.0, 1.0, //
                0.0, 0.0, 0.0, //
                0.0, 0.0, 3.0, //
                0.0, 0.0, 0.0,
            ],
        );
        let pass = Compressed {
            residuals: DVector::zeros(4),
            jacobian: r,
            rms_rel: f64::NAN,
            meat: None,
            model: None,
        };
        let (cost, m, n) = (5.0, 103, 3);
        let errors = standard_errors(&pass, cost, m, n);
        // The 2 × 2 problem of parameters 0 and 2: JᵀJ = [[4, 2], [2, 10]],
        // inverse [[10, -2], [-2, 4]] / 36; s² = 2 · 5 / 100.
        let s2 = 2.0 * cost / 100.0;
        assert!((errors.plain[0] - (s2 * 10.0 / 36.0).sqrt()).abs() < 1e-15);
        assert!((errors.plain[2] - (s2 * 4.0 / 36.0).sqrt()).abs() < 1e-15);
        assert!(errors.plain[1].is_nan());
        assert!(
            errors.robust.iter().all(|e| e.is_nan()),
            "no meat, no sandwich"
        );
    }
}
