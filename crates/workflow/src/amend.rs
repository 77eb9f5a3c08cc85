//! Commands that add to a fit folder: exports, Klems XML and plots. Each
//! works on a staged copy of the folder that replaces this command's own
//! files, keeps the rest and lists the new files in `fit.json`.

use crate::WorkflowError;
use crate::folder::relist;
use brtf_fit::FitResult;
use brtf_io::{FolderUpdate, Producer};
use brtf_radiance::export::klems::{self, KlemsExport, KlemsOptions};
use brtf_radiance::export::{ExportOptions, write_exports};
use std::path::{Path, PathBuf};

/// Reads a fit folder's `fit.json` ([`FitResult::read`]).
pub fn read_fit(dir: &Path) -> Result<FitResult, WorkflowError> {
    Ok(FitResult::read(&dir.join("fit.json"))?)
}

/// Files written into a folder, as the user sees them, and notes.
#[derive(Debug, Clone, Default)]
pub struct Amended {
    /// The files written.
    pub files: Vec<PathBuf>,
    /// Things the user should know, one line each.
    pub notes: Vec<String>,
}

/// Writes the Radiance materials of `result` into `folder` (created when
/// missing): `brtf export` and `Fit.export`.
pub fn export_into(
    folder: &Path,
    result: &FitResult,
    options: &ExportOptions,
) -> Result<Amended, WorkflowError> {
    options.validate()?;
    let update = FolderUpdate::amend(folder)?;
    let exported =
        write_exports(update.path(), result, options).map_err(|source| WorkflowError::Export {
            folder: folder.to_path_buf(),
            source,
        })?;
    relist(update.path(), &exported.files, Producer::Export)?;
    let files = exported
        .files
        .iter()
        .map(|f| folder.join(f.strip_prefix(update.path()).unwrap_or(f)))
        .collect();
    update.commit()?;
    Ok(Amended {
        files,
        notes: exported.notes,
    })
}

/// Writes `result`'s `fit.json` and `params.csv` into `folder` when it has
/// no `fit.json` yet, so that commands reading a fit folder can read it.
/// Returns the files written.
pub fn ensure_fit_json(folder: &Path, result: &FitResult) -> Result<Vec<PathBuf>, WorkflowError> {
    if folder.join("fit.json").is_file() {
        return Ok(Vec::new());
    }
    let update = FolderUpdate::amend(folder)?;
    result.write(update.path())?;
    update.commit()?;
    Ok(vec![folder.join("params.csv"), folder.join("fit.json")])
}

/// The Klems BSDF XML of the fit folder `dir` (one fit, or a two-sided
/// Klems fit's `front/` and `back/`), and its file stem. The material is
/// named `name`, else the fit's name (a two-sided folder: the folder's).
pub fn klems_of_fit_folder(
    dir: &Path,
    name: Option<&str>,
    mut options: KlemsOptions,
) -> Result<(String, KlemsExport), WorkflowError> {
    let two_sided = dir.join("front").join("fit.json").is_file();
    let name = match name {
        Some(n) => n.to_string(),
        // (A side's own folder, `…/front`, is named by its fit.)
        None if two_sided => match dir.file_name() {
            Some(n) => n.to_string_lossy().into_owned(),
            None => read_fit(&dir.join("front"))?.name,
        },
        None => read_fit(dir)?.name,
    };
    let stem = klems::klems_file_stem(&name);
    options.name = name;
    let export = klems::klems_from_fit_dir(dir, &options).map_err(|e| {
        WorkflowError::from(e).context(format!("exporting {} as Klems XML", dir.display()))
    })?;
    Ok((stem, export))
}

/// Writes `export` as `out/<stem>.xml`; in a fit folder, listed in its
/// `fit.json` with the other exports. Returns the file.
pub fn write_klems_into(
    out: &Path,
    stem: &str,
    export: &KlemsExport,
) -> Result<PathBuf, WorkflowError> {
    let path = out.join(format!("{stem}.xml"));
    if !out.join("fit.json").is_file() {
        brtf_io::ensure_folder(out)?;
        klems::write_klems(&path, export)?;
        return Ok(path);
    }
    let update = FolderUpdate::amend(out)?;
    let staged = update.path().join(format!("{stem}.xml"));
    klems::write_klems(&staged, export)?;
    // The other exports stay listed.
    let listed = FitResult::read(&update.path().join("fit.json"))?;
    let mut fresh: Vec<PathBuf> = listed
        .outputs
        .iter()
        .filter(|o| o.by == Producer::Export && update.path().join(&o.path).is_file())
        .map(|o| update.path().join(&o.path))
        .filter(|p| *p != staged)
        .collect();
    fresh.push(staged);
    relist(update.path(), &fresh, Producer::Export)?;
    update.commit()?;
    Ok(path)
}

/// Draws the plots and `report.html` of the fit folder `dir`: `brtf plot`.
pub fn plot_folder(
    dir: &Path,
    mut options: brtf_plot::PlotOptions,
) -> Result<brtf_plot::Written, WorkflowError> {
    let result = read_fit(dir)?;
    let update = FolderUpdate::amend(dir)?;
    options.search_dirs.push(dir.to_path_buf());
    let written = brtf_plot::write_plots(update.path(), &result, &options).map_err(|source| {
        WorkflowError::Plot {
            folder: dir.to_path_buf(),
            source,
        }
    })?;
    relist(update.path(), &written.files, Producer::Plot)?;
    update.commit()?;
    Ok(written)
}

/// The Klems BSDF XML of the material `name` of the Radiance file `path`
/// (one primitive or a lobe sum, a constant mixfunc tree), written as `<out>/<name>.xml` (`out` defaults to the file's folder);
/// with `with_cal` also `<name>-bsdf2klems.cal`, its BSDF as the function
/// `bsdf2klems -f` takes.
pub fn export_klems_of_material(
    path: &Path,
    name: Option<&str>,
    eval: &brtf_model::EvalOptions,
    mut options: KlemsOptions,
    out: Option<&Path>,
    with_cal: bool,
) -> Result<Amended, WorkflowError> {
    eval.validate()?;
    let (name, material) = crate::read_material_file(path, name)?;
    let bytes = brtf_io::read_input(path).map_err(|source| brtf_io::IoError {
        path: path.to_path_buf(),
        what: "cannot read",
        source,
    })?;
    options.name = name.clone();
    let export = klems::klems_from_composite(
        &material,
        eval,
        &path.display().to_string(),
        &brtf_io::sha256_hex(&bytes),
        &options,
    )?;
    let out = out
        .map(Path::to_path_buf)
        .or_else(|| path.parent().map(Path::to_path_buf))
        .unwrap_or_default();
    brtf_io::ensure_folder(&out)?;
    let xml = out.join(format!("{name}.xml"));
    klems::write_klems(&xml, &export)?;
    let mut files = vec![xml];
    if with_cal {
        let cal = brtf_radiance::export::klems_cal::composite_function_cal(&material)
            .map_err(|e| WorkflowError::Usage(format!("--klems-cal: {e}")))?;
        let cal_path = out.join(format!("{name}-bsdf2klems.cal"));
        brtf_io::write_atomic(&cal_path, cal.as_bytes())?;
        files.push(cal_path);
    }
    Ok(Amended {
        files,
        notes: export.notes,
    })
}

/// The Klems BSDF XML of `material`, named `name`, held in memory (the
/// Python package's `Material.to_klems`): the computation of
/// [`export_klems_of_material`], with the material's Radiance text standing
/// for the file (`source` names it) in the provenance.
pub fn klems_of_composite(
    material: &brtf_model::Composite,
    name: &str,
    eval: &brtf_model::EvalOptions,
    mut options: KlemsOptions,
    source: &str,
) -> Result<KlemsExport, WorkflowError> {
    eval.validate()?;
    let primitives = brtf_radiance::composite_primitives(material, name);
    let text: String = primitives
        .iter()
        .map(brtf_radiance::format_primitive)
        .collect();
    options.name = name.to_string();
    let sha = brtf_io::sha256_hex(text.as_bytes());
    Ok(klems::klems_from_composite(
        material, eval, source, &sha, &options,
    )?)
}

/// `brtf check`: renders the fit folder `dir` through the virtual
/// gonio-photometer ([`brtf_trace::check_fit`]) and writes the comparison
/// as CSV to `out` (default `DIR/check.csv`). Returns the report and the
/// file written.
pub fn check_folder(
    dir: &Path,
    options: &brtf_trace::CheckOptions,
    out: Option<&Path>,
) -> Result<(brtf_trace::CheckReport, PathBuf), WorkflowError> {
    options.validate()?;
    let fit = read_fit(dir)?;
    let out = out.map_or_else(|| dir.join("check.csv"), Path::to_path_buf);
    let inputs = brtf_io::fit_folder_inputs(dir, "check", &options.search_dirs);
    let inputs: Vec<&Path> = inputs.iter().map(PathBuf::as_path).collect();
    brtf_io::check_overwrite(&out, &inputs, None, true)?;
    let report = brtf_trace::check_fit(&fit, dir, options)?;
    if let Some(folder) = out.parent().filter(|p| !p.as_os_str().is_empty()) {
        brtf_io::ensure_folder(folder)?;
    }
    let csv = report
        .csv()
        .map_err(|e| WorkflowError::Usage(format!("cannot format the check's CSV: {e}")))?;
    brtf_io::write_atomic(&out, csv.as_bytes())?;
    Ok((report, out))
}
