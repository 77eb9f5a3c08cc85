//! `brtf fit FILE... --model M`: a progress bar around
//! [`brtf_workflow::fit_to_folder`] (or [`brtf_workflow::fit_samples`] for
//! sample folders), and what it prints.

mod args;

use crate::cmd::output::print;
use crate::cmd::shared::with_jobs;
use anyhow::{Result, bail};
pub(crate) use args::FitArgs;
use brtf_fit::Progress;
use brtf_workflow::{FitInputs, FitJob, FolderRequest, FolderRun};
use indicatif::{ProgressBar, ProgressStyle};

/// The progress bar of the fits: each fit set (a sample, a side) adds its
/// steps to the total when it begins them.
struct Bar(ProgressBar);

impl Bar {
    fn new() -> Bar {
        let template = "{spinner} fitting {msg}{pos}/{len} [{bar:30}] {elapsed}";
        let style = ProgressStyle::with_template(template).expect("valid template");
        Bar(ProgressBar::new(0).with_style(style.progress_chars("=> ")))
    }
}

impl Progress for Bar {
    fn begin(&self, total: u64) {
        self.0.inc_length(total);
    }
    fn advance(&self) {
        self.0.inc(1);
    }
    fn label(&self, text: &str) {
        self.0.set_message(format!("{text} "));
    }
}

/// The command line, for the provenance (lossy where not UTF-8).
pub(crate) fn command_line() -> Vec<String> {
    std::env::args_os()
        .map(|a| a.to_string_lossy().into_owned())
        .collect()
}

pub(crate) fn run(args: FitArgs) -> Result<()> {
    if let Some(values) = &args.en14501 {
        let text = brtf_workflow::en14501_material(values, args.name.as_deref(), &command_line())?;
        return print(&text);
    }
    let settings = args.settings()?;
    let request = FolderRequest {
        out: args.out.clone(),
        force: args.force,
        outputs: args.outputs(),
    };
    let inputs = FitInputs::classify(&args.files)?;
    if let FitInputs::Samples(folders) = &inputs {
        let bar = Bar::new();
        let outcomes = with_jobs(args.jobs, || {
            brtf_workflow::fit_samples(
                folders,
                &settings,
                args.name.clone(),
                &request,
                command_line(),
                &bar,
            )
        })??;
        bar.0.finish_and_clear();
        let mut failed = 0;
        let mut printed = String::new();
        for (folder, outcome) in &outcomes {
            match outcome {
                Ok(run) => {
                    report(run, Some(&run.name));
                    printed += &run.text;
                }
                Err(e) => {
                    failed += 1;
                    say!("brtf: error: sample {}: {e}", folder.display());
                }
            }
        }
        print(&printed)?;
        if failed > 0 {
            bail!("{failed} of {} samples failed", outcomes.len());
        }
        return Ok(());
    }
    let job = FitJob::new(&inputs, &settings, args.name.clone(), command_line())?;
    let bar = Bar::new();
    let run = with_jobs(args.jobs, || {
        brtf_workflow::fit_to_folder(&job, settings.sides, &request, &bar)
    });
    bar.0.finish_and_clear();
    let run = run??;
    report(&run, None);
    print(&run.text)
}

/// Prints the warnings and notes of one fit folder, prefixed with the
/// sample's name when there are many.
fn report(run: &FolderRun, sample: Option<&str>) {
    let prefix = sample.map(|s| format!("{s}: ")).unwrap_or_default();
    for result in &run.results {
        for warning in &result.warnings {
            say!("brtf: warning: {prefix}{warning}");
        }
    }
    for note in &run.notes {
        say!("{prefix}{note}");
    }
}
