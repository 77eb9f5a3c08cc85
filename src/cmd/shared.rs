//! Helpers several subcommands share: reading a fit folder and running
//! work on a chosen number of threads.

use anyhow::{Context, Result};
use brtf_fit::FitResult;
use std::path::Path;

/// Reads `DIR/fit.json`.
pub fn read_fit(dir: &Path) -> Result<FitResult> {
    let path = dir.join("fit.json");
    let text = std::fs::read_to_string(&path)
        .with_context(|| format!("cannot read {}", path.display()))?;
    serde_json::from_str(&text)
        .with_context(|| format!("{}: not a brtf fit result", path.display()))
}

/// Runs `f` on a rayon pool of `jobs` threads (or the global pool).
pub fn with_jobs<T: Send>(jobs: Option<usize>, f: impl FnOnce() -> T + Send) -> Result<T> {
    match jobs {
        Some(n) => {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(n.max(1))
                .build()
                .context("cannot start worker threads")?;
            Ok(pool.install(f))
        }
        None => Ok(f()),
    }
}

/// A CSV writer on stdout (buffered; flush it at the end).
pub fn csv_stdout() -> csv::Writer<std::io::StdoutLock<'static>> {
    csv::Writer::from_writer(std::io::stdout().lock())
}

/// Writes one CSV row of numbers, each as Rust's `{}` prints it (the
/// shortest text that reads back as the same `f64`).
pub fn write_numbers<W: std::io::Write>(out: &mut csv::Writer<W>, row: &[f64]) -> Result<()> {
    out.write_record(row.iter().map(f64::to_string))?;
    Ok(())
}
