//! `brtf info FILE...`: per-file summaries ([`brtf_workflow::describe_files`]).

use clap::Args;
use std::io::Write;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub(crate) struct InfoArgs {
    /// Measurement files (.mpc, pab-opto Mountain, Klems or tensor-tree BSDF XML).
    #[arg(required = true)]
    pub(crate) files: Vec<PathBuf>,
    /// Print machine-readable JSON instead of text.
    #[arg(long)]
    pub(crate) json: bool,
}

pub(crate) fn run(args: InfoArgs) -> anyhow::Result<()> {
    let mut out = crate::cmd::output::stdout();
    brtf_workflow::describe_files(&args.files, args.json, &mut out)?;
    Ok(out.flush()?)
}
