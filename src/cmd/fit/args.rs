//! The arguments of `brtf fit` and the settings they mean.

use crate::cmd::material::FormulaArgs;
use crate::cmd::shared::words;
use brtf_fit::klems::IncidenceFilter;
use brtf_fit::{
    ColourConversion, EnergyRule, Interpolation, KnownReflectance, ModelChoice, ResidualKind,
    RobustLoss,
};
use brtf_fit::{WeightRule, en14501::En14501};
use brtf_gonio::{Hemispheres, klems::Sides};
use brtf_workflow::{FitSettings, Outputs};
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub(crate) struct FitArgs {
    /// Measurement files, one incidence each (.mpc or pab-opto Mountain); or
    /// Klems BSDF XML files (each incident patch of a side an incidence;
    /// tensor trees: each --theta-in-grid angle, docs/klems.md); or sample
    /// folders, one sample each (its .mpc and .txt files), each fitted into
    /// OUT/<name>/.
    #[arg(required_unless_present = "en14501")]
    pub files: Vec<PathBuf>,
    /// Model to fit; `auto` fits plastic or metal, its anisotropic type,
    /// two lobes and two anisotropic lobes, and keeps the one with the best
    /// held-out E1 that earns its parameters.
    #[arg(long, required_unless_present = "en14501", value_parser = words::<ModelChoice>())]
    pub model: Option<ModelChoice>,
    /// No files: a grey roughness-0 `trans` from datasheet values at normal
    /// incidence (EN 14501), `tau_nh=…,tau_nn=…,rho_nh=…[,spec=…]`, printed
    /// as a Radiance material (docs/fitting.md, "EN 14501 shortcut").
    #[arg(long, value_name = "VALUES", conflicts_with_all = ["files", "model"],
          value_parser = |s: &str| s.parse::<En14501>())]
    pub en14501: Option<En14501>,
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
    /// Orientation vector of the *2 models, `x,y,z` [default: fitted, the
    /// in-plane angle `orient`; +x for Klems XML].
    #[arg(long, value_parser = brtf_workflow::parse_numbers::<3>, allow_hyphen_values = true)]
    pub orientation: Option<[f64; 3]>,
    /// Specular lobes over the one diffuse base, 1 to 3 (plastic, metal,
    /// plastic2, metal2): exported as a mixfunc of one primitive per lobe.
    #[arg(long, default_value_t = 1)]
    pub lobes: usize,
    /// How model and data are compared.
    #[arg(long, value_parser = words::<ResidualKind>(), default_value_t = ResidualKind::Absolute)]
    pub residual: ResidualKind,
    /// Floor for relative/log residuals, in the data's unit [default: 10% of the 10th percentile].
    #[arg(long)]
    pub floor: Option<f64>,
    /// `exact`: each incidence carries the data's ρ_dh and τ_dh, the shape fitted within (docs/fitting.md).
    #[arg(long, value_parser = words::<EnergyRule>(), default_value_t = EnergyRule::Free)]
    pub energy: EnergyRule,
    /// Robust loss: none, huber[:C] or cauchy[:C] (C in robust standard deviations).
    #[arg(long, default_value = "none", value_parser = |s: &str| s.parse::<RobustLoss>())]
    pub loss: RobustLoss,
    /// What three-channel files hold: CIE X, Y, Z (converted to Radiance
    /// RGB), or RGB already (files from brtf before it wrote true XYZ).
    #[arg(long, value_parser = words::<ColourConversion>(),
          default_value_t = ColourConversion::XyzToRadianceRgb)]
    pub colour: ColourConversion,
    /// Fit weights: the samples' solid angles (file Voronoi cells, else computed) or uniform.
    #[arg(long, value_parser = words::<WeightRule>(), default_value_t = WeightRule::SolidAngle)]
    pub weights: WeightRule,
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
    #[arg(long, value_parser = words::<Hemispheres>())]
    pub hemisphere: Option<Hemispheres>,
    /// Drop samples whose value is below this (in the data's unit).
    #[arg(long)]
    pub min_value: Option<f64>,
    /// Mask the pgII sample holder's shadow: alone or `band`, φ_out − φ_in 270 ± 45° at θ_out ≥ 73°; `auto`, the regions found far below their mirror across the plane of incidence
    #[arg(long, num_args = 0..=1, default_missing_value = "band", value_parser = words::<brtf_fit::HolderMask>())]
    pub mask_holder: Option<brtf_fit::HolderMask>,
    /// Turn of φ_out: `auto` turns it so that the data's specular peak lies in the plane of incidence (when 0.5° or more out of it), a number turns it by that many degrees, 0 keeps the file's frame [default: auto]
    #[arg(long, value_parser = |s: &str| s.parse::<brtf_fit::AzimuthRule>())]
    pub phi_offset: Option<brtf_fit::AzimuthRule>,
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
    #[arg(long, value_parser = words::<Interpolation>(), default_value_t = Interpolation::Pchip)]
    pub interpolation: Interpolation,
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
    #[arg(long, value_parser = words::<Sides>(), default_value_t = Sides::Both)]
    pub side: Sides,
    /// Klems XML: which incident patches, e.g. `theta<=60` or
    /// `theta>=10,theta<70` [default: all].
    #[arg(long, value_parser = |s: &str| s.parse::<IncidenceFilter>())]
    pub incidences: Option<IncidenceFilter>,
    /// Klems XML: stratified directions per outgoing patch over which the
    /// model is averaged.
    #[arg(long, default_value_t = brtf_fit::PatchAveraging::default().outgoing_samples)]
    pub patch_samples: usize,
    /// Tensor trees: the θ_in fitted, e.g. `0,15,30,45,60,75` [default: 0,10,…,70,82.5].
    #[arg(long, value_parser = |s: &str| s.parse::<brtf_workflow::ThetaGrid>())]
    pub theta_in_grid: Option<brtf_workflow::ThetaGrid>,
}

impl FitArgs {
    /// The fit settings these arguments give.
    pub(crate) fn settings(&self) -> anyhow::Result<FitSettings> {
        let Some(model) = self.model else {
            anyhow::bail!("--model is needed to fit measurement files");
        };
        Ok(FitSettings {
            gray: self.gray,
            variant: self.formula.variant,
            fresnel_k: self.formula.fresnel_k,
            source_omega: self.source_omega,
            orientation: self.orientation,
            lobes: self.lobes,
            residual: self.residual,
            floor: self.floor,
            loss: self.loss,
            energy: self.energy,
            colour: self.colour,
            weights: self.weights,
            multistart: !self.no_multistart,
            theta_cap: self.theta_cap,
            beam_mask: self.beam_mask,
            hemisphere: self.hemisphere,
            min_value: self.min_value,
            mask_holder: self.mask_holder,
            phi_offset: self.phi_offset,
            beam_integral: self.beam_integral,
            rho: self.rho,
            free_scale: self.free_scale,
            interpolation: self.interpolation,
            adequacy: !self.no_adequacy,
            sides: self.side,
            incidences: self.incidences.clone(),
            patch_samples: self.patch_samples,
            theta_in_grid: self.theta_in_grid.clone(),
            ..FitSettings::new(model)
        })
    }

    /// The optional outputs asked for.
    pub(crate) fn outputs(&self) -> Outputs {
        Outputs {
            export: !self.no_export,
            plots: !self.no_plots,
        }
    }
}
