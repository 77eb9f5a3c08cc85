//! Explicit conversions between the quantities a measurement can hold.
//!
//! This module owns the three formulas that relate the quantities:
//!
//! - DSF = BSDF × |cos θ_out|
//! - BSDF = DSF ÷ |cos θ_out|
//! - DSF = raw ÷ beam integral, so BSDF = raw ÷ beam integral ÷ |cos θ_out|
//!
//! The raw rule assumes the raw detector signal is already background
//! subtracted and normalised exactly as the beam integral was measured (same
//! detector, aperture and lamp current), so that the ratio is the fraction
//! of the incident flux scattered per steradian. This is how the ISE `.mpc`
//! columns relate (column 6 ÷ beam integral = column 7), and how
//! `pabopto2bsdf` treats pgII data.
//!
//! Dividing by |cos θ_out| is undefined at θ_out = 90°: samples with
//! |cos θ_out| < [`GRAZING_COS_LIMIT`] become "not available" (NaN), and
//! the count is returned. Every conversion returns a new measurement and
//! never guesses a missing beam integral.

use crate::error::ConvertError;
use crate::measurement::{Measurement, Quantity, Sample};
use rayon::prelude::*;

/// Samples per piece of the parallel conversion.
const SAMPLE_PIECE: usize = 8192;

/// Below this |cos θ_out| (θ_out within ~2e-7° of 90°) a division by the
/// cosine is undefined and the value becomes NaN.
pub const GRAZING_COS_LIMIT: f64 = 1e-9;

/// The result of a conversion.
#[derive(Clone, Debug, PartialEq)]
pub struct Converted {
    /// The converted measurement.
    pub measurement: Measurement,
    /// Samples whose value became "not available" (NaN) because the
    /// conversion divided by |cos θ_out| at θ_out = 90°.
    pub made_unavailable: usize,
}

impl Measurement {
    /// The DSF (BSDF × |cos θ_out|). A raw measurement needs its beam
    /// integral (in [`Quantity::Raw`]); use [`Measurement::raw_to_dsf`] to
    /// supply one.
    pub fn to_dsf(&self) -> Result<Converted, ConvertError> {
        match &self.quantity {
            Quantity::Dsf => Ok(self.unchanged()),
            Quantity::Bsdf => Ok(self.scaled(Quantity::Dsf, |cos| cos)),
            Quantity::Raw {
                unit,
                beam_integral,
            } => {
                let beam = beam_integral
                    .ok_or_else(|| ConvertError::MissingBeamIntegral { unit: unit.clone() })?;
                self.raw_to_dsf(beam)
            }
        }
    }

    /// The BSDF (DSF ÷ |cos θ_out|). A raw measurement needs its beam
    /// integral; use [`Measurement::raw_to_bsdf`] to supply one.
    pub fn to_bsdf(&self) -> Result<Converted, ConvertError> {
        match &self.quantity {
            Quantity::Bsdf => Ok(self.unchanged()),
            Quantity::Dsf => Ok(self.scaled(Quantity::Bsdf, |cos| 1.0 / cos)),
            Quantity::Raw {
                unit,
                beam_integral,
            } => {
                let beam = beam_integral
                    .ok_or_else(|| ConvertError::MissingBeamIntegral { unit: unit.clone() })?;
                self.raw_to_bsdf(beam)
            }
        }
    }

    /// Raw signal → DSF: `raw / beam_integral`. See the module docs for the
    /// assumption.
    pub fn raw_to_dsf(&self, beam_integral: f64) -> Result<Converted, ConvertError> {
        self.check_raw(beam_integral)?;
        Ok(self.scaled(Quantity::Dsf, |_| 1.0 / beam_integral))
    }

    /// Raw signal → BSDF: `raw / beam_integral / |cos θ_out|`. See the
    /// module docs for the assumption.
    pub fn raw_to_bsdf(&self, beam_integral: f64) -> Result<Converted, ConvertError> {
        self.check_raw(beam_integral)?;
        Ok(self.scaled(Quantity::Bsdf, |cos| 1.0 / (beam_integral * cos)))
    }

    fn check_raw(&self, beam_integral: f64) -> Result<(), ConvertError> {
        if !matches!(self.quantity, Quantity::Raw { .. }) {
            return Err(ConvertError::WrongQuantity {
                from: self.quantity.to_string(),
                reason: "only raw detector signal is divided by a beam integral",
            });
        }
        if !(beam_integral.is_finite() && beam_integral > 0.0) {
            return Err(ConvertError::InvalidBeamIntegral(beam_integral));
        }
        Ok(())
    }

    fn unchanged(&self) -> Converted {
        Converted {
            measurement: self.clone(),
            made_unavailable: 0,
        }
    }

    /// Multiplies every used value by `factor(|cos θ_out|)`. When the
    /// factor is not finite (a division at θ_out = 90°) the value becomes NaN.
    /// The samples are converted in parallel pieces, straight into the new
    /// measurement (no copy first).
    fn scaled(&self, quantity: Quantity, factor: impl Fn(f64) -> f64 + Sync) -> Converted {
        let channels = self.channels.count();
        let (samples, unavailable): (Vec<Sample>, Vec<bool>) = self
            .samples
            .par_iter()
            .with_min_len(SAMPLE_PIECE)
            .map(|sample| {
                let mut sample = *sample;
                let cos = sample.abs_cos_theta();
                let f = if cos < GRAZING_COS_LIMIT {
                    factor(0.0)
                } else {
                    factor(cos)
                };
                if f.is_finite() {
                    for v in &mut sample.values[..channels] {
                        *v *= f;
                    }
                    (sample, false)
                } else {
                    let was_available = sample.is_available(self.channels);
                    sample.values[..channels].fill(f64::NAN);
                    (sample, was_available)
                }
            })
            .unzip();
        let mut measurement = self.clone_without_samples();
        measurement.quantity = quantity;
        measurement.samples = samples;
        measurement.mpc_columns = self.mpc_columns.clone();
        Converted {
            measurement,
            made_unavailable: unavailable.iter().filter(|&&u| u).count(),
        }
    }
}
