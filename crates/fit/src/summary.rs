//! The plain-text summary `brtf fit` prints: inputs, the parameter table
//! with standard errors, the warnings and the all-incidence material.

use crate::report::FitReport;
use crate::result::FitResult;
use std::fmt::Write as _;
use std::path::Path;

/// The summary of `result`, written into `out`.
pub fn summary(result: &FitResult, out: &Path) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "brtf fit: {} {} ({} variant), {} incidence(s) -> {}",
        result.name,
        result.config.shape(),
        result.config.options.variant,
        result.incidences.len(),
        out.display()
    );
    if result.provenance.inputs.len() > GROUP_ABOVE {
        inputs_by_file(&mut s, result);
    } else {
        for i in &result.provenance.inputs {
            let _ = writeln!(
                s,
                "  {}: θ_in {}°, φ_in {}°, {} samples, {}{}",
                i.path,
                i.theta_in,
                i.phi_in,
                i.samples,
                i.conversion,
                i.describe_turn()
            );
            for shadow in &i.shadows {
                let _ = writeln!(s, "    shadow masked: {shadow}");
            }
        }
    }
    if result.colour_measured() == Some(false) {
        let _ = writeln!(
            s,
            "  colour not measured (one-channel CIE-Y data): the material is grey, R = G = B; \
             `brtf export DIR --colour R,G,B` gives it one"
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
    let _ = writeln!(s, " {:>7} {:>8} {:>8}  termination", "E1", "rms_rel", "ms");
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
        let e1 =
            r.e1.map_or_else(|| "–".to_string(), |e| format!("{:.1}%", 100.0 * e));
        let _ = writeln!(
            s,
            " {:>7} {:>8.4} {:>8.0}  {}",
            e1, r.rms_rel, r.elapsed_ms, r.termination
        );
    };
    for r in &result.incidences {
        line(format!("{}", r.theta_in), r);
    }
    if let Some(g) = &result.global {
        line("all".into(), g);
    }
    let _ = writeln!(s, "(! = at a bound, = = held fixed)");
    auto_table(&mut s, result);
    adequacy_table(&mut s, result);
    // The set's own warnings go to stderr (the CLI prints them).
    let warnings = warning_lines(result);
    if !warnings.is_empty() {
        let _ = writeln!(
            s,
            "\nwarnings, one line per kind (each incidence's own are in fit.json and report.html):"
        );
        for w in &warnings {
            let _ = writeln!(s, "  {w}");
        }
    }
    if !result.incidences.is_empty() {
        let verdict = result.verdict();
        let _ = writeln!(s, "\nverdict: {}", verdict.headline());
        for line in verdict.lines() {
            let _ = writeln!(s, "  {line}");
        }
    }
    if let Some(g) = &result.global {
        let shape = result.config.shape();
        let args: Vec<String> = g.material_args.iter().map(|a| format!("{a:.6}")).collect();
        if shape.is_single() {
            // As Radiance reads it: the *2 types carry their orientation.
            let strings = match result.config.orientation {
                [x, y, z] if shape.kind.is_anisotropic() => format!("4 {x} {y} {z} ."),
                _ => "0".to_string(),
            };
            let _ = writeln!(
                s,
                "\nall-incidence material: void {} {} {strings} 0 {} {}",
                shape.kind,
                result.name,
                args.len(),
                args.join(" ")
            );
        } else {
            let named: Vec<String> = shape
                .param_names()
                .iter()
                .zip(&args)
                .map(|(n, a)| format!("{n}={a}"))
                .collect();
            let _ = writeln!(s, "\nall-incidence material: {shape}: {}", named.join(" "));
        }
    }
    s
}

/// Above this many inputs (a Klems side has 145) they are listed per file.
const GROUP_ABOVE: usize = 12;

/// One line per input file: how many incidences it gave, over which θ_in.
fn inputs_by_file(s: &mut String, result: &FitResult) {
    let mut files: Vec<(&str, Vec<&crate::InputFile>)> = Vec::new();
    for i in &result.provenance.inputs {
        match files.iter_mut().find(|(path, _)| *path == i.path) {
            Some((_, list)) => list.push(i),
            None => files.push((&i.path, vec![i])),
        }
    }
    for (path, list) in files {
        let (lo, hi) = range(list.iter().map(|i| i.theta_in));
        let (fewest, most) = range(list.iter().map(|i| i.samples as f64));
        let samples = if fewest == most {
            format!("{fewest} samples each")
        } else {
            format!("{fewest}–{most} samples")
        };
        let _ = writeln!(
            s,
            "  {path}: {} incidences, θ_in {lo}–{hi}°, {samples}, {}",
            list.len(),
            list[0].conversion
        );
    }
}

/// The smallest and largest of `values`.
pub(crate) fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    })
}

/// The fit's warnings, one line per kind (and parameter): a kind that one
/// incidence has, in full with its incidence; one that several have, how
/// many, over which θ_in, and one example in full; the all-incidence fit's
/// own (with several incidences) counted with its kind. What the summary
/// and report.html show; fit.json keeps every incidence's own list.
pub fn warning_lines(result: &FitResult) -> Vec<String> {
    struct Group {
        kind: String,
        incidences: usize,
        theta: (f64, f64),
        global: bool,
        example: String,
    }
    let mut groups: Vec<Group> = Vec::new();
    let global = result.global.iter().filter(|_| result.incidences.len() > 1);
    let reports = result
        .incidences
        .iter()
        .map(|r| (r, false))
        .chain(global.map(|r| (r, true)));
    for (r, is_global) in reports {
        for w in &r.warnings {
            let kind = warning_kind(w);
            let example = if is_global {
                format!("all incidences: {w}")
            } else {
                format!("{} (θ_in {}): {w}", r.source, r.theta_in)
            };
            let group = match groups.iter_mut().position(|g| g.kind == kind) {
                Some(i) => &mut groups[i],
                None => {
                    groups.push(Group {
                        kind,
                        incidences: 0,
                        theta: (f64::INFINITY, f64::NEG_INFINITY),
                        global: false,
                        example,
                    });
                    groups.last_mut().expect("just pushed")
                }
            };
            if is_global {
                group.global = true;
            } else {
                group.incidences += 1;
                group.theta = (group.theta.0.min(r.theta_in), group.theta.1.max(r.theta_in));
            }
        }
    }
    groups
        .into_iter()
        .map(|g| {
            if g.incidences + usize::from(g.global) <= 1 {
                return g.example;
            }
            let (lo, hi) = g.theta;
            let also = if g.global {
                " and the all-incidence fit"
            } else {
                ""
            };
            let (count, theta) = match g.incidences {
                1 => ("1 incidence".to_string(), format!("θ_in {lo}°")),
                n => (format!("{n} incidences"), format!("θ_in {lo}–{hi}°")),
            };
            format!("{}: {count} ({theta}){also}; e.g. {}", g.kind, g.example)
        })
        .collect()
}

/// What a warning is about, without its numbers.
fn warning_kind(w: &crate::FitWarning) -> String {
    use crate::FitWarning as W;
    match w {
        W::AtBound { param, .. } => format!("{param} ended at a bound"),
        W::FreeScaleColour => "free scale: colour and scale are one product".into(),
        W::UnderstatedErrors { .. } => "standard errors understated".into(),
        W::DegenerateLobe => "specularity ≈ 0: degenerate lobe".into(),
        W::NotConverged { .. } => "not converged".into(),
        W::RobustNotSettled { .. } => "robust reweighting not settled".into(),
        W::EnergyMismatch { .. } => "data and model ρ_dh/τ_dh differ".into(),
        W::PeakOffset { .. } => "model peak away from the data's".into(),
        W::CollapsedLobe { .. } => "a lobe of the lobe sum collapsed".into(),
        W::ResidualKindSensitive { check } => format!(
            "{} moves with another residual kind ({:?})",
            check.param, check.residual
        ),
    }
}

/// `--model auto`'s candidates and its choice.
fn auto_table(s: &mut String, result: &FitResult) {
    let Some(auto) = &result.auto else {
        return;
    };
    let _ = writeln!(
        s,
        "\n--model auto: {} folds for the held-out E1 (* = chosen, – = not a candidate):",
        crate::FOLDS
    );
    let _ = writeln!(
        s,
        "  {:<40} {:>6} {:>7} {:>9} {:>6} {:>10} {:>7}",
        "model", "params", "E1", "held-out", "peak°", "cost", "ms"
    );
    for (i, c) in auto.candidates.iter().enumerate() {
        let mark = if i == auto.chosen {
            "*"
        } else if i < auto.first {
            "–"
        } else {
            " "
        };
        let peak = c
            .peak_offset_deg
            .map_or_else(|| "–".to_string(), |p| format!("{p:.1}"));
        let collapsed = if c.collapsed { "  (collapsed)" } else { "" };
        let _ = writeln!(
            s,
            "{mark} {:<40} {:>6} {:>6.1}% {:>8.1}% {:>6} {:>10.4e} {:>7.0}{collapsed}",
            c.model,
            c.parameters,
            100.0 * c.e1,
            100.0 * c.e1_heldout,
            peak,
            c.cost,
            c.elapsed_ms
        );
    }
    let _ = writeln!(s, "  chosen: {}", auto.reason);
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
    let raw_unit = rows
        .iter()
        .find_map(|(_, a)| a.energy().and_then(|e| e.unit));
    for (r, a) in rows {
        let figure = a.energy();
        let data = figure.as_ref().map(|e| e.data);
        let model = figure.as_ref().map_or(a.rho_model, |e| e.model);
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
    if let Some(unit) = raw_unit {
        let _ = writeln!(
            s,
            "  free scale: data and model are Σ Ω |cos θ_out| y over the measured directions, in \
             {unit} (the data's never depend on the fit; give --rho or a beam integral for ρ_dh)"
        );
    }
}
