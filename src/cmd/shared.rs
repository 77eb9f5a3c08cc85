//! Helpers several subcommands share: option words, worker threads and
//! CSV output.

use anyhow::Result;
use brtf_model::{OptionWords, WordError};
use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};

/// clap's parser for a library enum's words ([`OptionWords`]): `--help`
/// lists them, and older spellings are read as aliases.
pub(crate) fn words<T>() -> impl TypedValueParser<Value = T>
where
    T: OptionWords + std::str::FromStr<Err = WordError> + Clone + Send + Sync,
{
    let values = T::WORDS.iter().zip(T::ALL).map(|(&word, choice)| {
        let aliases = T::ALIASES.iter().filter(|(_, c)| c.word() == choice.word());
        PossibleValue::new(word).aliases(aliases.map(|(alias, _)| *alias))
    });
    PossibleValuesParser::new(values.collect::<Vec<_>>()).try_map(|s| s.parse::<T>())
}

/// Runs `f` on `jobs` worker threads (checked), or on all cores.
pub(crate) fn with_jobs<T: Send>(jobs: Option<usize>, f: impl FnOnce() -> T + Send) -> Result<T> {
    Ok(brtf_workflow::with_jobs(jobs, f)?)
}

/// A CSV writer on stdout (buffered; flush it at the end).
pub(crate) fn csv_stdout() -> csv::Writer<crate::cmd::output::Stdout> {
    csv::Writer::from_writer(crate::cmd::output::stdout())
}

/// Writes one CSV row of numbers, each as Rust's `{}` prints it (the
/// shortest text that reads back as the same `f64`).
pub(crate) fn write_numbers<W: std::io::Write>(
    out: &mut csv::Writer<W>,
    row: &[f64],
) -> Result<()> {
    out.write_record(row.iter().map(f64::to_string))?;
    Ok(())
}
