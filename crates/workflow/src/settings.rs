//! What a user chooses for a fit, typed: the one place the front ends'
//! options become [`FitSetOptions`].

use crate::WorkflowError;
use brtf_fit::klems::IncidenceFilter;
use brtf_fit::{
    AzimuthRule, ColourConversion, FitConfig, FitSetOptions, HolderMask, Interpolation,
    KnownReflectance, ModelChoice, Recipe, ResidualKind, RobustLoss, ScaleRule, SelectionOptions,
    WeightRule,
};
use brtf_gonio::Hemispheres;
use brtf_gonio::klems::Sides;
use brtf_model::{FRESNEL_K_CLASSIC, MaterialKind, Variant};

/// The most view directions per outgoing Klems patch.
pub const MAX_PATCH_SAMPLES: usize = 4096;

/// Every fit option of `brtf fit` and `brtf.fit`, with their defaults.
#[derive(Debug, Clone)]
pub struct FitSettings {
    /// The model fitted: one type, or `auto` (a candidate set).
    pub model: ModelChoice,
    /// Tie R = G = B.
    pub gray: bool,
    /// Formula set.
    pub variant: Variant,
    /// Fresnel constant of roughness-0 surfaces.
    pub fresnel_k: f64,
    /// The source's solid angle, sr.
    pub source_omega: f64,
    /// Orientation vector of the anisotropic types; `None`: fitted (the
    /// in-plane angle `orient`) for gonio scans, +x for Klems XML.
    pub orientation: Option<[f64; 3]>,
    /// Specular lobes over the one diffuse base (plastic and metal types).
    pub lobes: usize,
    /// How model and data are compared.
    pub residual: ResidualKind,
    /// Floor of relative and log residuals.
    pub floor: Option<f64>,
    /// Robust loss.
    pub loss: RobustLoss,
    /// Whether each incidence must carry the data's energy.
    pub energy: brtf_fit::EnergyRule,
    /// What three-channel files hold.
    pub colour: ColourConversion,
    /// The samples' weights.
    pub weights: WeightRule,
    /// Multi-start over roughness.
    pub multistart: bool,
    /// Largest θ_out fitted, degrees.
    pub theta_cap: f64,
    /// Half-angle of the masked cone around the beam, degrees.
    pub beam_mask: f64,
    /// Hemispheres fitted (`None`: front for opaque models, both for trans).
    pub hemisphere: Option<Hemispheres>,
    /// Samples below this value are dropped.
    pub min_value: Option<f64>,
    /// Mask the pgII holder's shadow: its fixed band or the shadows found.
    pub mask_holder: Option<HolderMask>,
    /// How φ_out is aligned with the plane of incidence (`None`: the
    /// peak aligned for gonio scans fitted with an isotropic model or
    /// `auto`; the file's frame for anisotropic models and Klems XML).
    pub phi_offset: Option<AzimuthRule>,
    /// Beam integral that makes raw-signal files absolute.
    pub beam_integral: Option<f64>,
    /// A known reflectance that makes a raw-signal fit absolute.
    pub rho: Option<KnownReflectance>,
    /// Fit a free scale even on absolute data.
    pub free_scale: bool,
    /// θ_in interpolation of the table.
    pub interpolation: Interpolation,
    /// Run the adequacy diagnostics.
    pub adequacy: bool,
    /// Klems XML: the sides fitted.
    pub sides: Sides,
    /// Klems XML: which incident patches.
    pub incidences: Option<IncidenceFilter>,
    /// Klems XML: view directions per outgoing patch.
    pub patch_samples: usize,
    /// Raised to stop the fit (Python's Ctrl-C): see [`brtf_fit::StopFlag`].
    pub stop: brtf_fit::StopFlag,
    /// Tensor trees: the θ_in fitted (degrees); the Klems rings' when `None`.
    pub theta_in_grid: Option<crate::ThetaGrid>,
}

impl FitSettings {
    /// The defaults for fitting `model`.
    pub fn new(model: ModelChoice) -> FitSettings {
        FitSettings {
            model,
            gray: false,
            variant: Variant::default(),
            fresnel_k: FRESNEL_K_CLASSIC,
            source_omega: 0.0,
            orientation: None,
            lobes: 1,
            residual: ResidualKind::default(),
            floor: None,
            loss: RobustLoss::None,
            energy: brtf_fit::EnergyRule::Free,
            colour: ColourConversion::XyzToRadianceRgb,
            weights: WeightRule::SolidAngle,
            multistart: true,
            theta_cap: brtf_gonio::DEFAULT_THETA_CAP_DEG,
            beam_mask: 3.0,
            hemisphere: None,
            min_value: None,
            mask_holder: None,
            phi_offset: None,
            beam_integral: None,
            rho: None,
            free_scale: false,
            interpolation: Interpolation::default(),
            adequacy: true,
            sides: Sides::default(),
            incidences: None,
            patch_samples: brtf_fit::PatchAveraging::default().outgoing_samples,
            stop: brtf_fit::StopFlag::default(),
            theta_in_grid: None,
        }
    }

    /// The library's options for a fit named `name`; `klems` when the
    /// inputs are Klems BSDF XML. Checks every value.
    pub fn options(
        &self,
        name: String,
        klems: bool,
        command_line: Vec<String>,
    ) -> Result<FitSetOptions, WorkflowError> {
        if !klems && self.incidences.is_some() {
            return Err(WorkflowError::Usage(
                "--incidences selects the incident patches of Klems BSDF XML files".into(),
            ));
        }
        if !klems && self.theta_in_grid.is_some() {
            return Err(WorkflowError::Usage(
                "--theta-in-grid sets the incidences of tensor-tree BSDF XML files".into(),
            ));
        }
        if klems && self.phi_offset.is_some() {
            return Err(WorkflowError::Usage(
                "--phi-offset turns gonio scans; Klems patches keep their basis".into(),
            ));
        }
        if !(1..=MAX_PATCH_SAMPLES).contains(&self.patch_samples) {
            return Err(WorkflowError::Usage(format!(
                "--patch-samples must be between 1 and {MAX_PATCH_SAMPLES}"
            )));
        }
        // `auto` fits plastic and metal families; its options are plastic's.
        let (kind, auto) = match self.model {
            ModelChoice::Fixed(kind) => (kind, false),
            ModelChoice::Auto => (MaterialKind::Plastic, true),
        };
        if auto && self.lobes != 1 {
            return Err(WorkflowError::Usage(
                "--model auto chooses the lobes itself: leave out --lobes".into(),
            ));
        }
        let hemisphere = match self.hemisphere {
            Some(h) => h.only(),
            None => SelectionOptions::default_hemisphere(kind),
        };
        let selections = SelectionOptions {
            hemisphere,
            theta_cap: self.theta_cap,
            beam_mask: self.beam_mask,
            min_value: self.min_value,
            mask_holder: self.mask_holder,
        }
        .gates(klems);
        let mut config = FitConfig::new(kind);
        config.options.variant = self.variant;
        config.options.fresnel_k = self.fresnel_k;
        config.options.source_omega = self.source_omega;
        if let Some([x, y, z]) = self.orientation {
            // Radiance projects the vector onto the surface ("illegal
            // orientation vector" when nothing is left).
            let along_normal = x.hypot(y) <= 1e-9 * x.hypot(y).hypot(z);
            if along_normal || ![x, y, z].iter().all(|c| c.is_finite()) {
                return Err(WorkflowError::Usage(format!(
                    "--orientation {x},{y},{z}: needs a direction with a part in the surface \
                     (not zero, not along the normal z)"
                )));
            }
        }
        config.orientation = self.orientation.unwrap_or([1.0, 0.0, 0.0]);
        // Auto's anisotropic candidates fit their orientation unless one is given.
        config.oriented = (auto || kind.is_anisotropic()) && !klems && self.orientation.is_none();
        config.lobes = self.lobes;
        if !auto {
            brtf_model::Shape::new(kind, self.lobes, config.oriented)
                .map_err(WorkflowError::Usage)?;
        }
        config.gray = self.gray;
        config.free_scale = self.free_scale;
        config.residual = self.residual;
        config.floor = self.floor;
        config.loss = self.loss;
        config.energy = self.energy;
        config.multistart = self.multistart;
        config.stop = self.stop.clone();
        let options = FitSetOptions {
            name,
            config,
            recipe: Recipe {
                scale: match self.beam_integral {
                    Some(value) => ScaleRule::BeamIntegral { value },
                    None => ScaleRule::FromFiles,
                },
                colour: self.colour,
                selections,
                weights: self.weights,
                patch_average: None,
                // An anisotropic lobe turned in the plane can move the
                // peak out of the plane of incidence itself.
                azimuth: self
                    .phi_offset
                    .unwrap_or(if kind.is_anisotropic() && !auto {
                        AzimuthRule::file_frame()
                    } else {
                        AzimuthRule::AlignPeak
                    }),
            },
            known_reflectance: self.rho.map(|k| (k.rho, k.theta_in)),
            interpolation: self.interpolation,
            command_line,
            adequacy: self.adequacy,
            klems: brtf_fit::KlemsOptions {
                side: None,
                incidences: self.incidences.clone(),
                theta_in_grid: self.theta_in_grid.as_ref().map(|g| g.0.clone()),
            },
            auto,
        };
        let options = if klems {
            options.for_klems(self.patch_samples)
        } else {
            options
        };
        options.validate()?;
        Ok(options)
    }
}
