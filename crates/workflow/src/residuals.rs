//! `residuals.csv` of a fit folder (see [`brtf_fit::residual_rows`]):
//! from the fitted data when the caller has them, else rebuilt from the
//! measurement files.

use crate::WorkflowError;
use brtf_fit::{FitResult, PreparedMeasurement};
use rayon::prelude::*;
use std::borrow::Cow;
use std::path::{Path, PathBuf};

/// Writes `stage/residuals.csv` for `result`, from `prepared` (the fitted
/// data by incidence) or, for incidences it lacks, from the measurement
/// files (looked for as [`brtf_io::locate_input`] does from `shown`).
/// Returns the file and a note per incidence left out.
pub(crate) fn write_residuals(
    stage: &Path,
    shown: &Path,
    result: &FitResult,
    prepared: &[PreparedMeasurement],
) -> Result<(PathBuf, Vec<String>), WorkflowError> {
    let mut notes = Vec::new();
    let mut data: Vec<Option<Cow<'_, PreparedMeasurement>>> = Vec::new();
    for k in 0..result.incidences.len() {
        match prepared.get(k) {
            Some(p) => data.push(Some(Cow::Borrowed(p))),
            None => match rebuild(result, k, shown) {
                Ok(p) => data.push(Some(Cow::Owned(p))),
                Err(e) => {
                    notes.push(format!("residuals.csv: {e}; its rows are left out"));
                    data.push(None);
                }
            },
        }
    }
    let channels = data.iter().flatten().next().map_or(1, |p| p.channels());
    // In parallel over the incidences as well as within each: a Klems
    // incidence's few hundred samples are one piece.
    let rows: Vec<Vec<Vec<u8>>> = data
        .par_iter()
        .enumerate()
        .filter_map(|(k, p)| Some(brtf_fit::residual_rows(result, k, p.as_ref()?)))
        .collect();
    let mut parts: Vec<&[u8]> = vec![brtf_fit::residuals_header(channels).as_bytes()];
    parts.extend(rows.iter().flatten().map(Vec::as_slice));
    let path = stage.join("residuals.csv");
    brtf_io::write_atomic_parts(&path, &parts)?;
    Ok((path, notes))
}

/// Incidence `index`'s data rebuilt from its measurement file.
fn rebuild(result: &FitResult, index: usize, shown: &Path) -> Result<PreparedMeasurement, String> {
    let report = &result.incidences[index];
    let input = result
        .input_of(index)
        .ok_or_else(|| format!("{}: not listed in the provenance", report.source))?;
    let path = brtf_io::locate_input(&input.path, shown, &[])
        .ok_or_else(|| format!("{}: measurement file not found", input.path))?;
    let bytes = brtf_io::read_input(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    brtf_fit::prepare_input(&result.recipe, input, &bytes, &path).map_err(|e| e.to_string())
}
