//! `brtf-fuzz`: runs mutated inputs through every brtf parser and prints
//! cases, panics, hangs and peak memory. Exit status 1 when anything
//! panicked, hung or misbehaved.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use brtf_fuzz::run::thread_cpu_time;
use brtf_fuzz::{Config, SeedSources, Seeds, Target, format_report, make_case, run, run_case};
use clap::Parser;

/// Mutation fuzzing of the .mpc, Mountain, .rad, fit.json, Klems XML and tensor-tree parsers.
#[derive(Parser, Debug)]
#[command(version)]
struct Args {
    /// Number of mutated inputs to run.
    #[arg(long, default_value_t = 100_000)]
    cases: u64,
    /// Run seed; case i of seed S is always the same input.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Worker threads (default: one per core).
    #[arg(long)]
    threads: Option<usize>,
    /// A case slower than this many milliseconds counts as a hang.
    #[arg(long, default_value_t = 1000)]
    hang_ms: u64,
    /// One case in N uses a whole big file instead of an excerpt (0: never).
    #[arg(long, default_value_t = 2000)]
    whole_file_every: u64,
    /// Repository root (default: the checkout this binary was built in).
    #[arg(long)]
    repo: Option<PathBuf>,
    /// Shared real-data folder (default: `../shared/data` beside the repository).
    #[arg(long)]
    data: Option<PathBuf>,
    /// Save inputs of panics, hangs and anomalies here.
    #[arg(long, default_value = "target/fuzz-findings")]
    findings: PathBuf,
    /// Run only case N (with the normal panic output) and write its input
    /// to `--dump`.
    #[arg(long, value_name = "N")]
    replay: Option<u64>,
    /// With --replay: where to write the case's input.
    #[arg(long, value_name = "FILE")]
    dump: Option<PathBuf>,
    /// Run only these parsers (repeat or comma-separate; default: all).
    #[arg(long, value_enum, value_delimiter = ',')]
    target: Vec<TargetArg>,
}

/// `--target` values.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
enum TargetArg {
    /// ISE `.mpc` reader.
    Mpc,
    /// pab-opto Mountain reader.
    Mountain,
    /// Format detection, then either reader.
    Detected,
    /// Radiance primitives and materials.
    Rad,
    /// `fit.json`.
    FitJson,
    /// Klems BSDF XML, and brtf's Klems writer.
    Klems,
    /// Tensor-tree BSDF XML.
    TensorTree,
}

impl TargetArg {
    fn target(self) -> Target {
        match self {
            TargetArg::Mpc => Target::Mpc,
            TargetArg::Mountain => Target::Mountain,
            TargetArg::Detected => Target::DetectedGonio,
            TargetArg::Rad => Target::Rad,
            TargetArg::FitJson => Target::FitJson,
            TargetArg::Klems => Target::Klems,
            TargetArg::TensorTree => Target::TensorTree,
        }
    }
}

fn main() -> ExitCode {
    let args = Args::parse();
    let mut sources = SeedSources::beside_this_checkout();
    if let Some(repo) = args.repo {
        sources.shared_data = repo.join("../shared/data");
        sources.repo = repo;
    }
    if let Some(data) = args.data {
        sources.shared_data = data;
    }
    let seeds = match Seeds::load(&sources) {
        Ok(seeds) => seeds,
        Err(message) => {
            eprintln!("brtf-fuzz: error: {message}");
            return ExitCode::from(2);
        }
    };
    let config = Config {
        cases: args.cases,
        seed: args.seed,
        threads: args
            .threads
            .unwrap_or_else(|| std::thread::available_parallelism().map_or(2, usize::from)),
        hang_limit: Duration::from_millis(args.hang_ms),
        whole_file_every: args.whole_file_every,
        findings_dir: Some(args.findings),
        progress: true,
        targets: args.target.iter().map(|t| t.target()).collect(),
        ..Config::default()
    };
    if let Some(index) = args.replay {
        let case = make_case(&seeds, &config, index);
        println!(
            "case {index}: {} from {}, mutations {:?}, {} bytes",
            case.target.label(),
            case.origin,
            case.mutations,
            case.bytes.len()
        );
        if let Some(path) = &args.dump
            && let Err(e) = std::fs::write(path, &case.bytes)
        {
            eprintln!("brtf-fuzz: error: cannot write {}: {e}", path.display());
            return ExitCode::from(2);
        }
        let began = std::time::Instant::now();
        let cpu_before = thread_cpu_time();
        let outcome = run_case(&case);
        let cpu = thread_cpu_time()
            .zip(cpu_before)
            .map(|(after, before)| after.saturating_sub(before));
        println!(
            "{outcome:?}\n{:.1} ms wall, {} CPU",
            began.elapsed().as_secs_f64() * 1e3,
            cpu.map_or_else(
                || "unknown".into(),
                |c| format!("{:.1} ms", c.as_secs_f64() * 1e3)
            )
        );
        return ExitCode::SUCCESS;
    }
    let seeds_count = seeds.all.len();
    eprintln!(
        "brtf-fuzz: {} cases from {seeds_count} seeds ({}, {}), {} threads",
        config.cases,
        sources.repo.display(),
        sources.shared_data.display(),
        config.threads
    );
    let report = run(&seeds, &config);
    print!("{}", format_report(&report, &config));
    if report.panics.is_empty() && report.hangs.is_empty() && report.anomalies.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}
