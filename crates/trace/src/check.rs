//! `brtf check`: a fit rendered through the virtual gonio-photometer.
//!
//! For every fitted incidence it rebuilds the fitted data from the
//! measurement file with the fit's own [`brtf_fit::Recipe`] (so raw
//! signal gets the fit's beam integral, `--rho` scale or free scale),
//! renders the fitted material at those directions with the instrument's
//! beam size, and compares three things per sample:
//!
//! * **rendered vs measured**: what a renderer makes of the fit, against
//!   the data (÷ the fit's free scale, so both are BSDF);
//! * **rendered vs model**: the renderer against the fitted formula
//!   (brtf-model with the fit's options, including rtrace's source
//!   widening); differences show what the formula's approximations cost;
//! * the fit's own **model vs measured** RMS, for reference.
//!
//! Beside the RMS it gives E1, the share of the measured light put in the
//! wrong place (`Σ ω |a − d| / Σ ω |d|`, with the fit's sample weights and,
//! for files that hold BSDF × |cos θ_out|, that cosine), for the rendered
//! material against the data and the fit's own.
//!
//! The fit may be of any shape: one primitive, a lobe sum (the model is
//! brtf-model's `CompositeBsdf`, the render the [`Shader`] of the lobes)
//! or an anisotropic type with its orientation fitted (the frame turns
//! with θ_in as the table's `orient` does).
//!
//! Differences are relative with the fit's floor, `(a − b)/sqrt(b² + floor²)`,
//! the same measure as the fit's `rms_rel`. Between fitted incidences it
//! renders intermediate θ_in (the θ_in table's interpolation) at the lower
//! neighbour's directions and compares with the model only.

use crate::Shader;
use crate::gonio::{GonioSetup, VirtualGonio};
use brtf_fit::{FitReport, FitResult, Gate};
use brtf_model::{Composite, CompositeBsdf, Rgb};
use glam::DVec3;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// What the check renders.
#[derive(Debug, Clone)]
pub struct CheckOptions {
    /// Rays per detector direction.
    pub samples: u32,
    /// Largest number of directions rendered per incidence (`None`: all
    /// of them, so that energy and E1 are over every fitted direction).
    pub max_directions: Option<usize>,
    /// Beam solid angle in sr (`None`: the fit's source ω when it has one,
    /// else the file header's aperture, else [`DEFAULT_SOURCE_APERTURE_DEG`]).
    pub source_omega: Option<f64>,
    /// Detector aperture solid angle in sr (`None`: the file header's,
    /// else [`DEFAULT_DETECTOR_APERTURE_DEG`]).
    pub detector_omega: Option<f64>,
    /// Intermediate θ_in rendered between neighbouring fitted incidences.
    pub intermediate: usize,
    /// Random seed.
    pub seed: u64,
    /// Extra folders to look for the measurement files in.
    pub search_dirs: Vec<PathBuf>,
}

impl Default for CheckOptions {
    fn default() -> Self {
        CheckOptions {
            samples: 128,
            max_directions: None,
            source_omega: None,
            detector_omega: None,
            intermediate: 1,
            seed: 1,
            search_dirs: Vec::new(),
        }
    }
}

impl CheckOptions {
    /// Checks the numbers before any work, naming the option: 1 to 10⁶
    /// rays per direction, 1 to 10⁷ directions, at most 100 intermediate
    /// incidences per interval, solid angles from 0 to 2π sr.
    pub fn validate(&self) -> Result<(), brtf_model::OptionError> {
        use brtf_model::OptionError;
        let samples = f64::from(self.samples);
        OptionError::check(
            "--samples",
            samples,
            (1.0..=1e6).contains(&samples),
            "1 to 1,000,000",
        )?;
        let directions = self.max_directions.unwrap_or(1) as f64;
        let ok = (1.0..=1e7).contains(&directions);
        OptionError::check("--max-directions", directions, ok, "1 to 10,000,000")?;
        let intermediate = self.intermediate as f64;
        OptionError::check(
            "--intermediate",
            intermediate,
            intermediate <= 100.0,
            "0 to 100",
        )?;
        let hemisphere = 2.0 * std::f64::consts::PI;
        for (option, omega) in [
            ("--source-omega", self.source_omega.unwrap_or(0.0)),
            ("--detector-omega", self.detector_omega.unwrap_or(0.0)),
        ] {
            let ok = (0.0..=hemisphere).contains(&omega);
            OptionError::check(option, omega, ok, "0 to 2π sr")?;
        }
        Ok(())
    }
}

/// The beam aperture (full cone angle, degrees) a check assumes when
/// neither the user, the fit nor the file gives one: the pgII's, and
/// `brtf synth`'s default.
pub const DEFAULT_SOURCE_APERTURE_DEG: f64 = 0.5;
/// The detector aperture a check assumes when nobody gives one.
pub const DEFAULT_DETECTOR_APERTURE_DEG: f64 = 0.75;

/// Where an aperture of the check came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ApertureOrigin {
    /// `--source-omega`/`--detector-omega` (or the apex options).
    Given,
    /// The fit's own source ω (`brtf fit --source-omega`).
    FitModel,
    /// The measurement file's header.
    Header,
    /// The stated default ([`DEFAULT_SOURCE_APERTURE_DEG`], …).
    Default,
}

impl std::fmt::Display for ApertureOrigin {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            ApertureOrigin::Given => "given",
            ApertureOrigin::FitModel => "the fit's source ω",
            ApertureOrigin::Header => "from the file header",
            ApertureOrigin::Default => "a typical pgII aperture: the file states none",
        })
    }
}

/// Why a check could not run.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CheckError {
    /// The fit holds no valid material.
    #[error("the fit holds no valid material")]
    NoMaterial,
    /// A solid angle is negative or not finite.
    #[error("solid angles must be ≥ 0 sr")]
    BadSolidAngle,
    /// The shader could not be made.
    #[error(transparent)]
    Shader(#[from] crate::ShaderError),
    /// A measurement file could not be read or prepared.
    #[error("{0}")]
    Data(String),
}

/// Whether a row is a fitted incidence or one between two.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RowKind {
    /// A fitted incidence, compared with its data.
    Fitted,
    /// Between two fitted incidences, compared with the model only.
    Intermediate,
}

impl std::fmt::Display for RowKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            RowKind::Fitted => "fitted",
            RowKind::Intermediate => "intermediate",
        })
    }
}

/// One row of the check.
#[derive(Debug, Clone)]
pub struct CheckRow {
    /// Incidence, degrees.
    pub theta_in: f64,
    /// Incidence azimuth, degrees.
    pub phi_in: f64,
    /// Fitted or intermediate.
    pub kind: RowKind,
    /// Directions rendered.
    pub n: usize,
    /// Directions the fit used at this incidence (`n` unless subsampled).
    pub of: usize,
    /// The fit's model-vs-data RMS (fitted incidences).
    pub fit_rms: Option<f64>,
    /// The fit's E1 (fitted incidences; over all its samples).
    pub fit_e1: Option<f64>,
    /// E1 of the rendered material against the data (over the rendered
    /// directions).
    pub render_vs_data_e1: Option<f64>,
    /// RMS relative difference, rendered vs measured.
    pub render_vs_data_rms: Option<f64>,
    /// RMS relative difference, rendered vs model.
    pub render_vs_model_rms: f64,
    /// Largest relative difference, rendered vs model.
    pub render_vs_model_max: f64,
    /// Σ rendered·|cos|·Ω / Σ measured·|cos|·Ω.
    pub render_data_ratio: Option<f64>,
    /// Σ rendered·|cos|·Ω / Σ model·|cos|·Ω.
    pub render_model_ratio: f64,
    /// RMS of the Monte Carlo standard error, relative as above.
    pub mc_rel: f64,
    /// The measurement file was not found: compared with the model only.
    pub data_missing: bool,
}

/// The whole check.
#[derive(Debug, Clone)]
pub struct CheckReport {
    /// The fit's name and model.
    pub name: String,
    /// The fitted shape: `metal`, `metal ×2 lobes`, `metal2 (orientation fitted)`...
    pub shape: brtf_model::Shape,
    /// The θ_in table was rendered (else the static material).
    pub table: bool,
    /// One row per fitted and intermediate incidence, by θ_in.
    pub rows: Vec<CheckRow>,
    /// Beam and detector solid angles used, sr.
    pub source_omega: f64,
    /// The fit model's source ω, sr.
    pub fit_source_omega: f64,
    /// Detector solid angle, sr.
    pub detector_omega: f64,
    /// Where the beam's and the detector's apertures came from.
    pub aperture_origins: [ApertureOrigin; 2],
    /// Rays per direction.
    pub samples: u32,
}

/// What is compared at one incidence.
struct Directions {
    theta_in: f64,
    phi_in: f64,
    /// Directions (towards the detector) and their solid angles.
    dirs: Vec<DVec3>,
    weights: Vec<f64>,
    /// The fitted directions before subsampling.
    total: usize,
    /// Measured BSDF per direction (÷ the fit's scale), `channels` used.
    measured: Option<Vec<Rgb>>,
    /// E1's weight per direction: the fit's sample weight, times |cos θ_out|
    /// when the file's quantity holds it (empty without data).
    e1_weights: Vec<f64>,
    channels: usize,
    /// The floor of relative differences, in BSDF units.
    floor: f64,
}

/// Runs the check of `fit`, whose folder is `dir`.
pub fn check_fit(
    fit: &FitResult,
    dir: &Path,
    options: &CheckOptions,
) -> Result<CheckReport, CheckError> {
    let eval_options = fit.options();
    let mut fitted = Vec::new();
    let mut stated = brtf_gonio::Apertures::default();
    for index in 0..fit.incidences.len() {
        let (directions, apertures) = fitted_directions(fit, index, dir, options)?;
        stated.source_deg = stated.source_deg.or(apertures.source_deg);
        stated.detector_deg = stated.detector_deg.or(apertures.detector_deg);
        fitted.push(directions);
    }
    let fit_source = (eval_options.source_omega > 0.0).then_some(eval_options.source_omega);
    let cone = |deg: Option<f64>| deg.map(brtf_model::cone_solid_angle);
    let (source_omega, source_origin) = resolve_aperture([
        (options.source_omega, ApertureOrigin::Given),
        (fit_source, ApertureOrigin::FitModel),
        (cone(stated.source_deg), ApertureOrigin::Header),
    ])
    .unwrap_or((
        brtf_model::cone_solid_angle(DEFAULT_SOURCE_APERTURE_DEG),
        ApertureOrigin::Default,
    ));
    let (detector_omega, detector_origin) = resolve_aperture([
        (options.detector_omega, ApertureOrigin::Given),
        (cone(stated.detector_deg), ApertureOrigin::Header),
    ])
    .unwrap_or((
        brtf_model::cone_solid_angle(DEFAULT_DETECTOR_APERTURE_DEG),
        ApertureOrigin::Default,
    ));
    let valid = |omega: f64| omega.is_finite() && omega >= 0.0;
    if !valid(source_omega) || !valid(detector_omega) {
        return Err(CheckError::BadSolidAngle);
    }
    let shader = match &fit.table {
        Some(table) => Shader::from_table(table, &eval_options)?,
        None => Shader::new(
            &fit.static_composite().ok_or(CheckError::NoMaterial)?,
            &eval_options,
        )?,
    };
    let render = |material: &Composite, d: &Directions, kind: RowKind| {
        let setup = GonioSetup {
            theta_in: d.theta_in,
            phi_in: d.phi_in,
            source_omega,
            detector_omega,
            samples: options.samples.max(1),
            seed: options.seed,
        };
        compare(&shader, material, fit, setup, d, kind)
    };
    let mut rows = Vec::new();
    for (report, directions) in fit.incidences.iter().zip(&fitted) {
        let material = fit
            .composite_at_direction(report.theta_in, report.phi_in, Some(report))
            .ok_or(CheckError::NoMaterial)?;
        let mut row = render(&material, directions, RowKind::Fitted);
        row.fit_rms = Some(report.rms_rel);
        row.fit_e1 = report.e1;
        row.data_missing = directions.measured.is_none();
        rows.push(row);
    }
    // Intermediate incidences between neighbouring fitted ones.
    if fit.table.is_some() && options.intermediate > 0 {
        fitted.sort_by(|a, b| a.theta_in.total_cmp(&b.theta_in));
        for pair in fitted.windows(2) {
            let (lo, hi) = (&pair[0], &pair[1]);
            for k in 1..=options.intermediate {
                let t = lo.theta_in
                    + (hi.theta_in - lo.theta_in) * k as f64 / (options.intermediate + 1) as f64;
                let material = fit
                    .composite_at_direction(t, lo.phi_in, None)
                    .ok_or(CheckError::NoMaterial)?;
                // The neighbour's directions, minus those near this beam.
                let between = Directions {
                    theta_in: t,
                    phi_in: lo.phi_in,
                    dirs: lo.dirs.clone(),
                    weights: lo.weights.clone(),
                    total: lo.total,
                    measured: None,
                    e1_weights: Vec::new(),
                    channels: lo.channels,
                    floor: 0.5 * (lo.floor + hi.floor),
                };
                let between = mask_beam(between, beam_mask(fit));
                rows.push(render(&material, &between, RowKind::Intermediate));
            }
        }
        rows.sort_by(|a, b| a.theta_in.total_cmp(&b.theta_in));
    }
    Ok(CheckReport {
        name: fit.name.clone(),
        shape: fit.config.shape(),
        table: fit.table.is_some(),
        rows,
        source_omega,
        fit_source_omega: eval_options.source_omega,
        detector_omega,
        aperture_origins: [source_origin, detector_origin],
        samples: options.samples.max(1),
    })
}

/// The first aperture (solid angle, sr) someone gave, with its origin.
fn resolve_aperture<const N: usize>(
    candidates: [(Option<f64>, ApertureOrigin); N],
) -> Option<(f64, ApertureOrigin)> {
    candidates
        .into_iter()
        .find_map(|(omega, origin)| omega.map(|o| (o, origin)))
}

/// The fit's beam-mask half-angle, degrees (0: none).
fn beam_mask(fit: &FitResult) -> f64 {
    fit.recipe
        .selections
        .iter()
        .find_map(|g| match g {
            Gate::BeamMask { half_angle_deg } => Some(*half_angle_deg),
            _ => None,
        })
        .unwrap_or(0.0)
}

/// The directions and data the fit of incidence `index` used (evenly
/// subsampled), or a model-only grid when its file is not found; with the
/// apertures the file's header states.
fn fitted_directions(
    fit: &FitResult,
    index: usize,
    dir: &Path,
    options: &CheckOptions,
) -> Result<(Directions, brtf_gonio::Apertures), CheckError> {
    let report = &fit.incidences[index];
    let scale = if report.scale > 0.0 {
        report.scale
    } else {
        1.0
    };
    let floor = if report.floor > 0.0 {
        report.floor / scale
    } else {
        1e-6
    };
    let input = fit.input_of(index);
    let located = input
        .and_then(|input| brtf_io::locate_input(&input.path, dir, &options.search_dirs))
        .zip(input);
    let Some((path, input)) = located else {
        let grid = model_grid(report, floor, beam_mask(fit));
        return Ok((grid, brtf_gonio::Apertures::default()));
    };
    let data = |e: String| CheckError::Data(format!("{}: {e}", path.display()));
    let bytes = brtf_io::read_input(&path).map_err(|e| data(e.to_string()))?;
    let prepared = brtf_fit::prepare_input(&fit.recipe, input, &bytes, &path)
        .map_err(|e| data(e.to_string()))?;
    let channels = prepared.channels();
    let total = prepared.fitted_count();
    let cap = options.max_directions.unwrap_or(total).max(1);
    let stride = total.div_ceil(cap).max(1);
    let samples: Vec<_> = prepared.fitted().step_by(stride).map(|(_, s)| s).collect();
    // The fitter's view of the same samples (in the same order): E1's weights.
    let fitted = prepared.incidence_data();
    let e1_weights = fitted
        .samples
        .iter()
        .step_by(stride)
        .map(|s| {
            let cosine = if fitted.cosine_weighted {
                s.view.z.abs()
            } else {
                1.0
            };
            s.weight.max(0.0) * cosine
        })
        .collect();
    let directions = Directions {
        theta_in: report.theta_in,
        phi_in: report.phi_in,
        total,
        dirs: samples.iter().map(|s| s.direction()).collect(),
        weights: samples
            .iter()
            .map(|s| s.solid_angle_sr.unwrap_or(1.0))
            .collect(),
        measured: Some(
            samples
                .iter()
                .map(|s| {
                    let v = s.values.map(|x| x / scale);
                    if channels == 1 { [v[0]; 3] } else { v }
                })
                .collect(),
        ),
        e1_weights,
        channels,
        floor,
    };
    Ok((directions, prepared.measurement.apertures()))
}

/// Without data: the model on a 5° × 15° grid of the front hemisphere.
fn model_grid(report: &FitReport, floor: f64, mask_deg: f64) -> Directions {
    let mut dirs = Vec::new();
    for t in (0..=80).step_by(5) {
        for p in (0..360).step_by(15) {
            dirs.push(brtf_model::direction(t as f64, p as f64));
        }
    }
    let n = dirs.len();
    let total = n;
    mask_beam(
        Directions {
            theta_in: report.theta_in,
            phi_in: report.phi_in,
            dirs,
            total,
            weights: vec![1.0; n],
            measured: None,
            e1_weights: Vec::new(),
            channels: 3,
            floor,
        },
        mask_deg,
    )
}

/// Drops directions within `half_angle_deg` of the beam.
fn mask_beam(mut d: Directions, half_angle_deg: f64) -> Directions {
    if half_angle_deg <= 0.0 {
        return d;
    }
    let l = brtf_model::direction(d.theta_in, d.phi_in);
    let cos_limit = half_angle_deg.to_radians().cos();
    let keep: Vec<bool> = d.dirs.iter().map(|v| v.dot(l) < cos_limit).collect();
    let mut flags = keep.iter();
    d.dirs.retain(|_| *flags.next().expect("same length"));
    let mut flags = keep.iter();
    d.weights.retain(|_| *flags.next().expect("same length"));
    if let Some(m) = &mut d.measured {
        let mut flags = keep.iter();
        m.retain(|_| *flags.next().expect("same length"));
    }
    if !d.e1_weights.is_empty() {
        let mut flags = keep.iter();
        d.e1_weights.retain(|_| *flags.next().expect("same length"));
    }
    d
}

/// Renders `d` and compares it with the model and the data.
#[allow(clippy::needless_range_loop)] // channel loops index several arrays at once
fn compare(
    shader: &Shader,
    material: &Composite,
    fit: &FitResult,
    setup: GonioSetup,
    d: &Directions,
    kind: RowKind,
) -> CheckRow {
    let gonio = VirtualGonio::new(shader.clone(), setup);
    let (rendered, _) = gonio.render(&d.dirs);
    let bsdf = CompositeBsdf::new(material, &fit.options());
    let l = setup.light();
    let model: Vec<Rgb> = d.dirs.iter().map(|&v| bsdf.eval(l, v)).collect();
    let channels = d.channels.clamp(1, 3);
    let floor2 = d.floor * d.floor;
    let rel = |a: f64, b: f64| (a - b) / (b * b + floor2).sqrt();
    let (mut sum_rm, mut max_rm, mut sum_mc, mut count) = (0.0, 0.0f64, 0.0, 0usize);
    let (mut energy_rendered, mut energy_model) = (0.0, 0.0);
    for (i, (r, m)) in rendered.iter().zip(&model).enumerate() {
        let w = d.weights[i] * d.dirs[i].z.abs();
        for c in 0..channels {
            let diff = rel(r.bsdf[c], m[c]);
            sum_rm += diff * diff;
            max_rm = max_rm.max(diff.abs());
            let e = r.std_err[c] / (m[c] * m[c] + floor2).sqrt();
            sum_mc += e * e;
            count += 1;
            energy_rendered += w * r.bsdf[c];
            energy_model += w * m[c];
        }
    }
    let n = count.max(1) as f64;
    let (render_vs_data_rms, render_data_ratio, render_vs_data_e1) = match &d.measured {
        Some(data) => {
            let (mut sum, mut energy_data) = (0.0, 0.0);
            let (mut misfit, mut light) = (0.0, 0.0);
            for (i, (r, y)) in rendered.iter().zip(data).enumerate() {
                let w = d.weights[i] * d.dirs[i].z.abs();
                let e1_weight = d.e1_weights.get(i).copied().unwrap_or(0.0);
                for c in 0..channels {
                    let diff = rel(r.bsdf[c], y[c]);
                    sum += diff * diff;
                    energy_data += w * y[c];
                    misfit += e1_weight * (r.bsdf[c] - y[c]).abs();
                    light += e1_weight * y[c].abs();
                }
            }
            let e1 = (light > 0.0).then(|| misfit / light);
            (
                Some((sum / n).sqrt()),
                Some(energy_rendered / energy_data),
                e1,
            )
        }
        None => (None, None, None),
    };
    CheckRow {
        theta_in: d.theta_in,
        phi_in: d.phi_in,
        kind,
        n: d.dirs.len(),
        of: d.total.max(d.dirs.len()),
        fit_rms: None,
        fit_e1: None,
        render_vs_data_e1,
        render_vs_data_rms,
        render_vs_model_rms: (sum_rm / n).sqrt(),
        render_vs_model_max: max_rm,
        render_data_ratio,
        render_model_ratio: energy_rendered / energy_model,
        mc_rel: (sum_mc / n).sqrt(),
        data_missing: false,
    }
}

impl CheckReport {
    /// The rows as CSV (`check.csv`).
    pub fn csv(&self) -> Result<String, csv::Error> {
        let mut w = csv::Writer::from_writer(Vec::new());
        w.write_record([
            "theta_in",
            "phi_in",
            "kind",
            "n",
            "fit_rms_rel",
            "render_vs_data_rms_rel",
            "fit_e1",
            "render_vs_data_e1",
            "render_vs_model_rms_rel",
            "render_vs_model_max_rel",
            "render_data_energy_ratio",
            "render_model_energy_ratio",
            "mc_rms_rel",
        ])?;
        let o = |x: Option<f64>| x.map_or_else(String::new, |v| v.to_string());
        for r in &self.rows {
            w.write_record([
                r.theta_in.to_string(),
                r.phi_in.to_string(),
                r.kind.to_string(),
                r.n.to_string(),
                o(r.fit_rms),
                o(r.render_vs_data_rms),
                o(r.fit_e1),
                o(r.render_vs_data_e1),
                r.render_vs_model_rms.to_string(),
                r.render_vs_model_max.to_string(),
                o(r.render_data_ratio),
                r.render_model_ratio.to_string(),
                r.mc_rel.to_string(),
            ])?;
        }
        let bytes = w
            .into_inner()
            .map_err(|e| csv::Error::from(e.into_error()))?;
        Ok(String::from_utf8(bytes).expect("CSV of UTF-8 text is UTF-8"))
    }
}

impl std::fmt::Display for CheckReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let opt = |x: Option<f64>| x.map_or_else(|| "-".to_string(), |v| format!("{v:.4}"));
        let percent =
            |x: Option<f64>| x.map_or_else(|| "-".to_string(), |v| format!("{:.1}%", 100.0 * v));
        writeln!(
            f,
            "brtf check {}: {} ({}); relative differences (a − b)/sqrt(b² + floor²)",
            self.name,
            self.shape,
            if self.table { "θ_in table" } else { "static" },
        )?;
        let mut s = String::new();
        let _ = writeln!(
            s,
            "{:>8} {:>7} {:<12} {:>6} {:>9} {:>12} {:>7} {:>12} {:>13} {:>13} {:>11} {:>12} {:>8}",
            "theta_in",
            "phi_in",
            "kind",
            "n",
            "fit rms",
            "render-data",
            "fit E1",
            "render-data",
            "render-model",
            "render-model",
            "energy",
            "energy",
            "MC"
        );
        let _ = writeln!(
            s,
            "{:>8} {:>7} {:<12} {:>6} {:>9} {:>12} {:>7} {:>12} {:>13} {:>13} {:>11} {:>12} {:>8}",
            "", "", "", "", "", "rms", "", "E1", "rms", "max", "render/data", "render/model", "rms"
        );
        for r in &self.rows {
            let _ = writeln!(
                s,
                "{:>8.2} {:>7.2} {:<12} {:>6} {:>9} {:>12} {:>7} {:>12} {:>13.4} {:>13.4} {:>11} {:>12.4} {:>8.4}{}",
                r.theta_in,
                r.phi_in,
                r.kind.to_string(),
                r.n,
                opt(r.fit_rms),
                opt(r.render_vs_data_rms),
                percent(r.fit_e1),
                percent(r.render_vs_data_e1),
                r.render_vs_model_rms,
                r.render_vs_model_max,
                opt(r.render_data_ratio),
                r.render_model_ratio,
                r.mc_rel,
                if r.data_missing {
                    "  (measurement file not found: model only)"
                } else {
                    ""
                }
            );
        }
        f.write_str(&s)?;
        let [source_origin, detector_origin] = self.aperture_origins;
        writeln!(
            f,
            "beam {} ({}), detector {} ({}); fit model's source {:.3e} sr; {} rays per direction",
            aperture_text(self.source_omega),
            source_origin,
            aperture_text(self.detector_omega),
            detector_origin,
            self.fit_source_omega,
            self.samples
        )?;
        let fitted = || {
            self.rows
                .iter()
                .filter(|r| r.kind == RowKind::Fitted && !r.data_missing)
        };
        let (n, of) = fitted().fold((0, 0), |(n, of), r| (n + r.n, of + r.of));
        if n < of {
            writeln!(
                f,
                "note: --max-directions rendered {n} of the {of} fitted directions: energy and \
                 E1 are over those only"
            )?;
        }
        if self.is_tautology() {
            writeln!(
                f,
                "note: a point beam and a point detector on a point-source fit: the render \
                 evaluates the fitted model itself, so render − model is 0 by construction and \
                 render − data repeats the fit; give --source-omega and --detector-omega (the \
                 instrument's apertures) for a check that can fail"
            )?;
        }
        Ok(())
    }
}

/// A solid angle as its cone's full apex angle and in sr.
fn aperture_text(omega: f64) -> String {
    if omega <= 0.0 {
        return "a point".to_string();
    }
    let apex = brtf_model::cone_apex_deg(omega);
    format!("{apex:.3}° cone = {omega:.3e} sr")
}

impl CheckReport {
    /// True when the check cannot differ from the fit: a point beam and a
    /// point detector on a fit made with a point source.
    pub fn is_tautology(&self) -> bool {
        self.source_omega == 0.0 && self.detector_omega == 0.0 && self.fit_source_omega == 0.0
    }
}
