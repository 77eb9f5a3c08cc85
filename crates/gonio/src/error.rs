//! Error types for reading, writing and converting measurements.
//!
//! This module owns every error the crate returns. Read errors carry the
//! file's display path and the 1-based line number and print as
//! `file:line: message`, like a compiler. The message says what was
//! expected and what was found. [`ParseErrorKind`] lets callers (and tests)
//! match on the kind of problem without parsing text. I/O errors keep the
//! operating-system error as their `source()` (print the chain, e.g. with
//! anyhow's `{:#}`, to see it).

use std::io;
use std::path::{Path, PathBuf};

/// Reading a measurement failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReadError {
    /// The file could not be opened or read.
    #[error("{}: cannot read", .path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating-system error.
        #[source]
        source: io::Error,
    },
    /// The bytes are not a valid measurement file.
    #[error("{}:{line}: {kind}", .path.display())]
    Parse {
        /// The file (or the display name given for in-memory input).
        path: PathBuf,
        /// 1-based line number the problem was found on.
        line: usize,
        /// What is wrong.
        kind: ParseErrorKind,
    },
}

impl ReadError {
    /// The file (or display name) the error is about.
    pub fn path(&self) -> &Path {
        match self {
            ReadError::Io { path, .. } | ReadError::Parse { path, .. } => path,
        }
    }

    /// The 1-based line number, for parse errors.
    pub fn line(&self) -> Option<usize> {
        match self {
            ReadError::Parse { line, .. } => Some(*line),
            ReadError::Io { .. } => None,
        }
    }

    /// What is wrong, for parse errors.
    pub fn kind(&self) -> Option<&ParseErrorKind> {
        match self {
            ReadError::Parse { kind, .. } => Some(kind),
            ReadError::Io { .. } => None,
        }
    }
}

/// What is wrong with a measurement file. Printed after `file:line: `.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ParseErrorKind {
    /// The file has no bytes, or only whitespace.
    #[error("the file is empty")]
    Empty,
    /// The file is not text: it contains a NUL byte or invalid UTF-8.
    #[error("not a text file: {what} at byte offset {offset}")]
    Binary {
        /// `NUL byte` or `invalid UTF-8`.
        what: &'static str,
        /// Byte offset of the first bad byte.
        offset: usize,
    },
    /// A data row has the wrong number of columns (for example a row cut
    /// off by truncation).
    #[error("expected {expected} columns ({layout}), found {found}")]
    ColumnCount {
        /// Columns the format requires.
        expected: usize,
        /// Columns on the line.
        found: usize,
        /// The column names, e.g. `theta phi value`.
        layout: &'static str,
    },
    /// A field that should be a number is not one.
    #[error("column {column} ({name}): expected a number, found `{text}`")]
    NotANumber {
        /// 1-based column.
        column: usize,
        /// The column's name.
        name: &'static str,
        /// The offending text (shortened to 40 characters).
        text: String,
    },
    /// A field is `nan`, `inf` or overflows `f64`. Files mark missing values
    /// with `9.9e+37`, never with NaN, so this is treated as corruption.
    #[error("column {column} ({name}): `{text}` is not a finite number")]
    NonFinite {
        /// 1-based column.
        column: usize,
        /// The column's name.
        name: &'static str,
        /// The offending text.
        text: String,
    },
    /// An angle lies outside its valid range (θ must be in [0°, 180°]).
    #[error("{what} = {} is outside [{min}, {max}] degrees", short_number(*value))]
    AngleOutOfRange {
        /// Which angle, e.g. `theta_out`.
        what: &'static str,
        /// The value found.
        value: f64,
        /// Lower bound.
        min: f64,
        /// Upper bound.
        max: f64,
    },
    /// No incidence in the header and none in the file name.
    #[error(
        "no incident {missing}: the header has none ({expected}) and the file name has no \
         `+THETA+PHI` suffix"
    )]
    MissingIncidence {
        /// `theta` or `phi`.
        missing: &'static str,
        /// The header spellings looked for.
        expected: &'static str,
    },
    /// Header and file name give different incidences.
    #[error(
        "the header gives incidence theta = {header_theta}, phi = {header_phi} but the file \
         name `{file_name}` gives theta = {name_theta}, phi = {name_phi}"
    )]
    IncidenceConflict {
        /// θ_in from the header.
        header_theta: f64,
        /// φ_in from the header.
        header_phi: f64,
        /// θ_in from the file name.
        name_theta: f64,
        /// φ_in from the file name.
        name_phi: f64,
        /// The file name.
        file_name: String,
    },
    /// Two header lines give different values for the same thing.
    #[error("`{key}` gives {what} = {this}, but an earlier header line gave {earlier}")]
    HeaderConflict {
        /// The header key of this line.
        key: String,
        /// What it sets, e.g. `theta_in`.
        what: &'static str,
        /// The value on this line.
        this: f64,
        /// The value given before.
        earlier: f64,
    },
    /// A header value the reader needs could not be understood.
    #[error("header `{key}`: expected {expected}, found `{text}`")]
    BadHeaderValue {
        /// The header key.
        key: String,
        /// What was expected.
        expected: &'static str,
        /// What was found.
        text: String,
    },
    /// A Mountain file has no `#format:` line, so the quantity is unknown.
    #[error(
        "no `#format: theta phi Q` header line before the data, so the quantity \
         (DSF, BSDF or a [unit]) is unknown"
    )]
    MissingFormat,
    /// `#datapoints_in_file N` disagrees with the rows actually present.
    #[error("`#datapoints_in_file` declares {declared} rows but the file has {found}")]
    DatapointsMismatch {
        /// N from the header.
        declared: usize,
        /// Data rows found.
        found: usize,
    },
    /// A header line follows the first data row.
    #[error(
        "header line after the first data row (line {first_data_line}); headers must come first"
    )]
    HeaderAfterData {
        /// Line of the first data row.
        first_data_line: usize,
    },
    /// The file has a header but no data rows.
    #[error("no data rows")]
    NoData,
    /// A Klems BSDF XML file that brtf cannot read; `element` is the XML
    /// element the problem was found in.
    #[error("<{element}>: {problem}")]
    Klems {
        /// The element's local name, e.g. `ScatteringData`.
        element: String,
        /// What is wrong.
        problem: KlemsProblem,
    },
}

/// What is wrong with a Klems BSDF XML file (see [`ParseErrorKind::Klems`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum KlemsProblem {
    /// The text is not well-formed XML.
    #[error("not well-formed XML: {0}")]
    Xml(String),
    /// The root element is not `WindowElement`.
    #[error("not a BSDF XML file: the root element is <{0}>, not <WindowElement>")]
    NotWindowElement(String),
    /// A required child element is missing.
    #[error("missing <{0}>")]
    Missing(&'static str),
    /// The data are a tensor tree, not a Klems matrix, and the caller
    /// asked for a matrix (`klems::read_any_path` reads both).
    #[error("a tensor tree (`{0}`), not a Klems matrix (Columns or Rows)")]
    TensorTree(String),
    /// A tensor tree block whose `AngleBasis` is not `LBNL/Shirley-Chiu`.
    #[error("unsupported angle basis `{0}` for a tensor tree (expected LBNL/Shirley-Chiu)")]
    TreeBasis(String),
    /// A tensor tree's `ScatteringData` that cannot be read.
    #[error("{what}: {problem}")]
    Tree {
        /// Band and direction, e.g. `Visible Reflection Back`.
        what: String,
        /// What is wrong.
        problem: TreeProblem,
    },
    /// `IncidentDataStructure` is neither `Columns` nor `Rows`.
    #[error("unknown data structure `{0}` (expected Columns or Rows)")]
    UnknownStructure(String),
    /// A basis name that neither the file nor the built-in Klems bases define.
    #[error(
        "unknown basis `{0}` (known: LBNL/Klems Full, LBNL/Klems Half, LBNL/Klems Quarter, \
         or an AngleBasis defined in the file)"
    )]
    UnknownBasis(String),
    /// An `AngleBasis` whose blocks do not make a valid basis.
    #[error("basis `{name}`: {reason}")]
    BadBasis {
        /// The basis name.
        name: String,
        /// Why.
        reason: String,
    },
    /// Column and row bases differ; brtf reads square matrices only.
    #[error("column basis `{column}` and row basis `{row}` differ (only square matrices are read)")]
    MismatchedBases {
        /// `ColumnAngleBasis`.
        column: String,
        /// `RowAngleBasis`.
        row: String,
    },
    /// A `WavelengthDataDirection` that is none of the four.
    #[error(
        "unknown direction `{0}` (expected Transmission Front, Transmission Back, \
         Reflection Front or Reflection Back)"
    )]
    UnknownDirection(String),
    /// The matrix has the wrong number of values.
    #[error("{what}: expected {expected} values ({n} x {n}), found {found}")]
    TokenCount {
        /// Band and direction, e.g. `Visible Transmission Front`.
        what: String,
        /// N².
        expected: usize,
        /// N.
        n: usize,
        /// Values found.
        found: usize,
    },
    /// A matrix value is not a finite number.
    #[error("{what}: value {index} is `{text}`, not a finite number")]
    NotANumber {
        /// Band and direction.
        what: String,
        /// 1-based position in the matrix text.
        index: usize,
        /// The text (at most 40 characters).
        text: String,
    },
    /// A matrix value below −1e-3 (Radiance's wrapBSDF refuses these too;
    /// smaller negative values are read as 0, as Radiance does).
    #[error("{what}: value {value} at row {row}, column {column} is negative (below -1e-3)")]
    Negative {
        /// Band and direction.
        what: String,
        /// The value.
        value: f64,
        /// 1-based row of the text.
        row: usize,
        /// 1-based column of the text.
        column: usize,
    },
    /// A number in the header or basis that cannot be read.
    #[error("expected {expected}, found `{text}`")]
    BadValue {
        /// What was expected.
        expected: &'static str,
        /// The text found.
        text: String,
    },
    /// The same band and direction twice.
    #[error("{0} appears twice")]
    Duplicate(String),
    /// No `WavelengthData` block with a Klems matrix.
    #[error("no WavelengthData block with a scattering matrix")]
    NoData,
    /// A Klems file holds many incidences; the one-measurement readers
    /// cannot return it.
    #[error(
        "a Klems BSDF XML file holds one measurement per incident patch and side; \
         read it with brtf_gonio::klems (brtf info reads it)"
    )]
    ManyIncidences,
}

/// What is wrong with a tensor tree's nested `{ … }` text (see
/// [`KlemsProblem::Tree`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum TreeProblem {
    /// A brace is missing or misplaced, or text follows the tree.
    #[error("{0}")]
    Syntax(&'static str),
    /// A grid whose number of values is not 2^(rank·k).
    #[error("a grid of {found} values (a grid holds 1, 2^{rank}, 4^{rank}, ... values)")]
    ValueCount {
        /// Values found.
        found: usize,
        /// 3 or 4.
        rank: usize,
    },
    /// A value that is not a finite number.
    #[error("`{0}` is not a finite number")]
    NotANumber(String),
    /// A value below −1e-3.
    #[error("value {0} is negative (below -1e-3)")]
    Negative(f64),
    /// More halvings than the reader accepts.
    #[error("the tree is more than {0} levels deep")]
    TooDeep(u32),
}

/// Writing a measurement failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum WriteError {
    /// Creating, writing or renaming the file failed.
    #[error("{}: cannot write", .path.display())]
    Io {
        /// The target file.
        path: PathBuf,
        /// The operating-system error.
        #[source]
        source: io::Error,
    },
    /// The measurement cannot be expressed in the target format.
    #[error("{}: cannot write as {format}: {reason}", .path.display())]
    Unsupported {
        /// The target file.
        path: PathBuf,
        /// The target format.
        format: crate::SourceFormat,
        /// Why not.
        reason: String,
    },
}

/// Converting between quantities failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ConvertError {
    /// Raw signal needs a beam integral to become a BSDF or DSF.
    #[error("raw signal [{unit}] needs a beam integral to become an absolute quantity")]
    MissingBeamIntegral {
        /// The raw unit.
        unit: String,
    },
    /// The beam integral must be finite and positive.
    #[error("beam integral {0} is not a finite positive number")]
    InvalidBeamIntegral(f64),
    /// The conversion does not apply to this quantity.
    #[error("cannot convert {from} with this function: {reason}")]
    WrongQuantity {
        /// The quantity held.
        from: String,
        /// Why.
        reason: &'static str,
    },
}

/// A number for messages: as written for ordinary magnitudes, in exponent
/// form for huge or tiny ones (`1e308`, not 309 digits).
fn short_number(v: f64) -> String {
    if v == 0.0 || !v.is_finite() || (1e-4..1e9).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}
