//! Why a workflow step failed.

use std::path::PathBuf;

/// A failed fit, export, plot or folder step. Each variant's message
/// names the file or the option concerned.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum WorkflowError {
    /// Inputs or options that do not go together.
    #[error("{0}")]
    Usage(String),
    /// An option value out of its range.
    #[error(transparent)]
    Option(#[from] brtf_model::OptionError),
    /// A file or folder could not be read or written.
    #[error(transparent)]
    Io(#[from] brtf_io::IoError),
    /// A Radiance file could not be read.
    #[error(transparent)]
    Rad(#[from] brtf_radiance::RadError),
    /// A fit's material could not be made ready to render.
    #[error(transparent)]
    Shader(#[from] brtf_trace::ShaderError),
    /// A virtual gonio-photometer setting is out of range.
    #[error(transparent)]
    Gonio(#[from] brtf_trace::GonioError),
    /// The render check failed.
    #[error(transparent)]
    Check(#[from] brtf_trace::CheckError),
    /// A picture's scene is not valid.
    #[error(transparent)]
    Scene(#[from] brtf_trace::SceneSpecError),
    /// A measurement file could not be written.
    #[error(transparent)]
    WriteMeasurement(#[from] brtf_gonio::WriteError),
    /// A measurement file could not be read.
    #[error(transparent)]
    Read(#[from] brtf_gonio::ReadError),
    /// The fit could not be made.
    #[error(transparent)]
    FitSet(#[from] brtf_fit::FitSetError),
    /// A fit folder's `fit.json` could not be read.
    #[error(transparent)]
    ReadFit(#[from] brtf_fit::ReadFitError),
    /// The Radiance exports could not be made.
    #[error("exporting Radiance materials into {}: {source}", folder.display())]
    Export {
        /// The folder written.
        folder: PathBuf,
        /// Why.
        source: brtf_radiance::export::ExportError,
    },
    /// The Klems XML export could not be made.
    #[error(transparent)]
    Klems(#[from] brtf_radiance::export::klems::KlemsExportError),
    /// Output could not be written (standard output, say).
    #[error("cannot write: {0}")]
    Write(#[from] std::io::Error),
    /// A step that failed, with what it was doing.
    #[error("{what}: {source}")]
    Context {
        /// What was being done.
        what: String,
        /// Why it failed.
        source: Box<WorkflowError>,
    },
    /// The plots could not be drawn.
    #[error("plotting into {}: {source}", folder.display())]
    Plot {
        /// The folder written.
        folder: PathBuf,
        /// Why.
        source: brtf_plot::PlotError,
    },
}

impl WorkflowError {
    /// This error, saying what was being done.
    pub fn context(self, what: impl Into<String>) -> WorkflowError {
        WorkflowError::Context {
            what: what.into(),
            source: Box::new(self),
        }
    }
}
