//! The Fraunhofer ISE `.mpc` reader.
//!
//! This module owns the `.mpc` quirks: label-then-value header pairs (a
//! `#…:` label line followed by its value, bare like `30` or commented like
//! `#0`), the `#using beam file: NAME VALUE` beam integral, the eight data
//! columns, and the incidence taken from the file name when the header
//! lacks it. The quantity is the BRTF column (BSDF, 1/sr) with the Voronoi
//! cell size as the solid angle; columns 3-6 are kept in
//! [`Measurement::mpc_columns`].

use std::path::Path;

use super::{HeaderAngle, Row, numbered_lines, parse_error, parse_number, resolve_incidence};
use crate::error::{ParseErrorKind, ReadError};
use crate::measurement::{
    BeamReference, Channels, Measurement, MpcColumns, Quantity, Sample, SourceFormat,
};

/// Data columns in a `.mpc` row.
pub(crate) const COLUMNS: usize = 8;

/// Column names, for error messages.
const LAYOUT: &str = "theta phi beam-ref org-data minus-background/beam-ref \
                      cosine-out-corrected brtf voronoi-cell-size";

/// The header spellings for the incidence, for error messages.
const INCIDENCE_KEYS: &str = "`#incident angle theta [degree]:` / `#incident angle phi [degree]:`";

/// What a pending label line announces.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Label {
    IncidentTheta,
    IncidentPhi,
    Other,
}

/// Classifies a header body (text after `#`) that ends in `:`.
fn classify_label(body_lower: &str) -> Label {
    // `incident angle theta [degree]:`; "incidence" starts the same way.
    let incident = body_lower.trim_start().starts_with("incident");
    if incident && body_lower.contains("theta") {
        Label::IncidentTheta
    } else if incident && body_lower.contains("phi") {
        Label::IncidentPhi
    } else {
        Label::Other
    }
}

pub(crate) fn parse(text: &str, name: &Path) -> Result<Measurement, ReadError> {
    let mut header: Vec<String> = Vec::new();
    let mut pending: Option<Label> = None;
    let mut theta_in: Option<HeaderAngle> = None;
    let mut phi_in: Option<HeaderAngle> = None;
    let mut beam: Option<BeamReference> = None;
    let mut samples: Vec<Sample> = Vec::with_capacity(text.len() / 80);
    let mut columns: Vec<MpcColumns> = Vec::with_capacity(text.len() / 80);
    let mut first_data_line: Option<usize> = None;
    let mut last_line = 1;

    let mut set_angle = |label: Label, value: f64, line: usize| -> Result<(), ReadError> {
        let slot = match label {
            Label::IncidentTheta => &mut theta_in,
            Label::IncidentPhi => &mut phi_in,
            Label::Other => return Ok(()),
        };
        if let Some(earlier) = *slot
            && earlier.value != value
        {
            let kind = ParseErrorKind::HeaderConflict {
                key: format!("incident angle {}", label_word(label)),
                what: if label == Label::IncidentTheta {
                    "theta_in"
                } else {
                    "phi_in"
                },
                this: value,
                earlier: earlier.value,
            };
            return Err(parse_error(name, line, kind));
        }
        *slot = Some(HeaderAngle { value, line });
        Ok(())
    };

    for (line_no, line) in numbered_lines(text) {
        last_line = line_no;
        if let Some(first) = first_data_line {
            if line.trim_start().starts_with('#') {
                let kind = ParseErrorKind::HeaderAfterData {
                    first_data_line: first,
                };
                return Err(parse_error(name, line_no, kind));
            }
            let (sample, extra) =
                parse_row(line).map_err(|kind| parse_error(name, line_no, kind))?;
            samples.push(sample);
            columns.push(extra);
            continue;
        }

        let trimmed = line.trim();
        if let Some(body) = trimmed.strip_prefix('#') {
            let body = body.trim();
            // A commented value (`#0`) right after a label line.
            if let Some(label) = pending.take()
                && let Ok(value) = body.parse::<f64>()
            {
                if value.is_finite() {
                    set_angle(label, value, line_no)?;
                }
                header.push(line.to_owned());
                continue;
            }
            let lower = body.to_ascii_lowercase();
            if lower.starts_with("using beam file") {
                beam = Some(parse_beam(body, name, line_no)?);
            } else if lower.ends_with(':') {
                pending = Some(classify_label(&lower));
            } else if let Some((label_text, value_text)) = lower.rsplit_once(':') {
                // `#incident angle theta [degree]: 30` on one line.
                let label = classify_label(label_text);
                if label != Label::Other
                    && let Ok(value) = value_text.trim().parse::<f64>()
                    && value.is_finite()
                {
                    set_angle(label, value, line_no)?;
                }
            }
            header.push(line.to_owned());
            continue;
        }

        let mut fields = trimmed.split_ascii_whitespace();
        let is_single_field = fields.next().is_some() && fields.next().is_none();
        if is_single_field {
            // A bare header value (`30`), normally right after a label line.
            let label = pending.take().unwrap_or(Label::Other);
            if label != Label::Other {
                let value = parse_number(trimmed, 1, "header value").map_err(|_| {
                    let kind = ParseErrorKind::BadHeaderValue {
                        key: format!("incident angle {}", label_word(label)),
                        expected: "a number of degrees",
                        text: trimmed.to_owned(),
                    };
                    parse_error(name, line_no, kind)
                })?;
                set_angle(label, value, line_no)?;
            }
            header.push(line.to_owned());
            continue;
        }

        // The first data row: the header is complete.
        pending = None;
        first_data_line = Some(line_no);
        let (sample, extra) = parse_row(line).map_err(|kind| parse_error(name, line_no, kind))?;
        samples.push(sample);
        columns.push(extra);
    }

    let Some(first_data_line) = first_data_line else {
        return Err(parse_error(name, last_line, ParseErrorKind::NoData));
    };
    let (incidence, incidence_origin) =
        resolve_incidence(theta_in, phi_in, name, first_data_line, INCIDENCE_KEYS)?;

    let mut measurement = Measurement::new(
        SourceFormat::Mpc,
        incidence,
        Quantity::Bsdf,
        Channels::Y,
        samples,
    );
    measurement.incidence_origin = incidence_origin;
    measurement.mpc_columns = columns;
    measurement.beam = beam;
    measurement.header = header;
    Ok(measurement)
}

fn label_word(label: Label) -> &'static str {
    match label {
        Label::IncidentTheta => "theta",
        Label::IncidentPhi => "phi",
        Label::Other => "value",
    }
}

/// `using beam file: NAME VALUE` (the body after `#`).
fn parse_beam(body: &str, name: &Path, line: usize) -> Result<BeamReference, ReadError> {
    let bad = |text: &str| {
        let kind = ParseErrorKind::BadHeaderValue {
            key: "using beam file".to_owned(),
            expected: "`NAME VALUE` with a positive number VALUE",
            text: text.to_owned(),
        };
        parse_error(name, line, kind)
    };
    let rest = body.split_once(':').map_or("", |(_, rest)| rest).trim();
    let Some((file, value)) = rest.rsplit_once(|c: char| c.is_ascii_whitespace()) else {
        return Err(bad(rest));
    };
    match value.parse::<f64>() {
        Ok(integral) if integral.is_finite() => Ok(BeamReference {
            file: file.trim().to_owned(),
            integral,
        }),
        _ => Err(bad(rest)),
    }
}

fn parse_row(line: &str) -> Result<(Sample, MpcColumns), ParseErrorKind> {
    let mut row = Row::new(line, COLUMNS, LAYOUT);
    let (theta, phi) = row.direction()?;
    let extra = MpcColumns {
        beam_reference: row.value(3, "beam-ref")?,
        raw_signal: row.value(4, "org-data")?,
        minus_background_per_beam_reference: row.value(5, "minus-background/beam-ref")?,
        cosine_corrected: row.value(6, "cosine-out-corrected")?,
    };
    let brtf = row.value(7, "brtf")?;
    let cell = row.value(8, "voronoi-cell-size")?;
    row.finish()?;
    let mut sample = Sample::luminance(theta, phi, brtf);
    sample.solid_angle_sr = (!cell.is_nan()).then_some(cell);
    Ok((sample, extra))
}
