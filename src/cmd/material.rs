//! Options shared by every command that evaluates a material file.

use anyhow::{Context, Result};
use brtf_model::{Bsdf, EvalOptions, FRESNEL_K_CLASSIC, FRESNEL_K_PYRADIANCE, Material, Variant};
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug, Clone)]
pub struct MaterialArgs {
    /// Radiance file holding the material primitive(s).
    #[arg(long, value_name = "M.rad")]
    pub material: PathBuf,
    /// Which material in the file (needed when it holds several).
    #[arg(long, value_name = "N")]
    pub name: Option<String>,
    /// Formula set: radiance (current rtrace), manual2004 or ward1992.
    #[arg(long, default_value = "radiance", value_parser = parse_variant)]
    pub variant: Variant,
    /// Fresnel constant K for roughness-0 surfaces: `classic` (e^-5.85),
    /// `pyradiance` (e^-6.2, the Radiance 6.0a binary on PyPI) or a number.
    #[arg(long, default_value = "classic", value_parser = parse_fresnel_k)]
    pub fresnel_k: f64,
    /// Solid angle of the light source in sr (widens the lobes as rtrace does).
    #[arg(long, default_value_t = 0.0, value_name = "SR")]
    pub source_omega: f64,
    /// The lit surface is not flat (a sphere, say): no flat-source widening.
    #[arg(long)]
    pub curved: bool,
}

/// The formula options of a material given by its arguments (`brtf fit`,
/// `brtf synth --material`).
#[derive(Args, Debug, Clone, Copy)]
pub struct FormulaArgs {
    /// Formula set: radiance (current rtrace), manual2004 or ward1992.
    #[arg(long, default_value = "radiance", value_parser = parse_variant)]
    pub variant: Variant,
    /// Fresnel constant for roughness-0 surfaces: classic, pyradiance or a number.
    #[arg(long, default_value = "classic", value_parser = parse_fresnel_k)]
    pub fresnel_k: f64,
}

/// Clap parser for `--variant`.
pub(crate) fn parse_variant(s: &str) -> Result<Variant, String> {
    s.parse()
}

/// Clap parser for `--fresnel-k`: `classic`, `pyradiance` or a number.
pub(crate) fn parse_fresnel_k(s: &str) -> Result<f64, String> {
    match s {
        "classic" => Ok(FRESNEL_K_CLASSIC),
        "pyradiance" => Ok(FRESNEL_K_PYRADIANCE),
        other => other
            .parse::<f64>()
            .map_err(|_| format!("expected classic, pyradiance or a number, found `{other}`")),
    }
}

impl MaterialArgs {
    /// Reads the file and picks the material.
    pub fn load(&self) -> Result<(String, Material)> {
        let path = self.material.display().to_string();
        let text = std::fs::read_to_string(&self.material)
            .with_context(|| format!("cannot read material file {path}"))?;
        let primitives = brtf_radiance::parse_primitives(&text, &path)?;
        Ok(brtf_radiance::select_material(
            &primitives,
            self.name.as_deref(),
            &path,
        )?)
    }

    pub fn options(&self) -> Result<EvalOptions> {
        let options = EvalOptions {
            variant: self.variant,
            fresnel_k: self.fresnel_k,
            source_omega: self.source_omega,
            flat: !self.curved,
            source_jitter: 0.0,
        };
        options.validate()?;
        Ok(options)
    }

    pub fn bsdf(&self) -> Result<Bsdf> {
        let (_, material) = self.load()?;
        Ok(Bsdf::new(&material, &self.options()?))
    }
}
