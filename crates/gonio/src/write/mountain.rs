//! The pab-opto "Mountain" writer.
//!
//! This module owns the Mountain header regeneration (which keys are
//! rewritten from the measurement's fields and where missing ones go) and
//! the tab-separated `theta phi value [value value]` rows, LF line ends.

use super::push_number;
use crate::measurement::{Measurement, Quantity, SourceFormat};
use crate::read::mountain::{
    BEAM_INTEGRAL_KEY, parse_colorimetry, parse_format_quantity, split_key, unquote,
};

/// The `Q` of `#format: theta phi Q` for a quantity.
fn format_word(quantity: &Quantity) -> String {
    match quantity {
        Quantity::Bsdf => "BSDF".to_owned(),
        Quantity::Dsf => "DSF".to_owned(),
        Quantity::Raw { unit, .. } => format!("[{unit}]"),
    }
}

/// Compares quantities as the `#format:` line can express them (the beam
/// integral travels on its own line).
fn same_format(a: &Quantity, b: &Quantity) -> bool {
    match (a, b) {
        (Quantity::Raw { unit: ua, .. }, Quantity::Raw { unit: ub, .. }) => ua == ub,
        _ => a == b,
    }
}

fn number_line(key: &str, values: &[f64]) -> String {
    let mut line = format!("#{key}");
    for &v in values {
        line.push('\t');
        push_number(&mut line, v);
    }
    line
}

fn first_number(rest: &str) -> Option<f64> {
    rest.split_ascii_whitespace().next()?.parse().ok()
}

/// The header lines to write, in order.
fn header_lines(m: &Measurement) -> Vec<String> {
    let theta = m.incidence.theta_deg;
    let phi = m.incidence.phi_deg;
    let beam_integral = match &m.quantity {
        Quantity::Raw { beam_integral, .. } => *beam_integral,
        _ => None,
    };
    let mut out: Vec<String> = Vec::with_capacity(m.header.len() + 8);
    let mut wrote_theta = false;
    let mut wrote_phi = false;
    let mut wrote_up_phi = false;
    let mut wrote_name = false;
    let mut wrote_colorimetry = false;
    let mut wrote_count = false;
    let mut wrote_beam = false;
    let mut format_at: Option<usize> = None;

    for line in &m.header {
        if m.format != SourceFormat::Mountain {
            // Foreign header lines survive as comments.
            out.push(super::foreign_header_line(line));
            continue;
        }
        let Some((key, rest)) = split_key(line) else {
            out.push(line.clone());
            continue;
        };
        let keep_if = |unchanged: bool, fresh: String| {
            if unchanged { line.clone() } else { fresh }
        };
        let new_line = match key.as_str() {
            "intheta" => {
                wrote_theta = true;
                keep_if(
                    first_number(rest) == Some(theta),
                    number_line("intheta", &[theta]),
                )
            }
            "inphi" => {
                wrote_phi = true;
                keep_if(
                    first_number(rest) == Some(phi),
                    number_line("inphi", &[phi]),
                )
            }
            "incident_angle" => {
                wrote_theta = true;
                wrote_phi = true;
                let mut tokens = rest.split_ascii_whitespace().map(str::parse::<f64>);
                let unchanged = tokens.next() == Some(Ok(theta)) && tokens.next() == Some(Ok(phi));
                keep_if(unchanged, number_line("incident_angle", &[theta, phi]))
            }
            "upphi" => {
                wrote_up_phi = true;
                keep_if(
                    first_number(rest) == Some(m.up_phi_deg),
                    number_line("upphi", &[m.up_phi_deg]),
                )
            }
            "format" => {
                format_at = Some(out.len());
                let unchanged =
                    parse_format_quantity(rest).is_some_and(|q| same_format(&q, &m.quantity));
                keep_if(unchanged, format_line(m))
            }
            "colorimetry" => {
                wrote_colorimetry = true;
                keep_if(
                    parse_colorimetry(rest) == Some(m.channels),
                    colorimetry_line(m),
                )
            }
            "sample_name" => {
                wrote_name = true;
                match &m.sample_name {
                    Some(name) => keep_if(unquote(rest) == name, sample_name_line(name)),
                    None => continue,
                }
            }
            "datapoints_in_file" => {
                wrote_count = true;
                let count = rest
                    .split_ascii_whitespace()
                    .next()
                    .map(str::parse::<usize>);
                keep_if(count == Some(Ok(m.samples.len())), count_line(m))
            }
            BEAM_INTEGRAL_KEY => {
                wrote_beam = true;
                match beam_integral {
                    Some(b) => keep_if(
                        first_number(rest) == Some(b),
                        number_line(BEAM_INTEGRAL_KEY, &[b]),
                    ),
                    None => continue,
                }
            }
            _ => line.clone(),
        };
        out.push(new_line);
    }

    // Keys the header lacked go just before the format line.
    let mut missing = Vec::new();
    if !wrote_name && let Some(name) = &m.sample_name {
        missing.push(sample_name_line(name));
    }
    if !wrote_theta {
        missing.push(number_line("intheta", &[theta]));
    }
    if !wrote_phi {
        missing.push(number_line("inphi", &[phi]));
    }
    if !wrote_up_phi && m.up_phi_deg != 0.0 {
        missing.push(number_line("upphi", &[m.up_phi_deg]));
    }
    if !wrote_beam && let Some(b) = beam_integral {
        missing.push(number_line(BEAM_INTEGRAL_KEY, &[b]));
    }
    if !wrote_colorimetry && m.channels != crate::Channels::Y {
        missing.push(colorimetry_line(m));
    }
    if !wrote_count {
        missing.push(count_line(m));
    }
    match format_at {
        Some(at) => {
            out.splice(at..at, missing);
        }
        None => {
            out.extend(missing);
            out.push(format_line(m));
        }
    }
    out
}

fn format_line(m: &Measurement) -> String {
    format!("#format: theta\tphi\t{}", format_word(&m.quantity))
}

fn colorimetry_line(m: &Measurement) -> String {
    format!("#colorimetry: {}", m.channels.colorimetry_name())
}

fn sample_name_line(name: &str) -> String {
    format!("#sample_name\t\"{name}\"")
}

fn count_line(m: &Measurement) -> String {
    format!("#datapoints_in_file\t{}", m.samples.len())
}

/// The whole file as text.
pub(crate) fn render(m: &Measurement) -> String {
    let channels = m.channels.count();
    let mut out = String::with_capacity(64 * 1024 + m.samples.len() * (12 + 12 * channels));
    for line in header_lines(m) {
        out.push_str(&line);
        out.push('\n');
    }
    for sample in &m.samples {
        push_number(&mut out, sample.theta_deg);
        out.push('\t');
        push_number(&mut out, sample.phi_deg);
        for &v in &sample.values[..channels] {
            out.push('\t');
            push_number(&mut out, v);
        }
        out.push('\n');
    }
    out
}
