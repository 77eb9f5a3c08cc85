//! Range checks of a fit set's settings, before any file is read: each
//! failure names the `brtf fit` option, the value and the allowed range.

use crate::config::RobustLoss;
use crate::recipe::ScaleRule;
use crate::set::FitSetOptions;
use brtf_model::OptionError;

impl FitSetOptions {
    /// Checks every number the user gives (NaN fails every check).
    pub fn validate(&self) -> Result<(), OptionError> {
        let config = &self.config;
        config.options.validate()?;
        let [x, y, z] = config.orientation;
        let length = (x * x + y * y + z * z).sqrt();
        OptionError::check(
            "--orientation",
            length,
            length.is_finite() && length > 0.0,
            "three finite numbers x,y,z, not all zero (value: their length)",
        )?;
        if let Some(floor) = config.floor {
            OptionError::check("--floor", floor, floor > 0.0 && floor.is_finite(), "> 0")?;
        }
        if let RobustLoss::Huber(c) | RobustLoss::Cauchy(c) = config.loss {
            OptionError::check("--loss", c, c > 0.0 && c.is_finite(), "C > 0")?;
        }
        for gate in &self.recipe.selections {
            gate.validate()?;
        }
        if let ScaleRule::BeamIntegral { value } = self.recipe.scale {
            OptionError::check(
                "--beam-integral",
                value,
                value > 0.0 && value.is_finite(),
                "> 0",
            )?;
        }
        if let Some((rho, theta)) = self.known_reflectance {
            OptionError::check("--rho", rho, rho > 0.0 && rho <= 1.0, "0 < ρ ≤ 1")?;
            OptionError::check(
                "--rho @θ",
                theta,
                (0.0..90.0).contains(&theta),
                "0 ≤ θ < 90",
            )?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use crate::{
        ColourConversion, FitConfig, FitSetOptions, Gate, Interpolation, Recipe, RobustLoss,
        ScaleRule, WeightRule,
    };
    use brtf_model::MaterialKind;

    fn options() -> FitSetOptions {
        FitSetOptions {
            name: "x".into(),
            config: FitConfig::new(MaterialKind::Plastic),
            recipe: Recipe {
                scale: ScaleRule::FromFiles,
                colour: ColourConversion::AsRecorded,
                selections: vec![Gate::ThetaCap { max_deg: 85.0 }],
                weights: WeightRule::SolidAngle,
                patch_average: None,
                azimuth: crate::AzimuthRule::file_frame(),
            },
            known_reflectance: None,
            interpolation: Interpolation::Pchip,
            command_line: Vec::new(),
            adequacy: false,
            klems: Default::default(),
            auto: false,
        }
    }

    #[test]
    fn each_bad_number_is_named_with_its_range() {
        assert_eq!(options().validate(), Ok(()));
        let message = |change: fn(&mut FitSetOptions)| {
            let mut o = options();
            change(&mut o);
            o.validate().unwrap_err().to_string()
        };
        assert_eq!(
            message(|o| o.config.floor = Some(-1.0)),
            "--floor -1: out of range; allowed: > 0"
        );
        assert!(message(|o| o.config.loss = RobustLoss::Cauchy(0.0)).starts_with("--loss 0:"));
        assert!(
            message(|o| o.recipe.selections = vec![Gate::ThetaCap { max_deg: 200.0 }])
                .starts_with("--theta-cap 200:")
        );
        assert!(message(|o| o.config.options.source_omega = 100.0).starts_with("--source-omega"));
        assert!(message(|o| o.config.orientation = [0.0; 3]).starts_with("--orientation 0"));
        assert!(
            message(|o| o.recipe.scale = ScaleRule::BeamIntegral { value: f64::NAN })
                .starts_with("--beam-integral NaN")
        );
    }
}
