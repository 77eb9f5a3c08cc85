//! Helpers several subcommands share: reading a fit folder and running
//! work on a chosen number of threads.

use anyhow::{Context, Result};
use brtf_fit::FitResult;
use std::path::Path;

/// Reads `DIR/fit.json` (see [`FitResult::read`]).
pub fn read_fit(dir: &Path) -> Result<FitResult> {
    Ok(FitResult::read(&dir.join("fit.json"))?)
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
pub fn csv_stdout() -> csv::Writer<crate::cmd::output::Stdout> {
    csv::Writer::from_writer(crate::cmd::output::stdout())
}

/// Writes one CSV row of numbers, each as Rust's `{}` prints it (the
/// shortest text that reads back as the same `f64`).
pub fn write_numbers<W: std::io::Write>(out: &mut csv::Writer<W>, row: &[f64]) -> Result<()> {
    out.write_record(row.iter().map(f64::to_string))?;
    Ok(())
}
