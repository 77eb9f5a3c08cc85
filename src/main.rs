//! The `brtf` command line: argument parsing, progress and wiring only.
//! Physics lives in `brtf-model`, file formats in `brtf-gonio`, Radiance
//! text in `brtf-radiance`.

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
}

fn main() {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Eval(args) => cmd::eval::run(args),
        Command::Albedo(args) => cmd::albedo::run(args),
        Command::Info(args) => cmd::info::run(args),
    };
    if let Err(err) = result {
        eprintln!("brtf: error: {err:#}");
        std::process::exit(1);
    }
}
