//! `brtf fit` as a library: one sample (files, or a Klems file's sides)
//! into its fit folder, or many sample folders at once.

use crate::folder::{FolderWritten, Outputs, write_fit_folder};
use crate::inputs::{FitInputs, default_name, sample_files};
use crate::{FitSettings, WorkflowError};
use brtf_fit::{FitResult, FitSetOptions, FittedSet, Progress};
use brtf_gonio::klems::{Side, Sides};
use brtf_io::FolderUpdate;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// One sample's fit, ready to run: its files, name and options.
#[derive(Debug, Clone)]
pub struct FitJob {
    files: Vec<PathBuf>,
    klems: bool,
    options: FitSetOptions,
}

impl FitJob {
    /// The fit of `inputs` (measurement or Klems files, not sample
    /// folders) with `settings`, named `name` or by
    /// [`crate::default_name`]. `command_line` goes into the provenance.
    pub fn new(
        inputs: &FitInputs,
        settings: &FitSettings,
        name: Option<String>,
        command_line: Vec<String>,
    ) -> Result<FitJob, WorkflowError> {
        let (files, klems) = match inputs {
            FitInputs::Measurements(files) => (files.clone(), false),
            FitInputs::Klems(files) => (files.clone(), true),
            FitInputs::Samples(_) => {
                return Err(WorkflowError::Usage(
                    "sample folders are fitted one job each (fit_samples)".into(),
                ));
            }
        };
        // Options first: a bad option is reported before any file is read.
        let mut options = settings.options(String::new(), klems, command_line)?;
        options.name = match name {
            Some(name) => name,
            None => default_name(&files, klems)?,
        };
        Ok(FitJob {
            files,
            klems,
            options,
        })
    }

    /// The material name.
    pub fn name(&self) -> &str {
        &self.options.name
    }

    /// The input files.
    pub fn files(&self) -> &[PathBuf] {
        &self.files
    }

    /// The sides a fit of `sides` takes, with a note when a Klems file
    /// asked for both holds one side only (genBSDF writes one): that side.
    /// Gonio files have no side: `[None]`.
    pub fn sides(&self, sides: Sides) -> Result<(Vec<Option<Side>>, Vec<String>), WorkflowError> {
        if !self.klems {
            return Ok((vec![None], Vec::new()));
        }
        let mut wanted = sides.sides();
        let mut notes = Vec::new();
        if sides == Sides::Both {
            let present = crate::inputs::klems_sides(&self.files)?;
            if let [only] = present[..] {
                wanted = vec![only];
                notes.push(format!(
                    "note: the BSDF XML file holds the {only} side only (light from {}): that side is fitted",
                    if only == Side::Front { "+z" } else { "−z" }
                ));
            }
        }
        Ok((wanted.into_iter().map(Some).collect(), notes))
    }

    /// Fits the files (of Klems XML, the incident patches of `side`).
    pub fn fit(
        &self,
        side: Option<Side>,
        progress: &dyn Progress,
    ) -> Result<FittedSet, WorkflowError> {
        if self.klems && side.is_none() {
            return Err(WorkflowError::Usage(
                "a Klems BSDF XML file is fitted one side at a time: front or back".into(),
            ));
        }
        let mut options = self.options.clone();
        options.klems.side = side;
        Ok(brtf_fit::fit_set_with_data(
            &self.files,
            &options,
            progress,
        )?)
    }
}

/// Where a fit folder goes and what it holds.
#[derive(Debug, Clone, Default)]
pub struct FolderRequest {
    /// The folder [default: `fits/<name>`]; for sample folders, the folder
    /// of their fit folders [default: `fits`].
    pub out: Option<PathBuf>,
    /// Replace a folder that holds another fit or other files.
    pub force: bool,
    /// The optional outputs.
    pub outputs: Outputs,
}

/// One fit folder written.
#[derive(Debug, Clone)]
pub struct FolderRun {
    /// The material name.
    pub name: String,
    /// The folder.
    pub out: PathBuf,
    /// The fit of each side (one for gonio files).
    pub results: Vec<FitResult>,
    /// What to print: the summary and the files written.
    pub text: String,
    /// Notes and plot warnings, one line each, ready to print.
    pub notes: Vec<String>,
}

/// Fits `job` into its folder, replaced as a whole. A Klems fit of both
/// sides writes one folder per side (`front/`, `back/`) and a side-by-side
/// `report.html`.
pub fn fit_to_folder(
    job: &FitJob,
    sides: Sides,
    request: &FolderRequest,
    progress: &dyn Progress,
) -> Result<FolderRun, WorkflowError> {
    let out = request
        .out
        .clone()
        .unwrap_or_else(|| Path::new("fits").join(job.name()));
    let update = FolderUpdate::fresh(&out)?;
    let (sides, notes) = job.sides(sides)?;
    let nested = sides.len() > 1;
    if nested {
        check_two_sided_replaceable(update.target(), &job.files, request.force)?;
    } else {
        brtf_io::check_replaceable(update.target(), &job.files, request.force)?;
    }
    let mut run = FolderRun {
        name: job.name().to_string(),
        out: out.clone(),
        results: Vec::new(),
        text: String::new(),
        notes,
    };
    for side in sides {
        if let Some(side) = side {
            progress.label(&format!("{side} side "));
        }
        let FittedSet {
            mut result,
            prepared,
        } = job.fit(side, progress)?;
        let (folder, shown) = match side {
            Some(side) if nested => (update.path().join(side.name()), out.join(side.name())),
            _ => (update.path().to_path_buf(), out.clone()),
        };
        brtf_io::ensure_folder(&folder)?;
        // The residuals and the plots draw the fitted data.
        let written: FolderWritten =
            write_fit_folder(&folder, &shown, &mut result, &prepared, request.outputs)?;
        drop(prepared);
        run.text += &format!("{}{written}", brtf_fit::summary(&result, &shown));
        run.notes.extend(written.notes);
        run.results.push(result);
    }
    if nested {
        let labels = Side::BOTH.map(|s| s.name().to_string());
        let report = brtf_plot::klems_sides_report(&run.results, &labels, update.path());
        brtf_io::write_atomic(&update.path().join("report.html"), report.as_bytes())?;
        run.text += &format!("wrote {} (both sides)\n", out.join("report.html").display());
    }
    update.commit()?;
    Ok(run)
}

/// A two-sided Klems fit folder may be replaced when each side's folder
/// may ([`brtf_io::check_replaceable`]) and nothing else is in it.
fn check_two_sided_replaceable(
    target: &Path,
    inputs: &[PathBuf],
    force: bool,
) -> Result<(), WorkflowError> {
    let Ok(entries) = std::fs::read_dir(target) else {
        return Ok(());
    };
    if force {
        return Ok(brtf_io::check_replaceable(target, inputs, true)?);
    }
    for entry in entries.flatten() {
        let name = entry.file_name();
        match name.to_string_lossy().as_ref() {
            "front" | "back" => brtf_io::check_replaceable(&entry.path(), inputs, false)?,
            "report.html" => {}
            other => {
                return Err(WorkflowError::Usage(format!(
                    "cannot replace the output folder {}: it holds {other}, which a two-sided \
                     Klems fit does not write; --force replaces it",
                    target.display()
                )));
            }
        }
    }
    // Inputs inside the folder are refused whatever it holds.
    Ok(brtf_io::check_replaceable(target, inputs, true)?)
}

/// One sample folder of [`fit_samples`] and how its fit went.
pub type SampleOutcome = (PathBuf, Result<FolderRun, WorkflowError>);

/// Fits many samples at once, one folder each.
///
/// Each folder given is one sample: its `.mpc` and `.txt` files (one
/// incidence each; other files are ignored) are fitted together, exactly
/// as their files alone would be, into `OUT/<name>/`. The samples run in
/// parallel on the current rayon pool, each written and dropped as soon as
/// it is done, so memory stays that of a few samples however many there
/// are. A sample that fails does not stop the others: each sample's
/// outcome is returned, by folder.
pub fn fit_samples(
    folders: &[PathBuf],
    settings: &FitSettings,
    name: Option<String>,
    request: &FolderRequest,
    command_line: Vec<String>,
    progress: &dyn Progress,
) -> Result<Vec<SampleOutcome>, WorkflowError> {
    if name.is_some() && folders.len() > 1 {
        return Err(WorkflowError::Usage(
            "--name names one sample; with several sample folders each takes its own name".into(),
        ));
    }
    // A bad option is reported once, before any file is read.
    settings.options(String::new(), false, Vec::new())?;
    let parent = request.out.clone().unwrap_or_else(|| PathBuf::from("fits"));
    // Naming reads each sample's files: in parallel too.
    let jobs: Vec<FitJob> = folders
        .par_iter()
        .map(|folder| {
            let inputs = FitInputs::Measurements(sample_files(folder)?);
            FitJob::new(&inputs, settings, name.clone(), command_line.clone())
                .map_err(|e| e.context(format!("naming the sample in {}", folder.display())))
        })
        .collect::<Result<_, _>>()?;
    // Two folders must not write one output folder.
    let mut seen: BTreeMap<&str, &Path> = BTreeMap::new();
    for (job, folder) in jobs.iter().zip(folders) {
        if let Some(first) = seen.insert(job.name(), folder) {
            return Err(WorkflowError::Usage(format!(
                "{} and {} are both sample {:?} (their #sample_name or file names): fit them \
                 apart with --name and --out",
                first.display(),
                folder.display(),
                job.name()
            )));
        }
    }
    progress.label(&format!("{} samples", jobs.len()));
    Ok(jobs
        .par_iter()
        .zip(folders)
        .map(|(job, folder)| {
            let request = FolderRequest {
                out: Some(parent.join(job.name())),
                ..request.clone()
            };
            let run = fit_to_folder(job, Sides::Both, &request, progress);
            (folder.clone(), run)
        })
        .collect())
}
