//! `brtf render` (being built).

use clap::Args;

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// What to render: `gonio` or `image`.
    pub what: String,
}

pub fn run(_args: RenderArgs) -> anyhow::Result<()> {
    anyhow::bail!("brtf render is not implemented yet")
}
