//! One-look summaries of a measurement, for `brtf info` and reports.
//!
//! This module owns [`Summary`] (serialisable, the `--json` form) and its
//! human-readable [`Display`](std::fmt::Display) form: incidence, quantity
//! and unit, per-hemisphere counts, angle ranges and coverage, negatives and
//! "not available" values, the data-side ρ_dh / τ_dh, and the front peak.

use std::fmt;

use serde::{Deserialize, Serialize};

use crate::integral::hemispherical_integral;
use crate::measurement::{
    BeamReference, Channels, Hemisphere, Incidence, IncidenceOrigin, Measurement, SourceFormat,
};
use crate::solid_angle::{SolidAngleSource, SolidAngles, solid_angles};

/// What one hemisphere of a measurement holds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct HemisphereSummary {
    /// Number of samples.
    pub count: usize,
    /// Smallest and largest θ_out, degrees.
    pub theta_range_deg: [f64; 2],
    /// Smallest and largest φ_out, degrees.
    pub phi_range_deg: [f64; 2],
    /// Samples with a negative value (noise floor).
    pub negatives: usize,
    /// Samples with a "not available" value (`9.9e+37` in the file) in
    /// any used channel.
    pub unavailable: usize,
    /// Σ ΔΩ of the samples, sr (2π ≈ 6.2832 when the hemisphere is covered).
    pub solid_angle_sr: f64,
    /// The largest single ΔΩ, sr: the biggest hole in the layout.
    pub largest_cell_sr: f64,
    /// Where that largest cell is, `[θ, φ]` in degrees.
    pub largest_cell_at_deg: [f64; 2],
    /// The data-side integral (ρ_dh in front, τ_dh in back), in
    /// [`Summary::integral_unit`].
    pub integral: f64,
}

/// The largest CIE-Y value of the front hemisphere.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Peak {
    /// θ_out, degrees.
    pub theta_deg: f64,
    /// φ_out, degrees.
    pub phi_deg: f64,
    /// The value, in the quantity's unit.
    pub value: f64,
}

/// A summary of one measurement.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// The source format.
    pub format: SourceFormat,
    /// `#sample_name`, if any.
    pub sample_name: Option<String>,
    /// Incident direction (towards the light), degrees.
    pub incidence: Incidence,
    /// Whether the incidence came from the header or the file name.
    pub incidence_origin: IncidenceOrigin,
    /// `BSDF`, `DSF` or `raw`.
    pub quantity: String,
    /// `1/sr`, or the raw unit (e.g. `uA`).
    pub unit: String,
    /// The quantity in words, including the beam integral if known.
    pub quantity_description: String,
    /// One (CIE-Y) or three (CIE-XYZ) values per sample.
    pub channels: Channels,
    /// The `.mpc` beam reference, if given.
    pub beam: Option<BeamReference>,
    /// All samples.
    pub samples: usize,
    /// Front hemisphere (θ ≤ 90°), if it has samples.
    pub front: Option<HemisphereSummary>,
    /// Back hemisphere (θ > 90°), if it has samples.
    pub back: Option<HemisphereSummary>,
    /// Samples with a negative value.
    pub negatives: usize,
    /// Samples with a "not available" value.
    pub unavailable: usize,
    /// Where the solid angles of the integrals came from.
    pub solid_angle_source: SolidAngleSource,
    /// ρ_dh of the data (front integral), in `integral_unit`.
    pub rho_dh: Option<f64>,
    /// τ_dh of the data (back integral), in `integral_unit`; only when back
    /// rows exist.
    pub tau_dh: Option<f64>,
    /// `1` for an absolute reflectance, or e.g. `uA·sr` for raw data.
    pub integral_unit: String,
    /// How to read the integrals.
    pub integral_note: String,
    /// The front hemisphere's largest CIE-Y value.
    pub peak: Option<Peak>,
}

impl Measurement {
    /// Summarises the measurement, computing solid angles when the file has
    /// none (≈ 50 ms for 127 000 samples).
    pub fn summary(&self) -> Summary {
        self.summary_with(&solid_angles(self))
    }

    /// Summarises with given solid angles (parallel to the samples).
    pub fn summary_with(&self, weights: &SolidAngles) -> Summary {
        let front = self.hemisphere_summary(Hemisphere::Front, &weights.per_sample_sr);
        let back = self.hemisphere_summary(Hemisphere::Back, &weights.per_sample_sr);
        let integral_unit = hemispherical_integral(self, &weights.per_sample_sr, Hemisphere::Front)
            .or_else(|| hemispherical_integral(self, &weights.per_sample_sr, Hemisphere::Back))
            .map_or_else(|| "1".to_owned(), |i| i.unit);
        let integral_note = if integral_unit == "1" {
            match &self.quantity {
                crate::Quantity::Raw { .. } => {
                    "sum of raw value x dOmega divided by the beam integral".to_owned()
                }
                crate::Quantity::Dsf => "sum of DSF x dOmega".to_owned(),
                crate::Quantity::Bsdf => "sum of BSDF x |cos theta_out| x dOmega".to_owned(),
            }
        } else {
            format!(
                "raw signal: sum of value x dOmega in {integral_unit}, proportional to the \
                 reflectance; divide by the beam integral (unknown) to get rho_dh"
            )
        };
        Summary {
            format: self.format,
            sample_name: self.sample_name.clone(),
            incidence: self.incidence,
            incidence_origin: self.incidence_origin,
            quantity: self.quantity.name().to_owned(),
            unit: self.quantity.unit().to_owned(),
            quantity_description: self.quantity.to_string(),
            channels: self.channels,
            beam: self.beam.clone(),
            samples: self.samples.len(),
            rho_dh: front.as_ref().map(|h| h.integral),
            tau_dh: back.as_ref().map(|h| h.integral),
            front,
            back,
            negatives: self.count_negative(),
            unavailable: self.count_unavailable(),
            solid_angle_source: weights.source,
            integral_unit,
            integral_note,
            peak: self.front_peak(),
        }
    }

    fn hemisphere_summary(
        &self,
        hemisphere: Hemisphere,
        weights: &[f64],
    ) -> Option<HemisphereSummary> {
        let integral = hemispherical_integral(self, weights, hemisphere)?;
        let n = self.channels.count();
        let mut theta = [f64::INFINITY, f64::NEG_INFINITY];
        let mut phi = [f64::INFINITY, f64::NEG_INFINITY];
        let mut negatives = 0;
        let mut unavailable = 0;
        let mut largest = (f64::NEG_INFINITY, [f64::NAN; 2]);
        for (s, &w) in self.samples.iter().zip(weights) {
            if s.hemisphere() != hemisphere {
                continue;
            }
            theta = [theta[0].min(s.theta_deg), theta[1].max(s.theta_deg)];
            phi = [phi[0].min(s.phi_deg), phi[1].max(s.phi_deg)];
            if s.values[..n].iter().any(|&v| v < 0.0) {
                negatives += 1;
            }
            if !s.is_available(self.channels) {
                unavailable += 1;
            }
            if w > largest.0 {
                largest = (w, [s.theta_deg, s.phi_deg]);
            }
        }
        Some(HemisphereSummary {
            count: integral.samples_used + integral.samples_skipped,
            theta_range_deg: theta,
            phi_range_deg: phi,
            negatives,
            unavailable,
            solid_angle_sr: integral.solid_angle_sr,
            largest_cell_sr: largest.0,
            largest_cell_at_deg: largest.1,
            integral: integral.value,
        })
    }

    /// The front sample with the largest finite CIE-Y value.
    pub fn front_peak(&self) -> Option<Peak> {
        self.samples
            .iter()
            .filter(|s| s.hemisphere() == Hemisphere::Front)
            .map(|s| (s, self.luminance_of(s)))
            .filter(|(_, v)| v.is_finite())
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(s, value)| Peak {
                theta_deg: s.theta_deg,
                phi_deg: s.phi_deg,
                value,
            })
    }
}

/// Six significant digits, in plain or exponent notation.
fn significant(v: f64) -> String {
    if v == 0.0 || (1e-3..1e6).contains(&v.abs()) {
        format!("{v:.6}")
    } else {
        format!("{v:.5e}")
    }
}

impl fmt::Display for Summary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let origin = match self.incidence_origin {
            IncidenceOrigin::Header => "from the header",
            IncidenceOrigin::FileName => "from the file name",
            IncidenceOrigin::Programmatic => "set by code",
        };
        writeln!(f, "  format        {}", self.format.describe())?;
        if let Some(name) = &self.sample_name {
            writeln!(f, "  sample        {name}")?;
        }
        writeln!(
            f,
            "  incidence     theta_in = {} deg, phi_in = {} deg ({origin})",
            self.incidence.theta_deg, self.incidence.phi_deg
        )?;
        writeln!(
            f,
            "  quantity      {} ({})",
            self.quantity_description,
            self.channels.colorimetry_name()
        )?;
        if let Some(beam) = &self.beam {
            writeln!(
                f,
                "  beam file     {} (integral {})",
                beam.file, beam.integral
            )?;
        }
        writeln!(
            f,
            "  samples       {} (front {}, back {}); {} negative, {} not available",
            self.samples,
            self.front.as_ref().map_or(0, |h| h.count),
            self.back.as_ref().map_or(0, |h| h.count),
            self.negatives,
            self.unavailable
        )?;
        let source = match self.solid_angle_source {
            SolidAngleSource::File => "file Voronoi cells",
            SolidAngleSource::Computed => "computed equal-area Voronoi cells",
        };
        for (label, h) in [("front", &self.front), ("back", &self.back)] {
            let Some(h) = h else { continue };
            writeln!(
                f,
                "  {label:<13} theta {:.2}..{:.2} deg, phi {:.2}..{:.2} deg",
                h.theta_range_deg[0], h.theta_range_deg[1], h.phi_range_deg[0], h.phi_range_deg[1]
            )?;
            writeln!(
                f,
                "  {:<13} cells sum {:.4} sr (hemisphere 2pi = 6.2832 sr; {source}); largest \
                 cell {:.3e} sr at theta {:.2}, phi {:.2}",
                "",
                h.solid_angle_sr,
                h.largest_cell_sr,
                h.largest_cell_at_deg[0],
                h.largest_cell_at_deg[1]
            )?;
        }
        let unit = if self.integral_unit == "1" {
            String::new()
        } else {
            format!(" {}", self.integral_unit)
        };
        if let Some(rho) = self.rho_dh {
            writeln!(f, "  rho_dh        {}{unit}", significant(rho))?;
        }
        if let Some(tau) = self.tau_dh {
            writeln!(f, "  tau_dh        {}{unit}", significant(tau))?;
        }
        writeln!(f, "  integral      {}", self.integral_note)?;
        if let Some(p) = &self.peak {
            writeln!(
                f,
                "  front peak    theta {:.2} deg, phi {:.2} deg, value {} {}",
                p.theta_deg, p.phi_deg, p.value, self.unit
            )?;
        }
        Ok(())
    }
}
