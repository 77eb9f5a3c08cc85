//! The one result type that flows from the fitter to exports, plots and
//! render checks: everything `brtf fit` learnt, with its provenance and
//! the [`Recipe`] that rebuilds its data. Serialised as `fit.json`, with a
//! schema version that every reader checks ([`FitResult::read`]).

use crate::config::FitConfig;
use crate::recipe::{Conversion, Recipe};
use crate::report::FitReport;
use crate::table::{Interpolation, ParamTable};
use brtf_model::{Composite, EvalOptions, Material};
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The `fit.json` schema this version writes and reads. Version 1 (no
/// `schema` field) stored gates, weighting, warnings and the data
/// quantity as English text.
pub const FIT_JSON_SCHEMA: u32 = 2;

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
    /// How the file's values became the fitted quantity.
    pub conversion: Conversion,
    /// Samples in the file.
    pub samples: usize,
    /// For a Klems BSDF XML file: which incident patch of which side this
    /// incidence is (one file gives many incidences).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub klems: Option<crate::klems::KlemsPatchRef>,
    /// The turn of φ_out (degrees) that aligned the file's peak with the
    /// plane of incidence ([`crate::AzimuthRule`]); 0 in the file's frame.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub phi_turn_deg: f64,
    /// How far (degrees of arc) the file's peak lay from the plane of
    /// incidence before any turn; `None` without a distinct peak.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peak_arc_deg: Option<f64>,
    /// The shadows `--mask-holder auto` found and masked.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub shadows: Vec<brtf_gonio::shadow::ShadowRegion>,
    /// Channels fitted: 1 (CIE Y, colour not measured) or 3; 0 in fits
    /// saved before the field.
    #[serde(default)]
    pub channels: usize,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

impl InputFile {
    /// The turn of φ_out in words, for summaries: empty in the file's frame.
    pub fn describe_turn(&self) -> String {
        match self.peak_arc_deg {
            _ if self.phi_turn_deg == 0.0 => String::new(),
            Some(arc) => format!(
                ", φ_out turned {:+.2}° (the peak lay {arc:.2}° out of the plane of incidence)",
                self.phi_turn_deg
            ),
            None => format!(", φ_out turned {:+.2}°", self.phi_turn_deg),
        }
    }

    /// True for an incident patch of a Klems file's back side, whose data
    /// are described in a mirrored frame ([`crate::azimuth_from_u`]).
    pub fn is_klems_back_side(&self) -> bool {
        self.klems
            .is_some_and(|k| k.side == brtf_gonio::klems::Side::Back)
    }

    /// The name its incidence's report carries as `source`: the path, or
    /// for a Klems patch `path [front patch 12]`.
    pub fn label(&self) -> String {
        match &self.klems {
            Some(k) => format!("{} [{} patch {}]", self.path, k.side, k.patch),
            None => self.path.clone(),
        }
    }
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

/// Something the user should know about the whole set of fits.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "warning", rename_all = "snake_case")]
pub enum SetWarning {
    /// No θ_in table could be made.
    NoTable {
        /// Why (the table's error, for people).
        reason: String,
    },
    /// `--rho` was given at an incidence far from every fitted one.
    RhoFarFromIncidence {
        /// The `--rho` incidence, degrees.
        requested: f64,
        /// The incidence used, degrees.
        used: f64,
    },
    /// `--rho` equals a detector integral from the file's header, which
    /// is in the file's unit × sr, not a reflectance.
    RhoFromHeader {
        /// The `--rho` value.
        rho: f64,
        /// The header key (without `#`).
        key: String,
        /// The header's number, as written.
        value: String,
        /// The file's unit.
        unit: String,
    },
}

impl std::fmt::Display for SetWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SetWarning::NoTable { reason } => {
                write!(f, "{reason}; no θ_in-dependent material is made")
            }
            SetWarning::RhoFarFromIncidence { requested, used } => write!(
                f,
                "--rho given at θ_in {requested}°, nearest fitted incidence is {used}°"
            ),
            SetWarning::RhoFromHeader {
                rho,
                key,
                value,
                unit,
            } => write!(
                f,
                "--rho {rho} equals the header's #{key} value {value}: that is the detector \
                 signal integrated over the sphere, in {unit}·sr, not a reflectance; give the \
                 sample's measured directional-hemispherical reflectance"
            ),
        }
    }
}

/// Everything a fit produced.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitResult {
    /// The `fit.json` schema version ([`FIT_JSON_SCHEMA`]).
    pub schema: u32,
    /// Material name used in exports.
    pub name: String,
    /// Provenance.
    pub provenance: Provenance,
    /// How every input file became the fitted data.
    pub recipe: Recipe,
    /// The fit settings.
    pub config: FitConfig,
    /// One report per incidence, sorted by θ_in.
    pub incidences: Vec<FitReport>,
    /// One parameter set for all incidences.
    pub global: Option<FitReport>,
    /// θ_in interpolation of the per-incidence parameters (two incidences or more).
    pub table: Option<ParamTable>,
    /// Interpolation method requested.
    pub interpolation: Interpolation,
    /// Warnings about the whole set.
    #[serde(default)]
    pub warnings: Vec<SetWarning>,
    /// `--model auto`: the candidates and why the fit's model won.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub auto: Option<crate::AutoChoice>,
    /// Every other file of the fit folder, with its SHA-256 and the step
    /// that wrote it (`docs/fit-json.md`, "Output files"). Empty until the
    /// folder is complete, and in folders written before the listing.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub outputs: Vec<brtf_io::OutputFile>,
}

/// Why `fit.json` could not be read.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReadFitError {
    /// The file could not be read.
    #[error("cannot read {}: {error}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error (not a `source`: the message already shows it).
        error: std::io::Error,
    },
    /// The file is not JSON, or not a brtf fit of this schema.
    #[error("{}:{}: not a brtf fit result: {error}", path.display(), error.line())]
    Parse {
        /// The file.
        path: PathBuf,
        /// What serde found.
        error: serde_json::Error,
    },
    /// The file parses but holds what no fit makes (e.g. a broken table).
    #[error("{}: not a valid brtf fit result: {why}", path.display())]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        why: String,
    },
    /// The schema version is not the one this brtf reads.
    #[error(
        "{}: fit.json schema version {found} is not supported (this brtf {} reads version {}); {}",
        path.display(), env!("CARGO_PKG_VERSION"), FIT_JSON_SCHEMA,
        if *found < u64::from(FIT_JSON_SCHEMA) { "refit with `brtf fit`" } else { "use a newer brtf" }
    )]
    Schema {
        /// The file.
        path: PathBuf,
        /// The version found (1 when the field is missing).
        found: u64,
    },
}

impl ReadFitError {
    /// The file concerned.
    pub fn path(&self) -> &Path {
        match self {
            ReadFitError::Io { path, .. }
            | ReadFitError::Parse { path, .. }
            | ReadFitError::Invalid { path, .. }
            | ReadFitError::Schema { path, .. } => path,
        }
    }
}

impl FitResult {
    /// Reads `fit.json`, or `DIR/fit.json` when `path` is a folder,
    /// checking the schema version first.
    pub fn read(path: &Path) -> Result<FitResult, ReadFitError> {
        let path = if path.is_dir() {
            path.join("fit.json")
        } else {
            path.to_path_buf()
        };
        let text = std::fs::read_to_string(&path).map_err(|error| ReadFitError::Io {
            path: path.clone(),
            error,
        })?;
        Self::from_json(&text, &path)
    }

    /// Parses the text of a `fit.json` read from `path` (for messages).
    pub fn from_json(text: &str, path: &Path) -> Result<FitResult, ReadFitError> {
        let parse = |error| ReadFitError::Parse {
            path: path.to_path_buf(),
            error,
        };
        let value: serde_json::Value = serde_json::from_str(text).map_err(parse)?;
        // Version 1 had no `schema` field.
        let found = match value.get("schema") {
            None => 1,
            Some(v) => v.as_u64().unwrap_or(0),
        };
        if found != u64::from(FIT_JSON_SCHEMA) {
            return Err(ReadFitError::Schema {
                path: path.to_path_buf(),
                found,
            });
        }
        // From the text again, so that errors name their line.
        let result: FitResult = serde_json::from_str(text).map_err(parse)?;
        result.validate().map_err(|why| ReadFitError::Invalid {
            path: path.to_path_buf(),
            why,
        })?;
        Ok(result)
    }

    /// Checks what readers rely on beyond the types: the table, and each
    /// report's arguments.
    fn validate(&self) -> Result<(), String> {
        if let Some(table) = &self.table {
            table.validate().map_err(|e| e.to_string())?;
            if table.shape() != self.config.shape() {
                return Err(format!(
                    "the table is of {}, the fit of {}",
                    table.shape(),
                    self.config.shape()
                ));
            }
        }
        for r in &self.incidences {
            let incidence = (0.0..=180.0).contains(&r.theta_in) && r.phi_in.is_finite();
            if !incidence || r.phi_in.abs() > 720.0 {
                return Err(format!(
                    "{}: incidence θ_in {:.6e}, φ_in {:.6e} is not one a file can hold",
                    r.source, r.theta_in, r.phi_in
                ));
            }
        }
        let shape =
            brtf_model::Shape::new(self.config.kind, self.config.lobes, self.config.oriented)?;
        let n = shape.n_args();
        for r in self.incidences.iter().chain(&self.global) {
            if r.material_args.len() != n || !r.material_args.iter().all(|a| a.is_finite()) {
                return Err(format!(
                    "{}: {} material arguments, a {shape} has {n} finite ones",
                    r.source,
                    r.material_args.len(),
                ));
            }
        }
        Ok(())
    }

    /// Writes `DIR/fit.json` and `DIR/params.csv`, each atomically;
    /// nothing when the JSON would not read back.
    pub fn write(&self, dir: &Path) -> Result<(), brtf_io::IoError> {
        let json = self.checked_json(dir)?;
        self.write_params_csv(dir)?;
        brtf_io::write_atomic(&dir.join("fit.json"), json.as_bytes())
    }

    /// Writes `DIR/params.csv` atomically (for a caller that writes
    /// `fit.json` last, with [`FitResult::write_fit_json`]).
    pub fn write_params_csv(&self, dir: &Path) -> Result<(), brtf_io::IoError> {
        let csv = self.params_csv().map_err(|e| brtf_io::IoError {
            path: dir.join("params.csv"),
            what: "cannot format",
            source: std::io::Error::other(e),
        })?;
        brtf_io::ensure_folder(dir)?;
        brtf_io::write_atomic(&dir.join("params.csv"), csv.as_bytes())
    }

    /// Writes `DIR/fit.json` atomically, unless it would not read back.
    pub fn write_fit_json(&self, dir: &Path) -> Result<(), brtf_io::IoError> {
        let json = self.checked_json(dir)?;
        brtf_io::ensure_folder(dir)?;
        brtf_io::write_atomic(&dir.join("fit.json"), json.as_bytes())
    }

    /// The `fit.json` text, checked to read back: JSON has no NaN or
    /// infinity (serde_json writes null), so a non-finite number would
    /// leave a folder no other command can read. Refused here instead.
    fn checked_json(&self, dir: &Path) -> Result<String, brtf_io::IoError> {
        let json = self.to_json();
        let path = dir.join("fit.json");
        match FitResult::from_json(&json, &path) {
            Ok(_) => Ok(json),
            Err(e) => Err(brtf_io::IoError {
                path,
                what: "refusing to write a fit.json that does not read back",
                source: std::io::Error::other(e.to_string()),
            }),
        }
    }

    /// The `fit.json` text.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("a FitResult always serialises")
    }

    /// The evaluation options the fit used (variant, Fresnel constant, ω).
    pub fn options(&self) -> EvalOptions {
        self.config.options
    }

    /// `Some(false)` when every input had one channel (CIE Y): the colour
    /// was never measured and the material is grey; `Some(true)` when
    /// some had three; `None` when the fit did not record it.
    pub fn colour_measured(&self) -> Option<bool> {
        let inputs = &self.provenance.inputs;
        if inputs.is_empty() || inputs.iter().any(|i| i.channels == 0) {
            return None;
        }
        Some(inputs.iter().any(|i| i.channels >= 3))
    }

    /// The material (any shape) of a report's fitted arguments.
    pub fn composite_of(&self, report: &FitReport) -> Option<Composite> {
        Composite::new(
            self.config.shape(),
            &report.material_args,
            Some(DVec3::from_array(self.config.orientation)),
        )
        .ok()
    }

    /// The one primitive of a one-lobe fit's report (`None` for a lobe sum).
    pub fn material_of(&self, report: &FitReport) -> Option<Material> {
        self.composite_of(report)?.single().copied()
    }

    /// The static material (any shape): the all-incidence fit, else the
    /// first incidence.
    pub fn static_composite(&self) -> Option<Composite> {
        self.global
            .as_ref()
            .or(self.incidences.first())
            .and_then(|r| self.composite_of(r))
    }

    /// The static material of a one-lobe fit (`None` for a lobe sum).
    pub fn static_material(&self) -> Option<Material> {
        self.static_composite()?.single().copied()
    }

    /// The input file of incidence `index`.
    pub fn input_of(&self, index: usize) -> Option<&InputFile> {
        let report = self.incidences.get(index)?;
        self.provenance
            .inputs
            .iter()
            .find(|i| i.label() == report.source)
            .or_else(|| self.provenance.inputs.get(index))
    }

    /// True when the fitted data are the back side of a Klems file, whose
    /// frame is mirrored ([`crate::azimuth_from_u`]).
    pub fn is_mirrored_side(&self) -> bool {
        self.provenance
            .inputs
            .iter()
            .any(InputFile::is_klems_back_side)
    }

    /// The material (any shape) at θ_in: the table's, else the
    /// incidence's own fit (`report`), else the static material.
    pub fn composite_at(&self, theta_in: f64, report: Option<&FitReport>) -> Option<Composite> {
        if let Some(table) = &self.table {
            return table.composite_at(theta_in).ok().map(|(m, _)| m);
        }
        report
            .and_then(|r| self.composite_of(r))
            .or_else(|| self.static_composite())
    }

    /// [`Self::composite_at`] of a one-lobe fit (`None` for a lobe sum).
    pub fn material_at(&self, theta_in: f64, report: Option<&FitReport>) -> Option<Material> {
        self.composite_at(theta_in, report)?.single().copied()
    }

    /// [`Self::composite_at`] for a light at (`theta_in`, `phi_in`), φ_in
    /// in the data's frame (as [`FitReport::phi_in`]): a table that
    /// follows φ_in gives its parameters at that azimuth.
    pub fn composite_at_direction(
        &self,
        theta_in: f64,
        phi_in: f64,
        report: Option<&FitReport>,
    ) -> Option<Composite> {
        match &self.table {
            Some(table) if table.depends_on_azimuth() => {
                let phi =
                    crate::azimuth_from_u(self.config.orientation, self.is_mirrored_side(), phi_in);
                table
                    .composite_at_direction(theta_in, phi)
                    .ok()
                    .map(|(m, _)| m)
            }
            _ => self.composite_at(theta_in, report),
        }
    }

    /// [`Self::composite_at_direction`] of a one-lobe fit.
    pub fn material_at_direction(
        &self,
        theta_in: f64,
        phi_in: f64,
        report: Option<&FitReport>,
    ) -> Option<Material> {
        self.composite_at_direction(theta_in, phi_in, report)?
            .single()
            .copied()
    }

    /// `params.csv`: one row per incidence, then the all-incidence fit as a
    /// row with θ_in `all`.
    pub fn params_csv(&self) -> Result<String, csv::Error> {
        let Some(first) = self.incidences.first() else {
            return Ok(String::new());
        };
        let names: Vec<&str> = first.params.iter().map(|p| p.name.as_str()).collect();
        let mut w = csv::Writer::from_writer(Vec::new());
        let mut header = vec!["theta_in".to_string(), "phi_in".into(), "n_points".into()];
        header.extend(names.iter().map(|n| n.to_string()));
        header.extend(names.iter().map(|n| format!("{n}_stderr")));
        header.extend(["rms_rel".into(), "cost".into(), "termination".into()]);
        // E1 and the adequacy columns follow the contract's (empty without them).
        header.push("e1".into());
        header.extend(["rho_dh_data".into(), "rho_dh_model".into()]);
        w.write_record(&header)?;
        let row = |r: &FitReport, theta: String, phi: String| -> Vec<String> {
            let mut v = vec![theta, phi, r.n_points.to_string()];
            v.extend(r.params.iter().map(|p| format!("{:.8}", p.value)));
            // An empty cell where there is no standard error.
            v.extend(
                r.params
                    .iter()
                    .map(|p| p.stderr.map_or_else(String::new, |e| format!("{e:.3e}"))),
            );
            v.extend([
                format!("{:.6}", r.rms_rel),
                format!("{:.6e}", r.cost),
                r.termination.label().into(),
            ]);
            let adequacy = r.adequacy.as_ref();
            let number = |x: Option<f64>| x.map_or_else(String::new, |v| format!("{v:.6}"));
            v.push(number(r.e1));
            v.push(number(adequacy.and_then(|a| a.rho_data)));
            v.push(number(adequacy.map(|a| a.rho_model)));
            v
        };
        for r in &self.incidences {
            w.write_record(row(r, format!("{}", r.theta_in), format!("{}", r.phi_in)))?;
        }
        if let Some(g) = &self.global {
            w.write_record(row(g, "all".into(), String::new()))?;
        }
        let bytes = w
            .into_inner()
            .map_err(|e| csv::Error::from(e.into_error()))?;
        Ok(String::from_utf8(bytes).expect("CSV of UTF-8 text is UTF-8"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A number JSON cannot hold (serde_json writes infinity as null) is
    /// refused before anything is written, instead of leaving a fit.json
    /// that no command can read.
    #[test]
    fn a_fit_json_that_would_not_read_back_is_not_written() {
        let shipped = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fits/alu-ggx/fit.json");
        let mut result = FitResult::read(&shipped).expect("the shipped fit reads");
        let dir = std::env::temp_dir().join(format!("brtf-fit-json-{}", std::process::id()));
        result.write(&dir).expect("a finite result writes");
        assert!(FitResult::read(&dir.join("fit.json")).is_ok());
        std::fs::remove_dir_all(&dir).unwrap();
        result.incidences[0].cost = f64::INFINITY;
        let error = result.write(&dir).unwrap_err().to_string();
        assert!(error.contains("does not read back"), "{error}");
        assert!(!dir.join("fit.json").exists());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
