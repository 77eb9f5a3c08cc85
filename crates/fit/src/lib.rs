//! # brtf-fit: Levenberg-Marquardt fits of Radiance materials
//!
//! Fits one of brtf-model's material types to the samples of each
//! incidence ([`fit_incidence`]) or to all incidences at once
//! ([`fit_global`]), and interpolates the per-incidence parameters in
//! θ_in ([`ParamTable`]).
//!
//! * Parameters are fitted in unconstrained coordinates: a logistic maps
//!   each to its physical box, `exp` keeps the free scale positive.
//! * The Jacobian is exact, from brtf-model's analytic gradients.
//! * Levenberg-Marquardt runs on the problem compressed to n + 1 rows (the
//!   triangle of `[J | r]`, from its Gram matrix accumulated in parallel
//!   chunks): the same steps as on the full problem, without storing or
//!   factorising the m × n Jacobian.
//! * Starting values come from the data (diffuse floor, peak height and
//!   width); a multi-start over roughness on a subsample that keeps every
//!   bright sample (the lobe) escapes the local minima a single start
//!   falls into.
//! * Standard errors are `s² (JᵀJ)⁻¹`, with `s² = Σr²/(m − n)`, mapped to
//!   physical units through the bound transform.
//!
//! This is the only crate that uses nalgebra and levenberg-marquardt.

mod data;
mod fitter;
mod params;
mod prepare;
mod problem;
mod result;
mod table;

/// Serialises a material type as its Radiance name.
pub(crate) mod serde_kind {
    use brtf_model::MaterialKind;
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(k: &MaterialKind, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(k.name())
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<MaterialKind, D::Error> {
        String::deserialize(d)?
            .parse()
            .map_err(serde::de::Error::custom)
    }
}

pub use data::{FitSample, GateReport, IncidenceData};
pub use fitter::{
    FitConfig, FitError, FitReport, ParamEstimate, RobustLoss, StartRecord, Termination,
    fit_global, fit_incidence,
};
pub use params::{MAX_ROUGHNESS, MIN_ROUGHNESS, ParamMap, Slot, Target};
pub use problem::ResidualKind;
pub use result::{FitResult, InputFile, Provenance};
pub use table::{Interpolation, ParamTable, TableError, TableLookup};
