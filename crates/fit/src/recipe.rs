//! The typed recipe that turns a measurement file into the fitted
//! quantity, and the one function that applies it
//! ([`Recipe::prepare`]). `brtf fit`, the plots and `brtf check` all
//! rebuild their data through it, from the recipe stored in `fit.json`,
//! so they cannot disagree.
//!
//! In order:
//! 1. **Colour**: three-channel files hold CIE X, Y, Z; they become
//!    Radiance RGB ([`brtf_model::xyz_to_rgb`]), the colour the models use.
//! 2. **Weights**: solid angles of the full layout (the file's Voronoi
//!    cells, else computed), before any selection; or uniform.
//! 3. **Conversion** to the fitted quantity ([`Conversion`]): BSDF as is;
//!    DSF ÷ |cos θ_out|; raw signal ÷ |cos θ_out| and ÷ the beam integral,
//!    or ÷ the instrument scale K of a known reflectance, or with a free
//!    fitted scale when neither is known.
//! 4. **Selections** ([`Gate`]), in order, each with the number it removed.
//! 5. **Azimuth** ([`AzimuthRule`]): φ_out turned so that the specular
//!    peak lies in the plane of incidence (see [`crate::align`]); the
//!    conversion and the selections are then made again in the turned
//!    frame.

use crate::align::{AzimuthRule, aligning_turn, peak_azimuth};
use crate::data::{FitSample, GateCount, IncidenceData, Weighting};
use brtf_gonio::shadow::ShadowRegion;
use brtf_gonio::{Gate, GateContext, Measurement, Quantity, SolidAngleSource};
use glam::DVec3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Samples per parallel piece of the gates and of the fitter's samples.
const SAMPLE_PIECE: usize = 8192;

/// How the scale of raw-signal files is fixed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "rule", rename_all = "snake_case")]
pub enum ScaleRule {
    /// As each file says: its beam integral when it has one, else a free
    /// fitted scale.
    FromFiles,
    /// Divide raw signal by this beam integral (overrides the files').
    BeamIntegral {
        /// The beam integral, in the files' unit.
        value: f64,
    },
    /// Divide raw signal by K, the instrument scale that gives the
    /// directional-hemispherical reflectance `rho` at `theta_in`.
    KnownReflectance {
        /// The known ρ_dh.
        rho: f64,
        /// Its incidence, degrees.
        theta_in: f64,
        /// The instrument scale K found from it.
        k: f64,
    },
}

/// How the colour channels are read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ColourConversion {
    /// Three channels are CIE X, Y, Z (as the files' colorimetry says):
    /// converted to Radiance RGB. One channel (CIE Y) is fitted grey.
    XyzToRadianceRgb,
    /// As recorded: three channels are taken as Radiance RGB already (for
    /// files that hold RGB under an XYZ header, such as those written by
    /// brtf before it wrote true XYZ).
    AsRecorded,
}

brtf_model::option_words!(ColourConversion {
    XyzToRadianceRgb => "xyz",
    AsRecorded => "as-recorded",
});

impl ColourConversion {
    /// What the conversion does, for people.
    pub fn describe(self) -> &'static str {
        match self {
            ColourConversion::XyzToRadianceRgb => "CIE XYZ converted to Radiance RGB",
            ColourConversion::AsRecorded => "three channels taken as Radiance RGB",
        }
    }
}

/// Which weights the fit gives the samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WeightRule {
    /// Each sample's solid angle (the file's cells, else computed).
    SolidAngle,
    /// Every sample weighs 1.
    Uniform,
}

brtf_model::option_words!(WeightRule { SolidAngle => "solid-angle", Uniform => "uniform" });

/// Everything that decides how a measurement file becomes fitted data.
/// The residual kind, floor and loss are the fit's ([`crate::FitConfig`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Recipe {
    /// How raw signal gets its scale.
    pub scale: ScaleRule,
    /// How the channels are read.
    pub colour: ColourConversion,
    /// The selections, in the order they are applied.
    pub selections: Vec<Gate>,
    /// The fit's weights.
    pub weights: WeightRule,
    /// Klems patch averages: the data are BSDF averages over patches, and
    /// the model is averaged the same way before it is compared with them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub patch_average: Option<PatchAveraging>,
    /// How φ_out is aligned with the plane of incidence (step 5). Fits
    /// saved without it used the file's frame.
    #[serde(default = "AzimuthRule::file_frame")]
    pub azimuth: AzimuthRule,
}

/// How the model is averaged over Klems patches (see
/// [`crate::klems`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PatchAveraging {
    /// Stratified directions per outgoing patch.
    pub outgoing_samples: usize,
    /// Stratified directions per incident patch.
    pub incident_samples: usize,
    /// Outgoing patches whose centre lies within this angle (degrees) of
    /// the mirror or straight-through direction of the incident patch's
    /// centre are averaged over every pairing of incident and outgoing
    /// directions (`incident_samples × outgoing_samples` pairs), so that
    /// narrow lobes are resolved; the others pair them one to one.
    pub near_lobe_deg: f64,
    /// Seed of the stratified directions.
    pub seed: u64,
}

impl Default for PatchAveraging {
    fn default() -> Self {
        PatchAveraging {
            outgoing_samples: 32,
            incident_samples: 32,
            near_lobe_deg: 35.0,
            seed: 1,
        }
    }
}

impl Recipe {
    /// `brtf fit`'s defaults for a model: scale from the files, channels
    /// as recorded, solid-angle weights; drop unavailable values, keep the
    /// front hemisphere (both for transmitting models), θ_out ≤ 85° and a
    /// 3° beam mask.
    pub fn for_kind(kind: brtf_model::MaterialKind) -> Recipe {
        let mut selections = vec![Gate::Unavailable];
        if !kind.is_transmitting() {
            selections.push(Gate::Hemisphere {
                keep: brtf_gonio::Hemisphere::Front,
            });
        }
        selections.push(Gate::ThetaCap {
            max_deg: brtf_gonio::DEFAULT_THETA_CAP_DEG,
        });
        selections.push(Gate::BeamMask {
            half_angle_deg: 3.0,
        });
        Recipe {
            scale: ScaleRule::FromFiles,
            colour: ColourConversion::XyzToRadianceRgb,
            selections,
            weights: WeightRule::SolidAngle,
            patch_average: None,
            azimuth: AzimuthRule::AlignPeak,
        }
    }

    /// The recipe for Klems patch averages: no beam mask or θ cap (the
    /// diagonal patch holds the peak and the last ring reaches 90°), the
    /// front hemisphere only for reflecting models, patch weights, and
    /// the model averaged over patches.
    pub fn for_klems(kind: brtf_model::MaterialKind) -> Recipe {
        let mut selections = vec![Gate::Unavailable];
        if !kind.is_transmitting() {
            selections.push(Gate::Hemisphere {
                keep: brtf_gonio::Hemisphere::Front,
            });
        }
        Recipe {
            scale: ScaleRule::FromFiles,
            colour: ColourConversion::XyzToRadianceRgb,
            selections,
            weights: WeightRule::SolidAngle,
            patch_average: Some(PatchAveraging::default()),
            azimuth: AzimuthRule::file_frame(),
        }
    }
}

/// The selection options of `brtf fit` (and the Python package's `fit`),
/// and the one place that turns them into [`Gate`]s.
#[derive(Debug, Clone, PartialEq)]
pub struct SelectionOptions {
    /// The hemisphere kept; `None` keeps both.
    pub hemisphere: Option<brtf_gonio::Hemisphere>,
    /// Largest θ_out used, degrees (not for Klems patch averages).
    pub theta_cap: f64,
    /// Half-angle of the masked cone around the beam, degrees; 0: none
    /// (not for Klems patch averages).
    pub beam_mask: f64,
    /// Drop samples below this value.
    pub min_value: Option<f64>,
    /// Mask the pgII sample holder's shadow: its fixed band, or the
    /// shadows found in each scan.
    pub mask_holder: Option<HolderMask>,
}

/// How `--mask-holder` finds the holder's shadow.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HolderMask {
    /// The fixed band in the instrument's frame ([`brtf_gonio::PGII_HOLDER_BAND`]).
    Band,
    /// The shadows found in each scan ([`brtf_gonio::DETECTED_SHADOW`]).
    Auto,
}

brtf_model::option_words!(HolderMask { Band => "band", Auto => "auto" });

impl SelectionOptions {
    /// The default hemisphere for `kind`: the front for opaque models,
    /// both (`None`) for transmitting ones.
    pub fn default_hemisphere(kind: brtf_model::MaterialKind) -> Option<brtf_gonio::Hemisphere> {
        (!kind.is_transmitting()).then_some(brtf_gonio::Hemisphere::Front)
    }

    /// The gates, in the order they are applied. Klems patches cover the
    /// hemisphere to 90° and the diagonal patch holds the peak, so
    /// `klems` data get no θ cap and no beam mask.
    pub fn gates(&self, klems: bool) -> Vec<Gate> {
        let mut selections = vec![Gate::Unavailable];
        selections.extend(self.hemisphere.map(|keep| Gate::Hemisphere { keep }));
        if !klems {
            selections.push(Gate::ThetaCap {
                max_deg: self.theta_cap,
            });
            if self.beam_mask > 0.0 {
                selections.push(Gate::BeamMask {
                    half_angle_deg: self.beam_mask,
                });
            }
        }
        selections.extend(self.min_value.map(|min| Gate::MinValue { min }));
        match self.mask_holder {
            Some(HolderMask::Band) => selections.push(brtf_gonio::PGII_HOLDER_BAND),
            Some(HolderMask::Auto) => selections.push(brtf_gonio::DETECTED_SHADOW),
            None => {}
        }
        selections
    }
}

/// Where a beam integral came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BeamOrigin {
    /// The file's header.
    File,
    /// The `--beam-integral` option.
    Option,
}

/// What the raw signal of a file was divided by.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "by", rename_all = "snake_case")]
pub enum RawScale {
    /// A beam integral: the result is the absolute BSDF.
    BeamIntegral {
        /// The beam integral.
        value: f64,
        /// Where it came from.
        origin: BeamOrigin,
    },
    /// The instrument scale K of a known reflectance: absolute BSDF.
    KnownReflectance {
        /// K, in the files' unit.
        k: f64,
        /// The known ρ_dh.
        rho: f64,
        /// Its incidence, degrees.
        theta_in: f64,
    },
    /// Nothing: the data stay in the file's unit and the fit has a free
    /// scale.
    Free,
}

/// How one file's values became the fitted quantity.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "quantity", rename_all = "snake_case")]
pub enum Conversion {
    /// The file holds the BSDF: used as it is.
    Bsdf,
    /// The file holds the DSF: divided by |cos θ_out|.
    Dsf,
    /// The file holds raw detector signal: divided by |cos θ_out| and by
    /// `scale`.
    Raw {
        /// The file's unit.
        unit: String,
        /// What else it was divided by.
        scale: RawScale,
    },
}

impl Conversion {
    /// True when the result is in the file's raw unit (free scale).
    pub fn is_free_scale(&self) -> bool {
        matches!(
            self,
            Conversion::Raw {
                scale: RawScale::Free,
                ..
            }
        )
    }

    /// The unit of the converted values.
    pub fn unit(&self) -> DataUnit {
        match self {
            Conversion::Raw {
                unit,
                scale: RawScale::Free,
            } => DataUnit::RawPerCos(unit.clone()),
            _ => DataUnit::Bsdf,
        }
    }
}

impl std::fmt::Display for Conversion {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Conversion::Bsdf => f.write_str("BSDF"),
            Conversion::Dsf => f.write_str("DSF, divided by |cos θ_out|"),
            Conversion::Raw { unit, scale } => match scale {
                RawScale::BeamIntegral { value, .. } => {
                    write!(f, "raw [{unit}] ÷ beam integral {value} ÷ |cos θ_out|")
                }
                RawScale::KnownReflectance { k, rho, theta_in } => write!(
                    f,
                    "raw [{unit}] ÷ |cos θ_out| ÷ K = {k:e} from --rho {rho}@{theta_in}"
                ),
                RawScale::Free => {
                    write!(
                        f,
                        "raw [{unit}] ÷ |cos θ_out|, free scale (no beam integral)"
                    )
                }
            },
        }
    }
}

/// The unit of converted values.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum DataUnit {
    /// BSDF in 1/sr.
    Bsdf,
    /// Raw signal ÷ |cos θ_out| in the file's unit (the model carries the
    /// free scale).
    RawPerCos(String),
}

impl DataUnit {
    /// Axis title for values of this unit.
    pub fn axis(&self) -> String {
        match self {
            DataUnit::Bsdf => "BSDF [1/sr]".into(),
            DataUnit::RawPerCos(u) => format!("raw signal ÷ |cos θ_out| [{u}]"),
        }
    }

    /// Axis title for a hemispherical integral Σ value·|cos θ|·ΔΩ.
    pub fn integral_axis(&self) -> String {
        match self {
            DataUnit::Bsdf => "ρ_dh (directional-hemispherical reflectance) [–]".into(),
            DataUnit::RawPerCos(u) => format!("Σ raw signal · ΔΩ [{u}·sr] (no beam integral)"),
        }
    }
}

/// Why a measurement could not be prepared.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum RecipeError {
    /// A conversion failed (e.g. an invalid beam integral).
    #[error("{origin}: {source}")]
    Convert {
        /// The file.
        origin: String,
        /// What went wrong.
        source: brtf_gonio::ConvertError,
    },
    /// A raw-signal scale was given for data that are not raw signal.
    #[error("{origin}: {what} applies to raw-signal files, but this file holds the {quantity}")]
    ScaleNotRaw {
        /// The file.
        origin: String,
        /// The option (`--beam-integral`, `--rho`).
        what: &'static str,
        /// What the file holds.
        quantity: &'static str,
    },
}

/// One measurement after the recipe: every sample of the file, converted,
/// with the gate that removed it (if any).
#[derive(Debug, Clone)]
pub struct PreparedMeasurement {
    /// Where it came from.
    pub source: String,
    /// The converted measurement, every sample in file order, each with
    /// its solid angle.
    pub measurement: Measurement,
    /// How the values were converted.
    pub conversion: Conversion,
    /// Per sample: the index into the recipe's selections of the gate that
    /// removed it, `None` when it is fitted.
    pub removed_by: Vec<Option<usize>>,
    /// Each selection with the number of samples it removed.
    pub gates: Vec<GateCount>,
    /// Which weights the fitted samples carry.
    pub weighting: Weighting,
    /// Patch-averaged data: every sample's (light, view) pairs, in file
    /// order (set by [`crate::klems`]).
    pub patch_pairs: Option<std::sync::Arc<crate::data::PatchPairs>>,
    /// Every sample's [`brtf_gonio::Sample::direction`], in file order:
    /// made once, beside the solid angles, for the gates and the fitter.
    pub directions: Vec<DVec3>,
    /// The turn of φ_out (degrees) the recipe's [`AzimuthRule`] made: the
    /// measurement's φ_out and the directions are in the turned frame.
    pub phi_turn_deg: f64,
    /// How far (degrees of arc) the data's peak lay from the plane of
    /// incidence before the turn; `None` without a distinct peak.
    pub peak_arc_deg: Option<f64>,
    /// The shadows a [`Gate::Shadow`] found (`--mask-holder auto`).
    pub shadows: Vec<ShadowRegion>,
}

/// What [`Recipe::convert_and_gate`] makes: the converted measurement,
/// per sample the gate that removed it, every sample's direction, and the
/// shadows a [`Gate::Shadow`] found.
type Converted = (
    Measurement,
    Conversion,
    Vec<Option<usize>>,
    Vec<DVec3>,
    Vec<ShadowRegion>,
);

impl Recipe {
    /// Applies the recipe to `measurement`, read from `source`.
    pub fn prepare(
        &self,
        measurement: Measurement,
        source: &str,
    ) -> Result<PreparedMeasurement, RecipeError> {
        // The weights describe the full layout, so they are computed from
        // every sample; the conversion and the gates do not read them, so
        // they run beside (the solid angles are the longest step).
        let (solid_angles, converted) = rayon::join(
            || brtf_gonio::solid_angles(&measurement),
            || self.convert_and_gate(&measurement, source),
        );
        let mut converted = converted?;
        let peak = self.peak_azimuth(&converted);
        let turn = match self.azimuth {
            AzimuthRule::AlignPeak => aligning_turn(peak),
            AzimuthRule::Turn { degrees } => degrees,
        };
        if turn != 0.0 {
            // A turn about the normal keeps every cell's solid angle and
            // every converted value (they depend on θ_out only): only the
            // directions and the gates are made again.
            let (turned, conversion, _, _, _) = converted;
            let mut turned = turned;
            turned
                .samples
                .par_iter_mut()
                .with_min_len(SAMPLE_PIECE)
                .for_each(|sample| {
                    sample.phi_deg = (sample.phi_deg + turn).rem_euclid(360.0);
                });
            let (removed_by, directions, shadows) = self.gate(&turned);
            converted = (turned, conversion, removed_by, directions, shadows);
        }
        let (mut measurement, conversion, removed_by, directions, shadows) = converted;
        // The conversions keep the samples and their order.
        measurement.set_solid_angles(&solid_angles);
        let weighting = match (self.weights, solid_angles.source) {
            (WeightRule::Uniform, _) => Weighting::Uniform,
            (WeightRule::SolidAngle, SolidAngleSource::File) => Weighting::FileSolidAngles,
            (WeightRule::SolidAngle, SolidAngleSource::Computed) => Weighting::ComputedSolidAngles,
        };
        let mut counts = vec![0; self.selections.len()];
        for &g in removed_by.iter().flatten() {
            counts[g] += 1;
        }
        let gates = self
            .selections
            .iter()
            .zip(counts)
            .map(|(gate, removed)| GateCount {
                gate: *gate,
                removed,
            })
            .collect();
        Ok(PreparedMeasurement {
            source: source.to_string(),
            measurement,
            conversion,
            removed_by,
            gates,
            weighting,
            patch_pairs: None,
            directions,
            phi_turn_deg: turn,
            peak_arc_deg: peak.map(|p| p.arc_deg),
            shadows,
        })
    }

    /// Where the fitted samples' peak lies against the plane of incidence
    /// (judged on the first channel's converted value, or luminance).
    fn peak_azimuth(
        &self,
        (m, _, removed_by, directions, _): &Converted,
    ) -> Option<crate::align::PeakAzimuth> {
        if self.patch_average.is_some() {
            return None;
        }
        let channels = m.channels.count();
        let samples: Vec<(DVec3, f64)> = m
            .samples
            .iter()
            .zip(removed_by)
            .zip(directions)
            .filter(|((_, removed), _)| removed.is_none())
            .map(|((s, _), &d)| (d, sample_luminance(s, channels)))
            .filter(|(_, v)| v.is_finite())
            .collect();
        peak_azimuth(&samples, m.incidence.phi_deg)
    }

    /// The colour conversion, the fitted quantity (step 3) and the gates:
    /// the converted measurement, per sample the first gate it fails, and
    /// every sample's direction.
    fn convert_and_gate(
        &self,
        measurement: &Measurement,
        source: &str,
    ) -> Result<Converted, RecipeError> {
        let (measurement, conversion) = if self.colour == ColourConversion::XyzToRadianceRgb
            && measurement.channels == brtf_gonio::Channels::Xyz
        {
            let mut rgb = measurement.clone();
            for sample in &mut rgb.samples {
                sample.values = brtf_model::xyz_to_rgb(sample.values);
            }
            self.convert(&rgb, source)?
        } else {
            self.convert(measurement, source)?
        };
        // The conversion keeps the angles, so the directions are the same.
        let (removed_by, directions, shadows) = self.gate(&measurement);
        Ok((measurement, conversion, removed_by, directions, shadows))
    }

    /// Per sample of the converted `measurement` the first gate it fails,
    /// if any, every sample's direction, and the shadows a
    /// [`Gate::Shadow`] found (it judges the samples the gates before it
    /// kept, all at once).
    fn gate(
        &self,
        measurement: &Measurement,
    ) -> (Vec<Option<usize>>, Vec<DVec3>, Vec<ShadowRegion>) {
        let context = GateContext::of(measurement);
        let (mut removed_by, directions): (Vec<Option<usize>>, Vec<DVec3>) = measurement
            .samples
            .par_iter()
            .with_min_len(SAMPLE_PIECE)
            .map(|sample| {
                let direction = sample.direction();
                let removed = self
                    .selections
                    .iter()
                    .position(|gate| !gate.keeps_at(sample, || direction, &context));
                (removed, direction)
            })
            .unzip();
        let shadow = self
            .selections
            .iter()
            .enumerate()
            .find_map(|(g, gate)| match *gate {
                Gate::Shadow {
                    max_ratio,
                    min_theta_deg,
                } => Some((g, max_ratio, min_theta_deg)),
                _ => None,
            });
        let Some((g, max_ratio, min_theta_deg)) = shadow else {
            return (removed_by, directions, Vec::new());
        };
        let channels = measurement.channels.count();
        let values: Vec<f64> = measurement
            .samples
            .iter()
            .map(|s| sample_luminance(s, channels))
            .collect();
        let candidates: Vec<bool> = removed_by.iter().map(Option::is_none).collect();
        let found = brtf_gonio::shadow::detect(
            &directions,
            &values,
            &candidates,
            measurement.incidence.phi_deg,
            max_ratio,
            min_theta_deg,
        );
        for (removed, flagged) in removed_by.iter_mut().zip(&found.flagged) {
            if *flagged {
                *removed = Some(g);
            }
        }
        (removed_by, directions, found.regions)
    }

    /// Step 3: the fitted quantity.
    fn convert(
        &self,
        m: &Measurement,
        source: &str,
    ) -> Result<(Measurement, Conversion), RecipeError> {
        let failed = |e| RecipeError::Convert {
            origin: source.to_string(),
            source: e,
        };
        let not_raw = |what| RecipeError::ScaleNotRaw {
            origin: source.to_string(),
            what,
            quantity: m.quantity.name(),
        };
        let (unit, file_beam) = match &m.quantity {
            Quantity::Raw {
                unit,
                beam_integral,
            } => (unit.clone(), *beam_integral),
            other => {
                return match self.scale {
                    ScaleRule::BeamIntegral { .. } => Err(not_raw("--beam-integral")),
                    ScaleRule::KnownReflectance { .. } => Err(not_raw("--rho")),
                    ScaleRule::FromFiles if *other == Quantity::Dsf => {
                        Ok((m.to_bsdf().map_err(failed)?.measurement, Conversion::Dsf))
                    }
                    ScaleRule::FromFiles => Ok((m.clone(), Conversion::Bsdf)),
                };
            }
        };
        let scale = match (self.scale, file_beam) {
            (ScaleRule::BeamIntegral { value }, _) => RawScale::BeamIntegral {
                value,
                origin: BeamOrigin::Option,
            },
            (ScaleRule::FromFiles, Some(value)) => RawScale::BeamIntegral {
                value,
                origin: BeamOrigin::File,
            },
            (ScaleRule::FromFiles, None) => RawScale::Free,
            (ScaleRule::KnownReflectance { rho, theta_in, k }, _) => {
                RawScale::KnownReflectance { k, rho, theta_in }
            }
        };
        let beam = match scale {
            RawScale::BeamIntegral { value, .. } => value,
            _ => 1.0,
        };
        let mut converted = m.raw_to_bsdf(beam).map_err(failed)?.measurement;
        if let RawScale::KnownReflectance { k, .. } = scale {
            divide(&mut converted, k);
        }
        Ok((converted, Conversion::Raw { unit, scale }))
    }
}

/// Divides every used value of `m` by `k`.
fn divide(m: &mut Measurement, k: f64) {
    let channels = m.channels.count();
    for sample in &mut m.samples {
        for v in &mut sample.values[..channels] {
            *v /= k;
        }
    }
}

impl PreparedMeasurement {
    /// Values per sample (1 or 3).
    pub fn channels(&self) -> usize {
        self.measurement.channels.count().clamp(1, 3)
    }

    /// Samples the fit uses: `(index in the file, sample)`.
    pub fn fitted(&self) -> impl Iterator<Item = (usize, &brtf_gonio::Sample)> {
        self.measurement
            .samples
            .iter()
            .zip(&self.removed_by)
            .enumerate()
            .filter(|(_, (_, removed))| removed.is_none())
            .map(|(i, (s, _))| (i, s))
    }

    /// The model value the fit compares with sample `index` (file order):
    /// averaged over the sample's patch pairs for patch-averaged data,
    /// else the BSDF at the sample's direction.
    pub fn model_value(&self, bsdf: &brtf_model::Bsdf, index: usize) -> [f64; 3] {
        match &self.patch_pairs {
            Some(pairs) => pairs.average(bsdf, index),
            None => bsdf.eval(
                self.measurement.incident_direction(),
                self.directions[index],
            ),
        }
    }

    /// How many samples the fit uses.
    pub fn fitted_count(&self) -> usize {
        self.removed_by.iter().filter(|r| r.is_none()).count()
    }

    /// Divides every value by the instrument scale `k` of a known
    /// reflectance, as [`Recipe::prepare`] does for
    /// [`ScaleRule::KnownReflectance`] (the same operations, so the same
    /// numbers). Only free-scale raw data can be rescaled.
    pub fn rescale_known_reflectance(&mut self, k: f64, rho: f64, theta_in: f64) -> bool {
        let Conversion::Raw { unit, scale } = &self.conversion else {
            return false;
        };
        if *scale != RawScale::Free {
            return false;
        }
        divide(&mut self.measurement, k);
        self.conversion = Conversion::Raw {
            unit: unit.clone(),
            scale: RawScale::KnownReflectance { k, rho, theta_in },
        };
        true
    }

    /// The fitter's input: the fitted samples with their weights.
    pub fn incidence_data(&self) -> IncidenceData {
        let uniform = self.weighting == Weighting::Uniform;
        IncidenceData {
            source: self.source.clone(),
            theta_in: self.measurement.incidence.theta_deg,
            phi_in: self.measurement.incidence.phi_deg,
            channels: self.channels(),
            samples: self
                .measurement
                .samples
                .par_iter()
                .zip(&self.removed_by)
                .zip(&self.directions)
                .with_min_len(SAMPLE_PIECE)
                .filter(|((_, removed), _)| removed.is_none())
                .map(|((s, _), &view)| FitSample {
                    view,
                    value: s.values,
                    weight: if uniform {
                        1.0
                    } else {
                        s.solid_angle_sr.unwrap_or(1.0)
                    },
                })
                .collect(),
            gates: self.gates.clone(),
            weighting: self.weighting,
            cosine_weighted: !matches!(self.conversion, Conversion::Bsdf),
            // Shared, not copied, when every sample is fitted: a Klems
            // side's pairs take hundreds of MB.
            patch_pairs: self.patch_pairs.as_ref().map(|pairs| {
                if self.fitted_count() == pairs.len() {
                    std::sync::Arc::clone(pairs)
                } else {
                    std::sync::Arc::new(pairs.select(self.fitted().map(|(i, _)| i)))
                }
            }),
        }
    }
}

/// A converted sample's luminance (its one value for grey data): what the
/// peak and the shadows are judged on.
fn sample_luminance(s: &brtf_gonio::Sample, channels: usize) -> f64 {
    if channels == 3 {
        brtf_model::luminance(s.values)
    } else {
        s.values[0]
    }
}
