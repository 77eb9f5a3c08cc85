//! `brtf info FILE...`: per-file measurement summaries.
//!
//! Reads each file with `brtf-gonio` (format from the extension or the
//! header), summarises it and prints either a readable block per file or,
//! with `--json`, one JSON array of summaries, each with its `file`.
//! Klems BSDF XML files (`.xml`, or text starting with `<`) get
//! `brtf_gonio::klems::KlemsInfo`: header, basis, bands, blocks and ρ_dh /
//! τ_dh per incidence and side.

use std::io::Write;
use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use serde::Serialize;

#[derive(Args, Debug)]
pub(crate) struct InfoArgs {
    /// Measurement files (.mpc, pab-opto Mountain or Klems BSDF XML).
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// Print machine-readable JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

/// One entry of the `--json` array.
#[derive(Serialize)]
struct FileSummary<S> {
    file: String,
    #[serde(flatten)]
    summary: S,
}

#[derive(Serialize)]
#[serde(untagged)]
enum Entry {
    Measurement(FileSummary<brtf_gonio::Summary>),
    Klems(FileSummary<brtf_gonio::klems::KlemsInfo>),
}

pub(crate) fn run(args: InfoArgs) -> anyhow::Result<()> {
    let mut out = crate::cmd::output::stdout();
    write_report(&args, &mut out)?;
    Ok(out.flush()?)
}

/// Summarises every file of `args` into `out`. Stops at the first file that
/// cannot be read, with the file named in the error.
fn write_report(args: &InfoArgs, out: &mut impl Write) -> anyhow::Result<()> {
    let mut entries = Vec::with_capacity(args.files.len());
    for (i, path) in args.files.iter().enumerate() {
        if i > 0 && !args.json {
            writeln!(out)?;
        }
        if brtf_gonio::klems::is_klems_file(path) {
            let bsdf = brtf_gonio::klems::read_path(path)
                .with_context(|| format!("reading Klems BSDF {}", path.display()))?;
            let summary = bsdf.info();
            if args.json {
                entries.push(Entry::Klems(FileSummary {
                    file: path.display().to_string(),
                    summary,
                }));
            } else {
                writeln!(out, "{}", path.display())?;
                write!(out, "{summary}")?;
            }
            continue;
        }
        let measurement = brtf_gonio::read_path(path)
            .with_context(|| format!("reading measurement {}", path.display()))?;
        let summary = measurement.summary();
        if args.json {
            entries.push(Entry::Measurement(FileSummary {
                file: path.display().to_string(),
                summary,
            }));
        } else {
            writeln!(out, "{}", path.display())?;
            write!(out, "{summary}")?;
        }
    }
    if args.json {
        serde_json::to_writer_pretty(&mut *out, &entries).context("writing JSON")?;
        writeln!(out)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fixture() -> PathBuf {
        PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("crates/gonio/tests/fixtures/pab-aluA-st1:+30+0.mpc")
    }

    fn report(files: Vec<PathBuf>, json: bool) -> anyhow::Result<String> {
        let mut out = Vec::new();
        write_report(&InfoArgs { files, json }, &mut out)?;
        Ok(String::from_utf8(out).unwrap())
    }

    #[test]
    fn text_report_names_the_file_and_the_quantity() {
        let text = report(vec![fixture(), fixture()], false).unwrap();
        assert_eq!(text.matches("pab-aluA-st1:+30+0.mpc\n").count(), 2);
        assert!(text.contains("theta_in = 30 deg, phi_in = 0 deg (from the header)"));
        assert!(text.contains("quantity      BSDF [1/sr] (CIE-Y)"));
        assert!(text.contains("6 (front 0, back 6); 5 negative, 0 not available"));
    }

    #[test]
    fn json_report_is_an_array_of_summaries() {
        let text = report(vec![fixture()], true).unwrap();
        let value: serde_json::Value = serde_json::from_str(&text).unwrap();
        let entry = &value.as_array().unwrap()[0];
        assert!(entry["file"].as_str().unwrap().ends_with(":+30+0.mpc"));
        assert_eq!(entry["quantity"], "BSDF");
        assert_eq!(entry["back"]["count"], 6);
        assert_eq!(entry["beam"]["integral"], 0.063626);
    }

    #[test]
    fn unreadable_files_are_named_in_the_error() {
        let err = report(vec![PathBuf::from("/nonexistent/scan.txt")], false).unwrap_err();
        let message = format!("{err:#}");
        assert!(
            message.contains("reading measurement /nonexistent/scan.txt"),
            "{message}"
        );
        assert!(message.contains("No such file"), "{message}");
    }
}
