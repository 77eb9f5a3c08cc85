//! `brtf eval`: BSDF values for directions read as CSV on stdin.

use super::material::MaterialArgs;
use super::shared::{csv_stdout, write_numbers};
use anyhow::{Context, Result};
use brtf_model::direction;
use clap::Args;
use std::io::BufRead;

#[derive(Args, Debug)]
pub(crate) struct EvalArgs {
    #[command(flatten)]
    pub material: MaterialArgs,
    /// Incident polar angle θ_in in degrees (towards the light).
    #[arg(long, allow_hyphen_values = true)]
    pub theta_in: f64,
    /// Incident azimuth φ_in in degrees.
    #[arg(long, allow_hyphen_values = true)]
    pub phi_in: f64,
}

pub(crate) fn run(args: EvalArgs) -> Result<()> {
    brtf_model::check_incidence(args.theta_in, args.phi_in)?;
    let bsdf = args.material.bsdf()?;
    let l = direction(args.theta_in, args.phi_in);
    let stdin = std::io::stdin();
    let mut out = csv_stdout();
    out.write_record(["theta_out", "phi_out", "r", "g", "b"])?;
    for (index, line) in stdin.lock().lines().enumerate() {
        let number = index + 1;
        let line = line.with_context(|| format!("<stdin>:{number}: cannot read"))?;
        let Some((theta, phi)) = brtf_workflow::parse_direction_line(&line, number)? else {
            continue;
        };
        let f = bsdf.eval(l, direction(theta, phi));
        write_numbers(&mut out, &[theta, phi, f[0], f[1], f[2]])?;
    }
    out.flush()?;
    Ok(())
}
