//! What decides a fit ([`FitConfig`], [`RobustLoss`]) and why one could
//! not run ([`FitError`]).

use crate::problem::ResidualKind;
use brtf_model::{EvalOptions, MaterialKind, Shape};
use serde::{Deserialize, Serialize};

/// The model asked for: one type, or `auto`, which fits a candidate set
/// and keeps the one that earns its parameters ([`crate::AutoChoice`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModelChoice {
    /// This type (with `--lobes` and the orientation as given).
    Fixed(MaterialKind),
    /// Plastic or metal, the anisotropic type with its orientation
    /// fitted, two lobes and two anisotropic lobes, chosen by held-out E1.
    Auto,
}

impl brtf_model::OptionWords for ModelChoice {
    const ALL: &'static [Self] = &[
        ModelChoice::Fixed(MaterialKind::Plastic),
        ModelChoice::Fixed(MaterialKind::Metal),
        ModelChoice::Fixed(MaterialKind::Trans),
        ModelChoice::Fixed(MaterialKind::Plastic2),
        ModelChoice::Fixed(MaterialKind::Metal2),
        ModelChoice::Fixed(MaterialKind::Trans2),
        ModelChoice::Auto,
    ];
    const WORDS: &'static [&'static str] = &[
        "plastic", "metal", "trans", "plastic2", "metal2", "trans2", "auto",
    ];
    const ALIASES: &'static [(&'static str, Self)] = &[];
    fn word(self) -> &'static str {
        match self {
            ModelChoice::Fixed(kind) => kind.name(),
            ModelChoice::Auto => "auto",
        }
    }
}

impl std::fmt::Display for ModelChoice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(brtf_model::OptionWords::word(*self))
    }
}

impl std::str::FromStr for ModelChoice {
    type Err = brtf_model::WordError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        brtf_model::parse_word(s)
    }
}

/// How a fit treats each incidence's energy: its directional-hemispherical
/// reflectance and transmittance over the fitted directions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum EnergyRule {
    /// The residuals alone decide: a model that cannot follow the data's
    /// shape may carry more or less light than they do.
    #[default]
    Free,
    /// Each incidence's model carries the data's energy, per side and
    /// channel (Σ ΔΩ |cos θ_out| m = Σ ΔΩ |cos θ_out| y over its fitted
    /// samples), and the residuals fit the shape within that: stiff
    /// penalty rows, met to about 1e-6 relative where the model can
    /// meet them. An all-incidence fit meets them as nearly as it can
    /// over every incidence.
    Exact,
}

brtf_model::option_words!(EnergyRule {
    Free => "free",
    Exact => "exact",
});

/// Robust loss, applied by iteratively reweighting the residuals.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
pub enum RobustLoss {
    /// Plain least squares.
    #[default]
    None,
    /// Huber with threshold `c` in robust standard deviations.
    Huber(f64),
    /// Cauchy with scale `c` in robust standard deviations.
    Cauchy(f64),
}

impl std::str::FromStr for RobustLoss {
    type Err = String;

    /// `none`, `huber[:C]` or `cauchy[:C]` (C in robust standard
    /// deviations; 1.345 and 2.385 by default, 95 % efficient).
    fn from_str(s: &str) -> Result<RobustLoss, String> {
        let (name, c) = match s.split_once(':') {
            // The range is checked with the other options (`FitSetOptions::validate`).
            Some((n, c)) => match c.parse::<f64>() {
                Ok(c) => (n, Some(c)),
                Err(_) => return Err(format!("bad loss scale `{c}`")),
            },
            None => (s, None),
        };
        match name {
            "none" if c.is_none() => Ok(RobustLoss::None),
            "huber" => Ok(RobustLoss::Huber(c.unwrap_or(1.345))),
            "cauchy" => Ok(RobustLoss::Cauchy(c.unwrap_or(2.385))),
            _ => Err(format!(
                "expected none, huber[:C] or cauchy[:C], found `{s}`"
            )),
        }
    }
}

/// A known directional-hemispherical reflectance of the sample,
/// `VALUE@THETA` (e.g. `0.85@30`), that makes a raw-signal fit absolute.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KnownReflectance {
    /// ρ_dh, in (0, 1].
    pub rho: f64,
    /// Its incidence, degrees in [0, 90).
    pub theta_in: f64,
}

impl std::str::FromStr for KnownReflectance {
    type Err = String;

    fn from_str(s: &str) -> Result<KnownReflectance, String> {
        let (value, theta) = s
            .split_once('@')
            .ok_or("expected VALUE@THETA, e.g. 0.85@30")?;
        let rho: f64 = value
            .parse()
            .map_err(|_| format!("bad reflectance `{value}`"))?;
        let theta_in: f64 = theta.parse().map_err(|_| format!("bad angle `{theta}`"))?;
        if !(rho > 0.0 && rho <= 1.0 && (0.0..90.0).contains(&theta_in)) {
            return Err("need 0 < VALUE ≤ 1 and 0 ≤ THETA < 90".into());
        }
        Ok(KnownReflectance { rho, theta_in })
    }
}

/// Everything that decides a fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitConfig {
    /// The model.
    #[serde(with = "crate::serde_kind")]
    pub kind: MaterialKind,
    /// Variant, Fresnel constant and source size of the model.
    #[serde(with = "options_serde")]
    pub options: EvalOptions,
    /// Orientation vector of the `*2` types.
    pub orientation: [f64; 3],
    /// Tie R = G = B.
    pub gray: bool,
    /// Fit a free overall scale (raw-signal data of unknown scale).
    pub free_scale: bool,
    /// How model and data are compared.
    pub residual: ResidualKind,
    /// Floor (same unit as the data) for relative and log residuals;
    /// `None` picks 10% of the data's 10th percentile.
    pub floor: Option<f64>,
    /// Robust loss.
    pub loss: RobustLoss,
    /// Try several starting roughnesses and keep the best.
    pub multistart: bool,
    /// Lowest roughness the fit may reach. Klems fits raise it to
    /// [`crate::klems::MIN_KLEMS_ROUGHNESS`]: a narrower lobe fits inside
    /// one patch, so patch averages cannot tell its width.
    #[serde(default = "default_min_roughness")]
    pub min_roughness: f64,
    /// Specular lobes over the one diffuse base (1: the plain type).
    #[serde(default = "one_lobe")]
    pub lobes: usize,
    /// The in-plane orientation of an anisotropic type is fitted
    /// (`orient`), not fixed by `orientation`.
    #[serde(default)]
    pub oriented: bool,
    /// Whether each incidence must carry the data's energy.
    #[serde(default)]
    pub energy: EnergyRule,
    /// Raised by the caller to stop the fit (Ctrl-C in Python): each
    /// solve ends at its next evaluation. Not part of what decides a fit.
    #[serde(skip)]
    pub stop: StopFlag,
}

/// A request to stop running fits early, shared between the caller and
/// the solver: every clone sees the same flag. The default is a flag
/// nobody can raise.
#[derive(Clone, Default)]
pub struct StopFlag(Option<std::sync::Arc<std::sync::atomic::AtomicBool>>);

impl StopFlag {
    /// A flag that [`StopFlag::raise`] raises.
    pub fn new() -> StopFlag {
        StopFlag(Some(Default::default()))
    }

    /// Asks every fit holding a clone of this flag to stop.
    pub fn raise(&self) {
        if let Some(flag) = &self.0 {
            flag.store(true, std::sync::atomic::Ordering::Relaxed);
        }
    }

    /// The stop was asked for.
    pub fn is_raised(&self) -> bool {
        self.0
            .as_ref()
            .is_some_and(|flag| flag.load(std::sync::atomic::Ordering::Relaxed))
    }
}

/// Flags never make two configurations differ.
impl PartialEq for StopFlag {
    fn eq(&self, _: &StopFlag) -> bool {
        true
    }
}

impl std::fmt::Debug for StopFlag {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "StopFlag({})", self.is_raised())
    }
}

fn default_min_roughness() -> f64 {
    crate::MIN_ROUGHNESS
}

fn one_lobe() -> usize {
    1
}

impl FitConfig {
    /// Defaults for `kind`: radiance variant, RGB, absolute residuals, multi-start.
    pub fn new(kind: MaterialKind) -> FitConfig {
        FitConfig {
            kind,
            options: EvalOptions::default(),
            orientation: [1.0, 0.0, 0.0],
            gray: false,
            free_scale: false,
            residual: ResidualKind::Absolute,
            floor: None,
            loss: RobustLoss::None,
            multistart: true,
            min_roughness: crate::MIN_ROUGHNESS,
            lobes: 1,
            oriented: false,
            energy: EnergyRule::Free,
            stop: StopFlag::default(),
        }
    }

    /// The shape fitted: the type, its lobes and whether the orientation
    /// is an argument.
    pub fn shape(&self) -> Shape {
        Shape {
            kind: self.kind,
            lobes: self.lobes,
            oriented: self.oriented,
        }
    }
}

mod options_serde {
    use brtf_model::{EvalOptions, Variant};
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    #[derive(Serialize, Deserialize)]
    struct Options {
        variant: String,
        fresnel_k: f64,
        source_omega: f64,
        flat: bool,
        source_jitter: f64,
    }

    pub(super) fn serialize<S: Serializer>(o: &EvalOptions, s: S) -> Result<S::Ok, S::Error> {
        Options {
            variant: o.variant.name().into(),
            fresnel_k: o.fresnel_k,
            source_omega: o.source_omega,
            flat: o.flat,
            source_jitter: o.source_jitter,
        }
        .serialize(s)
    }

    pub(super) fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<EvalOptions, D::Error> {
        let o = Options::deserialize(d)?;
        let variant: Variant = o.variant.parse().map_err(serde::de::Error::custom)?;
        Ok(EvalOptions {
            variant,
            fresnel_k: o.fresnel_k,
            source_omega: o.source_omega,
            flat: o.flat,
            source_jitter: o.source_jitter,
        })
    }
}

/// Why a fit could not run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FitError {
    /// No samples are left after the selections.
    #[error("{origin}: no samples left to fit after the selections ({gates})")]
    EmptySelection {
        /// The data's origin.
        origin: String,
        /// The selections applied.
        gates: String,
    },
    /// Every value is zero or negative.
    #[error("{origin}: all {count} values are zero or negative; nothing to fit")]
    AllZero {
        /// The data's origin.
        origin: String,
        /// How many samples.
        count: usize,
    },
    /// A value is NaN or infinite.
    #[error("{origin}: sample {index} has a non-finite value or weight")]
    NonFinite {
        /// The data's origin.
        origin: String,
        /// Sample index.
        index: usize,
    },
    /// A transmitting model needs back-hemisphere data.
    #[error("{origin}: a {kind} fit needs transmission data (back hemisphere), found none")]
    NoTransmission {
        /// The data's origin.
        origin: String,
        /// The model.
        kind: MaterialKind,
    },
    /// Incidences differ in channel count.
    #[error("incidences mix single-channel and RGB data")]
    MixedChannels,
    /// The caller stopped the run ([`crate::Progress::cancelled`]).
    #[error("the fit was interrupted")]
    Interrupted,
    /// The optimiser failed at the start.
    #[error("{origin}: the fit could not start: {reason}")]
    Failed {
        /// The data's origin.
        origin: String,
        /// What went wrong.
        reason: String,
    },
}
