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

use super::{HeaderAngle, Row, numbered_lines, parse_error, resolve_incidence};
use crate::error::{ParseErrorKind, ReadError};
use crate::measurement::{Channels, Measurement, Quantity, Sample, SourceFormat};

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

    for (line_no, line) in numbered_lines(text) {
        last_line = line_no;
        let is_header = line.trim_ascii_start().starts_with('#');
        if let Some(first) = first_data_line {
            if is_header {
                let kind = ParseErrorKind::HeaderAfterData {
                    first_data_line: first,
                };
                return Err(parse_error(name, line_no, kind));
            }
            let sample = match channels {
                Channels::Y => parse_row_y(line),
                Channels::Xyz => parse_row_xyz(line),
            }
            .map_err(|kind| parse_error(name, line_no, kind))?;
            samples.push(sample);
            continue;
        }

        if is_header {
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
        let sample = match channels {
            Channels::Y => parse_row_y(line),
            Channels::Xyz => parse_row_xyz(line),
        }
        .map_err(|kind| parse_error(name, line_no, kind))?;
        // Reserve once the row length is known: ~1 sample per 30 bytes.
        samples.reserve(text.len() / line.len().max(24));
        samples.push(sample);
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
}
