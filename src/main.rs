//! The `brtf` command line: argument parsing, progress and wiring only.
//! Physics lives in `brtf-model`, file formats in `brtf-gonio`, Radiance
//! text in `brtf-radiance`.

/// `eprintln!` that does not panic when standard error cannot be written
/// (closed, or a full device): the message is dropped, the run goes on.
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

mod cmd;

use clap::{Parser, Subcommand};

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
    /// Summarise measurement files (.mpc or Mountain).
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

/// glibc's malloc settings for brtf's runs: heap memory on transparent
/// huge pages, and freed memory kept for reuse rather than handed back to
/// the kernel. A run allocates and frees tens of MB in phases; with the
/// defaults each phase faulted its memory in again 4 KiB at a time (18.6k
/// page faults and a quarter of the CPU time in the kernel on a lean
/// golden_paper fit), and mimalloc, tried instead, zeroed ~100 MB of huge
/// pages. See docs/benchmarks.md ("The allocator").
const MALLOC_TUNABLES: &str = "glibc.malloc.hugetlb=1:\
                               glibc.malloc.trim_threshold=2147483647:\
                               glibc.malloc.top_pad=67108864";

/// glibc reads its tunables only when a process starts: unless they are
/// set (by us or by the user, whose own malloc tunables win), run this
/// same program again with them, in place of this process. If that
/// cannot be done the run goes on with the defaults.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn with_tuned_malloc() {
    use std::os::unix::process::CommandExt;
    let current = std::env::var_os("GLIBC_TUNABLES");
    if current
        .as_ref()
        .is_some_and(|v| v.to_string_lossy().contains("glibc.malloc."))
    {
        return;
    }
    let Ok(exe) = std::env::current_exe() else {
        return;
    };
    let tunables = match current {
        Some(v) if !v.is_empty() => format!("{}:{MALLOC_TUNABLES}", v.to_string_lossy()),
        _ => MALLOC_TUNABLES.to_string(),
    };
    let mut args = std::env::args_os();
    let mut again = std::process::Command::new(exe);
    if let Some(name) = args.next() {
        again.arg0(name);
    }
    // `exec` returns only when it failed.
    let _ = again.args(args).env("GLIBC_TUNABLES", tunables).exec();
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn with_tuned_malloc() {}

/// Exit codes (docs/outputs.md): 0 on success and when the reader of
/// standard output has gone (as ripgrep), 1 on every error, the command
/// line's included; `--help` and `--version` exit 0.
fn main() {
    with_tuned_malloc();
    let cli = Cli::try_parse().unwrap_or_else(|e| {
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
