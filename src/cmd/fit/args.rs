//! The arguments of `brtf fit` and the library options they mean.

use crate::cmd::material::FormulaArgs;
use anyhow::{Result, bail};
use brtf_fit::{
    ColourConversion, FitConfig, FitSetOptions, Interpolation, KnownReflectance, Recipe,
    ResidualKind, RobustLoss, ScaleRule, SelectionOptions, WeightRule,
};
use brtf_gonio::Hemisphere;
use brtf_gonio::klems::Side;
use brtf_model::MaterialKind;
use clap::{Args, ValueEnum};
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct FitArgs {
    /// Measurement files, one incidence each (.mpc or pab-opto Mountain); or
    /// Klems BSDF XML files (each incident patch of a side an incidence,
    /// docs/klems.md); or sample folders, one sample each (its .mpc and
    /// .txt files), each fitted into OUT/<name>/.
    #[arg(required_unless_present = "en14501")]
    pub files: Vec<PathBuf>,
    /// Model to fit: plastic, metal, trans, plastic2, metal2 or trans2.
    #[arg(long, required_unless_present = "en14501", value_parser = |s: &str| s.parse::<MaterialKind>())]
    pub model: Option<MaterialKind>,
    /// No files: a grey roughness-0 `trans` from datasheet values at normal
    /// incidence (EN 14501), `tau_nh=…,tau_nn=…,rho_nh=…[,spec=…]`, printed
    /// as a Radiance material (docs/fitting.md, "EN 14501 shortcut").
    #[arg(long, value_name = "VALUES", conflicts_with_all = ["files", "model"],
          value_parser = |s: &str| s.parse::<brtf_fit::en14501::En14501>())]
    pub en14501: Option<brtf_fit::en14501::En14501>,
    /// Tie R = G = B (always so for single-channel data).
    #[arg(long)]
    pub gray: bool,
    /// Output folder, replaced as a whole [default: fits/<name>]; with sample
    /// folders, the folder of their fit folders [default: fits].
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Replace an output folder that holds another fit or other files.
    #[arg(long)]
    pub force: bool,
    /// Material name [default: the files' #sample_name, else their common file-name stem].
    #[arg(long)]
    pub name: Option<String>,
    #[command(flatten)]
    pub formula: FormulaArgs,
    /// Solid angle of the instrument's source in sr, modelled as rtrace's widening.
    #[arg(long, default_value_t = 0.0)]
    pub source_omega: f64,
    /// Orientation vector of the *2 models, `x,y,z`.
    #[arg(
        long,
        default_value = "1,0,0",
        value_delimiter = ',',
        allow_hyphen_values = true
    )]
    pub orientation: Vec<f64>,
    /// How model and data are compared.
    #[arg(long, value_enum, default_value_t = ResidualArg::Absolute)]
    pub residual: ResidualArg,
    /// Floor for relative/log residuals, in the data's unit [default: 10% of the 10th percentile].
    #[arg(long)]
    pub floor: Option<f64>,
    /// Robust loss: none, huber[:C] or cauchy[:C] (C in robust standard deviations).
    #[arg(long, default_value = "none", value_parser = |s: &str| s.parse::<RobustLoss>())]
    pub loss: RobustLoss,
    /// What three-channel files hold: CIE X, Y, Z (converted to Radiance
    /// RGB), or RGB already (files from brtf before it wrote true XYZ).
    #[arg(long, value_enum, default_value_t = ColourArg::Xyz)]
    pub colour: ColourArg,
    /// Fit weights: the samples' solid angles (file Voronoi cells, else computed) or uniform.
    #[arg(long, value_enum, default_value_t = WeightsArg::SolidAngle)]
    pub weights: WeightsArg,
    /// Start from the data-driven values only (no multi-start over roughness).
    #[arg(long)]
    pub no_multistart: bool,
    /// Largest θ_out (from the nearer normal) used, degrees.
    #[arg(long, default_value_t = brtf_gonio::DEFAULT_THETA_CAP_DEG)]
    pub theta_cap: f64,
    /// Half-angle of the cone around the incident beam that is masked, degrees (0: none).
    #[arg(long, default_value_t = 3.0)]
    pub beam_mask: f64,
    /// Hemisphere(s) used [default: front for opaque models, both for trans].
    #[arg(long, value_enum)]
    pub hemisphere: Option<HemisphereArg>,
    /// Drop samples whose value is below this (in the data's unit).
    #[arg(long)]
    pub min_value: Option<f64>,
    /// Mask the pgII sample holder's shadow: φ_out 270 ± 15° at θ_out ≥ 70°.
    #[arg(long)]
    pub mask_holder: bool,
    /// Beam integral for raw-signal files (makes the fit absolute); overrides the file's.
    #[arg(long)]
    pub beam_integral: Option<f64>,
    /// A known directional-hemispherical reflectance `VALUE@THETA` (e.g.
    /// `0.85@30`) that makes a raw-signal fit absolute.
    #[arg(long, value_parser = |s: &str| s.parse::<KnownReflectance>())]
    pub rho: Option<KnownReflectance>,
    /// Fit a free overall scale even when the data are absolute.
    #[arg(long)]
    pub free_scale: bool,
    /// θ_in interpolation of the parameters.
    #[arg(long, value_enum, default_value_t = InterpArg::Pchip)]
    pub interpolation: InterpArg,
    /// Skip the adequacy diagnostics (energy, peak, and the second fit with
    /// another residual kind).
    #[arg(long)]
    pub no_adequacy: bool,
    /// Worker threads [default: all cores].
    #[arg(long)]
    pub jobs: Option<usize>,
    /// Do not write the Radiance exports.
    #[arg(long)]
    pub no_export: bool,
    /// Do not draw the plots.
    #[arg(long)]
    pub no_plots: bool,
    /// Klems XML: the side(s) fitted, each on its own (front = light from
    /// +z, Radiance's front; WINDOW calls it the back).
    #[arg(long, value_enum, default_value_t = SideArg::Both)]
    pub side: SideArg,
    /// Klems XML: which incident patches, e.g. `theta<=60` or
    /// `theta>=10,theta<70` [default: all].
    #[arg(long, value_parser = |s: &str| s.parse::<brtf_fit::klems::IncidenceFilter>())]
    pub incidences: Option<brtf_fit::klems::IncidenceFilter>,
    /// Klems XML: stratified directions per outgoing patch over which the
    /// model is averaged.
    #[arg(long, default_value_t = brtf_fit::PatchAveraging::default().outgoing_samples)]
    pub patch_samples: usize,
}

#[derive(Clone, Copy, Debug, PartialEq, ValueEnum)]
pub enum SideArg {
    Front,
    Back,
    Both,
}

impl SideArg {
    /// The sides fitted.
    pub fn sides(self) -> Vec<Side> {
        match self {
            SideArg::Front => vec![Side::Front],
            SideArg::Back => vec![Side::Back],
            SideArg::Both => Side::BOTH.to_vec(),
        }
    }
}

/// True when `path` is a Klems BSDF XML file (by its extension or its
/// first bytes), as `brtf_gonio::detect_format` decides.
pub fn is_klems(path: &std::path::Path) -> bool {
    use std::io::Read;
    let mut head = Vec::new();
    if let Ok(file) = std::fs::File::open(path) {
        let _ = file.take(512).read_to_end(&mut head);
    }
    brtf_gonio::detect_format(&head, path) == brtf_gonio::SourceFormat::KlemsXml
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum ResidualArg {
    Relative,
    Absolute,
    Log,
}

#[derive(Clone, Copy, Debug, PartialEq, ValueEnum)]
pub enum ColourArg {
    /// Three channels are CIE X, Y, Z: converted to Radiance RGB.
    Xyz,
    /// Three channels are Radiance RGB already.
    AsRecorded,
}

#[derive(Clone, Copy, Debug, PartialEq, ValueEnum)]
pub enum WeightsArg {
    SolidAngle,
    Uniform,
}

#[derive(Clone, Copy, Debug, PartialEq, ValueEnum)]
pub enum HemisphereArg {
    Front,
    Back,
    Both,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum InterpArg {
    Pchip,
    Linear,
}

impl FitArgs {
    /// The library's options for these arguments.
    pub fn options(&self, name: String) -> Result<FitSetOptions> {
        let Some(model) = self.model else {
            bail!("--model is needed to fit measurement files");
        };
        let [x, y, z] = self.orientation[..] else {
            bail!("--orientation needs three numbers x,y,z, not all zero");
        };
        if [x, y, z].iter().all(|c| *c == 0.0) {
            bail!("--orientation needs three numbers x,y,z, not all zero");
        }
        let hemisphere = match self.hemisphere {
            Some(HemisphereArg::Front) => Some(Hemisphere::Front),
            Some(HemisphereArg::Back) => Some(Hemisphere::Back),
            Some(HemisphereArg::Both) => None,
            None => SelectionOptions::default_hemisphere(model),
        };
        let klems = self.files.iter().filter(|f| is_klems(f)).count();
        if klems > 0 && klems < self.files.len() {
            bail!("Klems BSDF XML files are fitted on their own, not with gonio-photometer files");
        }
        let klems = klems > 0;
        if !klems && self.incidences.is_some() {
            bail!("--incidences selects the incident patches of Klems BSDF XML files");
        }
        if self.patch_samples == 0 || self.patch_samples > 4096 {
            bail!("--patch-samples must be between 1 and 4096");
        }
        let selections = SelectionOptions {
            hemisphere,
            theta_cap: self.theta_cap,
            beam_mask: self.beam_mask,
            min_value: self.min_value,
            mask_holder: self.mask_holder,
        }
        .gates(klems);
        let mut config = FitConfig::new(model);
        config.options.variant = self.formula.variant;
        config.options.fresnel_k = self.formula.fresnel_k;
        config.options.source_omega = self.source_omega;
        config.orientation = [x, y, z];
        config.gray = self.gray;
        config.free_scale = self.free_scale;
        config.residual = match self.residual {
            ResidualArg::Relative => ResidualKind::Relative,
            ResidualArg::Absolute => ResidualKind::Absolute,
            ResidualArg::Log => ResidualKind::Log,
        };
        config.floor = self.floor;
        config.loss = self.loss;
        config.multistart = !self.no_multistart;
        let options = FitSetOptions {
            name,
            config,
            recipe: Recipe {
                scale: match self.beam_integral {
                    Some(value) => ScaleRule::BeamIntegral { value },
                    None => ScaleRule::FromFiles,
                },
                colour: match self.colour {
                    ColourArg::Xyz => ColourConversion::XyzToRadianceRgb,
                    ColourArg::AsRecorded => ColourConversion::AsRecorded,
                },
                selections,
                weights: match self.weights {
                    WeightsArg::SolidAngle => WeightRule::SolidAngle,
                    WeightsArg::Uniform => WeightRule::Uniform,
                },
                patch_average: None,
            },
            known_reflectance: self.rho.map(|k| (k.rho, k.theta_in)),
            interpolation: match self.interpolation {
                InterpArg::Pchip => Interpolation::Pchip,
                InterpArg::Linear => Interpolation::Linear,
            },
            command_line: std::env::args().collect(),
            adequacy: !self.no_adequacy,
            klems: brtf_fit::KlemsOptions {
                side: None,
                incidences: self.incidences.clone(),
            },
        };
        Ok(if klems {
            options.for_klems(self.patch_samples)
        } else {
            options
        })
    }
}
