//! `brtf synth`: synthetic measurement files with instrument effects.

use super::material::{FormulaArgs, MaterialArgs};
use super::shared::words;
use anyhow::{Result, bail};
use brtf_gonio::synth::{GroundTruth, Instrument, Layout, SynthSet};
use brtf_gonio::{Channels, SourceFormat};
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub(crate) struct SynthArgs {
    /// Ground truth: a brtf-model material, one primitive or a lobe sum (a
    /// constant mixfunc tree), with --name, --variant, ...
    #[arg(long, value_name = "M.rad", conflicts_with = "ggx")]
    pub material: Option<PathBuf>,
    #[command(flatten)]
    pub model: SynthModelArgs,
    /// Ground truth: a GGX conductor with this normal-incidence Fresnel reflectance `r,g,b`.
    #[arg(long, value_delimiter = ',', value_name = "R,G,B")]
    pub ggx: Option<Vec<f64>>,
    /// GGX roughness α.
    #[arg(long, default_value_t = 0.1)]
    pub ggx_alpha: f64,
    /// Lambertian reflectance under the GGX lobe, `r,g,b`.
    #[arg(long, value_delimiter = ',', default_value = "0.02,0.02,0.02")]
    pub ggx_diffuse: Vec<f64>,
    /// Incident polar angles θ_in in degrees, comma-separated (one file each).
    #[arg(long, value_delimiter = ',', required = true)]
    pub theta_in: Vec<f64>,
    /// Incident azimuth φ_in in degrees.
    #[arg(long, default_value_t = 0.0)]
    pub phi_in: f64,
    /// Output format.
    #[arg(long, value_parser = words::<SourceFormat>(), default_value_t = SourceFormat::Mpc)]
    pub format: SourceFormat,
    /// Values per row: 1 (CIE-Y, the luminance) or 3 (CIE X, Y, Z; Mountain only).
    #[arg(long, default_value_t = 1)]
    pub channels: usize,
    /// Output folder.
    #[arg(long)]
    pub out: PathBuf,
    /// File-name prefix and sample name [default: the output folder's name].
    #[arg(long)]
    pub prefix: Option<String>,
    /// Relative noise, 1σ.
    #[arg(long, default_value_t = 0.02)]
    pub noise: f64,
    /// Additive noise floor, 1σ, 1/sr.
    #[arg(long, default_value_t = 1e-3)]
    pub noise_floor: f64,
    /// Source (beam) aperture, full angle in degrees.
    #[arg(long, default_value_t = 0.5)]
    pub source_aperture: f64,
    /// Detector aperture, full angle in degrees.
    #[arg(long, default_value_t = 0.75)]
    pub detector_aperture: f64,
    /// Half-angle of the blind spot around the incident beam, degrees.
    #[arg(long, default_value_t = 3.0)]
    pub blind_spot: f64,
    /// No holder-shadow gap.
    #[arg(long)]
    pub no_holder_gap: bool,
    /// Darken the holder's shadow 100× (φ_out − φ_in 270 ± 45° at θ_out ≥ 73.5°).
    #[arg(long)]
    pub holder_shadow: bool,
    /// No noise-only back rows for opaque samples.
    #[arg(long)]
    pub no_back_rows: bool,
    /// Coarse grid spacing, degrees.
    #[arg(long, default_value_t = 2.5)]
    pub coarse_step: f64,
    /// Dense patch spacing around the peak, degrees.
    #[arg(long, default_value_t = 0.5)]
    pub fine_step: f64,
    /// Noise seed (each file adds its index).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Replace existing files that brtf synth did not write.
    #[arg(long)]
    pub force: bool,
}

/// The model options of `--material` (same spellings as `brtf eval`).
#[derive(Args, Debug)]
pub(crate) struct SynthModelArgs {
    /// Which material in the file.
    #[arg(long)]
    pub name: Option<String>,
    #[command(flatten)]
    pub formula: FormulaArgs,
}

pub(crate) fn run(args: SynthArgs) -> Result<()> {
    let truth = match (&args.material, &args.ggx) {
        (Some(path), None) => {
            let material = MaterialArgs {
                material: path.clone(),
                name: args.model.name.clone(),
                formula: args.model.formula,
                source_omega: 0.0,
                curved: false,
            };
            GroundTruth::material(material.bsdf()?)
        }
        (None, Some(f0)) => {
            GroundTruth::ggx(f0, args.ggx_alpha, &args.ggx_diffuse).map_err(anyhow::Error::msg)?
        }
        _ => bail!("give the ground truth: --material M.rad or --ggx R,G,B"),
    };
    let command = super::fit::command_line().join(" ");
    let set = SynthSet {
        truth,
        theta_in: args.theta_in.clone(),
        phi_in: args.phi_in,
        instrument: Instrument {
            source_aperture_deg: args.source_aperture,
            detector_aperture_deg: args.detector_aperture,
            noise_relative: args.noise,
            noise_floor: args.noise_floor,
            blind_spot_deg: args.blind_spot,
            holder_gap: !args.no_holder_gap,
            holder_shadow: args.holder_shadow,
            back_rows: !args.no_back_rows,
            aperture_rays: 3,
        },
        layout: Layout {
            coarse_step_deg: args.coarse_step,
            fine_step_deg: args.fine_step,
            max_theta_deg: 88.0,
        },
        channels: match args.channels {
            1 => Channels::Y,
            3 => Channels::Xyz,
            n => bail!("--channels must be 1 or 3, not {n}"),
        },
        format: args.format,
        seed: args.seed,
        prefix: args.prefix.clone().unwrap_or_else(|| {
            args.out
                .file_name()
                .map_or_else(|| "synth".into(), |n| n.to_string_lossy().into_owned())
        }),
        header: vec![format!("#command: {command}")],
    };
    let written =
        brtf_workflow::write_synth_set(&set, &args.out, args.material.as_deref(), args.force)?;
    for (file, samples) in written {
        say!("wrote {} ({samples} samples)", file.display());
    }
    Ok(())
}
