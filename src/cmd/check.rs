//! `brtf check DIR`: renders a fit through the virtual gonio-photometer.
//!
//! For every fitted incidence it reads the measurement file again (the
//! path recorded in `fit.json`), renders the fitted material at the
//! file's sample directions with the instrument's beam size, and compares
//! three things per sample:
//!
//! * **rendered vs measured**: what a renderer makes of the fit, against
//!   the data;
//! * **rendered vs model**: the renderer against the fitted formula
//!   (brtf-model with the fit's options, including rtrace's source
//!   widening); differences show what the formula's approximations cost;
//! * the fit's own **model vs measured** RMS, for reference.
//!
//! Differences are relative with the fit's floor, `(a − b)/sqrt(b² + floor²)`,
//! the same measure as the fit's `rms_rel`. Between fitted incidences it
//! renders intermediate θ_in (the θ_in table's interpolation) at the lower
//! neighbour's directions and compares with the model only. A CSV goes to
//! `DIR/check.csv`.

use super::output::write_atomic;
use super::render::{read_fit, with_jobs};
use anyhow::{Context, Result};
use brtf_fit::{FitReport, FitResult};
use brtf_gonio::{Hemisphere, Measurement, Quantity};
use brtf_model::{Bsdf, EvalOptions, Material, Rgb};
use brtf_trace::Shader;
use brtf_trace::gonio::{GonioSetup, VirtualGonio};
use clap::Args;
use glam::DVec3;
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct CheckArgs {
    /// The fit folder (holds fit.json).
    pub dir: PathBuf,
    /// Rays per detector direction.
    #[arg(long, default_value_t = 128)]
    pub samples: u32,
    /// Largest number of directions rendered per incidence (evenly subsampled).
    #[arg(long, default_value_t = 4000)]
    pub max_directions: usize,
    /// Beam solid angle in sr [default: the fit's source ω].
    #[arg(long, value_name = "SR")]
    pub source_omega: Option<f64>,
    /// Beam as a full cone apex angle in degrees.
    #[arg(long, value_name = "DEG", conflicts_with = "source_omega")]
    pub source_apex: Option<f64>,
    /// Detector aperture solid angle in sr [default: a point].
    #[arg(long, value_name = "SR")]
    pub detector_omega: Option<f64>,
    /// Detector aperture as a full cone apex angle in degrees.
    #[arg(long, value_name = "DEG", conflicts_with = "detector_omega")]
    pub detector_apex: Option<f64>,
    /// Intermediate θ_in rendered between neighbouring fitted incidences.
    #[arg(long, default_value_t = 1)]
    pub intermediate: usize,
    /// Largest θ_out (from the nearer normal) compared, degrees.
    #[arg(long, default_value_t = brtf_gonio::DEFAULT_THETA_CAP_DEG)]
    pub theta_cap: f64,
    /// Half-angle of the cone around the incident beam left out, degrees.
    #[arg(long, default_value_t = 3.0)]
    pub beam_mask: f64,
    /// Beam integral for raw-signal files (else the file's, else the fit's free scale).
    #[arg(long)]
    pub beam_integral: Option<f64>,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// CSV output [default: DIR/check.csv].
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Worker threads [default: all cores].
    #[arg(long)]
    pub jobs: Option<usize>,
}

/// One row of the check.
#[derive(Debug, Clone)]
pub struct CheckRow {
    pub theta_in: f64,
    pub phi_in: f64,
    /// `fitted` or `intermediate`.
    pub kind: &'static str,
    pub n: usize,
    /// The fit's model-vs-data RMS (fitted incidences).
    pub fit_rms: Option<f64>,
    pub render_vs_data_rms: Option<f64>,
    pub render_vs_model_rms: f64,
    pub render_vs_model_max: f64,
    /// Σ rendered·|cos|·Ω / Σ measured·|cos|·Ω.
    pub render_data_ratio: Option<f64>,
    /// Σ rendered·|cos|·Ω / Σ model·|cos|·Ω.
    pub render_model_ratio: f64,
    /// RMS of the Monte Carlo standard error, relative as above.
    pub mc_rel: f64,
    pub note: String,
}

/// What is compared at one incidence.
struct Geometry {
    theta_in: f64,
    phi_in: f64,
    /// Directions (towards the detector) and their solid angles.
    dirs: Vec<DVec3>,
    weights: Vec<f64>,
    /// Measured BSDF per direction (÷ the fit's scale), `channels` used.
    measured: Option<Vec<Rgb>>,
    channels: usize,
    floor: f64,
}

pub fn run(args: CheckArgs) -> Result<()> {
    let fit = read_fit(&args.dir)?;
    let rows = check_fit(&fit, &args.dir, &args)?;
    let table = format_table(&fit, &rows);
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    write!(out, "{table}")?;
    let omega = |w: Option<f64>, a: Option<f64>, default: f64| {
        w.or(a.map(brtf_model::cone_solid_angle)).unwrap_or(default)
    };
    writeln!(
        out,
        "beam {:.3e} sr (fit model: {:.3e} sr), detector {:.3e} sr, {} rays per direction",
        omega(
            args.source_omega,
            args.source_apex,
            fit.options().source_omega
        ),
        fit.options().source_omega,
        omega(args.detector_omega, args.detector_apex, 0.0),
        args.samples
    )?;
    drop(out);
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| args.dir.join("check.csv"));
    write_atomic(&out, csv(&rows).as_bytes())?;
    eprintln!("brtf check: wrote {}", out.display());
    Ok(())
}

/// Runs the whole check (also used by tests through the binary).
pub fn check_fit(fit: &FitResult, dir: &Path, args: &CheckArgs) -> Result<Vec<CheckRow>> {
    let options = fit.options();
    let apex = |a: Option<f64>| a.map(brtf_model::cone_solid_angle);
    let source_omega = args
        .source_omega
        .or(apex(args.source_apex))
        .unwrap_or(options.source_omega);
    let detector_omega = args
        .detector_omega
        .or(apex(args.detector_apex))
        .unwrap_or(0.0);
    anyhow::ensure!(
        source_omega.is_finite()
            && source_omega >= 0.0
            && detector_omega.is_finite()
            && detector_omega >= 0.0,
        "solid angles must be ≥ 0 sr"
    );
    let shader = match &fit.table {
        Some(table) => Shader::from_table(table, &options)?,
        None => Shader::new(
            &fit.static_material()
                .context("the fit holds no valid material")?,
            &options,
        ),
    };
    let mut rows = Vec::new();
    let mut geometries: Vec<(f64, Geometry)> = Vec::new();
    for report in &fit.incidences {
        let geometry = fitted_geometry(fit, report, dir, args)?;
        let material = material_at(fit, report.theta_in, Some(report))?;
        let row = compare(
            &shader,
            &material,
            &options,
            &geometry,
            (source_omega, detector_omega),
            args,
            "fitted",
        )?;
        let mut row = row;
        row.fit_rms = Some(report.rms_rel);
        if geometry.measured.is_none() {
            row.note = "measurement file not found: model only".into();
        }
        rows.push(row);
        geometries.push((report.theta_in, geometry));
    }
    // Intermediate incidences between neighbouring fitted ones.
    if fit.table.is_some() && args.intermediate > 0 {
        geometries.sort_by(|a, b| a.0.total_cmp(&b.0));
        for pair in geometries.windows(2) {
            let (lo, hi) = (&pair[0].1, &pair[1].1);
            for k in 1..=args.intermediate {
                let t = lo.theta_in
                    + (hi.theta_in - lo.theta_in) * k as f64 / (args.intermediate + 1) as f64;
                let material = material_at(fit, t, None)?;
                let geometry = Geometry {
                    theta_in: t,
                    phi_in: lo.phi_in,
                    dirs: lo.dirs.clone(),
                    weights: lo.weights.clone(),
                    measured: None,
                    channels: lo.channels,
                    floor: 0.5 * (lo.floor + hi.floor),
                };
                // The neighbour's directions, minus those near this beam.
                let geometry = mask_beam(geometry, args.beam_mask);
                rows.push(compare(
                    &shader,
                    &material,
                    &options,
                    &geometry,
                    (source_omega, detector_omega),
                    args,
                    "intermediate",
                )?);
            }
        }
        rows.sort_by(|a, b| a.theta_in.total_cmp(&b.theta_in));
    }
    Ok(rows)
}

/// The fitted material at θ_in: the table's, else the incidence's own fit.
fn material_at(fit: &FitResult, theta_in: f64, report: Option<&FitReport>) -> Result<Material> {
    if let Some(table) = &fit.table {
        return Ok(table.at(theta_in)?.material);
    }
    report
        .and_then(|r| fit.material_of(r))
        .or_else(|| fit.static_material())
        .context("the fit holds no valid material")
}

/// Finds a recorded input path: as given, inside DIR, or DIR/../path.
fn locate_input(recorded: &str, dir: &Path) -> Option<PathBuf> {
    let p = PathBuf::from(recorded);
    let mut candidates = vec![p.clone(), dir.join(&p)];
    if let Some(parent) = dir.parent() {
        candidates.push(parent.join(&p));
    }
    if let Some(name) = p.file_name() {
        candidates.push(dir.join(name));
    }
    candidates.into_iter().find(|c| c.is_file())
}

fn fitted_geometry(
    fit: &FitResult,
    report: &FitReport,
    dir: &Path,
    args: &CheckArgs,
) -> Result<Geometry> {
    let recorded = fit
        .provenance
        .inputs
        .iter()
        .find(|i| i.path == report.source)
        .or_else(|| {
            fit.provenance.inputs.iter().find(|i| {
                (i.theta_in - report.theta_in).abs() < 1e-9
                    && (i.phi_in - report.phi_in).abs() < 1e-9
            })
        })
        .map(|i| i.path.clone())
        .unwrap_or_else(|| report.source.clone());
    let floor = if report.floor > 0.0 {
        report.floor
    } else {
        1e-6
    };
    let Some(path) = locate_input(&recorded, dir) else {
        // No data: compare with the model on a grid.
        let mut dirs = Vec::new();
        for t in (0..=80).step_by(5) {
            for p in (0..360).step_by(15) {
                dirs.push(brtf_model::direction(t as f64, p as f64));
            }
        }
        let n = dirs.len();
        return Ok(mask_beam(
            Geometry {
                theta_in: report.theta_in,
                phi_in: report.phi_in,
                dirs,
                weights: vec![1.0; n],
                measured: None,
                channels: 3,
                floor,
            },
            args.beam_mask,
        ));
    };
    let mut m: Measurement =
        brtf_gonio::read_path(&path).with_context(|| format!("cannot read {}", path.display()))?;
    m.fill_solid_angles();
    let m = match &m.quantity {
        Quantity::Bsdf => m,
        Quantity::Dsf => m.to_bsdf()?.measurement,
        Quantity::Raw { beam_integral, .. } => {
            let beam = args.beam_integral.or(*beam_integral).unwrap_or(1.0);
            m.raw_to_bsdf(beam)?.measurement
        }
    };
    let mut m = m.drop_unavailable().measurement;
    if !fit.config.kind.is_transmitting() {
        m = m.select_hemisphere(Hemisphere::Front).measurement;
    }
    m = m.cap_theta(args.theta_cap).measurement;
    if args.beam_mask > 0.0 {
        m = m.mask_incident_cone(args.beam_mask).measurement;
    }
    let stride = m.samples.len().div_ceil(args.max_directions.max(1)).max(1);
    let samples: Vec<_> = m.samples.iter().step_by(stride).collect();
    let channels = m.channels.count();
    let scale = if report.scale > 0.0 {
        report.scale
    } else {
        1.0
    };
    Ok(Geometry {
        theta_in: report.theta_in,
        phi_in: report.phi_in,
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
        channels,
        floor,
    })
}

/// Drops directions within `half_angle_deg` of the beam.
fn mask_beam(mut g: Geometry, half_angle_deg: f64) -> Geometry {
    if half_angle_deg <= 0.0 {
        return g;
    }
    let l = brtf_model::direction(g.theta_in, g.phi_in);
    let cos_limit = half_angle_deg.to_radians().cos();
    let keep: Vec<bool> = g.dirs.iter().map(|d| d.dot(l) < cos_limit).collect();
    let filter = |v: &mut Vec<_>| {
        let mut it = keep.iter();
        v.retain(|_| *it.next().expect("same length"));
    };
    filter(&mut g.dirs);
    let mut it = keep.iter();
    g.weights.retain(|_| *it.next().expect("same length"));
    if let Some(m) = &mut g.measured {
        let mut it = keep.iter();
        m.retain(|_| *it.next().expect("same length"));
    }
    g
}

#[allow(clippy::too_many_arguments)]
#[allow(clippy::needless_range_loop)] // channel loops index several arrays at once
fn compare(
    shader: &Shader,
    material: &Material,
    options: &EvalOptions,
    g: &Geometry,
    (source_omega, detector_omega): (f64, f64),
    args: &CheckArgs,
    kind: &'static str,
) -> Result<CheckRow> {
    let setup = GonioSetup {
        theta_in: g.theta_in,
        phi_in: g.phi_in,
        source_omega,
        detector_omega,
        samples: args.samples.max(1),
        seed: args.seed,
    };
    let gonio = VirtualGonio::new(shader.clone(), setup);
    let (rendered, _) = with_jobs(args.jobs, || gonio.render(&g.dirs))?;
    let bsdf = Bsdf::new(material, options);
    let l = setup.light();
    let model: Vec<Rgb> = g.dirs.iter().map(|&v| bsdf.eval(l, v)).collect();
    let nch = g.channels.clamp(1, 3);
    let floor = g.floor;
    let rel = |a: f64, b: f64| (a - b) / (b * b + floor * floor).sqrt();
    let mut s_rm = 0.0;
    let mut max_rm = 0.0f64;
    let mut s_mc = 0.0;
    let mut count = 0usize;
    let (mut e_r, mut e_m) = (0.0, 0.0);
    for (i, (r, m)) in rendered.iter().zip(&model).enumerate() {
        let w = g.weights[i] * g.dirs[i].z.abs();
        for c in 0..nch {
            let d = rel(r.bsdf[c], m[c]);
            s_rm += d * d;
            max_rm = max_rm.max(d.abs());
            let e = r.std_err[c] / (m[c] * m[c] + floor * floor).sqrt();
            s_mc += e * e;
            count += 1;
            e_r += w * r.bsdf[c];
            e_m += w * m[c];
        }
    }
    let n = count.max(1) as f64;
    let (render_vs_data_rms, render_data_ratio) = match &g.measured {
        Some(data) => {
            let (mut s, mut e_d, mut e_r2) = (0.0, 0.0, 0.0);
            for (i, (r, y)) in rendered.iter().zip(data).enumerate() {
                let w = g.weights[i] * g.dirs[i].z.abs();
                for c in 0..nch {
                    let d = rel(r.bsdf[c], y[c]);
                    s += d * d;
                    e_d += w * y[c];
                    e_r2 += w * r.bsdf[c];
                }
            }
            (Some((s / n).sqrt()), Some(e_r2 / e_d))
        }
        None => (None, None),
    };
    Ok(CheckRow {
        theta_in: g.theta_in,
        phi_in: g.phi_in,
        kind,
        n: g.dirs.len(),
        fit_rms: None,
        render_vs_data_rms,
        render_vs_model_rms: (s_rm / n).sqrt(),
        render_vs_model_max: max_rm,
        render_data_ratio,
        render_model_ratio: e_r / e_m,
        mc_rel: (s_mc / n).sqrt(),
        note: String::new(),
    })
}

fn opt(x: Option<f64>, prec: usize) -> String {
    x.map_or_else(|| "-".to_string(), |v| format!("{v:.prec$}"))
}

fn format_table(fit: &FitResult, rows: &[CheckRow]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "brtf check {}: {} ({}); relative differences (a − b)/sqrt(b² + floor²)",
        fit.name,
        fit.config.kind,
        if fit.table.is_some() {
            "θ_in table"
        } else {
            "static"
        },
    );
    let _ = writeln!(
        s,
        "{:>8} {:>7} {:<12} {:>6} {:>9} {:>12} {:>13} {:>13} {:>11} {:>12} {:>8}",
        "theta_in",
        "phi_in",
        "kind",
        "n",
        "fit rms",
        "render-data",
        "render-model",
        "render-model",
        "energy",
        "energy",
        "MC"
    );
    let _ = writeln!(
        s,
        "{:>8} {:>7} {:<12} {:>6} {:>9} {:>12} {:>13} {:>13} {:>11} {:>12} {:>8}",
        "", "", "", "", "", "rms", "rms", "max", "render/data", "render/model", "rms"
    );
    for r in rows {
        let _ = writeln!(
            s,
            "{:>8.2} {:>7.2} {:<12} {:>6} {:>9} {:>12} {:>13.4} {:>13.4} {:>11} {:>12.4} {:>8.4}{}",
            r.theta_in,
            r.phi_in,
            r.kind,
            r.n,
            opt(r.fit_rms, 4),
            opt(r.render_vs_data_rms, 4),
            r.render_vs_model_rms,
            r.render_vs_model_max,
            opt(r.render_data_ratio, 4),
            r.render_model_ratio,
            r.mc_rel,
            if r.note.is_empty() {
                String::new()
            } else {
                format!("  ({})", r.note)
            }
        );
    }
    s
}

fn csv(rows: &[CheckRow]) -> String {
    let mut s = String::from(
        "theta_in,phi_in,kind,n,fit_rms_rel,render_vs_data_rms_rel,render_vs_model_rms_rel,render_vs_model_max_rel,render_data_energy_ratio,render_model_energy_ratio,mc_rms_rel\n",
    );
    let o = |x: Option<f64>| x.map_or_else(String::new, |v| format!("{v}"));
    for r in rows {
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{},{},{},{}",
            r.theta_in,
            r.phi_in,
            r.kind,
            r.n,
            o(r.fit_rms),
            o(r.render_vs_data_rms),
            r.render_vs_model_rms,
            r.render_vs_model_max,
            o(r.render_data_ratio),
            r.render_model_ratio,
            r.mc_rel
        );
    }
    s
}
