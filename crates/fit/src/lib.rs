//! # brtf-fit: Levenberg-Marquardt fits of Radiance materials
//!
//! From measurement files to one [`FitResult`]:
//!
//! ```text
//! file ─brtf-gonio→ Measurement ─Recipe→ IncidenceData ─fit→ FitReport ─→ FitResult (fit.json)
//! ```
//!
//! * [`Recipe`] says exactly how a measurement becomes the fitted quantity
//!   (conversion, scale, colour, selections, weights);
//!   [`Recipe::prepare`] is the one function that applies it, for the
//!   fitter, the plots and the render check alike.
//! * [`fit_incidence`] fits one incidence, [`fit_global`] all at once,
//!   [`fit_set`] does the whole `brtf fit` (files → [`FitResult`]), and
//!   [`ParamTable`] interpolates the per-incidence parameters in θ_in.
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
//! * Standard errors are `s² (JᵀJ)⁻¹`, with `s² = Σr²/(m − n)`, and the
//!   sandwich (HC1), mapped to physical units through the bound transform.
//!
//! This is the only crate that uses nalgebra and levenberg-marquardt.

mod adequacy;
mod align;
mod auto;
mod colour;
mod config;
mod data;
mod diagnose;
pub mod en14501;
mod fitter;
mod gram;
pub mod klems;
mod lobes;
mod pair_geometry;
mod params;
mod prepare;
mod problem;
mod recipe;
mod report;
mod residuals;
mod result;
mod robust;
mod serde_kind;
mod set;
mod solve;
mod summary;
mod table;
#[cfg(test)]
mod tests;
pub mod ttree;
mod uncertainty;
mod validate;
mod verdict;

pub use adequacy::{
    Adequacy, ENERGY_TOLERANCE, EnergyFigure, GLOSS_WIDTH_TOLERANCE, PEAK_TOLERANCE_DEG,
    RESIDUAL_KIND_TOLERANCE, RawEnergy, ResidualCheck,
};
pub use align::{AzimuthRule, MAX_TURN_DEG, MIN_ARC_DEG};
pub use auto::{AutoChoice, CandidateRecord, FOLDS, MARGIN_POINTS, MARGIN_RELATIVE};
pub use brtf_gonio::Gate;
pub use colour::ColourError;
pub use config::{
    EnergyRule, FitConfig, FitError, KnownReflectance, ModelChoice, RobustLoss, StopFlag,
};
pub use data::{FitSample, GateCount, IncidenceData, PatchPairs, Weighting};
pub use fitter::{fit_global, fit_incidence};
pub use params::{MAX_ROUGHNESS, MIN_ROUGHNESS, ParamMap, Slot, Target};
pub use problem::ResidualKind;
pub use recipe::{
    BeamOrigin, ColourConversion, Conversion, DataUnit, HolderMask, PatchAveraging,
    PreparedMeasurement, RawScale, Recipe, RecipeError, ScaleRule, SelectionOptions, WeightRule,
};
pub use report::{
    FitReport, FitWarning, ParamEstimate, RobustRecord, StartRecord, StderrRatio, Termination,
};
pub use residuals::{residual_rows, residuals_header};
pub use result::{FIT_JSON_SCHEMA, FitResult, InputFile, Provenance, ReadFitError, SetWarning};
pub use set::{
    FitSetError, FitSetOptions, FittedSet, KlemsOptions, NoProgress, Progress, fit_set,
    fit_set_with_data, prepare_input, prepare_inputs_of_xml,
};
pub use summary::{summary, warning_lines};
pub use table::{AzimuthRing, Interpolation, ParamTable, TableError, TableLookup, azimuth_from_u};
pub use verdict::{Aspect, Trust, Verdict};
