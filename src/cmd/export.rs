//! `brtf export DIR`: the Radiance materials of a fit folder (static,
//! θ_in-dependent with its `.cal`, and a preview scene), from `fit.json`.

use anyhow::{Context, Result};
use brtf_fit::FitResult;
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
    let fit_path = args.dir.join("fit.json");
    let result = FitResult::read(&fit_path)?;
    let out = args.out.unwrap_or_else(|| args.dir.clone());
    std::fs::create_dir_all(&out)
        .with_context(|| format!("cannot create the folder {}", out.display()))?;
    let options = ExportOptions {
        name: args.name,
        at: args.at,
        theta_dependent: !args.static_only,
        preview: !args.no_preview,
    };
    let exported = write_exports(&out, &result, &options)
        .with_context(|| format!("exporting {}", fit_path.display()))?;
    for file in &exported.files {
        println!("wrote {}", file.display());
    }
    for note in &exported.notes {
        eprintln!("note: {note}");
    }
    Ok(())
}
