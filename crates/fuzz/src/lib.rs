//! # brtf-fuzz: mutation fuzzing of every brtf parser, on stable Rust
//!
//! Seeds are the real and shipped files ([`seeds`]); each case applies a
//! few random mutations ([`mutate`]) and feeds the result to one parser
//! and to what brtf does next with an accepted input ([`targets`]). The
//! runner ([`run`]) catches panics, times every case (over 1 s is a hang),
//! and reports peak memory. `scripts/fuzz.sh` runs a million cases;
//! `tests/main.rs` runs a short version in CI. Results: `docs/reliability.md`.

pub mod mutate;
pub mod run;
pub mod seeds;
pub mod targets;

use std::fmt::Write as _;

pub use run::{Config, Report, make_case, run, run_case};
pub use seeds::{SeedSources, Seeds, Target};

/// The report as text: the headline figures, then per target and per
/// mutation, then every finding (the first lines of each).
pub fn format_report(report: &Report, config: &Config) -> String {
    let mut out = String::new();
    let w = &mut out;
    let _ = writeln!(w, "seed          {}", config.seed);
    let _ = writeln!(w, "threads       {}", config.threads);
    let _ = writeln!(w, "cases         {}", report.cases);
    let _ = writeln!(w, "panics        {}", report.panics.len());
    let _ = writeln!(
        w,
        "hangs         {} (cases over {:.1} s of CPU time)",
        report.hangs.len(),
        config.hang_limit.as_secs_f64()
    );
    let _ = writeln!(
        w,
        "slow wall     {} (over {:.1} s of wall time only: waiting for a busy CPU)",
        report.slow_under_load.len(),
        config.hang_limit.as_secs_f64()
    );
    let _ = writeln!(w, "anomalies     {}", report.anomalies.len());
    if let Some((time, case, origin, target)) = &report.slowest {
        let _ = writeln!(
            w,
            "slowest case  {:.1} ms (case {case}, {}, {origin})",
            time.as_secs_f64() * 1e3,
            target.label()
        );
    }
    let memory = report.peak_memory_kib.map_or_else(
        || "unknown".into(),
        |k| format!("{:.1} MiB", k as f64 / 1024.0),
    );
    let _ = writeln!(w, "peak memory   {memory} (VmHWM)");
    let _ = writeln!(w, "time          {:.1} s", report.elapsed.as_secs_f64());
    let _ = writeln!(
        w,
        "\nper target        cases   accepted   rejected   slowest ms   largest input"
    );
    for target in Target::ALL {
        if let Some(s) = report.per_target.get(&target) {
            let _ = writeln!(
                w,
                "  {:<16}{:>7}{:>11}{:>11}{:>13.1}{:>16}",
                target.label(),
                s.cases,
                s.accepted,
                s.rejected,
                s.slowest.as_secs_f64() * 1e3,
                s.largest_input
            );
        }
    }
    let _ = writeln!(w, "\nmutations applied");
    for kind in mutate::Kind::ALL {
        let n = report.per_mutation.get(&kind).copied().unwrap_or(0);
        let _ = writeln!(w, "  {:<16}{n:>9}", format!("{kind:?}"));
    }
    for (title, list) in [
        ("panics", &report.panics),
        ("hangs", &report.hangs),
        ("slow under load", &report.slow_under_load),
        ("anomalies", &report.anomalies),
    ] {
        if list.is_empty() {
            continue;
        }
        let _ = writeln!(
            w,
            "\n{title} ({}), one case per distinct first line",
            list.len()
        );
        let mut seen = std::collections::HashMap::new();
        for f in list {
            *seen
                .entry(f.message.lines().next().unwrap_or(""))
                .or_insert(0usize) += 1;
        }
        let mut shown = std::collections::HashSet::new();
        for f in list {
            let first = f.message.lines().next().unwrap_or("");
            if !shown.insert(first) || shown.len() > 20 {
                continue;
            }
            let first_lines: Vec<&str> = f.message.lines().take(16).collect();
            let _ = writeln!(
                w,
                "  {} case(s) like case {} ({}, {}, {:?}, {:.1} ms){}\n    {}",
                seen[first],
                f.case,
                f.target.label(),
                f.origin,
                f.mutations,
                f.elapsed.as_secs_f64() * 1e3,
                f.saved_to
                    .as_ref()
                    .map_or_else(String::new, |p| format!(", input {}", p.display())),
                first_lines.join("\n    ")
            );
        }
        if seen.len() > 20 {
            let _ = writeln!(w, "  … and {} more kinds", seen.len() - 20);
        }
    }
    out
}
