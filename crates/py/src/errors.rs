//! Rust errors → the Python exception classes of `brtf/_errors.py`, with
//! the file and line as attributes (`err.file`, `err.line`).

use pyo3::prelude::*;

/// Which Python class an error becomes.
#[derive(Clone, Copy)]
pub(crate) enum Class {
    /// A file that is not valid (measurement, `.rad`, `fit.json`).
    Format,
    /// A file that does not exist.
    MissingFile,
    /// Any other I/O failure.
    File,
    /// A bad model name, material argument or option value.
    Model,
    /// A fit that could not be made.
    Fit,
    /// Exports or plots that could not be written.
    Export,
}

impl Class {
    fn name(self) -> &'static str {
        match self {
            Class::Format => "FormatError",
            Class::MissingFile => "MissingFileError",
            Class::File => "FileError",
            Class::Model => "ModelError",
            Class::Fit => "FitError",
            Class::Export => "ExportError",
        }
    }
}

/// A `brtf.<Class>` exception with `message`, `file` and `line`.
pub(crate) fn error(
    class: Class,
    message: String,
    file: Option<String>,
    line: Option<usize>,
) -> PyErr {
    Python::attach(|py| {
        let made = py
            .import("brtf._errors")
            .and_then(|m| m.getattr(class.name()))
            .and_then(|c| c.call1((message, file, line)));
        match made {
            Ok(value) => PyErr::from_value(value),
            Err(e) => e,
        }
    })
}

/// A `brtf.ModelError` (bad argument) with no file.
pub(crate) fn model(message: impl Into<String>) -> PyErr {
    error(Class::Model, message.into(), None, None)
}

/// The class for an I/O error: missing file or other.
pub(crate) fn io_class(e: &std::io::Error) -> Class {
    if e.kind() == std::io::ErrorKind::NotFound {
        Class::MissingFile
    } else {
        Class::File
    }
}

/// A measurement file that could not be read.
pub(crate) fn read(e: brtf_gonio::ReadError) -> PyErr {
    let file = Some(e.path().display().to_string());
    match &e {
        brtf_gonio::ReadError::Io { source, .. } => {
            let message = format!("{e}: {source}");
            error(io_class(source), message, file, None)
        }
        _ => {
            let line = e.line();
            error(Class::Format, e.to_string(), file, line)
        }
    }
}

/// A Radiance text that could not be read.
pub(crate) fn rad(e: brtf_radiance::RadError) -> PyErr {
    let (file, line) = (Some(e.path.clone()), Some(e.line));
    error(Class::Format, e.to_string(), file, line)
}

/// A fit set that could not be made.
pub(crate) fn fit_set(e: brtf_fit::FitSetError) -> PyErr {
    use brtf_fit::FitSetError;
    match e {
        FitSetError::Io { path, source } => {
            let message = format!("cannot read {}: {source}", path.display());
            error(
                io_class(&source),
                message,
                Some(path.display().to_string()),
                None,
            )
        }
        FitSetError::Read(e) => read(e),
        other => error(Class::Fit, other.to_string(), None, None),
    }
}

/// A `fit.json` that could not be read.
pub(crate) fn read_fit(e: brtf_fit::ReadFitError, path: &std::path::Path) -> PyErr {
    let file = Some(path.display().to_string());
    let message = e.to_string();
    match &e {
        brtf_fit::ReadFitError::Io { error: io, .. } => error(io_class(io), message, file, None),
        brtf_fit::ReadFitError::Parse { error: json, .. } => {
            error(Class::Format, message, file, Some(json.line()))
        }
        _ => error(Class::Format, message, file, None),
    }
}

/// Writing outputs failed.
pub(crate) fn export(message: String) -> PyErr {
    error(Class::Export, message, None, None)
}

/// A fit, export or folder step that failed.
pub(crate) fn workflow(e: brtf_workflow::WorkflowError) -> PyErr {
    use brtf_workflow::WorkflowError;
    match e {
        WorkflowError::Usage(message) => error(Class::Fit, message, None, None),
        WorkflowError::Option(e) => model(e.to_string()),
        WorkflowError::Io(e) => {
            let file = Some(e.path.display().to_string());
            error(io_class(&e.source), e.to_string(), file, None)
        }
        WorkflowError::Read(e) => read(e),
        WorkflowError::FitSet(e) => fit_set(e),
        WorkflowError::ReadFit(e) => {
            let path = e.path().to_path_buf();
            read_fit(e, &path)
        }
        other => export(other.to_string()),
    }
}
