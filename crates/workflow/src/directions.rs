//! Directions read as text: `theta_out,phi_out` lines (`brtf eval`).

use crate::WorkflowError;

/// The largest |φ_out| read, degrees: one turn either way.
const MAX_ABS_PHI: f64 = 360.0;

/// Reads line `number` (1-based) of `theta_out,phi_out` CSV, in degrees:
/// `None` for a blank or `#` line and for a header on the first line.
/// θ_out must lie in [0, 180] (beyond 90° is the back side) and φ_out in
/// [−360, 360]; the error names the line.
pub fn parse_direction_line(
    line: &str,
    number: usize,
) -> Result<Option<(f64, f64)>, WorkflowError> {
    let trimmed = line.trim();
    if trimmed.is_empty() || trimmed.starts_with('#') {
        return Ok(None);
    }
    let bad = |why: String| WorkflowError::Usage(format!("<stdin>:{number}: {why}"));
    let fields: Vec<&str> = trimmed.split(',').map(str::trim).collect();
    if fields.len() != 2 {
        return Err(bad(format!(
            "expected `theta_out,phi_out`, found {} fields",
            fields.len()
        )));
    }
    let parsed: Vec<Option<f64>> = fields.iter().map(|f| f.parse::<f64>().ok()).collect();
    let (theta, phi) = match (parsed[0], parsed[1]) {
        (Some(t), Some(p)) if t.is_finite() && p.is_finite() => (t, p),
        // A header line such as `theta_out,phi_out`.
        _ if number == 1 && parsed.iter().all(Option::is_none) => return Ok(None),
        _ => {
            return Err(bad(format!(
                "`{}` is not two numbers (theta_out,phi_out in degrees)",
                short(trimmed)
            )));
        }
    };
    if !(0.0..=180.0).contains(&theta) {
        return Err(bad(format!(
            "theta_out {} is out of range; allowed: 0 to 180 degrees (beyond 90: the back side)",
            short(fields[0])
        )));
    }
    if phi.abs() > MAX_ABS_PHI {
        return Err(bad(format!(
            "phi_out {} is out of range; allowed: -360 to 360 degrees",
            short(fields[1])
        )));
    }
    Ok(Some((theta, phi)))
}

/// `text`, cut to 40 characters for a message.
fn short(text: &str) -> String {
    match text.char_indices().nth(40) {
        Some((end, _)) => format!("{}…", &text[..end]),
        None => text.to_string(),
    }
}

/// `N` comma-separated numbers (`x,y,z`, `front,back`): a command-line
/// value.
pub fn parse_numbers<const N: usize>(text: &str) -> Result<[f64; N], String> {
    let numbers: Result<Vec<f64>, _> = text.split(',').map(|x| x.trim().parse::<f64>()).collect();
    numbers
        .ok()
        .and_then(|v| v.try_into().ok())
        .ok_or_else(|| format!("{text}: give {N} comma-separated numbers"))
}

/// The θ_in at which a tensor tree is fitted (`--theta-in-grid`):
/// comma-separated degrees, each in [0, 90).
#[derive(Debug, Clone, PartialEq)]
pub struct ThetaGrid(pub Vec<f64>);

impl std::str::FromStr for ThetaGrid {
    type Err = String;

    fn from_str(text: &str) -> Result<ThetaGrid, String> {
        let mut thetas = Vec::new();
        for part in text.split(',').map(str::trim) {
            match part.parse::<f64>() {
                Ok(t) if (0.0..90.0).contains(&t) => thetas.push(t),
                _ => {
                    return Err(format!(
                        "`{}`: give comma-separated angles from 0 to below 90 degrees",
                        short(part)
                    ));
                }
            }
        }
        Ok(ThetaGrid(thetas))
    }
}
