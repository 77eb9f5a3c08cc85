//! `brtf plot DIR`: residual maps, in-plane cuts, parameter curves and
//! `report.html` for a fit folder (what `brtf fit` also draws unless
//! `--no-plots`).

use super::output::print;
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args, Debug)]
pub(crate) struct PlotArgs {
    /// Fit folder (holds fit.json); plots go to DIR/plots, the report to DIR/report.html.
    pub dir: PathBuf,
    /// Another folder to look in for measurement files recorded with a relative path (repeatable).
    #[arg(long = "search-dir", value_name = "DIR")]
    pub search_dirs: Vec<PathBuf>,
    /// Model ÷ data ratio at the ends of the maps' colour bar (> 1) [default: from the data].
    #[arg(long)]
    pub ratio: Option<f64>,
    /// Largest angle between a sample and the plane of incidence in the cuts, degrees [default: automatic].
    #[arg(long)]
    pub plane_tolerance: Option<f64>,
    /// Draw each incidence's map and cut also for patch-averaged data (Klems, tensor trees), where they are left out by default.
    #[arg(long)]
    pub incidence_charts: bool,
}

pub(crate) fn run(args: PlotArgs) -> Result<()> {
    if let Some(r) = args.ratio {
        anyhow::ensure!(
            r.is_finite() && r > 1.0,
            "--ratio must be a number above 1, found {r}"
        );
    }
    if let Some(t) = args.plane_tolerance {
        anyhow::ensure!(
            t.is_finite() && t > 0.0 && t <= 45.0,
            "--plane-tolerance must be in (0, 45] degrees, found {t}"
        );
    }
    let started = Instant::now();
    let options = brtf_plot::PlotOptions {
        search_dirs: args.search_dirs,
        ratio: args.ratio,
        plane_tolerance_deg: args.plane_tolerance,
        incidence_charts: args.incidence_charts.then_some(true),
    };
    let written = brtf_workflow::plot_folder(&args.dir, options)?;
    for w in &written.warnings {
        say!("brtf: warning: {w}");
    }
    print(&format!(
        "brtf plot: {} files in {:.2} s -> {}\n",
        written.files.len(),
        started.elapsed().as_secs_f64(),
        args.dir.join("report.html").display()
    ))
}
