//! The `brtf` command line: argument parsing, progress and printing only;
//! the work is done by the crates (ARCHITECTURE.md).

/// `eprintln!` that does not panic when standard error cannot be written
/// (closed, or a full device): the message is dropped, the run goes on.
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

mod cmd;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};

/// Fit Radiance materials to gonio-photometer measurements.
#[derive(Parser, Debug)]
#[command(name = "brtf", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Evaluate a material's BSDF (1/sr, no cosine) for directions read as CSV on stdin.
    Eval(cmd::eval::EvalArgs),
    /// Directional-hemispherical reflectance and transmittance of a material.
    Albedo(cmd::albedo::AlbedoArgs),
    /// Summarise measurement files (.mpc, pab-opto Mountain, Klems or tensor-tree BSDF XML).
    Info(cmd::info::InfoArgs),
    /// Write synthetic measurement files with realistic instrument effects.
    Synth(cmd::synth::SynthArgs),
    /// Fit a material to measurement files, one incidence each.
    Fit(cmd::fit::FitArgs),
    /// Write Radiance materials (static and θ_in-dependent) from a fit folder.
    Export(cmd::export::ExportArgs),
    /// Render with brtf's own ray tracer: a virtual gonio-photometer or an image.
    Render(cmd::render::RenderArgs),
    /// Check a fit by rendering every incidence through the virtual gonio-photometer.
    Check(cmd::check::CheckArgs),
    /// Plot residuals and parameter curves of a fit folder.
    Plot(cmd::plot::PlotArgs),
}

/// mimalloc, keeping freed memory (no purging) on transparent huge pages:
/// glibc's malloc and mimalloc's defaults fault big blocks in again after
/// each free, 4 KiB at a time (docs/benchmarks.md, "The allocator").
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

#[allow(unsafe_code)]
fn tune_allocator() {
    // SAFETY: stores of two options, before any other thread is started.
    unsafe {
        libmimalloc_sys::mi_option_set(libmimalloc_sys::mi_option_large_os_pages, 1);
        // 15: mimalloc v2's `mi_option_purge_delay` (libmimalloc-sys names no constant).
        libmimalloc_sys::mi_option_set(15, -1);
    }
}

/// Exit codes (docs/outputs.md): 0 on success and when the reader of
/// standard output has gone (as ripgrep), 1 on every error, the command
/// line's included; `--help` and `--version` exit 0; Ctrl-C and kill: 130, 143.
fn main() {
    tune_allocator();
    // Ctrl-C and kill remove the staging folder and lock of a run.
    let _ = brtf_io::clean_up_on_signals();
    // `--theta-cap -5` is a value, not an unknown option, in every command.
    fn negative_numbers(c: clap::Command) -> clap::Command {
        c.allow_negative_numbers(true)
            .mut_subcommands(negative_numbers)
    }
    let command = negative_numbers(Cli::command());
    let parsed = command
        .try_get_matches()
        .and_then(|m| Cli::from_arg_matches(&m));
    let cli = parsed.unwrap_or_else(|e| {
        let _ = e.print();
        std::process::exit(if e.use_stderr() { 1 } else { 0 })
    });
    let result = match cli.command {
        Command::Eval(args) => cmd::eval::run(args),
        Command::Albedo(args) => cmd::albedo::run(args),
        Command::Info(args) => cmd::info::run(args),
        Command::Synth(args) => cmd::synth::run(args),
        Command::Fit(args) => cmd::fit::run(args),
        Command::Export(args) => cmd::export::run(args),
        Command::Render(args) => cmd::render::run(args),
        Command::Check(args) => cmd::check::run(args),
        Command::Plot(args) => cmd::plot::run(args),
    };
    if let Err(err) = result {
        if cmd::output::is_broken_pipe(&err) {
            std::process::exit(0);
        }
        say!("brtf: error: {err:#}");
        std::process::exit(1);
    }
}
