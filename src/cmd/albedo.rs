//! `brtf albedo`: directional-hemispherical reflectance and transmittance.

use super::material::MaterialArgs;
use anyhow::Result;
use brtf_model::{composite_albedo, direction};
use clap::Args;
use std::io::{BufWriter, Write};

#[derive(Args, Debug)]
pub(crate) struct AlbedoArgs {
    #[command(flatten)]
    pub material: MaterialArgs,
    /// Incident polar angles θ_in in degrees, comma-separated.
    #[arg(
        long,
        value_delimiter = ',',
        required = true,
        allow_hyphen_values = true
    )]
    pub theta_in: Vec<f64>,
    /// Incident azimuth φ_in in degrees.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub phi_in: f64,
    /// Target absolute accuracy per channel.
    #[arg(long, default_value_t = 1e-5)]
    pub tolerance: f64,
}

pub(crate) fn run(args: AlbedoArgs) -> Result<()> {
    for &t in &args.theta_in {
        brtf_model::check_incidence(t, args.phi_in)?;
    }
    let tolerance = args.tolerance;
    let ok = tolerance > 0.0 && tolerance < 1.0;
    brtf_model::OptionError::check("--tolerance", tolerance, ok, "0 < tolerance < 1")?;
    let bsdf = args.material.bsdf()?;
    let mut out = BufWriter::new(crate::cmd::output::stdout());
    writeln!(
        out,
        "theta_in,phi_in,rho_r,rho_g,rho_b,tau_r,tau_g,tau_b,rho_spike,tau_spike"
    )?;
    for &theta in &args.theta_in {
        let a = composite_albedo(&bsdf, direction(theta, args.phi_in), args.tolerance);
        // The delta spikes are reported as their mean over the three channels.
        let mean = |c: [f64; 3]| (c[0] + c[1] + c[2]) / 3.0;
        writeln!(
            out,
            "{},{},{:.7},{:.7},{:.7},{:.7},{:.7},{:.7},{:.7},{:.7}",
            theta,
            args.phi_in,
            a.rho[0],
            a.rho[1],
            a.rho[2],
            a.tau[0],
            a.tau[1],
            a.tau[2],
            mean(a.rho_spike),
            mean(a.tau_spike)
        )?;
    }
    out.flush()?;
    Ok(())
}
