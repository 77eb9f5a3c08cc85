//! `brtf check DIR`: renders a fit through the virtual gonio-photometer
//! ([`brtf_trace::check`]) and writes the comparison to `DIR/check.csv`.

use super::shared::with_jobs;
use anyhow::Result;
use brtf_trace::CheckOptions;
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub(crate) struct CheckArgs {
    /// The fit folder (holds fit.json).
    pub dir: PathBuf,
    /// Rays per detector direction.
    #[arg(long, default_value_t = 128)]
    pub samples: u32,
    /// Most directions rendered per incidence, evenly subsampled [default: all].
    #[arg(long, value_name = "N")]
    pub max_directions: Option<usize>,
    /// Beam solid angle in sr [default: the fit's source ω, the header's, or 0.5°].
    #[arg(long, value_name = "SR")]
    pub source_omega: Option<f64>,
    /// Beam as a full cone apex angle in degrees.
    #[arg(long, value_name = "DEG", conflicts_with = "source_omega")]
    pub source_apex: Option<f64>,
    /// Detector solid angle in sr [default: the file header's, or 0.75°]; 0: a point.
    #[arg(long, value_name = "SR")]
    pub detector_omega: Option<f64>,
    /// Detector aperture as a full cone apex angle in degrees.
    #[arg(long, value_name = "DEG", conflicts_with = "detector_omega")]
    pub detector_apex: Option<f64>,
    /// Intermediate θ_in rendered between neighbouring fitted incidences.
    #[arg(long, default_value_t = 1)]
    pub intermediate: usize,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// More folders to look for the measurement files in.
    #[arg(long = "search-dir", value_name = "DIR")]
    pub search_dirs: Vec<PathBuf>,
    /// CSV output [default: DIR/check.csv].
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Worker threads [default: all cores].
    #[arg(long)]
    pub jobs: Option<usize>,
}

pub(crate) fn run(args: CheckArgs) -> Result<()> {
    let apex = |a: Option<f64>| a.map(brtf_model::cone_solid_angle);
    let options = CheckOptions {
        samples: args.samples,
        max_directions: args.max_directions,
        source_omega: args.source_omega.or(apex(args.source_apex)),
        detector_omega: args.detector_omega.or(apex(args.detector_apex)),
        intermediate: args.intermediate,
        seed: args.seed,
        search_dirs: args.search_dirs.clone(),
    };
    let (report, out) = with_jobs(args.jobs, || {
        brtf_workflow::check_folder(&args.dir, &options, args.out.as_deref())
    })??;
    super::output::print(&report.to_string())?;
    say!("brtf check: wrote {}", out.display());
    Ok(())
}
