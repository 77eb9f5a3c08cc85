//! The one result type that flows from the fitter to exports, plots and
//! render checks: everything `brtf fit` learnt, with its provenance.
//! Serialised as `fit.json`.

use crate::fitter::{FitConfig, FitReport};
use crate::table::{Interpolation, ParamTable};
use brtf_model::{EvalOptions, Material};
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// One input measurement file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct InputFile {
    /// Path as given on the command line.
    pub path: String,
    /// SHA-256 of the file's bytes, hex.
    pub sha256: String,
    /// Incidence read from the file.
    pub theta_in: f64,
    /// Incidence azimuth.
    pub phi_in: f64,
    /// What the file holds (`BSDF`, `DSF`, `raw [uA]`...), and what the fit used.
    pub quantity: String,
    /// Samples in the file.
    pub samples: usize,
}

/// Where and how a result was made.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Provenance {
    /// `brtf` version.
    pub brtf_version: String,
    /// The full command line.
    pub command_line: Vec<String>,
    /// UTC time the fit finished, RFC 3339.
    pub created: String,
    /// Every input file with its hash.
    pub inputs: Vec<InputFile>,
}

/// Everything a fit produced.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitResult {
    /// Material name used in exports (the output folder's name by default).
    pub name: String,
    /// Provenance.
    pub provenance: Provenance,
    /// The fit settings.
    pub config: FitConfig,
    /// Selections applied to every file, as text (for the record).
    pub selections: Vec<String>,
    /// One report per incidence, sorted by θ_in.
    pub incidences: Vec<FitReport>,
    /// One parameter set for all incidences.
    pub global: Option<FitReport>,
    /// θ_in interpolation of the per-incidence parameters (two incidences or more).
    pub table: Option<ParamTable>,
    /// Interpolation method requested.
    pub interpolation: Interpolation,
}

impl FitResult {
    /// The evaluation options the fit used (variant, Fresnel constant, ω).
    pub fn options(&self) -> EvalOptions {
        self.config.options
    }

    /// Material of a report's fitted arguments.
    pub fn material_of(&self, report: &FitReport) -> Option<Material> {
        Material::new(
            self.config.kind,
            &report.material_args,
            Some(DVec3::from_array(self.config.orientation)),
        )
        .ok()
    }

    /// The static material: the all-incidence fit, else the first incidence.
    pub fn static_material(&self) -> Option<Material> {
        self.global
            .as_ref()
            .or(self.incidences.first())
            .and_then(|r| self.material_of(r))
    }
}
