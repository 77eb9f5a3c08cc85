//! Writers: [`Measurement`] out to `.mpc` or Mountain text.
//!
//! This module owns the shared writing rules: numbers are printed with
//! Rust's shortest round-trip formatting (so reading a written file gives
//! bit-identical `f64`s), NaN is written as the `9.9e+37` sentinel, and
//! files are written to a temporary file in the target directory and then
//! renamed over the target, so a crash never leaves a half-written file.
//! The format specifics live in the private submodules `mpc` and
//! `mountain`.
//!
//! Header lines read from a file of the same format are written back
//! verbatim unless the value they carry changed (then that one line is
//! regenerated in place); lines from a file of the other format are kept as
//! inert `#>` comments that neither reader interprets.

pub(crate) mod mountain;
pub(crate) mod mpc;

use std::fmt::Write as _;
use std::path::Path;

use crate::error::WriteError;
use crate::measurement::{Measurement, SENTINEL_TEXT, SourceFormat};

/// Writes `measurement` to `path` in `format`, atomically.
pub fn write_path(
    measurement: &Measurement,
    path: &Path,
    format: SourceFormat,
) -> Result<(), WriteError> {
    match format {
        SourceFormat::Mpc => write_mpc(measurement, path),
        SourceFormat::Mountain => write_mountain(measurement, path),
        SourceFormat::KlemsXml => Err(WriteError::Unsupported {
            path: path.to_path_buf(),
            format,
            reason: "brtf does not write Klems BSDF XML yet".into(),
        }),
    }
}

/// Writes a Mountain file (any quantity, one or three channels). Solid
/// angles are not part of the format and are not written.
pub fn write_mountain(measurement: &Measurement, path: &Path) -> Result<(), WriteError> {
    write_atomically(path, to_mountain_string(measurement).as_bytes())
}

/// Writes an `.mpc` file. Needs a one-channel BSDF measurement.
pub fn write_mpc(measurement: &Measurement, path: &Path) -> Result<(), WriteError> {
    let text = mpc::render(measurement).map_err(|reason| WriteError::Unsupported {
        path: path.to_path_buf(),
        format: SourceFormat::Mpc,
        reason,
    })?;
    write_atomically(path, text.as_bytes())
}

/// The Mountain text of a measurement.
pub fn to_mountain_string(measurement: &Measurement) -> String {
    mountain::render(measurement)
}

/// The `.mpc` text of a measurement, or why it cannot be written as `.mpc`
/// (the format holds a one-channel BSDF only).
pub fn to_mpc_string(measurement: &Measurement) -> Result<String, String> {
    mpc::render(measurement)
}

/// A header line from a file of the other format, made inert: `#>` plus the
/// line without its leading `#`, so no reader takes it for one of its keys.
pub(crate) fn foreign_header_line(line: &str) -> String {
    let trimmed = line.trim_start();
    format!("#>{}", trimmed.strip_prefix('#').unwrap_or(trimmed))
}

/// Appends a number in shortest round-trip form; NaN becomes the sentinel.
///
/// Plain notation for magnitudes in `[1e-5, 1e16)` (e.g. `89.98829`),
/// exponent notation otherwise (e.g. `2.138e-7`). Both parse back to the
/// identical `f64`.
pub(crate) fn push_number(out: &mut String, v: f64) {
    // Writing into a String cannot fail.
    let _ = if v.is_nan() {
        out.write_str(SENTINEL_TEXT)
    } else if v == 0.0 || (1e-5..1e16).contains(&v.abs()) {
        write!(out, "{v}")
    } else {
        write!(out, "{v:e}")
    };
}

/// Writes `contents` atomically (see [`brtf_io::write_atomic`]).
pub(crate) fn write_atomically(path: &Path, contents: &[u8]) -> Result<(), WriteError> {
    brtf_io::write_atomic(path, contents).map_err(|e| WriteError::Io {
        path: e.path,
        source: e.source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_round_trip() {
        for v in [
            89.98829,
            -4.574e-6,
            2.138e-6,
            0.0,
            -0.0,
            1e300,
            5e-324,
            0.1 + 0.2,
            -179.99933 + 360.0,
            123456789012345680.0,
        ] {
            let mut s = String::new();
            push_number(&mut s, v);
            let back: f64 = s.parse().unwrap();
            assert_eq!(back.to_bits(), v.to_bits(), "{s}");
        }
        let mut s = String::new();
        push_number(&mut s, f64::NAN);
        assert_eq!(s, "9.9e+37");
        s.clear();
        push_number(&mut s, 89.98829);
        assert_eq!(s, "89.98829");
    }
}
