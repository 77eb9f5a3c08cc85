//! `brtf check` (being built).

use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct CheckArgs {
    /// The fit folder (holds fit.json).
    pub dir: PathBuf,
}

pub fn run(_args: CheckArgs) -> anyhow::Result<()> {
    anyhow::bail!("brtf check is not implemented yet")
}
