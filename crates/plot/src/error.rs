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
    /// `fit.json` is not a valid fit result.
    #[error("{}:{line}: not a brtf fit result: {message}", .path.display())]
    FitJson {
        /// The `fit.json` file.
        path: PathBuf,
        /// 1-based line of the problem.
        line: usize,
        /// What serde_json found wrong.
        message: String,
    },
    /// The fit result has no incidence to plot.
    #[error("the fit result has no incidences to plot")]
    NoIncidences,
    /// plotters failed to draw a chart (a bug, or a font problem).
    #[error("drawing {name}: {message}")]
    Draw {
        /// The chart being drawn.
        name: String,
        /// plotters' message.
        message: String,
    },
}
