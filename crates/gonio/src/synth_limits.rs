//! Range checks of the synthetic instrument and layout, named by their
//! `brtf synth` options, before anything is computed: a step of 1e-6°
//! would otherwise ask for more memory than there is.

use crate::synth::{Instrument, Layout};
use brtf_model::OptionError as E;

/// The most samples one synthetic file may hold.
pub const MAX_SYNTH_SAMPLES: f64 = 2e6;

impl Instrument {
    /// Noise in [0, 1) relative and ≥ 0 absolute; apertures and the blind
    /// spot in [0, 90) degrees.
    pub fn validate(&self) -> Result<(), E> {
        let ok = (0.0..1.0).contains(&self.noise_relative);
        E::check("--noise", self.noise_relative, ok, "0 ≤ relative noise < 1")?;
        let ok = self.noise_floor >= 0.0 && self.noise_floor.is_finite();
        E::check("--noise-floor", self.noise_floor, ok, "≥ 0")?;
        for (option, angle) in [
            ("--source-aperture", self.source_aperture_deg),
            ("--detector-aperture", self.detector_aperture_deg),
            ("--blind-spot", self.blind_spot_deg),
        ] {
            E::check(
                option,
                angle,
                (0.0..90.0).contains(&angle),
                "0 ≤ angle < 90 degrees",
            )?;
        }
        Ok(())
    }
}

impl Layout {
    /// Steps in (0, 30] degrees that give at most [`MAX_SYNTH_SAMPLES`].
    pub fn validate(&self) -> Result<(), E> {
        let (coarse, fine) = (self.coarse_step_deg, self.fine_step_deg);
        for (option, step) in [("--coarse-step", coarse), ("--fine-step", fine)] {
            E::check(
                option,
                step,
                step > 0.0 && step <= 30.0,
                "0 < step ≤ 30 degrees",
            )?;
        }
        // Samples ≈ hemisphere / coarse cell + (20° patch) / fine cell, both sides.
        let (c, f) = (coarse.to_radians(), fine.to_radians());
        let samples = 2.0 * (std::f64::consts::TAU / (c * c) + 0.383 / (f * f));
        E::check(
            "--coarse-step/--fine-step",
            coarse.min(fine),
            samples <= MAX_SYNTH_SAMPLES,
            "steps giving at most 2,000,000 samples per file (about 0.1° coarse, 0.025° fine)",
        )
    }
}

#[cfg(test)]
mod tests {
    use crate::synth::{Instrument, Layout};

    #[test]
    fn defaults_pass_and_tiny_steps_are_refused_before_any_allocation() {
        assert_eq!(Instrument::default().validate(), Ok(()));
        assert_eq!(Layout::default().validate(), Ok(()));
        let tiny = Layout {
            fine_step_deg: 1e-6,
            ..Layout::default()
        };
        assert!(
            tiny.validate()
                .unwrap_err()
                .to_string()
                .contains("2,000,000 samples")
        );
        let noisy = Instrument {
            noise_relative: -1.0,
            ..Instrument::default()
        };
        assert!(
            noisy
                .validate()
                .unwrap_err()
                .to_string()
                .starts_with("--noise -1")
        );
    }
}
