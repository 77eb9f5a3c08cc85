//! `brtf synth`: synthetic measurement files with instrument effects.

use super::material::MaterialArgs;
use super::output::write_atomic;
use anyhow::{Context, Result, bail};
use brtf_gonio::synth::{GroundTruth, Instrument, Layout, SynthSpec, synthesize};
use brtf_gonio::{Channels, Incidence, SourceFormat};
use clap::{Args, ValueEnum};
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct SynthArgs {
    /// Ground truth: a brtf-model material (with --name, --variant, ...).
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
    #[arg(long, value_enum, default_value_t = FormatArg::Mpc)]
    pub format: FormatArg,
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

/// The header line that marks brtf synth's own files (which it may replace).
const SYNTH_MARKER: &str = "synth (synthetic data, not a measurement)";

/// The model options of `--material` (same spellings as `brtf eval`).
#[derive(Args, Debug)]
pub struct SynthModelArgs {
    /// Which material in the file.
    #[arg(long)]
    pub name: Option<String>,
    /// Formula set of the material.
    #[arg(long, default_value = "radiance")]
    pub variant: String,
    /// Fresnel constant: classic, pyradiance or a number.
    #[arg(long, default_value = "classic")]
    pub fresnel_k: String,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum FormatArg {
    Mpc,
    Mountain,
}

pub fn run(args: SynthArgs) -> Result<()> {
    let truth = match (&args.material, &args.ggx) {
        (Some(path), None) => {
            let material = MaterialArgs {
                material: path.clone(),
                name: args.model.name.clone(),
                variant: args.model.variant.parse().map_err(anyhow::Error::msg)?,
                fresnel_k: match args.model.fresnel_k.as_str() {
                    "classic" => brtf_model::FRESNEL_K_CLASSIC,
                    "pyradiance" => brtf_model::FRESNEL_K_PYRADIANCE,
                    k => k
                        .parse()
                        .context("--fresnel-k: expected classic, pyradiance or a number")?,
                },
                source_omega: 0.0,
                curved: false,
            };
            GroundTruth::Model(material.bsdf()?)
        }
        (None, Some(f0)) => {
            if f0.len() != 3 || args.ggx_diffuse.len() != 3 {
                bail!("--ggx and --ggx-diffuse take three numbers r,g,b");
            }
            if !(args.ggx_alpha > 0.0 && args.ggx_alpha <= 1.0) {
                bail!("--ggx-alpha must be in (0, 1]");
            }
            GroundTruth::Ggx {
                f0: [f0[0], f0[1], f0[2]],
                alpha: args.ggx_alpha,
                diffuse: [
                    args.ggx_diffuse[0],
                    args.ggx_diffuse[1],
                    args.ggx_diffuse[2],
                ],
            }
        }
        _ => bail!("give the ground truth: --material M.rad or --ggx R,G,B"),
    };
    let channels = match args.channels {
        1 => Channels::Y,
        3 => Channels::Xyz,
        n => bail!("--channels must be 1 or 3, not {n}"),
    };
    if matches!(args.format, FormatArg::Mpc) && channels == Channels::Xyz {
        bail!("the .mpc format holds one value per row; use --format mountain for --channels 3");
    }
    brtf_model::OptionError::check("--phi-in", args.phi_in, args.phi_in.is_finite(), "finite")?;
    let instrument = Instrument {
        source_aperture_deg: args.source_aperture,
        detector_aperture_deg: args.detector_aperture,
        noise_relative: args.noise,
        noise_floor: args.noise_floor,
        blind_spot_deg: args.blind_spot,
        holder_gap: !args.no_holder_gap,
        back_rows: !args.no_back_rows,
        aperture_rays: 3,
    };
    let layout = Layout {
        coarse_step_deg: args.coarse_step,
        fine_step_deg: args.fine_step,
        max_theta_deg: 88.0,
    };
    instrument.validate()?;
    layout.validate()?;
    let prefix = args.prefix.clone().unwrap_or_else(|| {
        args.out
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "synth".into())
    });
    // The prefix names files and goes into the header as the sample name.
    if prefix.is_empty() || prefix.contains(['/', '\\']) || prefix.contains(char::is_control) {
        bail!(
            "--prefix {prefix:?}: must be one line without / or \\ (it names files and the sample)"
        );
    }
    let ext = match args.format {
        FormatArg::Mpc => "mpc",
        FormatArg::Mountain => "txt",
    };
    let file_of = |theta: f64| {
        args.out
            .join(format!("{prefix}:{:+}{:+}.{ext}", theta, args.phi_in))
    };
    for &theta in &args.theta_in {
        let ok = (0.0..90.0).contains(&theta);
        brtf_model::OptionError::check("--theta-in", theta, ok, "0 ≤ θ_in < 90 degrees")?;
        let inputs: Vec<&std::path::Path> = args.material.iter().map(|m| m.as_path()).collect();
        brtf_io::check_overwrite(&file_of(theta), &inputs, Some(SYNTH_MARKER), args.force)?;
    }
    for (index, &theta) in args.theta_in.iter().enumerate() {
        let spec = SynthSpec {
            truth,
            incidence: Incidence::new(theta, args.phi_in),
            instrument: instrument.clone(),
            layout: layout.clone(),
            channels,
            seed: args.seed.wrapping_add(index as u64),
            sample_name: prefix.clone(),
        };
        let mut m = synthesize(&spec);
        let format = match args.format {
            FormatArg::Mpc => SourceFormat::Mpc,
            FormatArg::Mountain => SourceFormat::Mountain,
        };
        m.format = format;
        m.header = vec![
            format!(
                "#generated by brtf {} {SYNTH_MARKER}",
                env!("CARGO_PKG_VERSION")
            ),
            // One header line whatever the arguments hold.
            format!(
                "#command: {}",
                std::env::args().collect::<Vec<_>>().join(" ")
            )
            .replace(char::is_control, " "),
        ];
        let text = match format {
            SourceFormat::Mpc => brtf_gonio::to_mpc_string(&m).map_err(anyhow::Error::msg)?,
            SourceFormat::Mountain => brtf_gonio::to_mountain_string(&m),
        };
        let file = file_of(theta);
        write_atomic(&file, text.as_bytes())?;
        eprintln!("wrote {} ({} samples)", file.display(), m.samples.len());
    }
    Ok(())
}
