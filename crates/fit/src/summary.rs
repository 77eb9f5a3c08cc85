//! The plain-text summary `brtf fit` prints: inputs, the parameter table
//! with standard errors, the warnings and the all-incidence material.

use crate::report::FitReport;
use crate::result::FitResult;
use std::fmt::Write as _;
use std::path::Path;

/// The summary of `result`, written into `out`.
pub fn summary(result: &FitResult, out: &Path) -> String {
    let mut s = String::new();
    let kind = result.config.kind;
    let _ = writeln!(
        s,
        "brtf fit: {} {} ({} variant), {} incidence(s) -> {}",
        result.name,
        kind,
        result.config.options.variant,
        result.incidences.len(),
        out.display()
    );
    for i in &result.provenance.inputs {
        let _ = writeln!(
            s,
            "  {}: θ_in {}°, φ_in {}°, {} samples, {}",
            i.path, i.theta_in, i.phi_in, i.samples, i.conversion
        );
    }
    let names: Vec<&str> = result
        .incidences
        .first()
        .map(|r| r.params.iter().map(|p| p.name.as_str()).collect())
        .unwrap_or_default();
    let _ = write!(s, "\n{:>8} {:>7}", "θ_in", "points");
    for n in &names {
        let _ = write!(s, " {:>17}", n);
    }
    let _ = writeln!(s, " {:>8} {:>8}  termination", "rms_rel", "ms");
    let mut line = |label: String, r: &FitReport| {
        let _ = write!(s, "{:>8} {:>7}", label, r.n_points);
        for p in &r.params {
            let flag = if p.at_bound {
                "!"
            } else if p.fixed {
                "="
            } else {
                " "
            };
            match (p.stderr, p.missing_error_reason()) {
                (Some(e), _) => {
                    let _ = write!(s, " {:>8.5}±{:<7.1e}{}", p.value, e, flag);
                }
                // A held parameter says so with its flag alone.
                (None, Some("fixed")) => {
                    let _ = write!(s, " {:>8.5} {:<7}{}", p.value, "", flag);
                }
                (None, reason) => {
                    let _ = write!(s, " {:>8.5} {:<7}{}", p.value, reason.unwrap_or(""), flag);
                }
            }
        }
        let _ = writeln!(
            s,
            " {:>8.4} {:>8.0}  {}",
            r.rms_rel, r.elapsed_ms, r.termination
        );
    };
    for r in &result.incidences {
        line(format!("{}", r.theta_in), r);
    }
    if let Some(g) = &result.global {
        line("all".into(), g);
    }
    let _ = writeln!(s, "(! = at a bound, = = held fixed)");
    adequacy_table(&mut s, result);
    let global = result.global.iter().filter(|_| result.incidences.len() > 1);
    let labelled = result
        .incidences
        .iter()
        .map(|r| (r, format!("{} (θ_in {})", r.source, r.theta_in)))
        .chain(global.map(|r| (r, "all incidences".to_string())));
    // The set's own warnings go to stderr (the CLI prints them).
    let warnings: Vec<String> = labelled
        .flat_map(|(r, label)| r.warnings.iter().map(move |w| format!("{label}: {w}")))
        .collect();
    if !warnings.is_empty() {
        let _ = writeln!(s, "\nwarnings:");
        for w in &warnings {
            let _ = writeln!(s, "  {w}");
        }
    }
    if let Some(g) = &result.global {
        let args: Vec<String> = g.material_args.iter().map(|a| format!("{a:.6}")).collect();
        let _ = writeln!(
            s,
            "\nall-incidence material: void {kind} {} 0 0 {} {}",
            result.name,
            args.len(),
            args.join(" ")
        );
    }
    s
}

/// The adequacy diagnostics, one line per incidence that has them.
fn adequacy_table(s: &mut String, result: &FitResult) {
    let rows: Vec<(&FitReport, &crate::Adequacy)> = result
        .incidences
        .iter()
        .filter_map(|r| r.adequacy.as_ref().map(|a| (r, a)))
        .collect();
    if rows.is_empty() {
        return;
    }
    let _ = writeln!(
        s,
        "\nadequacy (warns beyond ±{:.0}% energy, {:.0}° peak offset, {:.0}% parameter change):",
        100.0 * crate::ENERGY_TOLERANCE,
        crate::PEAK_TOLERANCE_DEG,
        100.0 * crate::RESIDUAL_KIND_TOLERANCE
    );
    let _ = writeln!(
        s,
        "{:>8} {:>10} {:>10} {:>7} {:>6}  other residual kind",
        "θ_in", "data ρ/τ", "model ρ/τ", "ratio", "peak°"
    );
    let opt = |x: Option<f64>, width: usize, precision: usize| {
        x.map_or_else(
            || format!("{:>width$}", "–"),
            |v| format!("{v:>width$.precision$}"),
        )
    };
    for (r, a) in rows {
        let (data, model) = match a.rho_data {
            Some(d) => (Some(d), a.rho_model),
            None => (a.tau_data, a.tau_model),
        };
        let check = a.residual_check.as_ref().map_or_else(String::new, |c| {
            format!(
                "{:?}: {} {:.4} → {:.4} ({:.0}%)",
                c.residual,
                c.param,
                c.values[0],
                c.values[1],
                100.0 * c.relative_change
            )
        });
        let _ = writeln!(
            s,
            "{:>8} {} {:>10.4} {} {}  {check}",
            r.theta_in,
            opt(data, 10, 4),
            model,
            opt(a.energy_ratio(), 7, 3),
            opt(a.peak_offset_deg, 6, 1),
        );
    }
}
