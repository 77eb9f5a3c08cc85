//! Radiance exports of a fit: what `brtf export` (and the end of
//! `brtf fit`) writes into the fit folder.
//!
//! | file | what |
//! |---|---|
//! | `<name>.rad` | the **static** material: one `plastic`/`metal`/`trans` (or `*2`) primitive from the all-incidence fit, or from the table at a chosen θ_in, with a comment header (provenance, fit quality, variant, caveats); a lobe sum is its primitives `<name>.1` … and the constant `mixfunc` tree `<name>` that mixes them, last |
//! | `<name>-theta.rad` | the **θ_in-dependent** material: a `BRTDfunc` (or `plasfunc`/`metfunc`/`transfunc` when they suffice) with the same identifier |
//! | `<name>-theta.cal` | its function file: the parameter table as exact cubic segments and brtf-model's BSDF in Radiance's function language (a lobe sum's lobes summed with their θ_in-dependent weights) |
//! | `<name>-preview.rad` | a small scene (sphere and floor under a sun and a sky) that either material file can be rendered with |
//!
//! Everything is built in memory first ([`exports`]); [`write_exports`]
//! then writes each file atomically (a temporary file in the same folder,
//! renamed into place). `docs/radiance.md` explains how to use the files.

mod cal;
mod energy;
pub mod klems;
pub mod klems_cal;
mod num;
mod pieces;
mod preview;
mod report;
mod static_material;
mod theta;

use brtf_fit::{FitReport, FitResult};
use brtf_model::{Composite, MaterialKind, ModelError};
pub use energy::{EnergyOff, STATIC_ENERGY_TOLERANCE};
use std::path::{Path, PathBuf};

/// What to export.
#[derive(Debug, Clone, PartialEq)]
pub struct ExportOptions {
    /// Material identifier and file stem. `None`: the fit's name (with
    /// characters Radiance cannot take replaced by `_`).
    pub name: Option<String>,
    /// Take the static material from the parameters at this θ_in
    /// (degrees) instead of the all-incidence fit.
    pub at: Option<f64>,
    /// Write the θ_in-dependent material (needs two incidences or more).
    pub theta_dependent: bool,
    /// Write the preview scene.
    pub preview: bool,
    /// A colour measured elsewhere (`--colour R,G,B`): each material takes
    /// its chromaticity at its own fitted luminance.
    pub colour: Option<[f64; 3]>,
}

impl ExportOptions {
    /// Checks `at`: 0 ≤ θ_in < 90 degrees.
    pub fn validate(&self) -> Result<(), brtf_model::OptionError> {
        match self.at {
            Some(at) => brtf_model::OptionError::check(
                "--at",
                at,
                (0.0..90.0).contains(&at),
                "0 ≤ θ_in < 90 degrees",
            ),
            None => Ok(()),
        }
    }
}

impl Default for ExportOptions {
    fn default() -> Self {
        ExportOptions {
            name: None,
            at: None,
            theta_dependent: true,
            preview: true,
            colour: None,
        }
    }
}

/// Why the exports could not be made.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ExportError {
    /// The fit result holds neither an all-incidence fit nor any incidence.
    #[error("the fit result holds no fitted parameters (no all-incidence fit and no incidence)")]
    NoParameters,
    /// Fitted arguments do not make a valid material.
    #[error("the fitted parameters of {what} are not a valid {kind}: {source}")]
    Material {
        /// Which parameter set.
        what: String,
        /// The material type.
        kind: MaterialKind,
        /// What is wrong.
        source: ModelError,
    },
    /// `--colour` is not a colour.
    #[error(transparent)]
    Colour(#[from] brtf_fit::ColourError),
    /// The θ_in table's shape is not one brtf fits.
    #[error("the θ_in table: {0}")]
    Table(String),
    /// `--at` cannot be served.
    #[error("--at {theta}: {reason}")]
    At {
        /// The requested θ_in.
        theta: f64,
        /// Why not.
        reason: String,
    },
    /// The material name cannot be a Radiance identifier and file stem.
    #[error(
        "material name `{0}` cannot be used: give letters, digits, `_`, `-` or `.` (not first)"
    )]
    BadName(String),
    /// A file could not be written.
    #[error("cannot write {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
}

/// One exported file, in memory.
#[derive(Debug, Clone, PartialEq)]
pub struct ExportFile {
    /// File name (no folder).
    pub file_name: String,
    /// Its text.
    pub text: String,
}

/// All exports of a fit, in memory.
#[derive(Debug, Clone, PartialEq)]
pub struct Export {
    /// The material identifier used in every file.
    pub name: String,
    /// The files, static material first.
    pub files: Vec<ExportFile>,
    /// Things the user should know (skipped exports, caveats), one line each.
    pub notes: Vec<String>,
}

/// What [`write_exports`] wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct Exported {
    /// The files written, static material first.
    pub files: Vec<PathBuf>,
    /// Things the user should know, one line each.
    pub notes: Vec<String>,
}

/// File name of the static material.
pub fn static_file_name(name: &str) -> String {
    format!("{name}.rad")
}

/// File name of the θ_in-dependent material.
pub fn theta_file_name(name: &str) -> String {
    format!("{name}-theta.rad")
}

/// File name of the θ_in-dependent material's function file.
pub fn cal_file_name(name: &str) -> String {
    format!("{name}-theta.cal")
}

/// File name of the preview scene.
pub fn preview_file_name(name: &str) -> String {
    format!("{name}-preview.rad")
}

/// File name of a static material whose energy is off (see
/// [`STATIC_ENERGY_TOLERANCE`]).
pub fn energy_off_file_name(name: &str) -> String {
    format!("{name}-energy-off.rad")
}

/// Builds every export of `result` in memory.
pub fn exports(result: &FitResult, options: &ExportOptions) -> Result<Export, ExportError> {
    let coloured;
    let result = match options.colour {
        Some(rgb) => {
            coloured = result.with_colour(rgb)?;
            &coloured
        }
        None => result,
    };
    let name = material_name(result, options)?;
    let chosen = static_material::choose(result, options.at)?;
    let energy = energy::static_energy_off(result, &chosen.material);
    let static_file = match &energy {
        Some(_) => energy_off_file_name(&name),
        None => static_file_name(&name),
    };
    let mut files = Vec::new();
    let mut notes = Vec::new();
    let theta = match (&result.table, options.theta_dependent) {
        (Some(table), true) if table.oriented && table.depends_on_azimuth() => {
            notes.push(
                "no θ_in-dependent material: the table follows φ_in, which is counted from the \
                 orientation, and the orientation is fitted too"
                    .into(),
            );
            None
        }
        (Some(table), true) => Some(theta::build(
            result,
            table,
            &name,
            &static_file,
            options.colour,
        )?),
        (None, true) => {
            notes.push(format!(
                "no θ_in-dependent material: the fit has {} incidence(s), interpolation needs two",
                result.incidences.len()
            ));
            None
        }
        (_, false) => None,
    };
    let mut stat = static_material::text(
        result,
        &chosen,
        &name,
        &static_file,
        theta.is_some(),
        options.colour,
    );
    if let Some(off) = &energy {
        let what = energy_off_text(off);
        let instead = if theta.is_some() {
            format!("; {} follows each incidence", theta_file_name(&name))
        } else {
            String::new()
        };
        notes.push(format!(
            "{static_file}: written under this name, not {}, because {what}{instead}",
            static_file_name(&name)
        ));
        stat.text = format!("# ENERGY OFF: {}.\n{}", report::ascii(&what), stat.text);
    }
    notes.extend(stat.notes);
    files.push(ExportFile {
        file_name: static_file,
        text: stat.text,
    });
    if let Some(theta) = theta {
        notes.extend(theta.notes);
        files.push(ExportFile {
            file_name: theta_file_name(&name),
            text: theta.rad,
        });
        files.push(ExportFile {
            file_name: cal_file_name(&name),
            text: theta.cal,
        });
    }
    if options.preview && result.config.free_scale {
        notes.push(
            "no preview scene for a free-scale fit (refit with --rho VALUE@THETA or \
             --beam-integral B for a renderable material)"
                .into(),
        );
    } else if options.preview {
        files.push(ExportFile {
            file_name: preview_file_name(&name),
            text: preview::text(result, &name, &files[0].file_name, files.len() > 1),
        });
    }
    Ok(Export { name, files, notes })
}

/// Why a static material's file is renamed, in words.
fn energy_off_text(off: &energy::EnergyOff) -> String {
    let (quantity, side) = match off.label {
        "rho_dh" => ("ρ_dh", "reflects"),
        _ => ("τ_dh", "transmits"),
    };
    let more = if off.deviation() > 0.0 {
        "more"
    } else {
        "less"
    };
    format!(
        "it {side} {:.0}% {more} than the sample at θ_in = {}° ({quantity} {:.3} against the \
         data's {:.3}; beyond {:.0}%)",
        100.0 * off.deviation().abs(),
        num::sig(off.theta_in, 4),
        off.model,
        off.data,
        100.0 * STATIC_ENERGY_TOLERANCE
    )
}

/// Writes every export of `result` into `dir` (which must exist), each file
/// atomically. Returns the paths written, static material first.
pub fn write_exports(
    dir: &Path,
    result: &FitResult,
    options: &ExportOptions,
) -> Result<Exported, ExportError> {
    let export = exports(result, options)?;
    let mut files = Vec::with_capacity(export.files.len());
    for file in &export.files {
        let path = dir.join(&file.file_name);
        write_atomically(&path, file.text.as_bytes())?;
        files.push(path);
    }
    let mut notes = export.notes;
    notes.extend(remove_other_static_file(
        dir,
        &export.name,
        &export.files[0].file_name,
    ));
    Ok(Exported { files, notes })
}

/// An earlier export's static material under the other name (`<name>.rad`
/// after `<name>-energy-off.rad` or the reverse) would be taken for this
/// one: it is removed when its header says brtf exported it, and a note
/// says so. A file of another origin is left alone, with a note.
fn remove_other_static_file(dir: &Path, name: &str, written: &str) -> Option<String> {
    let other = [static_file_name(name), energy_off_file_name(name)]
        .into_iter()
        .find(|f| f != written)?;
    let path = dir.join(&other);
    let text = std::fs::read_to_string(&path).ok()?;
    let ours = text.lines().take(3).any(|l| {
        l.starts_with('#') && l.contains("written by brtf") && l.contains("(brtf export)")
    });
    if ours && std::fs::remove_file(&path).is_ok() {
        Some(format!(
            "removed {other}, an earlier export's static material: {written} replaces it"
        ))
    } else {
        Some(format!(
            "{other} is still in the folder and is not this export's static material ({written} is)"
        ))
    }
}

/// Writes `bytes` atomically (see [`brtf_io::write_atomic`]).
fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), ExportError> {
    brtf_io::write_atomic(path, bytes).map_err(|e| ExportError::Io {
        path: e.path,
        source: e.source,
    })
}

/// The identifier: `--name` (checked) or the fit's name (sanitised).
fn material_name(result: &FitResult, options: &ExportOptions) -> Result<String, ExportError> {
    let ok_char = |c: char| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.');
    if let Some(name) = &options.name {
        if name.is_empty() || !name.chars().all(ok_char) || name.starts_with(['-', '.']) {
            return Err(ExportError::BadName(name.clone()));
        }
        return Ok(name.clone());
    }
    // The fit's name may be a folder path: keep its last component.
    let base = result
        .name
        .rsplit(['/', '\\'])
        .find(|s| !s.is_empty())
        .unwrap_or("");
    let mut name: String = base
        .chars()
        .map(|c| if ok_char(c) { c } else { '_' })
        .collect();
    while name.starts_with(['-', '.']) {
        name.remove(0);
    }
    if name.is_empty() {
        name = "material".into();
    }
    Ok(name)
}

/// The material (any shape) of a fitted report, or a located error.
fn composite_of(
    result: &FitResult,
    report: &FitReport,
    what: &str,
) -> Result<Composite, ExportError> {
    Composite::new(
        result.config.shape(),
        &report.material_args,
        Some(glam::DVec3::from_array(result.config.orientation)),
    )
    .map_err(|source| ExportError::Material {
        what: what.to_string(),
        kind: result.config.kind,
        source,
    })
}
