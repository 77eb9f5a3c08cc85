//! The Fraunhofer ISE `.mpc` writer.
//!
//! This module owns the `.mpc` header regeneration (beam file line and the
//! label-then-value incidence pairs, kept in their original style) and the
//! eight-column rows. Columns 3-6 come from [`Measurement::mpc_columns`]
//! when known and are written as the `9.9e+37` sentinel otherwise; a
//! missing solid angle is written as the sentinel too.

use super::push_number;
use crate::measurement::{Channels, Measurement, MpcColumns, Quantity, SourceFormat};

/// The standard column line, written when the header has none.
const COLUMN_LINE: &str = "#theta phi beam-ref org-data minus-background/beam-ref \
                           cosine-out-corrected brtf voronoi-cell-size";

#[derive(Clone, Copy, PartialEq)]
enum Label {
    Theta,
    Phi,
    Other,
}

fn classify(body_lower: &str) -> Label {
    // `incident angle theta [degree]:`; "incidence" starts the same way.
    let incident = body_lower.trim_start().starts_with("incident");
    if incident && body_lower.contains("theta") {
        Label::Theta
    } else if incident && body_lower.contains("phi") {
        Label::Phi
    } else {
        Label::Other
    }
}

fn is_column_line(body_lower: &str) -> bool {
    let mut words = body_lower.split_ascii_whitespace();
    words.next() == Some("theta") && words.next() == Some("phi")
}

fn number_text(v: f64) -> String {
    let mut s = String::new();
    push_number(&mut s, v);
    s
}

fn beam_line(m: &Measurement) -> Option<String> {
    m.beam
        .as_ref()
        .map(|b| format!("#using beam file: {} {}", b.file, number_text(b.integral)))
}

/// The header lines to write (without the column line) and the column line.
fn header_lines(m: &Measurement) -> (Vec<String>, String) {
    let mut out = Vec::with_capacity(m.header.len() + 6);
    let mut column_line: Option<String> = None;
    let mut wrote_beam = false;
    let mut wrote_theta = false;
    let mut wrote_phi = false;
    let mut pending = Label::Other;
    let value_for = |label: Label| match label {
        Label::Theta => Some(m.incidence.theta_deg),
        Label::Phi => Some(m.incidence.phi_deg),
        Label::Other => None,
    };

    for line in &m.header {
        if m.format != SourceFormat::Mpc {
            out.push(super::foreign_header_line(line));
            continue;
        }
        let trimmed = line.trim();
        let label = std::mem::replace(&mut pending, Label::Other);
        let (commented, body) = match trimmed.strip_prefix('#') {
            Some(body) => (true, body.trim()),
            None => (false, trimmed),
        };
        // The value line after an incidence label: keep its style.
        if let Some(current) = value_for(label)
            && body.parse::<f64>().is_ok()
        {
            if label == Label::Theta {
                wrote_theta = true;
            } else {
                wrote_phi = true;
            }
            if body.parse::<f64>() == Ok(current) {
                out.push(line.clone());
            } else {
                let hash = if commented { "#" } else { "" };
                out.push(format!("{hash}{}", number_text(current)));
            }
            continue;
        }
        let lower = body.to_ascii_lowercase();
        if commented && lower.starts_with("using beam file") {
            wrote_beam = true;
            let fresh = beam_line(m);
            let unchanged = m.beam.as_ref().is_some_and(|b| {
                let rest = body.split_once(':').map_or("", |(_, r)| r).trim();
                rest.rsplit_once(|c: char| c.is_ascii_whitespace())
                    .is_some_and(|(file, v)| file.trim() == b.file && v.parse() == Ok(b.integral))
            });
            if unchanged {
                out.push(line.clone());
            } else if let Some(fresh) = fresh {
                out.push(fresh);
            }
            continue;
        }
        if commented && is_column_line(&lower) {
            column_line = Some(line.clone());
            continue;
        }
        if commented && lower.ends_with(':') {
            pending = classify(&lower);
        } else if commented
            && let Some((label_text, value_text)) = lower.rsplit_once(':')
            && let Some(current) = value_for(classify(label_text))
            && value_text.trim().parse::<f64>().is_ok()
        {
            // One-line form: `#incident angle theta [degree]: 30`.
            if classify(label_text) == Label::Theta {
                wrote_theta = true;
            } else {
                wrote_phi = true;
            }
            if value_text.trim().parse::<f64>() != Ok(current) {
                let label_end = body.rfind(':').map_or(body.len(), |i| i + 1);
                out.push(format!("#{} {}", &body[..label_end], number_text(current)));
                continue;
            }
        }
        out.push(line.clone());
    }

    if !wrote_beam && let Some(line) = beam_line(m) {
        out.insert(0, line);
    }
    if !wrote_theta {
        out.push("#incident angle theta [degree]:".to_owned());
        out.push(number_text(m.incidence.theta_deg));
    }
    if !wrote_phi {
        out.push("#incident angle phi [degree]:".to_owned());
        out.push(number_text(m.incidence.phi_deg));
    }
    (out, column_line.unwrap_or_else(|| COLUMN_LINE.to_owned()))
}

/// The whole file as text, or why the measurement cannot be an `.mpc`.
pub(crate) fn render(m: &Measurement) -> Result<String, String> {
    if m.quantity != Quantity::Bsdf {
        return Err(format!(
            "the .mpc format holds a BSDF (brtf column) but this measurement holds {}; \
             convert it first",
            m.quantity
        ));
    }
    if m.channels != Channels::Y {
        return Err("the .mpc format holds one value (CIE-Y) per sample, not CIE-XYZ".to_owned());
    }
    let extras_known = m.mpc_columns.len() == m.samples.len();
    let (header, column_line) = header_lines(m);
    let mut out = String::with_capacity(4096 + m.samples.len() * 100);
    for line in header.iter().chain(std::iter::once(&column_line)) {
        out.push_str(line);
        out.push('\n');
    }
    for (i, s) in m.samples.iter().enumerate() {
        let extra = if extras_known {
            m.mpc_columns[i]
        } else {
            MpcColumns::UNAVAILABLE
        };
        let fields = [
            s.theta_deg,
            s.phi_deg,
            extra.beam_reference,
            extra.raw_signal,
            extra.minus_background_per_beam_reference,
            extra.cosine_corrected,
            s.values[0],
            s.solid_angle_sr.unwrap_or(f64::NAN),
        ];
        for (k, v) in fields.into_iter().enumerate() {
            if k > 0 {
                out.push(' ');
            }
            push_number(&mut out, v);
        }
        out.push('\n');
    }
    Ok(out)
}
