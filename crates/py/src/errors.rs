//! Rust errors → the Python exception classes of `brtf/_errors.py`, with
//! the file and line as attributes (`err.file`, `err.line`): `FormatError`
//! (a file that is not valid), `MissingFileError`, `FileError` (other
//! I/O), `ModelError` (a bad model name, argument or option), `FitError`
//! (a fit that could not be made) and `ExportError` (outputs not written).

use pyo3::prelude::*;

/// A `brtf.<class>` exception with `message`, `file` and `line`.
pub(crate) fn error(
    class: &str,
    message: impl Into<String>,
    file: Option<String>,
    line: Option<usize>,
) -> PyErr {
    Python::attach(|py| {
        let message = python_terms(&message.into());
        let made = py
            .import("brtf._errors")
            .and_then(|m| m.getattr(class))
            .and_then(|c| c.call1((message, file, line)));
        match made {
            Ok(value) => PyErr::from_value(value),
            Err(e) => e,
        }
    })
}

/// Phrases of the library's messages that name the command line or Rust,
/// and their Python terms.
const PHRASES: [(&str, &str); 12] = [
    ("--energy exact", "energy=\"exact\""),
    ("--weights uniform", "weights=\"uniform\""),
    ("brtf_gonio::klems (brtf info reads it)", "brtf.read_klems"),
    ("--force replaces it", "force=True replaces it"),
    ("--force to replace it", "force=True to replace it"),
    ("--free-scale", "free_scale=True"),
    ("--no-adequacy", "adequacy=False"),
    ("--model auto", "model=\"auto\""),
    ("--rho VALUE@THETA", "rho=(VALUE, THETA)"),
    ("--klems-samples", "samples"),
    ("--en14501: ", ""),
    (
        "sample folders are fitted one job each (fit_samples)",
        "brtf.fit takes the files of one sample, not a folder",
    ),
];

/// `message` in Python's terms: the phrases above, then every other
/// command-line flag as a keyword, `--theta-in 90:` as `theta_in=90:`.
pub(crate) fn python_terms(message: &str) -> String {
    let mut text = message.to_string();
    for (cli, python) in PHRASES {
        text = text.replace(cli, python);
    }
    let mut out = String::with_capacity(text.len());
    let mut rest = text.as_str();
    while let Some(at) = rest.find("--") {
        out += &rest[..at];
        let after = &rest[at + 2..];
        let len = after
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '-'))
            .unwrap_or(after.len());
        if !after.starts_with(|c: char| c.is_ascii_lowercase()) {
            out += "--";
            rest = after;
            continue;
        }
        out += &after[..len].replace('-', "_");
        rest = &after[len..];
        // `--flag VALUE`: a value starts with a digit, sign, dot or capital,
        // or ends with a colon.
        let value = rest.strip_prefix(' ').filter(|v| {
            let word = v.split(' ').next().unwrap_or("");
            word.starts_with(|c: char| c.is_ascii_digit() || "+-.".contains(c) || c.is_uppercase())
                || word.ends_with(':')
        });
        out.push('=');
        rest = value.unwrap_or(rest);
    }
    out + rest
}

/// A value out of its range, named as the keyword argument it came from.
pub(crate) fn option(e: brtf_model::OptionError) -> PyErr {
    let name = e.option.trim_start_matches("--").replace('-', "_");
    let allowed = e.allowed;
    model(format!(
        "{name}={}: out of range; allowed: {allowed}",
        e.value
    ))
}

/// A `brtf.ModelError` (bad argument) with no file.
pub(crate) fn model(message: impl Into<String>) -> PyErr {
    error("ModelError", message, None, None)
}

/// The class for an I/O error: missing file or other.
fn io_class(e: &std::io::Error) -> &'static str {
    if e.kind() == std::io::ErrorKind::NotFound {
        "MissingFileError"
    } else {
        "FileError"
    }
}

/// A measurement file that could not be read.
pub(crate) fn read(e: brtf_gonio::ReadError) -> PyErr {
    let file = Some(e.path().display().to_string());
    match &e {
        brtf_gonio::ReadError::Io { source, .. } => {
            error(io_class(source), format!("{e}: {source}"), file, None)
        }
        _ => error("FormatError", e.to_string(), file, e.line()),
    }
}

/// A Radiance text that could not be read.
pub(crate) fn rad(e: brtf_radiance::RadError) -> PyErr {
    let (file, line) = (Some(e.path.clone()), Some(e.line));
    error("FormatError", e.to_string(), file, line)
}

/// A fit set that could not be made.
fn fit_set(e: brtf_fit::FitSetError) -> PyErr {
    use brtf_fit::FitSetError;
    match e {
        FitSetError::Io { path, source } => {
            let message = format!("cannot read {}: {source}", path.display());
            let file = Some(path.display().to_string());
            error(io_class(&source), message, file, None)
        }
        FitSetError::Read(e) => read(e),
        other => error("FitError", other.to_string(), None, None),
    }
}

/// A `fit.json` that could not be read.
pub(crate) fn read_fit(e: brtf_fit::ReadFitError) -> PyErr {
    let file = Some(e.path().display().to_string());
    let message = e.to_string();
    match &e {
        brtf_fit::ReadFitError::Io { error: io, .. } => error(io_class(io), message, file, None),
        brtf_fit::ReadFitError::Parse { error: json, .. } => {
            error("FormatError", message, file, Some(json.line()))
        }
        _ => error("FormatError", message, file, None),
    }
}

/// A fit, export or folder step that failed.
pub(crate) fn workflow(e: brtf_workflow::WorkflowError) -> PyErr {
    use brtf_workflow::WorkflowError;
    match e {
        WorkflowError::Usage(message) => error("FitError", message, None, None),
        WorkflowError::Option(e) => option(e),
        WorkflowError::Io(e) => {
            let file = Some(e.path.display().to_string());
            error(io_class(&e.source), e.to_string(), file, None)
        }
        WorkflowError::Read(e) => read(e),
        WorkflowError::FitSet(e) => fit_set(e),
        WorkflowError::ReadFit(e) => read_fit(e),
        other => error("ExportError", other.to_string(), None, None),
    }
}
