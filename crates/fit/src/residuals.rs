//! `residuals.csv`: every sample of every incidence with the model beside
//! it, and the gate that removed it. Users analyse fits in their own tools,
//! and the masks become checkable.
//!
//! Columns: `theta_in, phi_in, theta_out, phi_out` (degrees; φ_out in the
//! frame the fit used, after any azimuth turn), `data` and `model` (one
//! column each for grey data, `data_r … model_b` for colour), in the
//! fitted quantity (the BSDF, or a raw signal ÷ |cos θ_out| with the model
//! times its scale), values to 7 significant digits and angles to 4
//! decimals, `weight` (the sample's weight in the fit: its solid
//! angle in sr, or 1 for uniform weights) and `gate` (the gate that
//! removed it, by its `fit.json` name; empty when it was fitted). The
//! model is the fit's own value: at the sample's direction, or averaged
//! over the sample's patch pairs for Klems data.

use crate::recipe::PreparedMeasurement;
use crate::result::FitResult;
use brtf_model::CompositeBsdf;
use rayon::prelude::*;

/// Samples per parallel piece of the text.
const PIECE: usize = 4096;

/// The header line of `residuals.csv` for data with `channels` channels.
pub fn residuals_header(channels: usize) -> &'static str {
    if channels >= 3 {
        "theta_in,phi_in,theta_out,phi_out,data_r,data_g,data_b,model_r,model_g,model_b,weight,gate\n"
    } else {
        "theta_in,phi_in,theta_out,phi_out,data,model,weight,gate\n"
    }
}

/// The rows of incidence `index` of `result`, whose data `prepared` holds
/// (as [`crate::prepare_input`] rebuilds them), every sample in file
/// order, in pieces of text to be written one after the other; none when
/// the report has no material.
pub fn residual_rows(
    result: &FitResult,
    index: usize,
    prepared: &PreparedMeasurement,
) -> Vec<Vec<u8>> {
    let report = &result.incidences[index];
    let Some(material) = result.composite_of(report) else {
        return Vec::new();
    };
    let bsdf = CompositeBsdf::new(&material, &result.options());
    let channels = prepared.channels();
    let uniform = result.recipe.weights == crate::WeightRule::Uniform;
    let light = prepared.measurement.incident_direction();
    let gates: Vec<&'static str> = result.recipe.selections.iter().map(|g| g.name()).collect();
    let mut incidence = Vec::new();
    push_angle(&mut incidence, report.theta_in);
    incidence.push(b',');
    push_angle(&mut incidence, report.phi_in);
    let samples = &prepared.measurement.samples;
    (0..samples.len().div_ceil(PIECE))
        .into_par_iter()
        .map(|piece| {
            let mut out = Vec::with_capacity(PIECE * 96);
            let first = piece * PIECE;
            let end = (first + PIECE).min(samples.len());
            for (i, s) in (first..end).zip(&samples[first..end]) {
                let f = match (&prepared.patch_pairs, bsdf.parts()) {
                    (Some(pairs), [(_, single)]) => pairs.average(single, i),
                    _ => bsdf.eval(light, prepared.directions[i]),
                };
                out.extend_from_slice(&incidence);
                for angle in [s.theta_deg, s.phi_deg] {
                    out.push(b',');
                    push_angle(&mut out, angle);
                }
                for &v in &s.values[..channels] {
                    out.push(b',');
                    push_value(&mut out, v);
                }
                for m in &f[..channels] {
                    out.push(b',');
                    push_value(&mut out, report.scale * m);
                }
                let weight = if uniform {
                    1.0
                } else {
                    s.solid_angle_sr.unwrap_or(1.0)
                };
                out.push(b',');
                push_value(&mut out, weight);
                out.push(b',');
                out.extend_from_slice(prepared.removed_by[i].map_or("", |g| gates[g]).as_bytes());
                out.push(b'\n');
            }
            out
        })
        .collect()
}

/// Appends an angle in degrees with at most 4 decimals (trailing zeros
/// dropped): 0.0001° is below any gonio-photometer's step.
fn push_angle(out: &mut Vec<u8>, degrees: f64) {
    if !degrees.is_finite() {
        return;
    }
    let scaled = (degrees.abs() * 1e4).round() as u64;
    if degrees < 0.0 && scaled != 0 {
        out.push(b'-');
    }
    push_integer(out, scaled / 10_000);
    push_fraction(out, scaled % 10_000, 4);
}

/// Appends a value with 7 significant digits, as `d.dddddde±x` (trailing
/// zeros dropped; `0` for zero), nothing when it is not finite: the data's
/// own precision at best, at a fraction of the shortest form's length and
/// time.
fn push_value(out: &mut Vec<u8>, x: f64) {
    if !x.is_finite() {
        return;
    }
    if x == 0.0 {
        out.push(b'0');
        return;
    }
    if x < 0.0 {
        out.push(b'-');
    }
    let a = x.abs();
    // Near the ends of f64 the scaling below under- or overflows (10^(e−6)
    // of a subnormal is 0): the standard formatter does those few.
    if !(1e-290..=1e290).contains(&a) {
        let text = format!("{a:.6e}");
        let (mantissa, exponent) = text.split_once('e').unwrap_or((&text, "0"));
        let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
        out.extend_from_slice(mantissa.as_bytes());
        if exponent != "0" {
            out.push(b'e');
            out.extend_from_slice(exponent.as_bytes());
        }
        return;
    }
    let mut exponent = a.log10().floor() as i32;
    let mut mantissa = (a / 10f64.powi(exponent - 6)).round() as u64;
    if mantissa >= 10_000_000 {
        mantissa = (mantissa + 5) / 10;
        exponent += 1;
    } else if mantissa < 1_000_000 {
        mantissa = (a / 10f64.powi(exponent - 7)).round() as u64;
        exponent -= 1;
    }
    out.push(b'0' + (mantissa / 1_000_000) as u8);
    push_fraction(out, mantissa % 1_000_000, 6);
    if exponent != 0 {
        out.push(b'e');
        if exponent < 0 {
            out.push(b'-');
        }
        push_integer(out, exponent.unsigned_abs() as u64);
    }
}

/// Appends `.` and the `digits`-digit decimal fraction `fraction` (zero
/// padded, trailing zeros dropped); nothing when it is 0.
fn push_fraction(out: &mut Vec<u8>, fraction: u64, digits: usize) {
    if fraction == 0 {
        return;
    }
    let (mut fraction, mut digits) = (fraction, digits);
    while fraction.is_multiple_of(10) {
        fraction /= 10;
        digits -= 1;
    }
    out.push(b'.');
    let start = out.len();
    push_integer(out, fraction);
    let written = out.len() - start;
    out.splice(start..start, std::iter::repeat_n(b'0', digits - written));
}

/// Appends the decimal digits of `n`.
fn push_integer(out: &mut Vec<u8>, n: u64) {
    let mut digits = [0u8; 20];
    let mut at = digits.len();
    let mut n = n;
    loop {
        at -= 1;
        digits[at] = b'0' + (n % 10) as u8;
        n /= 10;
        if n == 0 {
            break;
        }
    }
    out.extend_from_slice(&digits[at..]);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn value(x: f64) -> String {
        let mut out = Vec::new();
        push_value(&mut out, x);
        String::from_utf8(out).unwrap()
    }

    fn angle(x: f64) -> String {
        let mut out = Vec::new();
        push_angle(&mut out, x);
        String::from_utf8(out).unwrap()
    }

    #[test]
    fn values_keep_seven_significant_digits() {
        assert_eq!(value(0.0), "0");
        assert_eq!(value(1.0), "1");
        assert_eq!(value(-2.5e-3), "-2.5e-3");
        assert_eq!(value(3.6562871234), "3.656287");
        assert_eq!(value(9.9999999), "1e1");
        assert_eq!(value(123456789.0), "1.234568e8");
        assert_eq!(value(f64::NAN), "");
        // The ends of f64: subnormals and the largest values.
        assert_eq!(value(4.9e-324), "4.940656e-324");
        assert_eq!(value(-f64::MIN_POSITIVE), "-2.225074e-308");
        assert_eq!(value(1e300), "1e300");
        assert_eq!(value(f64::MAX), "1.797693e308");
        assert_eq!(value(2.5e-295), "2.5e-295");
        for x in [
            1e-300,
            3.7e-5,
            0.02710,
            7.0625,
            4.2e7,
            1.0000005,
            9.999995e-3,
        ] {
            let back: f64 = value(x).parse().unwrap();
            assert!((back / x - 1.0).abs() <= 5e-7, "{x}: {}", value(x));
        }
    }

    #[test]
    fn angles_keep_four_decimals() {
        assert_eq!(angle(0.0), "0");
        assert_eq!(angle(26.8421), "26.8421");
        assert_eq!(angle(176.56123456), "176.5612");
        assert_eq!(angle(2.5), "2.5");
        assert_eq!(angle(0.05), "0.05");
        assert_eq!(angle(359.99999), "360");
        assert_eq!(angle(-3.0001), "-3.0001");
    }
}
