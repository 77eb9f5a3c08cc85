//! Re-reading the measurements of a fit and putting the fitted model next to
//! them, sample by sample, exactly as `brtf fit` compared them.
//!
//! This module owns the "recipe" that turns a measurement file into the
//! data the fitter saw, rebuilt from `fit.json`:
//!
//! * **Conversion** (from [`InputFile::quantity`]): BSDF files are used as
//!   they are, DSF files are divided by |cos θ_out|, raw-signal files by
//!   |cos θ_out| and by the beam integral or the `--rho` scale K when the
//!   fit had one. Without either the data stay in the file's unit and the
//!   model is `scale × f` with the fitted free scale ([`FitReport::scale`],
//!   1 when there is none).
//! * **Selections**, in the order of the report's [`FitReport::gates`]:
//!   not available, hemisphere, θ cap, beam mask, value floor. Every sample
//!   remembers whether it was fitted and, if not, which gate removed it.
//!
//! The rebuild is checked: the number of fitted samples must equal
//! [`FitReport::n_points`] and the RMS relative error recomputed here must
//! equal [`FitReport::rms_rel`]. A mismatch becomes a warning in the report,
//! so a plot never silently shows other data than the fit used.
//!
//! For three-channel data every plotted value (data and model) is the mean
//! of the three channels.

use crate::disk::{self, Coverage};
use brtf_fit::{FitReport, FitResult, InputFile};
use brtf_gonio::{Hemisphere, Measurement, Quantity};
use brtf_model::Bsdf;
use glam::DVec3;
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// One selection step of the fit, parsed from its [`brtf_fit::GateReport`].
#[derive(Debug, Clone, PartialEq)]
pub enum Gate {
    /// Values not available (9.9e+37) or not finite.
    Unavailable,
    /// Only one hemisphere.
    Hemisphere(Hemisphere),
    /// θ_out ≤ cap (degrees from the nearer normal).
    ThetaCap(f64),
    /// A cone of this half-angle (degrees) around the incident beam.
    BeamMask(f64),
    /// Values below this floor.
    MinValue(f64),
    /// A gate this version does not know; it is not reproduced.
    Unknown(String),
}

impl Gate {
    /// Parses the text `brtf fit` writes into `gates[].gate`.
    pub fn parse(text: &str) -> Gate {
        let t = text.trim();
        let number = |s: &str| s.trim().trim_end_matches('°').trim().parse::<f64>().ok();
        if t == "not available or not finite" {
            Gate::Unavailable
        } else if t == "front hemisphere only" {
            Gate::Hemisphere(Hemisphere::Front)
        } else if t == "back hemisphere only" {
            Gate::Hemisphere(Hemisphere::Back)
        } else if let Some(cap) = t.strip_prefix("theta_out <=").and_then(number) {
            Gate::ThetaCap(cap)
        } else if let Some(mask) = t.strip_suffix("beam mask").and_then(number) {
            Gate::BeamMask(mask)
        } else if let Some(v) = t.strip_prefix("value >=").and_then(number) {
            Gate::MinValue(v)
        } else {
            Gate::Unknown(t.to_string())
        }
    }

    /// A short label for legends.
    pub fn label(&self) -> String {
        match self {
            Gate::Unavailable => "not available".into(),
            Gate::Hemisphere(Hemisphere::Front) => "back hemisphere".into(),
            Gate::Hemisphere(Hemisphere::Back) => "front hemisphere".into(),
            Gate::ThetaCap(c) => format!("θ_out > {c}°"),
            Gate::BeamMask(m) => format!("{m}° beam mask"),
            Gate::MinValue(v) => format!("value < {v}"),
            Gate::Unknown(t) => t.clone(),
        }
    }

    fn apply(&self, m: &Measurement) -> Option<brtf_gonio::Selection> {
        match self {
            Gate::Unavailable => Some(m.drop_unavailable()),
            Gate::Hemisphere(h) => Some(m.select_hemisphere(*h)),
            Gate::ThetaCap(c) => Some(m.cap_theta(*c)),
            Gate::BeamMask(h) => Some(m.mask_incident_cone(*h)),
            Gate::MinValue(v) => Some(m.drop_below(*v)),
            Gate::Unknown(_) => None,
        }
    }
}

/// What the plotted data values are.
#[derive(Debug, Clone, PartialEq)]
pub enum DataUnit {
    /// BSDF in 1/sr (from BSDF, DSF or raw data with a beam integral).
    Bsdf,
    /// Raw signal ÷ |cos θ_out| in the file's unit (no beam integral; the
    /// model carries the free scale).
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

/// One sample of the file, with the model next to it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlotSample {
    /// θ_out in degrees.
    pub theta: f64,
    /// φ_out in degrees.
    pub phi: f64,
    /// Unit direction towards the detector.
    pub dir: DVec3,
    /// Measured value after conversion (channel mean); NaN if not available.
    pub data: f64,
    /// Model value `scale × f(l, v)` in the same unit (channel mean).
    pub model: f64,
    /// Index into [`Incidence::gates`] of the gate that removed the
    /// sample, `None` when it was fitted.
    pub removed_by: Option<usize>,
}

impl PlotSample {
    /// The sample was fitted.
    pub fn used(&self) -> bool {
        self.removed_by.is_none()
    }

    /// Front or back hemisphere.
    pub fn hemisphere(&self) -> Hemisphere {
        Hemisphere::of_theta(self.theta)
    }
}

/// One incidence: the report, the samples and what the plots need.
#[derive(Debug, Clone)]
pub struct Incidence {
    /// Position in [`FitResult::incidences`].
    pub index: usize,
    /// File-name tag (`t30`, or `t30-p90` when θ_in repeats).
    pub tag: String,
    /// Incident polar angle, degrees.
    pub theta_in: f64,
    /// Incident azimuth, degrees.
    pub phi_in: f64,
    /// Unit vector towards the light.
    pub light: DVec3,
    /// Every sample of the file.
    pub samples: Vec<PlotSample>,
    /// The selections, in the order they were applied.
    pub gates: Vec<Gate>,
    /// Unit of [`PlotSample::data`] and [`PlotSample::model`].
    pub unit: DataUnit,
    /// The floor of relative residuals and log ratios (the report's).
    pub floor: f64,
    /// The fitted material, prepared for evaluation.
    pub bsdf: Bsdf,
    /// The free scale (1 when not fitted).
    pub scale: f64,
    /// Channels in the file (1 or 3); plotted values are their mean.
    pub channels: usize,
    /// Things the reader should know about this incidence's plots.
    pub warnings: Vec<String>,
    /// Nearest-sample grids of the front and back disks, made when first needed.
    coverage: [OnceLock<Coverage>; 2],
}

impl Incidence {
    /// Every pixel of the `hemisphere`'s equal-area disk and the sample
    /// that owns it (fitted or not; an index into `samples`), computed on
    /// first use. The maps draw it, the hemispherical integrals sum over it.
    pub fn coverage(&self, hemisphere: Hemisphere) -> &Coverage {
        let slot = match hemisphere {
            Hemisphere::Front => 0,
            Hemisphere::Back => 1,
        };
        self.coverage[slot].get_or_init(|| {
            let (ids, points): (Vec<u32>, Vec<(f64, f64)>) = self
                .samples
                .iter()
                .enumerate()
                .filter(|(_, s)| s.hemisphere() == hemisphere && s.dir.is_finite())
                .filter(|(_, s)| !s.used() || s.data.is_finite())
                .map(|(k, s)| (k as u32, disk::project(s.dir, hemisphere)))
                .unzip();
            Coverage::new(
                &points,
                &ids,
                disk::COVERAGE_SIZE,
                disk::radius_of(disk::FILL_DEG),
            )
        })
    }

    /// Model value `scale × f` (channel mean) for direction `v`.
    pub fn model_at(&self, v: DVec3) -> f64 {
        let f = self.bsdf.eval(self.light, v);
        self.scale * f[..self.channels].iter().sum::<f64>() / self.channels as f64
    }

    /// The θ cap, if one was applied.
    pub fn theta_cap(&self) -> Option<f64> {
        self.gates.iter().find_map(|g| match g {
            Gate::ThetaCap(c) => Some(*c),
            _ => None,
        })
    }

    /// The beam-mask half-angle, if one was applied.
    pub fn beam_mask(&self) -> Option<f64> {
        self.gates.iter().find_map(|g| match g {
            Gate::BeamMask(m) if *m > 0.0 => Some(*m),
            _ => None,
        })
    }

    /// Hemispheres that hold fitted samples (front first).
    pub fn hemispheres(&self) -> Vec<Hemisphere> {
        [Hemisphere::Front, Hemisphere::Back]
            .into_iter()
            .filter(|h| {
                self.samples
                    .iter()
                    .any(|s| s.used() && s.hemisphere() == *h)
            })
            .collect()
    }

    /// Mirror direction (θ_in, φ_in + 180°).
    pub fn mirror(&self) -> DVec3 {
        DVec3::new(-self.light.x, -self.light.y, self.light.z)
    }

    /// `ln((model + floor)/(data + floor))` of a sample (data clamped at 0).
    pub fn log_ratio(&self, s: &PlotSample) -> f64 {
        ((s.model.max(0.0) + self.floor) / (s.data.max(0.0) + self.floor)).ln()
    }
}

/// Finds a measurement file: as given (relative to the current folder),
/// then relative to every extra folder, the fit folder and its ancestors.
pub fn locate(path: &str, fit_dir: &Path, search: &[PathBuf]) -> Option<PathBuf> {
    let given = Path::new(path);
    if given.is_file() {
        return Some(given.to_path_buf());
    }
    if given.is_absolute() {
        return None;
    }
    let mut bases: Vec<PathBuf> = search.to_vec();
    if let Ok(dir) = std::fs::canonicalize(fit_dir) {
        bases.extend(dir.ancestors().map(Path::to_path_buf));
    }
    bases
        .into_iter()
        .map(|b| b.join(given))
        .find(|p| p.is_file())
}

/// Hex SHA-256 of `bytes`.
fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// The number following `marker` in the quantity text, if any.
fn number_after(quantity: &str, marker: &str) -> Option<f64> {
    let rest = quantity.split(marker).nth(1)?;
    rest.split_whitespace().next()?.parse().ok()
}

/// What the fit divided raw signal by (besides |cos θ_out|), from the
/// quantity text: the beam integral (`raw [uA] ÷ beam integral 123 ÷ |cos
/// θ_out|`) or the instrument scale of `--rho` (`raw [uA] ÷ |cos θ_out| ÷ K
/// = 3.2e-2 from --rho 0.8@30`).
fn raw_divisor(quantity: &str) -> Option<f64> {
    number_after(quantity, "beam integral")
        .or_else(|| number_after(quantity, "÷ K ="))
        .filter(|v| v.is_finite() && *v > 0.0)
}

/// Converts the file's values to what the fitter compared (see the module
/// docs), with the unit they end up in.
fn convert(m: &Measurement, input: &InputFile) -> Result<(Measurement, DataUnit), String> {
    let converted = match &m.quantity {
        Quantity::Bsdf => return Ok((m.clone(), DataUnit::Bsdf)),
        Quantity::Dsf => m.to_bsdf().map(|c| (c.measurement, DataUnit::Bsdf)),
        Quantity::Raw { unit, .. } => match raw_divisor(&input.quantity) {
            Some(beam) => m.raw_to_bsdf(beam).map(|c| (c.measurement, DataUnit::Bsdf)),
            None => m
                .raw_to_bsdf(1.0)
                .map(|c| (c.measurement, DataUnit::RawPerCos(unit.clone()))),
        },
    };
    converted.map_err(|e| e.to_string())
}

/// Reads the file of `report` and builds the incidence, or says why not.
pub fn load(
    result: &FitResult,
    index: usize,
    tag: String,
    fit_dir: &Path,
    search: &[PathBuf],
) -> Result<Incidence, String> {
    let report = &result.incidences[index];
    let input = result
        .provenance
        .inputs
        .iter()
        .find(|i| i.path == report.source)
        .or_else(|| result.provenance.inputs.get(index))
        .ok_or_else(|| format!("{}: not listed in the provenance", report.source))?;
    let path = locate(&input.path, fit_dir, search).ok_or_else(|| {
        format!(
            "{}: measurement file not found (looked relative to the current folder and {}); \
             its map and cut are not drawn",
            input.path,
            fit_dir.display()
        )
    })?;
    let bytes =
        std::fs::read(&path).map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
    let mut warnings = Vec::new();
    if !input.sha256.is_empty() && sha256_hex(&bytes) != input.sha256 {
        warnings.push(format!(
            "{}: the file changed since the fit (SHA-256 differs); the plots show the new contents",
            input.path
        ));
    }
    let m = brtf_gonio::read_bytes(&bytes, &path).map_err(|e| e.to_string())?;
    let channels = m.channels.count().clamp(1, 3);
    let (m, unit) = convert(&m, input)?;
    let material = result
        .material_of(report)
        .ok_or_else(|| format!("{}: the fitted arguments are not a material", input.path))?;
    let bsdf = Bsdf::new(&material, &result.options());
    let light = brtf_model::direction(report.theta_in, report.phi_in);

    // Apply the gates in order, remembering which removed what.
    let gates: Vec<Gate> = report.gates.iter().map(|g| Gate::parse(&g.gate)).collect();
    let mut removed_by: Vec<Option<usize>> = vec![None; m.len()];
    let mut alive: Vec<usize> = (0..m.len()).collect();
    let mut current = m.clone();
    for (g, gate) in gates.iter().enumerate() {
        let Some(sel) = gate.apply(&current) else {
            warnings.push(format!(
                "{}: selection `{}` is not known to brtf-plot and was not reproduced",
                input.path,
                gate.label()
            ));
            continue;
        };
        let mut keep = vec![false; alive.len()];
        for &k in &sel.kept {
            keep[k] = true;
        }
        for (k, &orig) in alive.iter().enumerate() {
            if !keep[k] {
                removed_by[orig] = Some(g);
            }
        }
        alive = sel.kept.iter().map(|&k| alive[k]).collect();
        current = sel.measurement;
    }

    let floor = report.floor;
    let floor2 = floor * floor;
    let mut sum_rel = 0.0;
    let mut n_used = 0usize;
    let samples: Vec<PlotSample> = m
        .samples
        .iter()
        .zip(&removed_by)
        .map(|(s, removed)| {
            let dir = s.direction();
            let f = bsdf.eval(light, dir);
            let mut data = 0.0;
            let mut model = 0.0;
            for (&y, &fc) in s.values.iter().zip(&f).take(channels) {
                let mv = report.scale * fc;
                if removed.is_none() {
                    let e = mv - y;
                    sum_rel += e * e / (y * y + floor2);
                }
                data += y;
                model += mv;
            }
            if removed.is_none() {
                n_used += 1;
            }
            PlotSample {
                theta: s.theta_deg,
                phi: s.phi_deg,
                dir,
                data: data / channels as f64,
                model: model / channels as f64,
                removed_by: *removed,
            }
        })
        .collect();
    if n_used != report.n_points {
        warnings.push(format!(
            "{}: {} samples are marked as fitted here but the fit used {}; \
             the plotted selection may differ from the fit's",
            input.path, n_used, report.n_points
        ));
    } else {
        let rms = (sum_rel / (n_used * channels).max(1) as f64).sqrt();
        // Loose enough for numbers rounded in the quantity text.
        let tolerance = 1e-5 * report.rms_rel.abs().max(1e-9);
        if (rms - report.rms_rel).abs() > tolerance.max(1e-9) {
            warnings.push(format!(
                "{}: the RMS relative error recomputed from the file ({rms:.6}) differs from \
                 the fit's ({:.6}); the plotted data may not be what was fitted",
                input.path, report.rms_rel
            ));
        }
    }
    Ok(Incidence {
        index,
        tag,
        theta_in: report.theta_in,
        phi_in: report.phi_in,
        light,
        samples,
        gates,
        unit,
        floor,
        bsdf,
        scale: report.scale,
        channels,
        warnings,
        coverage: Default::default(),
    })
}

/// File-name tags for every incidence: `t<θ>`, plus `-p<φ>` when a θ_in
/// occurs more than once or φ_in is not 0, plus `-<k>` if still not unique.
pub fn tags(reports: &[FitReport]) -> Vec<String> {
    let mut tags: Vec<String> = reports
        .iter()
        .map(|r| {
            let repeated = reports.iter().filter(|o| o.theta_in == r.theta_in).count() > 1;
            if repeated || r.phi_in != 0.0 {
                format!("t{}-p{}", num(r.theta_in), num(r.phi_in))
            } else {
                format!("t{}", num(r.theta_in))
            }
        })
        .collect();
    for i in 0..tags.len() {
        if tags[..i].contains(&tags[i]) {
            tags[i] = format!("{}-{}", tags[i], i + 1);
        }
    }
    tags
}

/// A number for file names and labels: at most 4 decimals, no trailing zeros.
pub fn num(x: f64) -> String {
    let s = format!("{:.4}", x);
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gates_parse_as_brtf_fit_writes_them() {
        assert_eq!(
            Gate::parse("not available or not finite"),
            Gate::Unavailable
        );
        assert_eq!(
            Gate::parse("front hemisphere only"),
            Gate::Hemisphere(Hemisphere::Front)
        );
        assert_eq!(Gate::parse("theta_out <= 85°"), Gate::ThetaCap(85.0));
        assert_eq!(Gate::parse("3° beam mask"), Gate::BeamMask(3.0));
        assert_eq!(Gate::parse("2.5° beam mask"), Gate::BeamMask(2.5));
        assert_eq!(Gate::parse("value >= 0.001"), Gate::MinValue(0.001));
        assert!(matches!(Gate::parse("something new"), Gate::Unknown(_)));
    }

    #[test]
    fn the_raw_divisor_is_read_from_the_quantity_text() {
        assert_eq!(
            raw_divisor("raw [uA] ÷ beam integral 6.3 ÷ |cos θ_out|"),
            Some(6.3)
        );
        assert_eq!(
            raw_divisor("raw [uA] ÷ |cos θ_out|, free scale (no beam integral)"),
            None
        );
        assert_eq!(
            raw_divisor("raw [uA] ÷ |cos θ_out| ÷ K = 3.210000e-2 from --rho 0.8@30"),
            Some(0.0321)
        );
    }

    #[test]
    fn numbers_for_names_are_short() {
        assert_eq!(num(15.0), "15");
        assert_eq!(num(26.8421), "26.8421");
        assert_eq!(num(-0.0), "0");
        assert_eq!(num(2.5), "2.5");
    }
}
