//! Readers: bytes or files in, [`Measurement`] out.
//!
//! This module owns the entry points ([`read_path`], [`read_bytes`] and the
//! per-format variants), format detection, and everything both readers
//! share: the text check (empty, NUL bytes; decoding lives in `text`:
//! UTF-8 with a Latin-1 fallback per line), the line walk with 1-based
//! line numbers, number fields with the sentinel rule, and the
//! incidence found in a file name (`…:+15+0.mpc`). The format specifics
//! live in the private submodules `mpc` and `mountain`.
//!
//! Input is read in one go and parsed from the byte buffer; rows are split
//! on ASCII whitespace (spaces or tabs); lines end at LF, CRLF or a lone CR.
//! No input makes a reader panic.

pub(crate) mod mountain;
pub(crate) mod mpc;
pub(crate) mod number;
mod text;

use std::borrow::Cow;
use std::path::Path;

use crate::error::{ParseErrorKind, ReadError};
use crate::measurement::{
    Incidence, IncidenceOrigin, Measurement, SENTINEL_THRESHOLD, SourceFormat,
};

/// Reads a measurement file, choosing the format with [`detect_format`].
pub fn read_path(path: &Path) -> Result<Measurement, ReadError> {
    let bytes = read_file(path)?;
    read_bytes(&bytes, path)
}

/// Reads a measurement file in the given format.
pub fn read_path_as(path: &Path, format: SourceFormat) -> Result<Measurement, ReadError> {
    let bytes = read_file(path)?;
    read_bytes_as(&bytes, path, format)
}

/// Parses in-memory bytes, choosing the format with [`detect_format`].
///
/// `name` is used in error messages and, for `.mpc`, to find the incidence
/// in the file name when the header lacks it.
pub fn read_bytes(bytes: &[u8], name: impl AsRef<Path>) -> Result<Measurement, ReadError> {
    let name = name.as_ref();
    let format = detect_format(bytes, name);
    read_bytes_as(bytes, name, format)
}

/// Parses in-memory text, choosing the format with [`detect_format`].
pub fn read_str(text: &str, name: impl AsRef<Path>) -> Result<Measurement, ReadError> {
    read_bytes(text.as_bytes(), name)
}

/// Parses in-memory bytes in the given format.
pub fn read_bytes_as(
    bytes: &[u8],
    name: impl AsRef<Path>,
    format: SourceFormat,
) -> Result<Measurement, ReadError> {
    let name = name.as_ref();
    let text = check_text(bytes, name)?;
    match format {
        SourceFormat::Mpc => mpc::parse(&text, name),
        SourceFormat::Mountain => mountain::parse(&text, name),
        // One file, many incidences: `crate::klems` reads it.
        SourceFormat::KlemsXml => Err(parse_error(
            name,
            1,
            ParseErrorKind::Klems {
                element: "WindowElement".into(),
                problem: crate::error::KlemsProblem::ManyIncidences,
            },
        )),
    }
}

/// The [`Measurement::sample_name`] that [`read_bytes`] would give, read
/// from the header alone (what a command that only names a sample needs):
/// a Mountain file's last `#sample_name` before its first data row; `None`
/// for the other formats, which carry no sample name. The data rows are
/// not read, so a file that [`read_bytes`] refuses may still get a name.
pub fn read_sample_name(bytes: &[u8], name: impl AsRef<Path>) -> Option<String> {
    if detect_format(bytes, name.as_ref()) != SourceFormat::Mountain {
        return None;
    }
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let end = header_end(bytes).unwrap_or(bytes.len());
    mountain::header_sample_name(&text::decode(&bytes[..end]))
}

/// [`read_sample_name`] of the file at `path`, reading only as much of it
/// as holds the header (and the first data row, which may decide the
/// format).
pub fn read_sample_name_at(path: impl AsRef<Path>) -> std::io::Result<Option<String>> {
    use std::io::Read;
    let path = path.as_ref();
    let (mut file, limit) = brtf_io::open_input(path)?;
    let mut bytes = Vec::new();
    let mut want = 64 * 1024;
    loop {
        let before = bytes.len();
        (&mut file)
            .take((want - before) as u64)
            .read_to_end(&mut bytes)?;
        let at_end = bytes.len() < want;
        let body = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(&bytes);
        // A prefix will do once its header ends with a whole line.
        let whole_header = header_end(body).is_some_and(|end| body[..end].ends_with(b"\n"));
        if at_end || whole_header || want as u64 > limit {
            return Ok(read_sample_name(&bytes, path));
        }
        want *= 4;
    }
}

/// Where the header of a Mountain file's text ends: after the LF-ended
/// piece that holds the first data row (a line that is neither blank nor
/// a `#` comment); `None` without a data row. A lone-CR file is one piece.
fn header_end(bytes: &[u8]) -> Option<usize> {
    let mut end = 0;
    for piece in bytes.split_inclusive(|&b| b == b'\n') {
        end += piece.len();
        let data_row = piece
            .split(|&b| b == b'\r' || b == b'\n')
            .map(<[u8]>::trim_ascii)
            .any(|line| !line.is_empty() && !line.starts_with(b"#"));
        if data_row {
            return Some(end);
        }
    }
    None
}

/// Guesses the format: a `.mpc` extension; else the header (a `#format:`
/// or `#intheta` line means Mountain, which `.mpc` files never have; a
/// `#using beam file`, `#incident angle …` or `#theta phi beam-ref …` line
/// means `.mpc`); else the column count of the first data row (8 means
/// `.mpc`). Defaults to Mountain. An `.xml` extension, or text starting
/// with `<`, is Klems BSDF XML.
pub fn detect_format(bytes: &[u8], name: &Path) -> SourceFormat {
    let extension_is = |ext: &str| {
        name.extension()
            .is_some_and(|e| e.eq_ignore_ascii_case(ext))
    };
    if extension_is("mpc") {
        return SourceFormat::Mpc;
    }
    if extension_is("xml") || is_xml(bytes) {
        return SourceFormat::KlemsXml;
    }
    // Only the head of the file matters, and only its ASCII keys.
    let head = &bytes[..bytes.len().min(64 * 1024)];
    let head = String::from_utf8_lossy(head);
    let mut mpc_marker = false;
    for (_, line) in text::Lines::new(&head) {
        let line = line.trim();
        if line.is_empty() {
            continue;
        }
        if let Some(body) = line.strip_prefix('#') {
            let body = body.trim_start().to_ascii_lowercase();
            if body.starts_with("format:") || body.starts_with("intheta") {
                return SourceFormat::Mountain;
            }
            mpc_marker |= body.starts_with("using beam file")
                || body.starts_with("incident angle")
                || body.starts_with("theta phi beam-ref");
            continue;
        }
        let columns = line.split_ascii_whitespace().count();
        if columns < 2 {
            continue; // an `.mpc` bare header value
        }
        return if mpc_marker || columns == mpc::COLUMNS {
            SourceFormat::Mpc
        } else {
            SourceFormat::Mountain
        };
    }
    if mpc_marker {
        SourceFormat::Mpc
    } else {
        SourceFormat::Mountain
    }
}

/// True when the first non-blank character (after a UTF-8 byte-order
/// mark) is `<`: gonio text files never start so.
pub fn is_xml(bytes: &[u8]) -> bool {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    bytes.iter().find(|b| !b.is_ascii_whitespace()) == Some(&b'<')
}

pub(crate) fn read_file(path: &Path) -> Result<Vec<u8>, ReadError> {
    brtf_io::read_input(path).map_err(|source| ReadError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Builds a parse error for `name` at `line`.
pub(crate) fn parse_error(name: &Path, line: usize, kind: ParseErrorKind) -> ReadError {
    ReadError::Parse {
        path: name.to_path_buf(),
        line,
        kind,
    }
}

/// Rejects empty and binary input and returns the text (without a BOM),
/// with lines that are not UTF-8 read as Latin-1.
pub(crate) fn check_text<'a>(bytes: &'a [u8], name: &Path) -> Result<Cow<'a, str>, ReadError> {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    if bytes.iter().all(u8::is_ascii_whitespace) {
        return Err(parse_error(name, 1, ParseErrorKind::Empty));
    }
    // `contains` scans with memchr, several times faster than `position`.
    if bytes.contains(&0)
        && let Some(offset) = bytes.iter().position(|&b| b == 0)
    {
        let kind = ParseErrorKind::Binary {
            what: "NUL byte",
            offset,
        };
        return Err(parse_error(name, text::line_number_at(bytes, offset), kind));
    }
    Ok(text::decode(bytes))
}

/// The non-blank lines of `text` with their 1-based numbers, line ends
/// (`\n`, `\r\n` or a lone `\r`) removed.
pub(crate) fn numbered_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text::Lines::new(text).filter(|(_, line)| !line.trim_ascii().is_empty())
}

/// A cursor over the whitespace-separated number fields of one data row.
///
/// This is the readers' hot loop: one byte scan per field, with the number
/// parsed during the scan ([`number::parse_prefix`]). Any problem is
/// reported as a wrong column count first (when the row does not have
/// exactly `expected` fields), otherwise as the bad field.
pub(crate) struct Row<'a> {
    line: &'a str,
    pos: usize,
    expected: usize,
    layout: &'static str,
}

impl<'a> Row<'a> {
    pub(crate) fn new(line: &'a str, expected: usize, layout: &'static str) -> Self {
        Self {
            line,
            pos: 0,
            expected,
            layout,
        }
    }

    fn column_count_error(&self) -> Option<ParseErrorKind> {
        let found = self.line.split_ascii_whitespace().count();
        (found != self.expected).then_some(ParseErrorKind::ColumnCount {
            expected: self.expected,
            found,
            layout: self.layout,
        })
    }

    /// The next field as a finite number (`column` is 1-based).
    #[inline]
    pub(crate) fn number(
        &mut self,
        column: usize,
        name: &'static str,
    ) -> Result<f64, ParseErrorKind> {
        let bytes = self.line.as_bytes();
        while self.pos < bytes.len() && bytes[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        let start = self.pos;
        if let Some((value, used)) = number::parse_prefix(&bytes[start..]) {
            let end = start + used;
            if end == bytes.len() || bytes[end].is_ascii_whitespace() {
                self.pos = end;
                return Ok(value);
            }
        }
        // Slow path: a missing field, an unusual spelling, or an error.
        let mut end = start;
        while end < bytes.len() && !bytes[end].is_ascii_whitespace() {
            end += 1;
        }
        self.pos = end;
        // Both ends sit next to ASCII bytes (or the ends), so they are char
        // boundaries.
        let field = &self.line[start..end];
        match parse_number(field, column, name) {
            Ok(value) if !field.is_empty() => Ok(value),
            Ok(_) => Err(self
                .column_count_error()
                .unwrap_or(ParseErrorKind::NotANumber {
                    column,
                    name,
                    text: String::new(),
                })),
            Err(kind) => Err(self.column_count_error().unwrap_or(kind)),
        }
    }

    /// The next field as a value: like [`Row::number`], but the
    /// `9.9e+37` sentinel becomes NaN.
    #[inline]
    pub(crate) fn value(
        &mut self,
        column: usize,
        name: &'static str,
    ) -> Result<f64, ParseErrorKind> {
        let v = self.number(column, name)?;
        Ok(if v.abs() >= SENTINEL_THRESHOLD {
            f64::NAN
        } else {
            v
        })
    }

    /// θ_out and φ_out, the first two fields, checked and normalised.
    #[inline]
    pub(crate) fn direction(&mut self) -> Result<(f64, f64), ParseErrorKind> {
        let theta = self.number(1, "theta")?;
        let phi = self.number(2, "phi")?;
        check_direction(theta, phi)
    }

    /// Succeeds when no fields are left.
    #[inline]
    pub(crate) fn finish(self) -> Result<(), ParseErrorKind> {
        let rest = &self.line.as_bytes()[self.pos..];
        if rest.iter().all(u8::is_ascii_whitespace) {
            Ok(())
        } else {
            Err(self
                .column_count_error()
                .unwrap_or(ParseErrorKind::ColumnCount {
                    expected: self.expected,
                    found: self.expected + 1,
                    layout: self.layout,
                }))
        }
    }
}

/// Parses a finite number. Literal `nan`/`inf` and overflow are errors.
pub(crate) fn parse_number(
    text: &str,
    column: usize,
    name: &'static str,
) -> Result<f64, ParseErrorKind> {
    match number::parse_f64(text) {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(ParseErrorKind::NonFinite {
            column,
            name,
            text: shorten(text),
        }),
        Err(_) => Err(ParseErrorKind::NotANumber {
            column,
            name,
            text: shorten(text),
        }),
    }
}

/// Checks θ_out (must lie in [0, 180]) and normalises φ_out to [0, 360).
pub(crate) fn check_direction(theta: f64, phi: f64) -> Result<(f64, f64), ParseErrorKind> {
    if !(0.0..=180.0).contains(&theta) {
        return Err(ParseErrorKind::AngleOutOfRange {
            what: "theta_out",
            value: theta,
            min: 0.0,
            max: 180.0,
        });
    }
    if phi.abs() >= SENTINEL_THRESHOLD {
        return Err(ParseErrorKind::AngleOutOfRange {
            what: "phi_out",
            value: phi,
            min: -360.0,
            max: 720.0,
        });
    }
    Ok((theta, crate::measurement::normalize_phi_deg(phi)))
}

fn shorten(text: &str) -> String {
    const MAX: usize = 40;
    match text.char_indices().nth(MAX) {
        Some((cut, _)) => format!("{}…", &text[..cut]),
        None => text.to_owned(),
    }
}

/// Tolerance (degrees) when comparing incidences from two sources.
pub(crate) const INCIDENCE_TOLERANCE_DEG: f64 = 1e-3;

/// Brings an incident angle pair into θ ∈ [0, 180], φ ∈ [0, 360).
/// A negative θ (in-plane signed convention, `-15+0`) means (|θ|, φ + 180°).
pub(crate) fn normalize_incidence(theta: f64, phi: f64) -> (f64, f64) {
    let (theta, phi) = if theta < 0.0 {
        (-theta, phi + 180.0)
    } else {
        (theta, phi)
    };
    (theta, crate::measurement::normalize_phi_deg(phi))
}

/// The incidence `(θ, φ)` encoded at the end of a file name, as in
/// `pab-xenon-aluA-elox1-b:+15+0.mpc`: two signed decimal numbers at the end
/// of the stem, at least one of them with an explicit `+`.
pub fn incidence_from_file_name(name: &Path) -> Option<(f64, f64)> {
    let file_name = name.file_name()?.to_str()?;
    // Strip an alphabetic extension (".mpc", ".txt"), never "+15.5".
    let stem = match file_name.rfind('.') {
        Some(dot)
            if dot + 1 < file_name.len()
                && file_name[dot + 1..]
                    .bytes()
                    .all(|b| b.is_ascii_alphabetic()) =>
        {
            &file_name[..dot]
        }
        _ => file_name,
    };
    let (rest, phi_text) = split_trailing_signed_number(stem)?;
    let (before, theta_text) = split_trailing_signed_number(rest)?;
    if before.ends_with(|c: char| c.is_ascii_digit() || c == '.') {
        return None;
    }
    if !theta_text.starts_with('+') && !phi_text.starts_with('+') {
        return None;
    }
    let theta: f64 = theta_text.parse().ok()?;
    let phi: f64 = phi_text.parse().ok()?;
    (theta.is_finite() && phi.is_finite() && theta.abs() <= 180.0)
        .then(|| normalize_incidence(theta, phi))
}

/// Splits `text` into `(before, "+12.5")` when it ends in a signed number.
fn split_trailing_signed_number(text: &str) -> Option<(&str, &str)> {
    let digits_start = text
        .rfind(|c: char| !(c.is_ascii_digit() || c == '.'))
        .map_or(0, |i| i + 1);
    let digits = &text[digits_start..];
    if !digits.bytes().any(|b| b.is_ascii_digit()) || digits_start == 0 {
        return None;
    }
    let sign_at = digits_start - 1;
    match text.as_bytes()[sign_at] {
        b'+' | b'-' => Some((&text[..sign_at], &text[sign_at..])),
        _ => None,
    }
}

/// One incident angle found in a header, with its line.
#[derive(Clone, Copy, Debug)]
pub(crate) struct HeaderAngle {
    pub value: f64,
    pub line: usize,
}

/// Combines header and file-name incidence as the spec asks: the header
/// wins, the name fills gaps, and a disagreement is an error naming both.
/// `line` is where a missing angle is reported (the first data row).
pub(crate) fn resolve_incidence(
    header_theta: Option<HeaderAngle>,
    header_phi: Option<HeaderAngle>,
    name: &Path,
    line: usize,
    expected: &'static str,
) -> Result<(Incidence, IncidenceOrigin), ReadError> {
    let from_name = incidence_from_file_name(name);
    let theta = match (header_theta, from_name) {
        (Some(h), _) => h.value,
        (None, Some((t, _))) => t,
        (None, None) => {
            let kind = ParseErrorKind::MissingIncidence {
                missing: "theta",
                expected,
            };
            return Err(parse_error(name, line, kind));
        }
    };
    let phi = match (header_phi, from_name) {
        (Some(h), _) => h.value,
        (None, Some((_, p))) => p,
        (None, None) => {
            let kind = ParseErrorKind::MissingIncidence {
                missing: "phi",
                expected,
            };
            return Err(parse_error(name, line, kind));
        }
    };
    if !(-180.0..=180.0).contains(&theta) {
        let kind = ParseErrorKind::AngleOutOfRange {
            what: "theta_in",
            value: theta,
            min: -180.0,
            max: 180.0,
        };
        return Err(parse_error(
            name,
            header_theta.map_or(line, |a| a.line),
            kind,
        ));
    }
    let (theta, phi) = normalize_incidence(theta, phi);
    let origin = if header_theta.is_some() && header_phi.is_some() {
        IncidenceOrigin::Header
    } else if header_theta.is_none() && header_phi.is_none() {
        IncidenceOrigin::FileName
    } else {
        // Mixed: some from the header, the rest from the name.
        IncidenceOrigin::Header
    };
    if let Some((name_theta, name_phi)) = from_name
        && !same_incidence((theta, phi), (name_theta, name_phi))
    {
        let conflict_line = header_theta.or(header_phi).map_or(line, |angle| angle.line);
        let kind = ParseErrorKind::IncidenceConflict {
            header_theta: theta,
            header_phi: phi,
            name_theta,
            name_phi,
            file_name: name
                .file_name()
                .map_or_else(String::new, |n| n.to_string_lossy().into_owned()),
        };
        return Err(parse_error(name, conflict_line, kind));
    }
    Ok((Incidence::new(theta, phi), origin))
}

/// True when two normalised incidences agree within
/// [`INCIDENCE_TOLERANCE_DEG`]; φ is ignored at normal incidence.
fn same_incidence(a: (f64, f64), b: (f64, f64)) -> bool {
    if (a.0 - b.0).abs() > INCIDENCE_TOLERANCE_DEG {
        return false;
    }
    let at_pole = a.0 < INCIDENCE_TOLERANCE_DEG || (180.0 - a.0) < INCIDENCE_TOLERANCE_DEG;
    let dphi = (a.1 - b.1).rem_euclid(360.0);
    at_pole || dphi.min(360.0 - dphi) <= INCIDENCE_TOLERANCE_DEG
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_header_alone_gives_the_readers_sample_name() {
        let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data");
        let files = [
            data.join("rgl-epfl-pgII-raw/golden_paper.txt"),
            data.join("rgl-epfl-pgII-raw/layer_020_030.txt"),
            Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/pab-aluA-st1:+30+0.mpc"),
        ];
        for path in files {
            let bytes = std::fs::read(&path).unwrap();
            let whole = read_bytes(&bytes, &path).unwrap().sample_name;
            assert_eq!(read_sample_name(&bytes, &path), whole, "{}", path.display());
            assert_eq!(
                read_sample_name_at(&path).unwrap(),
                whole,
                "{}",
                path.display()
            );
        }
        // A header longer than the first read, its name at the end, and a
        // file that is all header.
        let dir = std::env::temp_dir().join(format!("brtf-name-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let long = format!(
            "#intheta 30\n#inphi 0\n{}#sample_name late\n10 0 0.5\n20 0 0.25\n",
            "# a long comment line of the header, repeated\n".repeat(6000)
        );
        for (file, text, want) in [
            ("long.txt", long.clone(), Some("late")),
            (
                "header.txt",
                long[..long.len() - 20].to_string(),
                Some("late"),
            ),
            (
                "short.txt",
                "#sample_name s\n1 2 3\n".to_string(),
                Some("s"),
            ),
        ] {
            let path = dir.join(file);
            std::fs::write(&path, &text).unwrap();
            let got = read_sample_name_at(&path).unwrap();
            assert_eq!(got, read_sample_name(text.as_bytes(), &path), "{file}");
            assert_eq!(got.as_deref(), want, "{file}");
        }
        assert!(read_sample_name_at(dir.join("missing.txt")).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
        let head = "#intheta 30\n#inphi 0\n#format: theta phi BSDF\n";
        let rows = "10 0 0.5\n20 0 0.25\n";
        let variants: Vec<Vec<u8>> = vec![
            format!("#sample_name \"a\"\n{head}\n#sample_name: \"b c\"\n{rows}").into_bytes(),
            format!("\u{feff}{head}#Sample_Name\tplain\r\n{rows}").into_bytes(),
            format!("{head}#sample_name x\r\r{rows}")
                .replace('\n', "\r")
                .into_bytes(),
            format!("{head}{rows}").into_bytes(),
            [
                head.as_bytes(),
                b"#sample_name \"Fl\xe4che\"\n",
                rows.as_bytes(),
            ]
            .concat(),
        ];
        let expected = [Some("b c"), Some("plain"), Some("x"), None, Some("Fläche")];
        for (bytes, expected) in variants.iter().zip(expected) {
            let whole = read_bytes(bytes, "x.txt").unwrap().sample_name;
            assert_eq!(whole.as_deref(), expected);
            assert_eq!(read_sample_name(bytes, "x.txt"), whole);
        }
        // A header line after the data is the reader's error; the header
        // ends at the first row.
        let late = format!("{head}{rows}#sample_name late\n");
        assert!(read_bytes(late.as_bytes(), "x.txt").is_err());
        assert_eq!(read_sample_name(late.as_bytes(), "x.txt"), None);
    }

    #[test]
    fn file_name_incidence() {
        let p = |s: &str| incidence_from_file_name(Path::new(s));
        assert_eq!(p("pab-xenon-aluA-elox1-b:+15+0.mpc"), Some((15.0, 0.0)));
        assert_eq!(p("dir/pab-aluA-st1:+30+0.mpc"), Some((30.0, 0.0)));
        assert_eq!(p("x:+22.5-90.mpc"), Some((22.5, 270.0)));
        assert_eq!(p("x:-15+0.mpc"), Some((15.0, 180.0)));
        assert_eq!(p("x:+15.5+0"), Some((15.5, 0.0)));
        assert_eq!(p("golden_paper.txt"), None);
        assert_eq!(p("layer_020_030.txt"), None);
        assert_eq!(p("sample-15-0.txt"), None);
        assert_eq!(p("+15+0.mpc"), Some((15.0, 0.0)));
        assert_eq!(p("x:+999+0.mpc"), None);
    }

    #[test]
    fn rows_and_numbers() {
        let mut row = Row::new("1\t2  3", 3, "a b c");
        assert_eq!(row.number(1, "a"), Ok(1.0));
        assert_eq!(row.number(2, "b"), Ok(2.0));
        assert_eq!(row.number(3, "c"), Ok(3.0));
        assert_eq!(row.finish(), Ok(()));
        let mut short = Row::new("1 2", 3, "a b c");
        short.number(1, "a").unwrap();
        short.number(2, "b").unwrap();
        assert!(matches!(
            short.number(3, "c"),
            Err(ParseErrorKind::ColumnCount { found: 2, .. })
        ));
        let mut long = Row::new("1 2 3 4", 3, "a b c");
        for c in 1..=3 {
            long.number(c, "x").unwrap();
        }
        assert!(matches!(
            long.finish(),
            Err(ParseErrorKind::ColumnCount { found: 4, .. })
        ));
        let mut bad = Row::new("1 x2 3", 3, "a b c");
        bad.number(1, "a").unwrap();
        assert!(matches!(
            bad.number(2, "b"),
            Err(ParseErrorKind::NotANumber { column: 2, .. })
        ));
        assert!(Row::new("9.9e+37", 1, "v").value(1, "v").unwrap().is_nan());
        assert!(matches!(
            parse_number("nan", 3, "v"),
            Err(ParseErrorKind::NonFinite { .. })
        ));
        assert!(matches!(
            parse_number("1e999", 3, "v"),
            Err(ParseErrorKind::NonFinite { .. })
        ));
        assert!(matches!(
            parse_number("1,5", 3, "v"),
            Err(ParseErrorKind::NotANumber { .. })
        ));
    }
}
