//! `brtf render gonio|image`: brtf's own ray tracer (brtf-trace).
//!
//! * `gonio` ([`gonio`]): the virtual gonio-photometer. It reproduces a
//!   measurement's geometry (`--like FILE`) or a θ/φ grid, renders the
//!   BSDF per sample and writes it as a measurement file (`.mpc` or
//!   Mountain) or CSV.
//! * `image` ([`image`]): the material on a sphere and a plane under a
//!   source, as a Radiance HDR picture and a tone-mapped PNG; `--radiance`
//!   also writes the same scene and view for `rpict`.
//!
//! The material comes from a Radiance file (`--material`) or a fit folder
//! (`--fit DIR`: its θ_in-interpolated table, or `--static` for one set).
//! The scenes, grids and checks live in brtf-trace; this module maps the
//! options onto them, reports progress and writes the files.

pub(crate) mod gonio;
pub(crate) mod image;

use super::material::{FormulaArgs, MaterialArgs};
use super::shared::words;
use anyhow::{Context, Result};
use brtf_fit::FitResult;
use brtf_model::{FRESNEL_K_CLASSIC, Material, Variant, parse_fresnel_k};
use brtf_trace::Shader;
use clap::{Args, Subcommand};
use gonio::GonioArgs;
use image::ImageArgs;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub(crate) struct RenderArgs {
    #[command(subcommand)]
    pub what: RenderWhat,
}

#[derive(Subcommand, Debug)]
pub(crate) enum RenderWhat {
    /// Virtual gonio-photometer: the rendered BSDF at a measurement's directions.
    Gonio(GonioArgs),
    /// A picture of the material on a sphere and a plane (HDR + PNG).
    Image(ImageArgs),
}

pub(crate) fn run(args: RenderArgs) -> Result<()> {
    match args.what {
        RenderWhat::Gonio(a) => gonio::run(a),
        RenderWhat::Image(a) => image::run(a),
    }
}

/// Where the material comes from.
#[derive(Args, Debug, Clone)]
pub(crate) struct SampleMaterial {
    /// Radiance file holding the material primitive(s).
    #[arg(
        long,
        value_name = "M.rad",
        required_unless_present = "fit",
        conflicts_with = "fit"
    )]
    pub material: Option<PathBuf>,
    /// Which material in the file (needed when it holds several).
    #[arg(long, value_name = "N")]
    pub name: Option<String>,
    /// A fit folder (fit.json): render its θ_in-interpolated material.
    #[arg(long, value_name = "DIR")]
    pub fit: Option<PathBuf>,
    /// With --fit: the one all-incidence material instead of the θ_in table.
    #[arg(long = "static", requires = "fit")]
    pub static_material: bool,
    /// Formula set [default: radiance, or the fit's].
    #[arg(long, value_parser = words::<Variant>())]
    pub variant: Option<Variant>,
    /// Fresnel constant for roughness-0 surfaces: classic, pyradiance or a
    /// number [default: classic, or the fit's].
    #[arg(long, value_parser = parse_fresnel_k)]
    pub fresnel_k: Option<f64>,
}

/// A loaded material: the shader and a one-set material for exports.
pub(crate) struct Loaded {
    pub shader: Shader,
    /// The static material (the fit's all-incidence set, or the file's).
    pub material: Material,
    pub name: String,
    /// The fit, when the material came from one.
    pub fit: Option<FitResult>,
}

impl SampleMaterial {
    pub(crate) fn load(&self) -> Result<Loaded> {
        if let Some(dir) = &self.fit {
            let fit = brtf_workflow::read_fit(dir)?;
            let mut options = fit.options();
            if let Some(v) = self.variant {
                options.variant = v;
            }
            if let Some(k) = self.fresnel_k {
                options.fresnel_k = k;
            }
            let material = fit
                .static_material()
                .context("the fit holds no valid material")?;
            let shader = match (&fit.table, self.static_material) {
                (Some(table), false) => Shader::from_table(table, &options)?,
                _ => Shader::new(&material, &options),
            };
            return Ok(Loaded {
                shader,
                material,
                name: fit.name.clone(),
                fit: Some(fit),
            });
        }
        let file = self
            .material
            .clone()
            .expect("clap requires --material or --fit");
        let args = MaterialArgs {
            material: file,
            name: self.name.clone(),
            formula: FormulaArgs {
                variant: self.variant.unwrap_or_default(),
                fresnel_k: self.fresnel_k.unwrap_or(FRESNEL_K_CLASSIC),
            },
            source_omega: 0.0,
            curved: false,
        };
        let (name, material) = args.load()?;
        let options = args.options()?;
        Ok(Loaded {
            shader: Shader::new(&material, &options),
            material,
            name,
            fit: None,
        })
    }
}
