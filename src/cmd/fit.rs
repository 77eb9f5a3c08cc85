//! `brtf fit FILE... --model M`: per-incidence fits, the all-incidence fit,
//! the θ_in table, and the outputs in the fit folder.

use super::material::{parse_fresnel_k, parse_variant};
use super::output::write_atomic;
use anyhow::{Context, Result, bail};
use brtf_fit::{
    FitConfig, FitReport, FitResult, FitSample, GateReport, IncidenceData, InputFile,
    Interpolation, ParamTable, Provenance, ResidualKind, RobustLoss, fit_global, fit_incidence,
};
use brtf_gonio::{Hemisphere, Measurement, Quantity};
use brtf_model::{MaterialKind, Variant};
use clap::{Args, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use sha2::{Digest, Sha256};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct FitArgs {
    /// Measurement files, one incidence each (.mpc or pab-opto Mountain).
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// Model to fit.
    #[arg(long, value_parser = parse_kind)]
    pub model: MaterialKind,
    /// Tie R = G = B (always so for single-channel data).
    #[arg(long)]
    pub gray: bool,
    /// Output folder [default: fits/<name>].
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Material name [default: the files' folder name].
    #[arg(long)]
    pub name: Option<String>,
    /// Formula set: radiance (current rtrace), manual2004 or ward1992.
    #[arg(long, default_value = "radiance", value_parser = parse_variant)]
    pub variant: Variant,
    /// Fresnel constant for roughness-0 surfaces: classic, pyradiance or a number.
    #[arg(long, default_value = "classic", value_parser = parse_fresnel_k)]
    pub fresnel_k: f64,
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
    #[arg(long, default_value = "none", value_parser = parse_loss)]
    pub loss: RobustLoss,
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
    /// Beam integral for raw-signal files (makes the fit absolute); overrides the file's.
    #[arg(long)]
    pub beam_integral: Option<f64>,
    /// A known directional-hemispherical reflectance `VALUE@THETA` (e.g.
    /// `0.85@30`) that makes a raw-signal fit absolute.
    #[arg(long, value_parser = parse_rho)]
    pub rho: Option<(f64, f64)>,
    /// Fit a free overall scale even when the data are absolute.
    #[arg(long)]
    pub free_scale: bool,
    /// θ_in interpolation of the parameters.
    #[arg(long, value_enum, default_value_t = InterpArg::Pchip)]
    pub interpolation: InterpArg,
    /// Worker threads [default: all cores].
    #[arg(long)]
    pub jobs: Option<usize>,
    /// Do not write the Radiance exports.
    #[arg(long)]
    pub no_export: bool,
    /// Do not draw the plots.
    #[arg(long)]
    pub no_plots: bool,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum ResidualArg {
    Relative,
    Absolute,
    Log,
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

fn parse_kind(s: &str) -> Result<MaterialKind, String> {
    s.parse()
}

fn parse_rho(s: &str) -> Result<(f64, f64), String> {
    let (value, theta) = s
        .split_once('@')
        .ok_or("expected VALUE@THETA, e.g. 0.85@30")?;
    let value: f64 = value
        .parse()
        .map_err(|_| format!("bad reflectance `{value}`"))?;
    let theta: f64 = theta.parse().map_err(|_| format!("bad angle `{theta}`"))?;
    if !(value > 0.0 && value <= 1.0 && (0.0..90.0).contains(&theta)) {
        return Err("need 0 < VALUE ≤ 1 and 0 ≤ THETA < 90".into());
    }
    Ok((value, theta))
}

fn parse_loss(s: &str) -> Result<RobustLoss, String> {
    let (name, c) = match s.split_once(':') {
        Some((n, c)) => (
            n,
            Some(
                c.parse::<f64>()
                    .map_err(|_| format!("bad loss scale `{c}`"))?,
            ),
        ),
        None => (s, None),
    };
    match name {
        "none" => Ok(RobustLoss::None),
        "huber" => Ok(RobustLoss::Huber(c.unwrap_or(1.345))),
        "cauchy" => Ok(RobustLoss::Cauchy(c.unwrap_or(2.385))),
        _ => Err(format!(
            "expected none, huber[:C] or cauchy[:C], found `{s}`"
        )),
    }
}

/// One input file, read and prepared for the fitter.
struct Prepared {
    input: InputFile,
    data: IncidenceData,
}

pub fn run(args: FitArgs) -> Result<()> {
    if args.orientation.len() != 3 || args.orientation.iter().all(|x| *x == 0.0) {
        bail!("--orientation needs three numbers x,y,z, not all zero");
    }
    let name = args
        .name
        .clone()
        .unwrap_or_else(|| default_name(&args.files));
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| Path::new("fits").join(&name));
    let hemisphere = args.hemisphere.unwrap_or(if args.model.is_transmitting() {
        HemisphereArg::Both
    } else {
        HemisphereArg::Front
    });

    // Read and prepare every file (in parallel: the solid angles cost most).
    let prepared: Vec<Result<Prepared>> = args
        .files
        .par_iter()
        .map(|path| prepare(path, &args, hemisphere))
        .collect();
    let mut prepared: Vec<Prepared> = prepared.into_iter().collect::<Result<_>>()?;
    prepared.sort_by(|a, b| a.data.theta_in.total_cmp(&b.data.theta_in));
    let free_scale = args.free_scale
        || prepared
            .iter()
            .any(|p| p.input.quantity.contains("free scale"));
    if free_scale
        && prepared
            .iter()
            .any(|p| !p.input.quantity.contains("free scale"))
        && !args.free_scale
    {
        bail!("the files mix absolute and raw-signal data; give --beam-integral or --free-scale");
    }

    let mut config = FitConfig {
        kind: args.model,
        options: brtf_model::EvalOptions {
            variant: args.variant,
            fresnel_k: args.fresnel_k,
            source_omega: args.source_omega,
            flat: true,
            source_jitter: 0.0,
        },
        orientation: [
            args.orientation[0],
            args.orientation[1],
            args.orientation[2],
        ],
        gray: args.gray,
        free_scale,
        residual: match args.residual {
            ResidualArg::Relative => ResidualKind::Relative,
            ResidualArg::Absolute => ResidualKind::Absolute,
            ResidualArg::Log => ResidualKind::Log,
        },
        floor: args.floor,
        loss: args.loss,
        multistart: !args.no_multistart,
    };

    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.jobs.unwrap_or(0))
        .build()?;
    let (mut reports, mut global) = pool.install(|| fit_all(&prepared, &config))?;

    // A known reflectance turns a free-scale fit absolute: the fitted model's
    // ρ_dh at that incidence fixes the instrument's scale K; the data are
    // divided by K and fitted again without a free scale.
    if let Some((rho, theta)) = args.rho {
        if !config.free_scale {
            bail!("--rho is for raw-signal data fitted with a free scale; these data are absolute");
        }
        let nearest = reports
            .iter()
            .min_by(|a, b| {
                (a.theta_in - theta)
                    .abs()
                    .total_cmp(&(b.theta_in - theta).abs())
            })
            .expect("at least one incidence");
        if (nearest.theta_in - theta).abs() > 5.0 {
            eprintln!(
                "brtf: warning: --rho given at θ_in {theta}°, nearest fitted incidence is {}°",
                nearest.theta_in
            );
        }
        let material = brtf_model::Material::new(
            config.kind,
            &nearest.material_args,
            Some(glam::DVec3::from_array(config.orientation)),
        )?;
        let bsdf = brtf_model::Bsdf::new(&material, &config.options);
        let albedo = brtf_model::albedo(&bsdf, brtf_model::direction(theta, nearest.phi_in), 1e-6);
        let model_rho = nearest.scale * (albedo.rho.iter().sum::<f64>() / 3.0);
        let k = model_rho / rho;
        anyhow::ensure!(
            k.is_finite() && k > 0.0,
            "--rho: the fitted model has no reflectance at {theta}°"
        );
        eprintln!(
            "brtf: --rho {rho}@{theta}: instrument scale K = {k:.6e} (data ÷ K are absolute BSDF)"
        );
        for p in &mut prepared {
            for sample in &mut p.data.samples {
                sample.value = sample.value.map(|v| v / k);
            }
            let base = p
                .input
                .quantity
                .replace(", free scale (no beam integral)", "");
            p.input.quantity = format!("{base} ÷ K = {k:e} from --rho {rho}@{theta}");
        }
        config.free_scale = false;
        (reports, global) = pool.install(|| fit_all(&prepared, &config))?;
    }
    let interpolation = match args.interpolation {
        InterpArg::Pchip => Interpolation::Pchip,
        InterpArg::Linear => Interpolation::Linear,
    };
    let table =
        match ParamTable::from_reports(config.kind, config.orientation, &reports, interpolation) {
            Ok(t) => Some(t),
            Err(e) => {
                eprintln!("brtf: warning: {e}; no θ_in-dependent material is made");
                None
            }
        };

    let result = FitResult {
        name: name.clone(),
        provenance: Provenance {
            brtf_version: env!("CARGO_PKG_VERSION").into(),
            command_line: std::env::args().collect(),
            created: utc_now(),
            inputs: prepared.iter().map(|p| p.input.clone()).collect(),
        },
        config,
        selections: selection_text(&args, hemisphere),
        incidences: reports,
        global: Some(global),
        table,
        interpolation,
    };
    write_outputs(&out, &result)?;
    print!("{}", summary(&result, &out));
    if !args.no_export {
        let options = brtf_radiance::export::ExportOptions::default();
        let exported = brtf_radiance::export::write_exports(&out, &result, &options)
            .with_context(|| format!("exporting Radiance materials into {}", out.display()))?;
        for file in &exported.files {
            println!("wrote {}", file.display());
        }
        for note in &exported.notes {
            eprintln!("note: {note}");
        }
    }
    if !args.no_plots {
        let written = brtf_plot::write_plots(&out, &result, &brtf_plot::PlotOptions::default())
            .with_context(|| format!("plotting into {}", out.display()))?;
        println!(
            "wrote {} plots and {}",
            written.files.len().saturating_sub(1),
            written.report.display()
        );
        for warning in &written.warnings {
            eprintln!("brtf: warning: {warning}");
        }
    }
    Ok(())
}

/// Fits every incidence and all of them at once, in parallel, with a
/// progress bar.
fn fit_all(prepared: &[Prepared], config: &FitConfig) -> Result<(Vec<FitReport>, FitReport)> {
    let bar = ProgressBar::new(prepared.len() as u64 + 1);
    bar.set_style(
        ProgressStyle::with_template("{spinner} fitting {pos}/{len} [{bar:30}] {elapsed} {msg}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    let (reports, global) = rayon::join(
        || {
            prepared
                .par_iter()
                .map(|p| {
                    let r = fit_incidence(&p.data, config);
                    bar.inc(1);
                    r
                })
                .collect::<Vec<_>>()
        },
        || {
            // With one incidence the all-incidence fit is that fit.
            if prepared.len() < 2 {
                return None;
            }
            let data: Vec<IncidenceData> = prepared.iter().map(|p| p.data.clone()).collect();
            let r = fit_global(&data, config);
            bar.inc(1);
            Some(r)
        },
    );
    bar.finish_and_clear();
    let reports = reports.into_iter().collect::<Result<Vec<_>, _>>()?;
    let global = match global {
        Some(g) => g?,
        None => FitReport {
            source: "all incidences".into(),
            ..reports[0].clone()
        },
    };
    Ok((reports, global))
}

/// The files' common folder name, else `fit`.
fn default_name(files: &[PathBuf]) -> String {
    let folder = |p: &PathBuf| {
        std::fs::canonicalize(p).ok().and_then(|c| {
            c.parent()
                .and_then(|d| d.file_name())
                .map(|n| n.to_string_lossy().into_owned())
        })
    };
    let first = folder(&files[0]);
    if files.iter().all(|f| folder(f) == first) {
        first.unwrap_or_else(|| "fit".into())
    } else {
        "fit".into()
    }
}

fn selection_text(args: &FitArgs, hemisphere: HemisphereArg) -> Vec<String> {
    let mut s = vec![
        "drop samples not available (9.9e+37) or not finite".to_string(),
        format!("hemisphere: {hemisphere:?}").to_lowercase(),
        format!("theta_out <= {}° from the nearer normal", args.theta_cap),
    ];
    if args.beam_mask > 0.0 {
        s.push(format!(
            "mask a {}° cone around the incident beam",
            args.beam_mask
        ));
    }
    if let Some(v) = args.min_value {
        s.push(format!("drop values below {v}"));
    }
    s
}

fn prepare(path: &Path, args: &FitArgs, hemisphere: HemisphereArg) -> Result<Prepared> {
    let bytes = std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?;
    let sha256 = Sha256::digest(&bytes)
        .iter()
        .fold(String::new(), |mut s, b| {
            let _ = write!(s, "{b:02x}");
            s
        });
    let mut m: Measurement = brtf_gonio::read_bytes(&bytes, path)?;
    let samples_in_file = m.len();
    // The weights describe the full layout, so compute them before selecting.
    let weight_source = m.fill_solid_angles();
    let (mut m, quantity) = match &m.quantity {
        Quantity::Bsdf => (m.clone(), "BSDF".to_string()),
        Quantity::Dsf => (
            m.to_bsdf()?.measurement,
            "DSF, divided by |cos θ_out|".into(),
        ),
        Quantity::Raw {
            unit,
            beam_integral,
        } => match args.beam_integral.or(*beam_integral) {
            Some(beam) => (
                m.raw_to_bsdf(beam)?.measurement,
                format!("raw [{unit}] ÷ beam integral {beam} ÷ |cos θ_out|"),
            ),
            None => (
                m.raw_to_bsdf(1.0)?.measurement,
                format!("raw [{unit}] ÷ |cos θ_out|, free scale (no beam integral)"),
            ),
        },
    };
    let mut gates = Vec::new();
    let mut apply = |m: &mut Measurement, gate: String, sel: brtf_gonio::Selection| {
        gates.push(GateReport {
            gate,
            removed: sel.removed,
        });
        *m = sel.measurement;
    };
    let sel = m.drop_unavailable();
    apply(&mut m, "not available or not finite".into(), sel);
    match hemisphere {
        HemisphereArg::Front => {
            let sel = m.select_hemisphere(Hemisphere::Front);
            apply(&mut m, "front hemisphere only".into(), sel);
        }
        HemisphereArg::Back => {
            let sel = m.select_hemisphere(Hemisphere::Back);
            apply(&mut m, "back hemisphere only".into(), sel);
        }
        HemisphereArg::Both => {}
    }
    let sel = m.cap_theta(args.theta_cap);
    apply(&mut m, format!("theta_out <= {}°", args.theta_cap), sel);
    if args.beam_mask > 0.0 {
        let sel = m.mask_incident_cone(args.beam_mask);
        apply(&mut m, format!("{}° beam mask", args.beam_mask), sel);
    }
    if let Some(v) = args.min_value {
        let sel = m.drop_below(v);
        apply(&mut m, format!("value >= {v}"), sel);
    }
    let uniform = args.weights == WeightsArg::Uniform;
    let weighting = if uniform {
        "uniform".to_string()
    } else {
        format!(
            "solid angle ({})",
            match weight_source {
                brtf_gonio::SolidAngleSource::File => "the file's Voronoi cells",
                brtf_gonio::SolidAngleSource::Computed => "computed from the sample directions",
            }
        )
    };
    let samples = m
        .samples
        .iter()
        .map(|s| FitSample {
            view: s.direction(),
            value: s.values,
            weight: if uniform {
                1.0
            } else {
                s.solid_angle_sr.unwrap_or(1.0)
            },
        })
        .collect();
    let source = path.display().to_string();
    Ok(Prepared {
        input: InputFile {
            path: source.clone(),
            sha256,
            theta_in: m.incidence.theta_deg,
            phi_in: m.incidence.phi_deg,
            quantity,
            samples: samples_in_file,
        },
        data: IncidenceData {
            source,
            theta_in: m.incidence.theta_deg,
            phi_in: m.incidence.phi_deg,
            channels: m.channels.count(),
            samples,
            gates,
            weighting,
        },
    })
}

fn write_outputs(out: &Path, result: &FitResult) -> Result<()> {
    let json = serde_json::to_string_pretty(result)?;
    write_atomic(&out.join("params.csv"), params_csv(result)?.as_bytes())?;
    write_atomic(&out.join("fit.json"), json.as_bytes())?;
    Ok(())
}

/// `params.csv`: one row per incidence, then the all-incidence fit as a
/// row with an empty θ_in.
pub fn params_csv(result: &FitResult) -> Result<String> {
    let first = result.incidences.first().context("no incidences")?;
    let names: Vec<&str> = first.params.iter().map(|p| p.name.as_str()).collect();
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut header = vec!["theta_in".to_string(), "phi_in".into(), "n_points".into()];
    header.extend(names.iter().map(|n| n.to_string()));
    header.extend(names.iter().map(|n| format!("{n}_stderr")));
    header.extend(["rms_rel".into(), "cost".into(), "termination".into()]);
    w.write_record(&header)?;
    let row = |r: &FitReport, theta: String, phi: String| -> Vec<String> {
        let mut v = vec![theta, phi, r.n_points.to_string()];
        v.extend(r.params.iter().map(|p| format!("{:.8}", p.value)));
        v.extend(r.params.iter().map(|p| format!("{:.3e}", p.stderr)));
        v.extend([
            format!("{:.6}", r.rms_rel),
            format!("{:.6e}", r.cost),
            r.termination.label().into(),
        ]);
        v
    };
    for r in &result.incidences {
        w.write_record(row(r, format!("{}", r.theta_in), format!("{}", r.phi_in)))?;
    }
    if let Some(g) = &result.global {
        w.write_record(row(g, "all".into(), String::new()))?;
    }
    Ok(String::from_utf8(w.into_inner()?)?)
}

fn summary(result: &FitResult, out: &Path) -> String {
    let mut s = String::new();
    let kind = result.config.kind;
    let _ = writeln!(
        s,
        "brtf fit: {} {} ({} variant), {} incidence(s) -> {}",
        result.name,
        kind,
        result.config.options.variant,
        result.incidences.len(),
        out.display()
    );
    for i in &result.provenance.inputs {
        let _ = writeln!(
            s,
            "  {}: θ_in {}°, φ_in {}°, {} samples, {}",
            i.path, i.theta_in, i.phi_in, i.samples, i.quantity
        );
    }
    let names: Vec<String> = result.incidences[0]
        .params
        .iter()
        .map(|p| p.name.clone())
        .collect();
    let _ = write!(s, "\n{:>8} {:>7}", "θ_in", "points");
    for n in &names {
        let _ = write!(s, " {:>17}", n);
    }
    let _ = writeln!(s, " {:>8} {:>8}  termination", "rms_rel", "ms");
    let mut line = |label: String, r: &FitReport| {
        let _ = write!(s, "{:>8} {:>7}", label, r.n_points);
        for p in &r.params {
            let flag = if p.at_bound {
                "!"
            } else if p.fixed {
                "="
            } else {
                " "
            };
            let _ = write!(s, " {:>8.5}±{:<7.1e}{}", p.value, p.stderr, flag);
        }
        let _ = writeln!(
            s,
            " {:>8.4} {:>8.0}  {}",
            r.rms_rel,
            r.elapsed_ms,
            r.termination.label()
        );
    };
    for r in &result.incidences {
        line(format!("{}", r.theta_in), r);
    }
    if let Some(g) = &result.global {
        line("all".into(), g);
    }
    let _ = writeln!(s, "(! = at a bound, = = held fixed)");
    let mut warned = false;
    let global = result.global.iter().filter(|_| result.incidences.len() > 1);
    let labelled = result
        .incidences
        .iter()
        .map(|r| (r, format!("{} (θ_in {})", r.source, r.theta_in)))
        .chain(global.map(|r| (r, "all incidences".to_string())));
    for (r, label) in labelled {
        for w in &r.warnings {
            if !warned {
                let _ = writeln!(s, "\nwarnings:");
                warned = true;
            }
            let _ = writeln!(s, "  {label}: {w}");
        }
    }
    if let Some(g) = &result.global {
        let args: Vec<String> = g.material_args.iter().map(|a| format!("{a:.6}")).collect();
        let _ = writeln!(
            s,
            "\nall-incidence material: void {kind} {} 0 0 {} {}",
            result.name,
            args.len(),
            args.join(" ")
        );
    }
    s
}

/// UTC time as RFC 3339, from the system clock (no date crate needed).
fn utc_now() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs() as i64)
        .unwrap_or(0);
    let (days, rem) = (secs.div_euclid(86_400), secs.rem_euclid(86_400));
    // Civil-from-days (proleptic Gregorian).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        (rem / 60) % 60,
        rem % 60
    )
}
