//! A fit folder, written whole: `params.csv`, `residuals.csv`, the Radiance exports, the
//! plots and `report.html`, then `fit.json` listing every file, staged
//! and swapped in as one ([`brtf_io::FolderUpdate`]).

use crate::WorkflowError;
use brtf_fit::{FitResult, PreparedMeasurement};
use brtf_io::{FolderUpdate, OutputFile, Producer, describe_outputs};
use std::path::{Path, PathBuf};

/// Which optional outputs a fit folder gets.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Outputs {
    /// The Radiance materials (static, θ_in-dependent, preview).
    pub export: bool,
    /// The plots and `report.html`.
    pub plots: bool,
}

impl Default for Outputs {
    fn default() -> Outputs {
        Outputs {
            export: true,
            plots: true,
        }
    }
}

/// What writing one fit folder produced.
#[derive(Debug, Clone, Default)]
pub struct FolderWritten {
    /// The Radiance exports, as the user sees them (under the final folder).
    pub exports: Vec<PathBuf>,
    /// How many plot files (SVG and PNG) were drawn.
    pub plots: usize,
    /// `report.html`, when plotted.
    pub report: Option<PathBuf>,
    /// Things the user should know, one line each, ready to print.
    pub notes: Vec<String>,
}

impl std::fmt::Display for FolderWritten {
    /// The `wrote …` lines.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        for file in &self.exports {
            writeln!(f, "wrote {}", file.display())?;
        }
        if let Some(report) = &self.report {
            writeln!(f, "wrote {} plots and {}", self.plots, report.display())?;
        }
        Ok(())
    }
}

/// Writes one fit's folder into `stage` (shown to the user as `shown`):
/// `params.csv`, `residuals.csv`, the exports and plots `outputs` asks for, then
/// `fit.json` listing them. The plots draw `prepared` (the fitted data,
/// as [`brtf_fit::fit_set_with_data`] keeps them) and read the
/// measurement files for incidences it lacks.
pub fn write_fit_folder(
    stage: &Path,
    shown: &Path,
    result: &mut FitResult,
    prepared: &[PreparedMeasurement],
    outputs: Outputs,
) -> Result<FolderWritten, WorkflowError> {
    // fit.json is written once, last: it lists every other file. The
    // residuals (megabytes of text) are written beside the exports and
    // plots.
    result.write_params_csv(stage)?;
    let shared: &FitResult = result;
    let (residuals, rest) = rayon::join(
        || crate::residuals::write_residuals(stage, shown, shared, prepared),
        || exports_and_plots(stage, shown, shared, prepared, outputs),
    );
    let (residuals, notes) = residuals?;
    let (mut written, exported) = rest?;
    let mut listed =
        describe_outputs(stage, &[stage.join("params.csv"), residuals], Producer::Fit)?;
    listed.extend(exported);
    written
        .notes
        .splice(0..0, notes.iter().map(|n| format!("note: {n}")));
    listed.sort_by(|a, b| a.path.cmp(&b.path));
    result.outputs = listed;
    result.write_fit_json(stage)?;
    Ok(written)
}

/// The exports and plots `outputs` asks for, written into `stage`: what
/// the user is told, and the files' listing.
fn exports_and_plots(
    stage: &Path,
    shown: &Path,
    result: &FitResult,
    prepared: &[PreparedMeasurement],
    outputs: Outputs,
) -> Result<(FolderWritten, Vec<OutputFile>), WorkflowError> {
    let mut listed = Vec::new();
    let mut written = FolderWritten::default();
    if outputs.export {
        let options = brtf_radiance::export::ExportOptions::default();
        let exported =
            brtf_radiance::export::write_exports(stage, result, &options).map_err(|source| {
                WorkflowError::Export {
                    folder: shown.to_path_buf(),
                    source,
                }
            })?;
        listed.extend(describe_outputs(stage, &exported.files, Producer::Export)?);
        written.exports = shown_paths(stage, shown, &exported.files);
        written
            .notes
            .extend(exported.notes.iter().map(|n| format!("note: {n}")));
    }
    if outputs.plots {
        let mut options = brtf_plot::PlotOptions::default();
        options.search_dirs.push(shown.to_path_buf());
        let plotted = brtf_plot::write_plots_with_data(stage, result, prepared, &options).map_err(
            |source| WorkflowError::Plot {
                folder: shown.to_path_buf(),
                source,
            },
        )?;
        listed.extend(describe_outputs(stage, &plotted.files, Producer::Plot)?);
        written.plots = plotted.files.len().saturating_sub(1);
        written.report = Some(shown.join("report.html"));
        written.notes.extend(
            plotted
                .warnings
                .iter()
                .map(|w| format!("brtf: warning: {w}")),
        );
    }
    Ok((written, listed))
}

/// `files` (under `stage`) as the user will find them (under `shown`).
fn shown_paths(stage: &Path, shown: &Path, files: &[PathBuf]) -> Vec<PathBuf> {
    files
        .iter()
        .map(|f| shown.join(f.strip_prefix(stage).unwrap_or(f)))
        .collect()
}

/// Saves `result` as the fit folder `out`, replacing it as a whole (see
/// [`brtf_io::check_replaceable`]; `force` replaces a folder that holds
/// another fit or other files). Returns every file of the folder.
pub fn save_fit(
    result: &FitResult,
    prepared: &[PreparedMeasurement],
    inputs: &[PathBuf],
    out: &Path,
    outputs: Outputs,
    force: bool,
) -> Result<(Vec<PathBuf>, FolderWritten), WorkflowError> {
    let update = FolderUpdate::fresh(out)?;
    brtf_io::check_replaceable(update.target(), inputs, force)?;
    let mut result = result.clone();
    let written = write_fit_folder(update.path(), out, &mut result, prepared, outputs)?;
    let mut files: Vec<PathBuf> = result.outputs.iter().map(|o| out.join(&o.path)).collect();
    files.push(out.join("fit.json"));
    update.commit()?;
    Ok((files, written))
}

/// Lists `fresh`, the files `by` wrote into the staged folder `stage`, in
/// its `fit.json`, and removes the files `by` listed there before and did
/// not write again. A folder without `fit.json` keeps no listing.
pub(crate) fn relist(stage: &Path, fresh: &[PathBuf], by: Producer) -> Result<(), WorkflowError> {
    let path = stage.join("fit.json");
    if !path.exists() {
        return Ok(());
    }
    let mut fit = FitResult::read(&path)?;
    let fresh: Vec<OutputFile> = describe_outputs(stage, fresh, by)?;
    fit.outputs = brtf_io::replace_outputs(stage, &fit.outputs, fresh, by)?;
    Ok(brtf_io::write_atomic(&path, fit.to_json().as_bytes())?)
}
