//! `brtf render gonio`: the virtual gonio-photometer.

use super::SampleMaterial;
use crate::cmd::shared::{csv_stdout, with_jobs, words, write_numbers};
use anyhow::{Context, Result, bail};
use brtf_gonio::{Channels, Measurement, SourceFormat};
use brtf_trace::{
    Aperture, GonioSetup, VirtualGonio, aperture_solid_angle, grid, measurement_from,
};
use clap::Args;
use glam::DVec3;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub(crate) struct GonioArgs {
    #[command(flatten)]
    pub sample: SampleMaterial,
    /// Reproduce this measurement's geometry: its incidence and every sample direction.
    #[arg(long, value_name = "FILE")]
    pub like: Option<PathBuf>,
    /// Incident polar angle θ_in in degrees (overrides the --like file's).
    #[arg(long, allow_hyphen_values = true)]
    pub theta_in: Option<f64>,
    /// Incident azimuth φ_in in degrees.
    #[arg(long, allow_hyphen_values = true)]
    pub phi_in: Option<f64>,
    /// Without --like: θ_out grid step in degrees.
    #[arg(long, default_value_t = 5.0)]
    pub theta_step: f64,
    /// Without --like: φ_out grid step in degrees.
    #[arg(long, default_value_t = 15.0)]
    pub phi_step: f64,
    /// Without --like: also the back (transmission) hemisphere [default: for trans types].
    #[arg(long)]
    pub back: bool,
    /// Beam solid angle in sr [default: the fit's source ω, else a point].
    #[arg(long, value_name = "SR")]
    pub source_omega: Option<f64>,
    /// Beam as a full cone apex angle in degrees.
    #[arg(long, value_name = "DEG")]
    pub source_apex: Option<f64>,
    /// Detector aperture solid angle in sr [default: a point].
    #[arg(long, value_name = "SR")]
    pub detector_omega: Option<f64>,
    /// Detector aperture as a full cone apex angle in degrees.
    #[arg(long, value_name = "DEG")]
    pub detector_apex: Option<f64>,
    /// Rays per detector direction.
    #[arg(long, default_value_t = 256)]
    pub samples: u32,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Values per sample in the output file: `y` (luminance) or `rgb`
    /// (the material's colour, written as CIE X, Y, Z) [default: the --like
    /// file's, else y].
    #[arg(long, value_parser = words::<Channels>())]
    pub channels: Option<Channels>,
    /// Output measurement file: `.mpc` (ISE) or anything else (Mountain).
    /// Without it, CSV goes to stdout.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Worker threads [default: all cores].
    #[arg(long)]
    pub jobs: Option<usize>,
    /// Overwrite --out even when it is the --like or --material file.
    #[arg(long)]
    pub force: bool,
}

pub(crate) fn run(args: GonioArgs) -> Result<()> {
    let loaded = args.sample.load()?;
    let like: Option<Measurement> = match &args.like {
        Some(p) => {
            Some(brtf_gonio::read_path(p).with_context(|| format!("cannot read {}", p.display()))?)
        }
        None => None,
    };
    let theta_in = args
        .theta_in
        .or(like.as_ref().map(|m| m.incidence.theta_deg))
        .context("give --theta-in (and --phi-in), or --like FILE")?;
    let phi_in = args
        .phi_in
        .or(like.as_ref().map(|m| m.incidence.phi_deg))
        .unwrap_or(0.0);
    brtf_model::check_incidence(theta_in, phi_in)?;
    if let Some(out) = &args.out {
        let inputs = [&args.like, &args.sample.material];
        let inputs: Vec<&std::path::Path> = inputs.iter().filter_map(|p| p.as_deref()).collect();
        brtf_io::check_overwrite(out, &inputs, None, args.force)?;
    }
    let fit_omega = loaded.fit.as_ref().map(|f| f.options().source_omega);
    let source_omega = aperture_solid_angle(Aperture::Source, args.source_omega, args.source_apex)?
        .or(fit_omega)
        .unwrap_or(0.0);
    let detector_omega =
        aperture_solid_angle(Aperture::Detector, args.detector_omega, args.detector_apex)?
            .unwrap_or(0.0);
    let setup = GonioSetup {
        theta_in,
        phi_in,
        source_omega,
        detector_omega,
        samples: args.samples.max(1),
        seed: args.seed,
    };
    setup.validate()?;
    let directions: Vec<(f64, f64)> = match &like {
        Some(m) => m.samples.iter().map(|s| (s.theta_deg, s.phi_deg)).collect(),
        None => grid(
            args.theta_step,
            args.phi_step,
            args.back || loaded.material.kind().is_transmitting(),
        )?,
    };
    let out_format = match &args.out {
        Some(p) if p.extension().is_some_and(|e| e.eq_ignore_ascii_case("mpc")) => {
            SourceFormat::Mpc
        }
        _ => SourceFormat::Mountain,
    };
    let mut channels = args
        .channels
        .unwrap_or_else(|| like.as_ref().map_or(Channels::Y, |m| m.channels));
    if out_format == SourceFormat::Mpc && args.out.is_some() {
        if args.channels == Some(Channels::Xyz) {
            bail!(".mpc holds one channel; use --channels y or a Mountain file");
        }
        channels = Channels::Y;
    }

    let gonio = VirtualGonio::new(loaded.shader, setup);
    let dirs: Vec<DVec3> = directions
        .iter()
        .map(|&(t, p)| brtf_model::direction(t, p))
        .collect();
    let start = std::time::Instant::now();
    let (values, rays) = with_jobs(args.jobs, || gonio.render(&dirs))?;
    let elapsed = start.elapsed().as_secs_f64();
    say!(
        "brtf render gonio: {} directions × {} rays, {:.2} M rays in {:.2} s ({:.2} M rays/s)",
        dirs.len(),
        setup.samples,
        rays.total() as f64 / 1e6,
        elapsed,
        rays.total() as f64 / 1e6 / elapsed.max(1e-9)
    );

    let Some(path) = &args.out else {
        let mut out = csv_stdout();
        out.write_record([
            "theta_out",
            "phi_out",
            "r",
            "g",
            "b",
            "r_err",
            "g_err",
            "b_err",
        ])?;
        for (&(t, p), v) in directions.iter().zip(&values) {
            let ([r, g, b], [er, eg, eb]) = (v.bsdf, v.std_err);
            write_numbers(&mut out, &[t, p, r, g, b, er, eg, eb])?;
        }
        out.flush()?;
        return Ok(());
    };
    let mut m = measurement_from(&setup, &directions, &values, channels, out_format);
    if let Some(l) = &like {
        for (s, src) in m.samples.iter_mut().zip(&l.samples) {
            s.solid_angle_sr = src.solid_angle_sr;
        }
        m.sample_name = l.sample_name.clone();
    }
    m.header.push(format!(
        "# rendered by brtf render gonio: material {}, beam {} sr, detector {} sr, {} rays per direction, seed {}",
        loaded.name, source_omega, detector_omega, setup.samples, setup.seed
    ));
    brtf_gonio::write_path(&m, path, out_format)
        .with_context(|| format!("cannot write {}", path.display()))?;
    Ok(())
}
