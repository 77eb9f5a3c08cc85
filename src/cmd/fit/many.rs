//! `brtf fit DIR... --model M`: many samples at once, one folder each.
//!
//! Each folder given is one sample: its `.mpc` and `.txt` measurement
//! files (one incidence each; other files are ignored) are fitted
//! together, exactly as `brtf fit DIR/*.mpc` would, into
//! `OUT/<name>/` (`OUT` is `--out`, default `fits`; `<name>` is the
//! sample's material name, found as for one sample). The samples run in
//! parallel on the worker threads, each written and dropped as soon as it
//! is done, so memory stays that of a few samples however many there are.
//! One progress bar counts every fit step of every sample. A sample that
//! fails is reported and the others go on; the command then fails.

use super::{FitArgs, default_name, write_fit_folder};
use anyhow::{Context, Result, bail};
use brtf_fit::{FitSetOptions, Progress};
use brtf_io::FolderUpdate;
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// One progress bar over all samples: each sample's fit set adds its steps
/// to the total when it begins them.
struct SharedBar(ProgressBar);

impl Progress for SharedBar {
    fn begin(&self, total: u64) {
        self.0.inc_length(total);
    }
    fn advance(&self) {
        self.0.inc(1);
    }
}

/// One sample: its folder, files, name and output folder.
struct Sample {
    folder: PathBuf,
    files: Vec<PathBuf>,
    name: String,
    out: PathBuf,
}

pub fn run(args: &FitArgs, options: FitSetOptions) -> Result<()> {
    if let Some(file) = args.files.iter().find(|f| !f.is_dir()) {
        bail!(
            "{} is a file, but other inputs are folders: give either measurement files (one \
             sample) or sample folders (one sample each), not both",
            file.display()
        );
    }
    if args.name.is_some() && args.files.len() > 1 {
        bail!("--name names one sample; with several sample folders each takes its own name");
    }
    let parent = args.out.clone().unwrap_or_else(|| PathBuf::from("fits"));
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.jobs.unwrap_or(0))
        .build()?;
    // Naming reads each sample's files: in parallel too.
    let samples: Vec<Sample> = pool.install(|| {
        args.files
            .par_iter()
            .map(|folder| {
                let files = measurement_files(folder)?;
                let name = match &args.name {
                    Some(name) => name.clone(),
                    None => default_name(&files, false)
                        .with_context(|| format!("naming the sample in {}", folder.display()))?,
                };
                Ok(Sample {
                    folder: folder.clone(),
                    out: parent.join(&name),
                    files,
                    name,
                })
            })
            .collect::<Result<_>>()
    })?;
    // Two folders must not write one output folder.
    let mut seen: BTreeMap<&str, &Path> = BTreeMap::new();
    for sample in &samples {
        if let Some(first) = seen.insert(&sample.name, &sample.folder) {
            bail!(
                "{} and {} are both sample {:?} (their #sample_name or file names): fit them \
                 apart with --name and --out",
                first.display(),
                sample.folder.display(),
                sample.name
            );
        }
    }

    let bar = SharedBar(
        ProgressBar::new(0).with_style(
            ProgressStyle::with_template(
                "{spinner} fitting {msg} {pos}/{len} [{bar:30}] {elapsed}",
            )
            .expect("valid template")
            .progress_chars("=> "),
        ),
    );
    bar.0.set_message(format!("{} samples", samples.len()));
    let outcomes: Vec<Result<String>> = pool.install(|| {
        samples
            .par_iter()
            .map(|sample| {
                fit_one(args, &options, sample, &bar)
                    .with_context(|| format!("sample {}", sample.folder.display()))
            })
            .collect()
    });
    bar.0.finish_and_clear();

    let mut failed = 0;
    let mut printed = String::new();
    for outcome in outcomes {
        match outcome {
            Ok(summary) => printed += &summary,
            Err(e) => {
                failed += 1;
                say!("brtf: error: {e:#}");
            }
        }
    }
    crate::cmd::output::print(&printed)?;
    if failed > 0 {
        bail!("{failed} of {} samples failed", samples.len());
    }
    Ok(())
}

/// The measurement files of a sample folder: `.mpc` and `.txt`, sorted.
fn measurement_files(folder: &Path) -> Result<Vec<PathBuf>> {
    let entries =
        std::fs::read_dir(folder).with_context(|| format!("cannot list {}", folder.display()))?;
    let mut files = Vec::new();
    for entry in entries {
        let path = entry
            .with_context(|| format!("cannot list {}", folder.display()))?
            .path();
        let measured = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("mpc") || e.eq_ignore_ascii_case("txt"));
        if measured && path.is_file() {
            files.push(path);
        }
    }
    if files.is_empty() {
        bail!(
            "{} holds no measurement files (.mpc or .txt)",
            folder.display()
        );
    }
    files.sort();
    Ok(files)
}

/// Fits one sample into its folder; returns the lines to print. The
/// result is written and dropped here, so nothing of it outlives the
/// sample.
fn fit_one(
    args: &FitArgs,
    options: &FitSetOptions,
    sample: &Sample,
    bar: &SharedBar,
) -> Result<String> {
    let mut options = options.clone();
    options.name = sample.name.clone();
    let update = FolderUpdate::fresh(&sample.out)?;
    brtf_io::check_replaceable(update.target(), &sample.files, args.force)?;
    let brtf_fit::FittedSet {
        mut result,
        prepared,
    } = brtf_fit::fit_set_with_data(&sample.files, &options, bar)?;
    // Only the plots draw the fitted data.
    let prepared = if args.no_plots { Vec::new() } else { prepared };
    let mut notes = Vec::new();
    let lines = write_fit_folder(
        update.path(),
        &sample.out,
        &mut result,
        &prepared,
        args,
        &mut notes,
    )?;
    drop(prepared);
    update.commit()?;
    for warning in &result.warnings {
        say!("brtf: warning: {}: {warning}", sample.name);
    }
    for note in &notes {
        say!("{}: {note}", sample.name);
    }
    Ok(format!(
        "{}{lines}",
        brtf_fit::summary(&result, &sample.out)
    ))
}
