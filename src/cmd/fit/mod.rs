//! `brtf fit FILE... --model M`: a progress bar around
//! [`brtf_fit::fit_set`], and its outputs in the fit folder.

mod args;

use anyhow::{Context, Result};
pub use args::FitArgs;
use brtf_fit::Progress;
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
    let name = args
        .name
        .clone()
        .unwrap_or_else(|| default_name(&args.files));
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| Path::new("fits").join(&name));
    let options = args.options(name)?;
    let bar = Bar(ProgressBar::new(0).with_style(
        ProgressStyle::with_template("{spinner} fitting {pos}/{len} [{bar:30}] {elapsed} {msg}")
            .expect("valid template")
            .progress_chars("=> "),
    ));
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.jobs.unwrap_or(0))
        .build()?;
    let result = pool.install(|| brtf_fit::fit_set(&args.files, &options, &bar))?;
    result
        .write(&out)
        .with_context(|| format!("writing the fit into {}", out.display()))?;
    print!("{}", brtf_fit::summary(&result, &out));
    for warning in &result.warnings {
        eprintln!("brtf: warning: {warning}");
    }
    if !args.no_export {
        let options = brtf_radiance::export::ExportOptions::default();
        let exported = brtf_radiance::export::write_exports(&out, &result, &options)
            .with_context(|| format!("exporting Radiance materials into {}", out.display()))?;
        for file in &exported.files {
            println!("wrote {}", file.display());
        }
        for note in &exported.notes {
            eprintln!("note: {note}");
        }
    }
    if !args.no_plots {
        let written = brtf_plot::write_plots(&out, &result, &brtf_plot::PlotOptions::default())
            .with_context(|| format!("plotting into {}", out.display()))?;
        println!(
            "wrote {} plots and {}",
            written.files.len().saturating_sub(1),
            written.report.display()
        );
        for warning in &written.warnings {
            eprintln!("brtf: warning: {warning}");
        }
    }
    Ok(())
}

/// The files' common folder name, else `fit`.
fn default_name(files: &[PathBuf]) -> String {
    let folder = |p: &PathBuf| {
        std::fs::canonicalize(p).ok().and_then(|c| {
            c.parent()
                .and_then(|d| d.file_name())
                .map(|n| n.to_string_lossy().into_owned())
        })
    };
    let first = folder(&files[0]);
    if files.iter().all(|f| folder(f) == first) {
        first.unwrap_or_else(|| "fit".into())
    } else {
        "fit".into()
    }
}
