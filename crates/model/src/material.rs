//! A material: a type, its real arguments and (for `*2` types) its
//! orientation vector, validated once at construction.

use crate::kind::MaterialKind;
use glam::DVec3;
use std::fmt;

/// Largest number of real arguments of any type (trans2).
pub const MAX_ARGS: usize = 8;

/// Radiance's `FTINY` in the double-precision build.
pub const FTINY: f64 = 1e-6;

/// Why a material could not be built.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum ModelError {
    /// The number of real arguments does not match the type.
    ArgCount {
        /// The material type.
        kind: MaterialKind,
        /// What the type needs.
        expected: usize,
        /// What was given.
        found: usize,
    },
    /// An argument is NaN or infinite.
    NonFinite {
        /// Which argument (0-based).
        index: usize,
    },
    /// An anisotropic roughness is ≤ 1e-6; rtrace stops with "roughness too small".
    RoughnessTooSmall,
    /// The orientation vector is zero or not finite.
    BadOrientation,
    /// A lobe sum's split (mixing coefficient) is outside [0, 1].
    BadSplit,
}

impl fmt::Display for ModelError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ModelError::ArgCount {
                kind,
                expected,
                found,
            } => write!(f, "{kind} takes {expected} real arguments, found {found}"),
            ModelError::NonFinite { index } => {
                write!(f, "real argument {} is not a finite number", index + 1)
            }
            ModelError::RoughnessTooSmall => f.write_str(
                "anisotropic roughness must be > 1e-6 (rtrace stops with \"roughness too small\")",
            ),
            ModelError::BadOrientation => {
                f.write_str("orientation vector must be finite and non-zero")
            }
            ModelError::BadSplit => f.write_str("a lobe split must be in [0, 1]"),
        }
    }
}

impl std::error::Error for ModelError {}

/// A Radiance Ward-type material.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    kind: MaterialKind,
    args: [f64; MAX_ARGS],
    orientation: DVec3,
}

impl Material {
    /// Builds a material from its Radiance real arguments.
    ///
    /// `orientation` is the `*2` types' `ux uy uz` vector (ignored by the
    /// isotropic types; `None` means +x).
    pub fn new(
        kind: MaterialKind,
        args: &[f64],
        orientation: Option<DVec3>,
    ) -> Result<Material, ModelError> {
        if args.len() != kind.n_args() {
            return Err(ModelError::ArgCount {
                kind,
                expected: kind.n_args(),
                found: args.len(),
            });
        }
        if let Some(index) = args.iter().position(|a| !a.is_finite()) {
            return Err(ModelError::NonFinite { index });
        }
        let orientation = orientation.unwrap_or(DVec3::X);
        if !orientation.is_finite() || orientation.length_squared() == 0.0 {
            return Err(ModelError::BadOrientation);
        }
        if kind.is_anisotropic() && (args[4] <= FTINY || args[5] <= FTINY) {
            return Err(ModelError::RoughnessTooSmall);
        }
        let mut stored = [0.0; MAX_ARGS];
        stored[..args.len()].copy_from_slice(args);
        Ok(Material {
            kind,
            args: stored,
            orientation,
        })
    }

    /// The material type.
    pub fn kind(&self) -> MaterialKind {
        self.kind
    }

    /// The real arguments, in Radiance order.
    pub fn args(&self) -> &[f64] {
        &self.args[..self.kind.n_args()]
    }

    /// The orientation vector of the `*2` types (+x for the isotropic ones).
    pub fn orientation(&self) -> DVec3 {
        self.orientation
    }

    /// The same material with other real arguments (same count required).
    pub fn with_args(&self, args: &[f64]) -> Result<Material, ModelError> {
        Material::new(self.kind, args, Some(self.orientation))
    }

    /// RGB colour (arguments 1–3).
    pub fn color(&self) -> [f64; 3] {
        [self.args[0], self.args[1], self.args[2]]
    }

    /// Specularity (argument 4).
    pub fn spec(&self) -> f64 {
        self.args[3]
    }
}

/// Checks the real arguments of a material read from a file: none
/// negative, and `spec`, `trans` and `tspec` (fractions) at most 1.
/// Returns the first problem, naming the argument, for a located error.
pub fn check_args(kind: MaterialKind, args: &[f64]) -> Result<(), String> {
    for (name, &value) in kind.param_names().iter().zip(args) {
        if value < 0.0 {
            return Err(format!("{name} is {value}; it must not be negative"));
        }
        if matches!(*name, "spec" | "trans" | "tspec") && value > 1.0 {
            return Err(format!("{name} is {value}; it is a fraction, at most 1"));
        }
    }
    Ok(())
}

#[cfg(test)]
mod check_args_tests {
    use super::*;

    #[test]
    fn negative_and_above_one_fractions_are_named() {
        assert_eq!(
            check_args(MaterialKind::Plastic, &[0.5, 0.5, 0.5, 0.05, 0.1]),
            Ok(())
        );
        let err = check_args(MaterialKind::Plastic, &[0.5, 0.5, 0.5, 0.05, -0.1]).unwrap_err();
        assert_eq!(err, "rough is -0.1; it must not be negative");
        let err = check_args(MaterialKind::Metal, &[0.5, 0.5, 0.5, 1.5, 0.1]).unwrap_err();
        assert!(err.starts_with("spec is 1.5"), "{err}");
        let args = [0.5, 0.5, 0.5, 0.0, 0.1, 1.2, 0.0];
        assert!(
            check_args(MaterialKind::Trans, &args)
                .unwrap_err()
                .starts_with("trans is 1.2")
        );
    }
}
