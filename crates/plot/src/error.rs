//! The errors of brtf-plot. Problems with one incidence's measurement file
//! (missing, changed, unreadable) are not errors: that incidence's plots are
//! skipped and the report says why (see [`crate::Written::warnings`]).

use std::path::PathBuf;

/// Plotting a fit folder failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PlotError {
    /// A file or folder could not be read or written.
    #[error("{}: {what}", .path.display())]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// What was being done (`cannot write`, `cannot read`, ...).
        what: &'static str,
        /// The operating-system error.
        #[source]
        source: std::io::Error,
    },
    /// `fit.json` could not be read, or is not a fit result of this schema.
    #[error(transparent)]
    FitJson(#[from] brtf_fit::ReadFitError),
    /// The fit result has no incidence to plot.
    #[error("the fit result has no incidences to plot")]
    NoIncidences,
    /// No measurement file of the fit could be read again.
    #[error("no measurement of the fit could be read: {0}")]
    NoData(String),
    /// plotters failed to draw a chart (a bug, or a font problem).
    #[error("drawing {name}: {message}")]
    Draw {
        /// The chart being drawn.
        name: String,
        /// plotters' message.
        message: String,
    },
}
