//! The instrument's apertures as a file's header states them.
//!
//! `.mpc` files carry `#input aperture used: X` and `#detector aperture
//! used: X`, where `X` is `def` (the instrument's default, size not given)
//! or a full cone angle in degrees. brtf synth writes the same two lines
//! (in either format) with the apertures it averaged over.

use crate::Measurement;

/// The beam and detector apertures a header gives, full cone angles in
/// degrees; `None` where it gives none (or only `def`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Apertures {
    /// The beam (source, "input") aperture.
    pub source_deg: Option<f64>,
    /// The detector aperture.
    pub detector_deg: Option<f64>,
}

/// The header key of the beam aperture, as `.mpc` files write it.
pub const SOURCE_APERTURE_KEY: &str = "input aperture used:";
/// The header key of the detector aperture.
pub const DETECTOR_APERTURE_KEY: &str = "detector aperture used:";

impl Apertures {
    /// The two header lines that state these apertures (for the ones known).
    pub fn header_lines(&self) -> Vec<String> {
        [
            (SOURCE_APERTURE_KEY, self.source_deg),
            (DETECTOR_APERTURE_KEY, self.detector_deg),
        ]
        .into_iter()
        .filter_map(|(key, deg)| deg.map(|d| format!("#{key} {d} [deg]")))
        .collect()
    }
}

/// An aperture angle: the first word as degrees, when it is a number in
/// [0, 180).
fn angle(value: &str) -> Option<f64> {
    let word = value.split_whitespace().next()?;
    let deg: f64 = word.trim_end_matches('°').parse().ok()?;
    (deg.is_finite() && (0.0..180.0).contains(&deg)).then_some(deg)
}

impl Measurement {
    /// The apertures the header states (`#input aperture used: 0.5 [deg]`,
    /// `#detector aperture used: 0.75 [deg]`).
    pub fn apertures(&self) -> Apertures {
        let mut found = Apertures::default();
        for line in &self.header {
            let Some(body) = line.trim().strip_prefix('#') else {
                continue;
            };
            let body = body.trim();
            let lower = body.to_ascii_lowercase();
            for (key, slot) in [
                (SOURCE_APERTURE_KEY, &mut found.source_deg),
                (DETECTOR_APERTURE_KEY, &mut found.detector_deg),
            ] {
                if lower.starts_with(key) {
                    *slot = angle(&body[key.len()..]).or(*slot);
                }
            }
        }
        found
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Channels, Incidence, Quantity, SourceFormat};

    fn with_header(lines: &[&str]) -> Measurement {
        let mut m = Measurement::new(
            SourceFormat::Mpc,
            Incidence::new(30.0, 0.0),
            Quantity::Bsdf,
            Channels::Y,
            Vec::new(),
        );
        m.header = lines.iter().map(|l| l.to_string()).collect();
        m
    }

    #[test]
    fn reads_numbers_and_ignores_def() {
        let m = with_header(&["#input aperture used: def", "#detector aperture used: def"]);
        assert_eq!(m.apertures(), Apertures::default());
        let m = with_header(&[
            "#Input aperture used: 0.5 [deg]",
            "#detector aperture used: 0.75°",
        ]);
        let a = m.apertures();
        assert_eq!((a.source_deg, a.detector_deg), (Some(0.5), Some(0.75)));
        // What header_lines writes reads back.
        assert_eq!(with_header(&[]).apertures(), Apertures::default());
        let lines = a.header_lines();
        let refs: Vec<&str> = lines.iter().map(String::as_str).collect();
        assert_eq!(with_header(&refs).apertures(), a);
        let bad = with_header(&["#detector aperture used: -3", "#input aperture used: nan"]);
        assert_eq!(bad.apertures(), Apertures::default());
    }
}
