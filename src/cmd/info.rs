//! `brtf info FILE...`: per-file measurement summaries.
//!
//! Reads each file with `brtf-gonio` (format from the extension or the
//! header), summarises it and prints either a readable block per file or,
//! with `--json`, one JSON array of summaries, each with its `file`.

use std::io::Write;
use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use serde::Serialize;

#[derive(Args, Debug)]
pub struct InfoArgs {
    /// Measurement files (.mpc or pab-opto Mountain).
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// Print machine-readable JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

/// One entry of the `--json` array.
#[derive(Serialize)]
struct FileSummary {
    file: String,
    #[serde(flatten)]
    summary: brtf_gonio::Summary,
}

pub fn run(args: InfoArgs) -> anyhow::Result<()> {
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    let mut entries = Vec::with_capacity(args.files.len());
    for (i, path) in args.files.iter().enumerate() {
        let measurement = brtf_gonio::read_path(path)
            .with_context(|| format!("reading measurement {}", path.display()))?;
        let summary = measurement.summary();
        if args.json {
            entries.push(FileSummary {
                file: path.display().to_string(),
                summary,
            });
        } else {
            if i > 0 {
                writeln!(out)?;
            }
            writeln!(out, "{}", path.display())?;
            write!(out, "{summary}")?;
        }
    }
    if args.json {
        serde_json::to_writer_pretty(&mut out, &entries).context("writing JSON")?;
        writeln!(out)?;
    }
    Ok(())
}
