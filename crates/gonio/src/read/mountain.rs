//! The pab-opto "Mountain" reader (pgII gonio-photometer files, the input of
//! Radiance's `pabopto2bsdf`).
//!
//! This module owns the Mountain header keys (`#intheta`, `#inphi`,
//! `#incident_angle`, `#upphi`, `#format:`, `#colorimetry:`,
//! `#sample_name`, `#datapoints_in_file`) and the `theta phi value [value
//! value]` rows. Unknown keys are kept verbatim in [`Measurement::header`].
//! brtf adds one key of its own, `#beam_integral VALUE`, to carry the beam
//! integral of a raw measurement through a write and read.

use std::path::Path;

use super::number::parse_prefix;
use super::text::Lines;
use super::{HeaderAngle, Row, check_direction, parse_error, resolve_incidence};
use crate::error::{ParseErrorKind, ReadError};
use crate::measurement::{
    Channels, Measurement, Quantity, SENTINEL_THRESHOLD, Sample, SourceFormat,
};

const LAYOUT_Y: &str = "theta phi value";
const LAYOUT_XYZ: &str = "theta phi X Y Z";
/// brtf's own key carrying a raw measurement's beam integral
/// (`#beam_integral 0.0636`); other readers ignore it as an unknown key.
pub(crate) const BEAM_INTEGRAL_KEY: &str = "beam_integral";
const INCIDENCE_KEYS: &str = "`#intheta`/`#inphi` or `#incident_angle THETA PHI`";

/// A Mountain header line split into its key (lower case, without `#` and
/// a trailing `:`) and the rest of the line.
pub(crate) fn split_key(line: &str) -> Option<(String, &str)> {
    let body = line.trim().strip_prefix('#')?.trim_start();
    let end = body
        .find(|c: char| c.is_ascii_whitespace() || c == ':')
        .unwrap_or(body.len());
    let key = body[..end].to_ascii_lowercase();
    let rest = body[end..].strip_prefix(':').unwrap_or(&body[end..]).trim();
    Some((key, rest))
}

/// Parses the `Q` of `#format: theta phi Q [Q Q]`.
pub(crate) fn parse_format_quantity(rest: &str) -> Option<Quantity> {
    let mut tokens = rest.split_ascii_whitespace();
    let theta = tokens.next()?;
    let phi = tokens.next()?;
    if !theta.eq_ignore_ascii_case("theta") || !phi.eq_ignore_ascii_case("phi") {
        return None;
    }
    let q = tokens.next()?;
    // Three-channel files may repeat the quantity once per channel.
    if tokens.any(|t| t != q) {
        return None;
    }
    let upper = q.to_ascii_uppercase();
    match upper.as_str() {
        "DSF" => Some(Quantity::Dsf),
        "BSDF" | "BRDF" | "BTDF" => Some(Quantity::Bsdf),
        _ => {
            let unit = q.strip_prefix('[')?.strip_suffix(']')?;
            (!unit.is_empty()).then(|| Quantity::Raw {
                unit: unit.to_owned(),
                beam_integral: None,
            })
        }
    }
}

/// Parses the value of `#colorimetry:`.
pub(crate) fn parse_colorimetry(rest: &str) -> Option<Channels> {
    let word = rest.split_ascii_whitespace().next()?;
    if word.eq_ignore_ascii_case("CIE-Y") {
        Some(Channels::Y)
    } else if word.eq_ignore_ascii_case("CIE-XYZ") {
        Some(Channels::Xyz)
    } else {
        None
    }
}

/// Strips one pair of surrounding double quotes.
pub(crate) fn unquote(text: &str) -> &str {
    text.strip_prefix('"')
        .and_then(|t| t.strip_suffix('"'))
        .unwrap_or(text)
}

/// The last `#sample_name` of the header of `text` (the lines before the
/// first data row), as [`parse`] reads it.
pub(crate) fn header_sample_name(text: &str) -> Option<String> {
    let mut sample_name = None;
    for (_, line) in Lines::new(text) {
        if line.trim_ascii().is_empty() {
            continue;
        }
        if !line.trim_ascii_start().starts_with('#') {
            break;
        }
        if let Some((key, rest)) = split_key(line)
            && key == "sample_name"
        {
            sample_name = Some(unquote(rest).to_owned());
        }
    }
    sample_name
}

pub(crate) fn parse(text: &str, name: &Path) -> Result<Measurement, ReadError> {
    let mut header: Vec<String> = Vec::new();
    let mut theta_in: Option<HeaderAngle> = None;
    let mut phi_in: Option<HeaderAngle> = None;
    let mut up_phi = 0.0;
    let mut quantity: Option<Quantity> = None;
    let mut channels = Channels::Y;
    let mut sample_name: Option<String> = None;
    let mut declared_rows: Option<(usize, usize)> = None;
    let mut beam_integral: Option<f64> = None;
    let mut samples: Vec<Sample> = Vec::new();
    let mut first_data_line: Option<usize> = None;
    let mut last_line = 1;

    let mut lines = Lines::new(text);
    for (line_no, line) in lines.by_ref() {
        if line.trim_ascii().is_empty() {
            continue;
        }
        last_line = line_no;
        if line.trim_ascii_start().starts_with('#') {
            header.push(line.to_owned());
            let Some((key, rest)) = split_key(line) else {
                continue;
            };
            let err = |expected: &'static str| {
                let kind = ParseErrorKind::BadHeaderValue {
                    key: format!("#{key}"),
                    expected,
                    text: rest.to_owned(),
                };
                parse_error(name, line_no, kind)
            };
            let number = |text: Option<&str>, expected| -> Result<f64, ReadError> {
                match text.map(str::parse::<f64>) {
                    Some(Ok(v)) if v.is_finite() => Ok(v),
                    _ => Err(err(expected)),
                }
            };
            let mut tokens = rest.split_ascii_whitespace();
            match key.as_str() {
                "intheta" => {
                    let v = number(tokens.next(), "an angle in degrees")?;
                    set_angle(&mut theta_in, v, line_no, &key, "theta_in", name)?;
                }
                "inphi" => {
                    let v = number(tokens.next(), "an angle in degrees")?;
                    set_angle(&mut phi_in, v, line_no, &key, "phi_in", name)?;
                }
                "incident_angle" => {
                    let t = number(tokens.next(), "two angles THETA PHI in degrees")?;
                    let p = number(tokens.next(), "two angles THETA PHI in degrees")?;
                    set_angle(&mut theta_in, t, line_no, &key, "theta_in", name)?;
                    set_angle(&mut phi_in, p, line_no, &key, "phi_in", name)?;
                }
                "upphi" => up_phi = number(tokens.next(), "an angle in degrees")?,
                "format" => {
                    let expected = "`theta phi Q` with Q one of DSF, BSDF, BRDF, BTDF or [unit]";
                    quantity = Some(parse_format_quantity(rest).ok_or_else(|| err(expected))?);
                }
                "colorimetry" => {
                    channels = parse_colorimetry(rest).ok_or_else(|| err("CIE-Y or CIE-XYZ"))?;
                }
                BEAM_INTEGRAL_KEY => {
                    beam_integral = Some(number(tokens.next(), "a beam integral")?);
                }
                "sample_name" => sample_name = Some(unquote(rest).to_owned()),
                "datapoints_in_file" => {
                    let n = tokens
                        .next()
                        .and_then(|t| t.parse::<usize>().ok())
                        .ok_or_else(|| err("a row count"))?;
                    declared_rows = Some((n, line_no));
                }
                _ => {}
            }
            continue;
        }

        // The first data row: the header is complete.
        first_data_line = Some(line_no);
        if quantity.is_none() {
            return Err(parse_error(name, line_no, ParseErrorKind::MissingFormat));
        }
        let sample = parse_row(line, channels).map_err(|kind| parse_error(name, line_no, kind))?;
        // Reserve once the row length is known: ~1 sample per 30 bytes.
        samples.reserve(text.len() / line.len().max(24));
        samples.push(sample);
        break;
    }
    if let Some(first) = first_data_line {
        let rest = DataRows {
            text,
            pos: lines.position(),
            lines_before: first,
            first_data_line: first,
            channels,
            line_feed: None,
        };
        rest.read_into(&mut samples, name)?;
    }

    let Some(first_data_line) = first_data_line else {
        return Err(parse_error(name, last_line, ParseErrorKind::NoData));
    };
    if let Some((declared, line)) = declared_rows
        && declared != samples.len()
    {
        let kind = ParseErrorKind::DatapointsMismatch {
            declared,
            found: samples.len(),
        };
        return Err(parse_error(name, line, kind));
    }
    let (incidence, incidence_origin) =
        resolve_incidence(theta_in, phi_in, name, first_data_line, INCIDENCE_KEYS)?;
    let Some(mut quantity) = quantity else {
        return Err(parse_error(
            name,
            first_data_line,
            ParseErrorKind::MissingFormat,
        ));
    };
    if let Quantity::Raw {
        beam_integral: slot,
        ..
    } = &mut quantity
    {
        *slot = beam_integral;
    }

    let mut measurement = Measurement::new(
        SourceFormat::Mountain,
        incidence,
        quantity,
        channels,
        samples,
    );
    measurement.incidence_origin = incidence_origin;
    measurement.sample_name = sample_name;
    measurement.up_phi_deg = up_phi;
    measurement.header = header;
    Ok(measurement)
}

fn set_angle(
    slot: &mut Option<HeaderAngle>,
    value: f64,
    line: usize,
    key: &str,
    what: &'static str,
    name: &Path,
) -> Result<(), ReadError> {
    if let Some(earlier) = *slot
        && (earlier.value - value).abs() > super::INCIDENCE_TOLERANCE_DEG
    {
        let kind = ParseErrorKind::HeaderConflict {
            key: format!("#{key}"),
            what,
            this: value,
            earlier: earlier.value,
        };
        return Err(parse_error(name, line, kind));
    }
    if slot.is_none() {
        *slot = Some(HeaderAngle { value, line });
    }
    Ok(())
}

/// The data rows after the first: a byte loop for plain rows, the general
/// line-by-line rules for anything else.
struct DataRows<'a> {
    text: &'a str,
    /// Where the unread rows start (the start of a line).
    pos: usize,
    /// Lines before `pos`.
    lines_before: usize,
    first_data_line: usize,
    channels: Channels,
    /// Where the general rules last found the next `\n` (see
    /// [`Lines::line_feed`]): a file of lone-CR line ends has none, and
    /// looking again for every row would read the rest of the file each
    /// time (a CR-only 127 000-row scan took 15 s).
    line_feed: Option<usize>,
}

impl DataRows<'_> {
    /// Reads every remaining row into `samples`. Plain rows (numbers that
    /// take the exact fast path, separated by spaces or tabs, ended by LF,
    /// CRLF or the end of the text) are read by [`plain_rows`]; a row it
    /// does not take (a blank line, a lone CR, a header line, an unusual
    /// number, an error) goes through the same rules as the first row, so
    /// results and errors are the same as reading every line that way.
    fn read_into(mut self, samples: &mut Vec<Sample>, name: &Path) -> Result<(), ReadError> {
        let bytes = self.text.as_bytes();
        self.read_halves(samples);
        loop {
            let (pos, rows) = plain_rows_of(self.channels, bytes, self.pos, samples);
            self.pos = pos;
            self.lines_before += rows;
            let mut lines = Lines::resume(self.text, self.pos, self.lines_before)
                .with_line_feed(self.line_feed);
            let Some((line_no, line)) = lines.next() else {
                return Ok(());
            };
            self.line_feed = lines.line_feed();
            self.pos = lines.position();
            self.lines_before = line_no;
            if line.trim_ascii().is_empty() {
                continue;
            }
            if line.trim_ascii_start().starts_with('#') {
                let kind = ParseErrorKind::HeaderAfterData {
                    first_data_line: self.first_data_line,
                };
                return Err(parse_error(name, line_no, kind));
            }
            let sample =
                parse_row(line, self.channels).map_err(|kind| parse_error(name, line_no, kind))?;
            samples.push(sample);
        }
    }

    /// Reads the rows of a large file as two halves on two threads, split at
    /// a line start: when the first half is plain to its end, both halves'
    /// samples are kept and `self` moves past them; otherwise the second
    /// half's work is dropped and nothing but the first half's plain rows
    /// is kept, so [`DataRows::read_into`] goes on exactly as it would have.
    fn read_halves(&mut self, samples: &mut Vec<Sample>) {
        let bytes = self.text.as_bytes();
        // A last line without a line end leaves `pos` one past the end.
        let rest = bytes.len().saturating_sub(self.pos);
        if rest < PARALLEL_BYTES {
            return;
        }
        let middle = self.pos + rest / 2;
        let Some(split) = bytes[middle..]
            .iter()
            .position(|&b| b == b'\n')
            .map(|at| middle + at + 1)
        else {
            return;
        };
        let channels = self.channels;
        let rows = |slice: &[u8], from: usize, out: &mut Vec<Sample>| {
            plain_rows_of(channels, slice, from, out)
        };
        let mut second = Vec::with_capacity(samples.capacity().saturating_sub(samples.len()) / 2);
        let ((end, first_rows), (second_end, second_rows)) = rayon::join(
            || rows(&bytes[..split], self.pos, samples),
            || rows(bytes, split, &mut second),
        );
        self.pos = end;
        self.lines_before += first_rows;
        if end == split {
            samples.append(&mut second);
            self.pos = second_end;
            self.lines_before += second_rows;
        }
    }
}

/// Files with more data bytes than this are read in two halves at once.
const PARALLEL_BYTES: usize = 1 << 20;

/// [`plain_rows`] with the number of values of `channels`.
fn plain_rows_of(
    channels: Channels,
    bytes: &[u8],
    pos: usize,
    samples: &mut Vec<Sample>,
) -> (usize, usize) {
    match channels {
        Channels::Y => plain_rows::<1>(bytes, pos, samples),
        Channels::Xyz => plain_rows::<3>(bytes, pos, samples),
    }
}

/// Reads plain rows of θ, φ and `VALUES` values from `bytes[pos..]` until
/// one is not plain; returns where that row starts and how many rows were
/// read. A plain row gives the same sample as [`parse_row`]: the numbers
/// take the exact fast path ([`parse_prefix`]), which the general path
/// also tries first.
fn plain_rows<const VALUES: usize>(
    bytes: &[u8],
    mut pos: usize,
    samples: &mut Vec<Sample>,
) -> (usize, usize) {
    let mut rows = 0;
    while pos < bytes.len() {
        let Some((sample, next)) = plain_row::<VALUES>(bytes, pos) else {
            break;
        };
        samples.push(sample);
        pos = next;
        rows += 1;
    }
    (pos, rows)
}

/// One plain row starting at `pos`: the sample and where the next line
/// starts, or `None` when the row is not plain.
#[inline]
fn plain_row<const VALUES: usize>(bytes: &[u8], mut pos: usize) -> Option<(Sample, usize)> {
    let blank = |b: u8| b == b' ' || b == b'\t';
    let mut fields = [0.0; 5];
    for (k, field) in fields.iter_mut().take(2 + VALUES).enumerate() {
        // Leading blanks, and at least one blank between fields.
        let start = pos;
        while pos < bytes.len() && blank(bytes[pos]) {
            pos += 1;
        }
        if k > 0 && pos == start {
            return None;
        }
        let (value, used) = parse_prefix(bytes.get(pos..)?)?;
        *field = value;
        pos += used;
    }
    while pos < bytes.len() && blank(bytes[pos]) {
        pos += 1;
    }
    let next = match bytes.get(pos) {
        None => pos,
        Some(b'\n') => pos + 1,
        Some(b'\r') if bytes.get(pos + 1) == Some(&b'\n') => pos + 2,
        Some(_) => return None,
    };
    let (theta, phi) = check_direction(fields[0], fields[1]).ok()?;
    let value = |v: f64| {
        if v.abs() >= SENTINEL_THRESHOLD {
            f64::NAN
        } else {
            v
        }
    };
    let sample = if VALUES == 1 {
        Sample::luminance(theta, phi, value(fields[2]))
    } else {
        Sample::new(
            theta,
            phi,
            [value(fields[2]), value(fields[3]), value(fields[4])],
        )
    };
    Some((sample, next))
}

fn parse_row(line: &str, channels: Channels) -> Result<Sample, ParseErrorKind> {
    match channels {
        Channels::Y => parse_row_y(line),
        Channels::Xyz => parse_row_xyz(line),
    }
}

fn parse_row_y(line: &str) -> Result<Sample, ParseErrorKind> {
    let mut row = Row::new(line, 3, LAYOUT_Y);
    let (theta, phi) = row.direction()?;
    let value = row.value(3, "value")?;
    row.finish()?;
    Ok(Sample::luminance(theta, phi, value))
}

fn parse_row_xyz(line: &str) -> Result<Sample, ParseErrorKind> {
    let mut row = Row::new(line, 5, LAYOUT_XYZ);
    let (theta, phi) = row.direction()?;
    let x = row.value(3, "X")?;
    let y = row.value(4, "Y")?;
    let z = row.value(5, "Z")?;
    row.finish()?;
    Ok(Sample::new(theta, phi, [x, y, z]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_keys() {
        assert_eq!(
            split_key("#format: theta\tphi\t[uA]"),
            Some(("format".to_owned(), "theta\tphi\t[uA]"))
        );
        assert_eq!(
            split_key("#intheta\t26.8421"),
            Some(("intheta".to_owned(), "26.8421"))
        );
        assert_eq!(
            parse_format_quantity("theta phi [uA]"),
            Some(Quantity::Raw {
                unit: "uA".into(),
                beam_integral: None
            })
        );
        assert_eq!(
            parse_format_quantity("theta phi BRDF"),
            Some(Quantity::Bsdf)
        );
        assert_eq!(
            parse_format_quantity("theta phi DSF DSF DSF"),
            Some(Quantity::Dsf)
        );
        assert_eq!(parse_format_quantity("theta phi"), None);
        assert_eq!(parse_format_quantity("theta phi lux"), None);
        assert_eq!(parse_colorimetry("CIE-XYZ"), Some(Channels::Xyz));
        assert_eq!(unquote("\"Golden_glossy_paper\""), "Golden_glossy_paper");
    }

    /// A file of `rows` plain rows (above [`PARALLEL_BYTES`], so read in
    /// two halves) with `odd` put in place of row `at` (0-based).
    fn big_file(rows: usize, at: usize, odd: &str) -> String {
        let mut text = String::from("#format: theta phi BRDF\n#intheta 30\n#inphi 0\n");
        for i in 0..rows {
            if i == at {
                text.push_str(odd);
            } else {
                let theta = (i % 9000) as f64 * 0.01;
                let phi = (i / 9000) as f64 * 7.5;
                text.push_str(&format!("{theta}\t{phi}\t{}\n", i as f64 * 0.5));
            }
        }
        text
    }

    #[test]
    fn halves_read_as_one() {
        let rows = 90_000;
        let header_lines = 3;
        let expected = |i: usize| i as f64 * 0.5;
        // Plain throughout; an unusual row (CRLF, blank line, exponent) in
        // either half; an error in either half keeps its line number.
        for at in [rows / 4, 3 * rows / 4] {
            let plain = parse(&big_file(rows, usize::MAX, ""), Path::new("t")).unwrap();
            assert!(big_file(rows, usize::MAX, "").len() > PARALLEL_BYTES);
            assert_eq!(plain.samples.len(), rows);
            assert!(
                plain
                    .samples
                    .iter()
                    .enumerate()
                    .all(|(i, s)| s.values[0] == expected(i))
            );
            for odd in ["1.5\t2.5\t7e0\r\n", "\n1.5\t2.5\t7\n"] {
                let m = parse(&big_file(rows, at, odd), Path::new("t")).unwrap();
                assert_eq!(m.samples.len(), rows, "{odd:?} at {at}");
                assert_eq!(m.samples[at].values[0], 7.0);
                assert_eq!(m.samples[at].theta_deg, 1.5);
                for (i, s) in m.samples.iter().enumerate().filter(|&(i, _)| i != at) {
                    assert_eq!(s.values[0], expected(i), "row {i}, {odd:?} at {at}");
                }
            }
            let err = parse(&big_file(rows, at, "1.5\tx\t7\n"), Path::new("t")).unwrap_err();
            assert_eq!(err.line(), Some(header_lines + at + 1), "error at row {at}");
        }
    }
}
