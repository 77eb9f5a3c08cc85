//! `brtf render gonio|image`: brtf's own ray tracer through
//! [`brtf_workflow::render_gonio`] and [`brtf_workflow::render_image`], on
//! a material from a Radiance file (`--material`) or a fit folder (`--fit`).

pub(crate) mod gonio;
pub(crate) mod image;

use super::shared::words;
use anyhow::Result;
use brtf_model::{Variant, parse_fresnel_k};
use brtf_workflow::{MaterialSource, RenderMaterial, load_render_material};
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
    /// Radiance file holding the material: a Ward-type primitive, or a
    /// constant mixfunc tree of them (a lobe sum).
    #[arg(
        long,
        value_name = "M.rad",
        required_unless_present = "fit",
        conflicts_with = "fit"
    )]
    pub material: Option<PathBuf>,
    /// Which material in the file (needed when it holds several; a lobe
    /// sum's name is its top mixfunc's).
    #[arg(long, value_name = "N")]
    pub name: Option<String>,
    /// A fit folder (fit.json): render its θ_in-interpolated material (of
    /// any shape: lobe sums, fitted orientations).
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

impl SampleMaterial {
    /// The material, ready to render.
    pub(crate) fn load(&self) -> anyhow::Result<RenderMaterial> {
        let source = match (&self.fit, &self.material) {
            (Some(dir), _) => MaterialSource::Fit {
                dir: dir.clone(),
                fixed: self.static_material,
            },
            (None, Some(path)) => MaterialSource::File {
                path: path.clone(),
                name: self.name.clone(),
            },
            (None, None) => anyhow::bail!("give --material M.rad or --fit DIR"),
        };
        Ok(load_render_material(&source, self.variant, self.fresnel_k)?)
    }
}
