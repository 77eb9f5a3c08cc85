//! Options shared by every command that evaluates a material file.

use super::shared::words;
use anyhow::Result;
use brtf_model::{Composite, CompositeBsdf, EvalOptions, Variant, parse_fresnel_k};
use brtf_workflow::read_material_file;
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug, Clone)]
pub(crate) struct MaterialArgs {
    /// Radiance file holding the material: a Ward-type primitive, or a
    /// constant mixfunc tree of them (a lobe sum).
    #[arg(long, value_name = "M.rad")]
    pub material: PathBuf,
    /// Which material in the file (needed when it holds several; a lobe
    /// sum's name is its top mixfunc's).
    #[arg(long, value_name = "N")]
    pub name: Option<String>,
    #[command(flatten)]
    pub formula: FormulaArgs,
    /// Solid angle of the light source in sr (widens the lobes as rtrace does).
    #[arg(long, default_value_t = 0.0, value_name = "SR")]
    pub source_omega: f64,
    /// The lit surface is not flat (a sphere, say): no flat-source widening.
    #[arg(long)]
    pub curved: bool,
}

/// The formula options of a material: `--variant` and `--fresnel-k`.
#[derive(Args, Debug, Clone, Copy)]
pub(crate) struct FormulaArgs {
    /// Formula set: radiance (current rtrace), manual2004 or ward1992.
    #[arg(long, value_parser = words::<Variant>(), default_value_t = Variant::Radiance)]
    pub variant: Variant,
    /// Fresnel constant K for roughness-0 surfaces: `classic` (e^-5.85),
    /// `pyradiance` (e^-6.2, the Radiance 6.0a binary on PyPI) or a number.
    #[arg(long, default_value = "classic", value_parser = parse_fresnel_k)]
    pub fresnel_k: f64,
}

impl FormulaArgs {
    /// Default evaluation options with this formula set.
    pub(crate) fn options(&self) -> EvalOptions {
        EvalOptions {
            variant: self.variant,
            fresnel_k: self.fresnel_k,
            ..EvalOptions::default()
        }
    }
}

impl MaterialArgs {
    /// Reads the file and picks the material (one primitive or a lobe sum).
    pub(crate) fn load(&self) -> Result<(String, Composite)> {
        Ok(read_material_file(&self.material, self.name.as_deref())?)
    }

    pub(crate) fn options(&self) -> Result<EvalOptions> {
        let options = EvalOptions {
            source_omega: self.source_omega,
            flat: !self.curved,
            ..self.formula.options()
        };
        options.validate()?;
        Ok(options)
    }

    /// The material prepared for evaluation: `Σ w_k f_k` over its lobes.
    pub(crate) fn bsdf(&self) -> Result<CompositeBsdf> {
        let (_, material) = self.load()?;
        Ok(CompositeBsdf::new(&material, &self.options()?))
    }
}
