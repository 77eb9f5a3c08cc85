//! `brtf info FILE...`: per-file measurement summaries.

use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct InfoArgs {
    /// Measurement files (.mpc or pab-opto Mountain).
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// Print machine-readable JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

pub fn run(_args: InfoArgs) -> anyhow::Result<()> {
    anyhow::bail!("brtf info is not implemented yet")
}
