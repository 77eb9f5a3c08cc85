//! `brtf export` (being built).

use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct ExportArgs {
    /// The fit folder (holds fit.json).
    pub dir: PathBuf,
}

pub fn run(_args: ExportArgs) -> anyhow::Result<()> {
    anyhow::bail!("brtf export is not implemented yet")
}
