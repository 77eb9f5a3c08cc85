//! `brtf export DIR`: the Radiance materials of a fit folder (static,
//! θ_in-dependent with its `.cal`, and a preview scene), from `fit.json`.

use super::output::{print, relist};
use anyhow::{Context, Result};
use brtf_fit::FitResult;
use brtf_io::{FolderUpdate, Producer};
use brtf_radiance::export::{ExportOptions, write_exports};
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct ExportArgs {
    /// The fit folder (holds fit.json).
    pub dir: PathBuf,
    /// Static material from the parameters at this θ_in (degrees) instead of
    /// the all-incidence fit: the matching incidence's fit, or the θ_in table.
    #[arg(long, value_name = "THETA")]
    pub at: Option<f64>,
    /// Material identifier and file stem (default: the fit's name).
    #[arg(long, value_name = "NAME")]
    pub name: Option<String>,
    /// Write into this folder instead of DIR (created if missing).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Only the static material: no θ_in-dependent material, no .cal.
    #[arg(long)]
    pub static_only: bool,
    /// No preview scene.
    #[arg(long)]
    pub no_preview: bool,
}

pub fn run(args: ExportArgs) -> Result<()> {
    if let Some(at) = args.at {
        anyhow::ensure!(
            (0.0..90.0).contains(&at),
            "--at {at}: out of range; allowed: 0 ≤ θ_in < 90 degrees"
        );
    }
    let fit_path = args.dir.join("fit.json");
    let result = FitResult::read(&fit_path)?;
    let out = args.out.unwrap_or_else(|| args.dir.clone());
    let options = ExportOptions {
        name: args.name,
        at: args.at,
        theta_dependent: !args.static_only,
        preview: !args.no_preview,
    };
    // Into a copy of the folder, swapped in at the end: replaces this
    // command's own files, keeps the rest.
    let update = FolderUpdate::amend(&out)?;
    let exported = write_exports(update.path(), &result, &options)
        .with_context(|| format!("exporting {}", fit_path.display()))?;
    relist(update.path(), &exported.files, Producer::Export)?;
    let mut lines = String::new();
    for file in &exported.files {
        let name = file.strip_prefix(update.path()).unwrap_or(file);
        lines += &format!("wrote {}\n", out.join(name).display());
    }
    update.commit()?;
    for note in &exported.notes {
        say!("note: {note}");
    }
    print(&lines)
}
