//! `brtf fit FILE... --model M`: a progress bar around
//! [`brtf_fit::fit_set`], and its outputs, written into a staging folder
//! and swapped in as a whole ([`brtf_io::FolderUpdate`]).

mod args;

use crate::cmd::output::print;
use anyhow::{Context, Result};
pub use args::FitArgs;
use brtf_fit::Progress;
use brtf_io::{FolderUpdate, Producer, describe_outputs};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};

/// The progress bar of the fits.
struct Bar(ProgressBar);

impl Progress for Bar {
    fn begin(&self, total: u64) {
        self.0.set_length(total);
        self.0.set_position(0);
    }
    fn advance(&self) {
        self.0.inc(1);
    }
    fn end(&self) {
        self.0.finish_and_clear();
    }
}

pub fn run(args: FitArgs) -> Result<()> {
    let mut options = args.options(String::new())?;
    options.validate()?;
    options.name = match &args.name {
        Some(name) => name.clone(),
        None => default_name(&args.files)?,
    };
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| Path::new("fits").join(&options.name));
    let update = FolderUpdate::fresh(&out)?;
    brtf_io::check_replaceable(update.target(), &args.files, args.force)?;
    let bar = Bar(ProgressBar::new(0).with_style(
        ProgressStyle::with_template("{spinner} fitting {pos}/{len} [{bar:30}] {elapsed} {msg}")
            .expect("valid template")
            .progress_chars("=> "),
    ));
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.jobs.unwrap_or(0))
        .build()?;
    let mut result = pool.install(|| brtf_fit::fit_set(&args.files, &options, &bar))?;
    let stage = update.path();
    let context = || format!("writing the fit into {}", out.display());
    result.write(stage).with_context(context)?;
    let mut outputs = describe_outputs(stage, &[stage.join("params.csv")], Producer::Fit)?;
    let mut lines = String::new();
    let mut notes = Vec::new();
    if !args.no_export {
        let options = brtf_radiance::export::ExportOptions::default();
        let exported = brtf_radiance::export::write_exports(stage, &result, &options)
            .with_context(|| format!("exporting Radiance materials into {}", out.display()))?;
        outputs.extend(describe_outputs(stage, &exported.files, Producer::Export)?);
        for file in &exported.files {
            let name = file.strip_prefix(stage).unwrap_or(file);
            lines += &format!("wrote {}\n", out.join(name).display());
        }
        notes.extend(exported.notes.iter().map(|n| format!("note: {n}")));
    }
    if !args.no_plots {
        let mut plot_options = brtf_plot::PlotOptions::default();
        plot_options.search_dirs.push(out.clone());
        let written = brtf_plot::write_plots(stage, &result, &plot_options)
            .with_context(|| format!("plotting into {}", out.display()))?;
        outputs.extend(describe_outputs(stage, &written.files, Producer::Plot)?);
        lines += &format!(
            "wrote {} plots and {}\n",
            written.files.len().saturating_sub(1),
            out.join("report.html").display()
        );
        notes.extend(
            written
                .warnings
                .iter()
                .map(|w| format!("brtf: warning: {w}")),
        );
    }
    outputs.sort_by(|a, b| a.path.cmp(&b.path));
    result.outputs = outputs;
    // fit.json last: it lists every other file of the folder.
    result.write(stage).with_context(context)?;
    update.commit()?;
    for warning in &result.warnings {
        say!("brtf: warning: {warning}");
    }
    for note in &notes {
        say!("{note}");
    }
    print(&format!("{}{lines}", brtf_fit::summary(&result, &out)))
}

/// The material name: the files' `#sample_name` when they agree, else the
/// longest common start of their file names, as a Radiance identifier
/// (else `fit`; [`brtf_io::check_replaceable`] keeps it from replacing the
/// fit of another sample).
fn default_name(files: &[PathBuf]) -> Result<String> {
    let mut sample_names = Vec::new();
    for file in files {
        let m = brtf_gonio::read_path(file)
            .with_context(|| format!("cannot read {}", file.display()))?;
        sample_names.push(m.sample_name);
    }
    if let Some(Some(first)) = sample_names.first()
        && sample_names.iter().all(|n| n.as_ref() == Some(first))
        && let Some(name) = brtf_radiance::identifier(first)
    {
        return Ok(name);
    }
    let stems: Vec<String> = files
        .iter()
        .map(|f| {
            f.file_stem()
                .unwrap_or_default()
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    let common = stems.iter().fold(stems[0].clone(), |acc, s| {
        acc.chars()
            .zip(s.chars())
            .take_while(|(a, b)| a == b)
            .map(|(a, _)| a)
            .collect()
    });
    // `alu:+30+0` and `alu:+45+0` share `alu:+`; the identifier drops the `:+`.
    let common = common.split(':').next().unwrap_or_default();
    Ok(brtf_radiance::identifier(common).unwrap_or_else(|| "fit".into()))
}
