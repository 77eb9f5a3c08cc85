//! `brtf render gonio`: the virtual gonio-photometer.

use super::SampleMaterial;
use crate::cmd::shared::{csv_stdout, with_jobs, words, write_numbers};
use anyhow::Result;
use brtf_gonio::Channels;
use brtf_trace::{Aperture, aperture_solid_angle};
use brtf_workflow::{GonioRequest, render_gonio};
use clap::Args;
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
    /// Replace an existing --out file that brtf render gonio did not write (never an input).
    #[arg(long)]
    pub force: bool,
}

pub(crate) fn run(args: GonioArgs) -> Result<()> {
    let request = GonioRequest {
        like: args.like.clone(),
        incidence: [args.theta_in, args.phi_in],
        grid_steps: [args.theta_step, args.phi_step],
        back: args.back,
        source_omega: aperture_solid_angle(Aperture::Source, args.source_omega, args.source_apex)?,
        detector_omega: aperture_solid_angle(
            Aperture::Detector,
            args.detector_omega,
            args.detector_apex,
        )?,
        samples: args.samples,
        seed: args.seed,
        channels: args.channels,
        out: args.out.clone(),
        force: args.force,
    };
    let material = args.sample.load()?;
    let file = args.sample.material.as_deref();
    let run = with_jobs(args.jobs, || render_gonio(material, &request, file))??;
    let secs = run.elapsed.as_secs_f64();
    say!(
        "brtf render gonio: {} directions × {} rays, {:.2} M rays in {:.2} s ({:.2} M rays/s)",
        run.directions.len(),
        args.samples.max(1),
        run.rays.total() as f64 / 1e6,
        secs,
        run.rays.total() as f64 / 1e6 / secs.max(1e-9)
    );
    if args.out.is_some() {
        return Ok(());
    }
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
    for (&(t, p), v) in run.directions.iter().zip(&run.values) {
        let ([r, g, b], [er, eg, eb]) = (v.bsdf, v.std_err);
        write_numbers(&mut out, &[t, p, r, g, b, er, eg, eb])?;
    }
    out.flush()?;
    Ok(())
}
