//! What each case runs: the parser, then what brtf does next with an
//! accepted input (so a parser that lets a bad value through is caught
//! where it would hurt).
//!
//! * measurements: read; on success summarise (as `brtf info`), write as
//!   Mountain and `.mpc` and read back (as `brtf convert`);
//! * `.rad`: parse, pick the material (as `brtf eval`), convert every
//!   primitive, evaluate each material, print and re-parse primitives;
//! * `fit.json`: read; on success write it again, build `params.csv`, the
//!   materials at several θ_in and the Radiance exports (as `brtf export`).
//!
//! Beyond panics, an "anomaly" is a wrong result that is no crash: an
//! error that does not start with `file:line` (line ≥ 1 and inside the
//! file), a written file that does not read back, or a valid material
//! whose BSDF is not finite.

use std::path::Path;

use brtf_gonio::{Measurement, SourceFormat};
use brtf_model::{Bsdf, EvalOptions, Material};
use glam::DVec3;

use crate::seeds::Target;

/// How a case ended (a panic never returns here; the runner catches it).
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    /// The input was accepted.
    Accepted,
    /// The input was refused with this error message.
    Rejected(String),
    /// Something is wrong without a crash.
    Anomaly {
        /// The kind of problem, for grouping (`written .mpc does not read back`).
        class: &'static str,
        /// The details.
        detail: String,
    },
}

/// Runs `bytes`, named `name`, through `target`.
pub fn exercise(target: Target, name: &str, bytes: &[u8]) -> Outcome {
    match target {
        Target::Mpc => gonio(bytes, name, Some(SourceFormat::Mpc)),
        Target::Mountain => gonio(bytes, name, Some(SourceFormat::Mountain)),
        Target::DetectedGonio => gonio(bytes, name, None),
        Target::Rad => rad(bytes, name),
        Target::FitJson => fit_json(bytes, name),
        Target::Klems => klems(bytes, name, true),
        Target::TensorTree => tensor_tree(bytes, name),
    }
}

/// The BSDF XML reader on tensor trees, then `brtf info`'s totals and the
/// measurements and leaf directions a fit takes at `brtf info`'s θ_in.
fn tensor_tree(bytes: &[u8], name: &str) -> Outcome {
    use brtf_gonio::klems::{BsdfXml, ttree::INFO_THETAS};
    let tree = match brtf_gonio::klems::read_any_bytes(bytes, name) {
        Ok(BsdfXml::TensorTree(tree)) => tree,
        Ok(BsdfXml::Klems(_)) => return Outcome::Accepted,
        Err(e) => return refused(e.to_string(), e.line(), bytes, name),
    };
    let info = tree.info();
    let _ = info.to_string();
    let not_finite = |v: Option<f64>| v.is_some_and(|v| !v.is_finite());
    if let Some(p) = info
        .incidences
        .iter()
        .find(|p| not_finite(p.rho_dh) || not_finite(p.tau_dh))
    {
        return anomaly(
            "accepted tensor tree has a non-finite total",
            format!("{p:?}"),
        );
    }
    for side in tree.sides_present() {
        for theta in INFO_THETAS {
            let Some((m, places)) = tree.measurement(side, theta, 0.0) else {
                continue;
            };
            let _ = m.summary();
            let mut rng = brtf_model::Rng::new(1, 0);
            for place in places.iter().take(50) {
                for (light, view) in place.stratified_pairs(4, &mut rng) {
                    if !(light.is_finite() && view.is_finite()) {
                        return anomaly(
                            "tensor-tree leaf direction is not finite",
                            format!("{place:?}"),
                        );
                    }
                }
            }
        }
    }
    Outcome::Accepted
}

/// An accepted Klems file written by brtf's writer reads back with the
/// same matrices.
fn klems_round_trip(bsdf: &brtf_gonio::klems::KlemsBsdf, name: &str) -> Outcome {
    let written = match crate::seeds::rewrite(bsdf, name) {
        Ok(w) => w,
        Err(e) => return anomaly("accepted Klems file cannot be written", e),
    };
    match brtf_gonio::klems::read_str(&written, name) {
        Ok(again) if again.matrices.len() == bsdf.matrices.len() => Outcome::Accepted,
        Ok(again) => anomaly(
            "written Klems file reads back other matrices",
            format!(
                "{} matrices read back as {}",
                bsdf.matrices.len(),
                again.matrices.len()
            ),
        ),
        Err(e) => anomaly("written Klems file does not read back", e.to_string()),
    }
}

fn gonio(bytes: &[u8], name: &str, format: Option<SourceFormat>) -> Outcome {
    // Detected Klems XML goes where `brtf info` sends it.
    if format.is_none()
        && brtf_gonio::detect_format(bytes, Path::new(name)) == SourceFormat::KlemsXml
    {
        return klems(bytes, name, false);
    }
    let result = match format {
        Some(format) => brtf_gonio::read_bytes_as(bytes, name, format),
        None => brtf_gonio::read_bytes(bytes, name),
    };
    let measurement = match result {
        Ok(m) => m,
        Err(e) => return refused(e.to_string(), e.line(), bytes, name),
    };
    let _ = measurement.summary();
    if let Some((class, detail)) = round_trip(&measurement, name) {
        return anomaly(class, detail);
    }
    if let Some((class, detail)) = residuals_csv(measurement, name) {
        return anomaly(class, detail);
    }
    Outcome::Accepted
}

/// The committed fit of `data/alu-ggx`, whose recipe and first material
/// turn an accepted measurement into `residuals.csv` rows.
fn template_fit() -> &'static brtf_fit::FitResult {
    static FIT: std::sync::OnceLock<brtf_fit::FitResult> = std::sync::OnceLock::new();
    FIT.get_or_init(|| {
        let text = include_str!("../../../fits/alu-ggx/fit.json");
        brtf_fit::FitResult::from_json(text, Path::new("fits/alu-ggx/fit.json"))
            .expect("the committed fit reads")
    })
}

/// `residuals.csv` of an accepted measurement, as `brtf fit` writes it
/// (prepared by a fit's recipe, the model beside each sample): one row per
/// sample with the header's columns, every angle a finite number, every
/// value one or empty (not available), every gate empty or a gate's name. A measurement the recipe refuses is no anomaly
/// (the fit refuses it too, with its own message).
fn residuals_csv(measurement: Measurement, name: &str) -> Option<(&'static str, String)> {
    let fit = template_fit();
    let samples = measurement.len();
    let prepared = fit.recipe.prepare(measurement, name).ok()?;
    let header = brtf_fit::residuals_header(prepared.channels());
    let columns = header.trim_end().split(',').count();
    let rows = brtf_fit::residual_rows(fit, 0, &prepared).concat();
    let Ok(text) = String::from_utf8(rows) else {
        return Some(("residuals.csv is not UTF-8", name.to_string()));
    };
    let gates: Vec<&str> = fit.recipe.selections.iter().map(|g| g.name()).collect();
    let mut count = 0;
    for line in text.lines() {
        count += 1;
        let fields: Vec<&str> = line.split(',').collect();
        // Angles are numbers; a value that is not finite (a sample not
        // available) is written as an empty field.
        let number = |f: &&str| f.parse::<f64>().is_ok_and(f64::is_finite);
        let numbers_read = fields.len() == columns
            && fields[..4].iter().all(number)
            && fields[4..columns - 1]
                .iter()
                .all(|f| f.is_empty() || number(f));
        let gate = fields[fields.len() - 1];
        if fields.len() != columns || !numbers_read || !(gate.is_empty() || gates.contains(&gate)) {
            return Some(("residuals.csv row does not read back", line.to_string()));
        }
    }
    (count != samples).then(|| {
        (
            "residuals.csv has other rows than samples",
            format!("{count} rows for {samples} samples"),
        )
    })
}

/// A refusal with `message` at `line`: an anomaly when the line lies
/// outside the file (lone `\r` count as line ends, as editors and the
/// text readers count them; the XML parser counts `\n` only, so a line is
/// outside only beyond both counts), else as [`located`] judges it.
fn refused(message: String, line: Option<usize>, bytes: &[u8], name: &str) -> Outcome {
    let lines = line_count(bytes, true);
    match line {
        Some(line) if line == 0 || line > lines => anomaly(
            "error line outside the file",
            format!("error on line {line} of a {lines}-line file: {message}"),
        ),
        _ => located(message, name),
    }
}

/// The Klems reader, then what `brtf info` and the conversion to
/// measurements do with an accepted file, and (`round_trip`) brtf's
/// writer and a read back.
fn klems(bytes: &[u8], name: &str, round_trip: bool) -> Outcome {
    let bsdf = match brtf_gonio::klems::read_bytes(bytes, name) {
        Ok(b) => b,
        Err(e) => return refused(e.to_string(), e.line(), bytes, name),
    };
    let info = bsdf.info();
    let _ = info.to_string();
    let not_finite = |v: Option<f64>| v.is_some_and(|v| !v.is_finite());
    if let Some(p) = info
        .incidences
        .iter()
        .find(|p| not_finite(p.rho_dh) || not_finite(p.tau_dh))
    {
        return anomaly(
            "accepted Klems file has a non-finite column total",
            format!("{p:?}"),
        );
    }
    for m in bsdf.to_measurements() {
        let _ = m.summary();
    }
    if round_trip {
        return klems_round_trip(&bsdf, name);
    }
    Outcome::Accepted
}

/// Writes `m` in both formats and reads it back; `Some((class, detail))`
/// if that fails.
fn round_trip(m: &Measurement, name: &str) -> Option<(&'static str, String)> {
    let mountain = brtf_gonio::to_mountain_string(m);
    match brtf_gonio::read_bytes_as(mountain.as_bytes(), name, SourceFormat::Mountain) {
        Ok(again) if again.len() == m.len() => {}
        Ok(again) => {
            return Some((
                "written Mountain file reads back other rows",
                format!("{} rows read back as {}", m.len(), again.len()),
            ));
        }
        Err(e) => return Some(("written Mountain file does not read back", e.to_string())),
    }
    if let Ok(mpc) = brtf_gonio::to_mpc_string(m) {
        match brtf_gonio::read_bytes_as(mpc.as_bytes(), name, SourceFormat::Mpc) {
            Ok(again) if again.len() == m.len() => {}
            Ok(again) => {
                return Some((
                    "written .mpc file reads back other rows",
                    format!("{} rows read back as {}", m.len(), again.len()),
                ));
            }
            Err(e) => return Some(("written .mpc file does not read back", e.to_string())),
        }
    }
    None
}

fn rad(bytes: &[u8], name: &str) -> Outcome {
    // `brtf eval` reads the file with `read_to_string`, which refuses
    // non-UTF-8; the lossy text still reaches the parser's corners.
    let text = String::from_utf8_lossy(bytes);
    let primitives = match brtf_radiance::parse_primitives(&text, name) {
        Ok(p) => p,
        Err(e) => return rad_error(&e, bytes, name),
    };
    for p in &primitives {
        if let Ok(material) = brtf_radiance::material_from_primitive(p, name)
            && let Some(problem) = eval_problem(&material)
        {
            return anomaly(
                "valid material evaluates to a non-finite BSDF",
                format!("`{}` ({}): {problem}", p.name, p.kind),
            );
        }
        let printed = brtf_radiance::format_primitive(p);
        if let Err(e) = brtf_radiance::parse_primitives(&printed, name) {
            return anomaly("printed primitive does not parse again", e.to_string());
        }
    }
    match brtf_radiance::select_material(&primitives, None, name) {
        Ok(_) => Outcome::Accepted,
        Err(e) => rad_error(&e, bytes, name),
    }
}

fn rad_error(e: &brtf_radiance::RadError, bytes: &[u8], name: &str) -> Outcome {
    let lines = line_count(bytes, false);
    if e.line == 0 || e.line > lines {
        return anomaly(
            "error line outside the file",
            format!("error on line {} of a {lines}-line file: {e}", e.line),
        );
    }
    located(e.to_string(), name)
}

fn fit_json(bytes: &[u8], name: &str) -> Outcome {
    // `FitResult::read` uses `read_to_string`: non-UTF-8 is an I/O error
    // before the parser; the lossy text goes further.
    let text = String::from_utf8_lossy(bytes);
    let result = match brtf_fit::FitResult::from_json(&text, Path::new(name)) {
        Ok(r) => r,
        Err(e) => return located(e.to_string(), name),
    };
    let _ = result.to_json();
    let _ = result.params_csv();
    let mut thetas: Vec<f64> = result.incidences.iter().map(|r| r.theta_in).collect();
    thetas.extend([0.0, 22.5, 45.0, 89.9]);
    for theta in thetas {
        if let Some(material) = result.material_at(theta, None)
            && let Some(problem) = eval_problem(&material)
        {
            return anomaly(
                "valid material evaluates to a non-finite BSDF",
                format!("material at theta_in = {theta}: {problem}"),
            );
        }
    }
    match brtf_radiance::export::exports(&result, &brtf_radiance::export::ExportOptions::default())
    {
        Ok(_) => Outcome::Accepted,
        Err(e) => Outcome::Rejected(e.to_string()),
    }
}

/// Evaluates `material` at a few (l, v) pairs: normal, oblique, grazing,
/// mirror and back side. `Some(problem)` when a value is not finite.
fn eval_problem(material: &Material) -> Option<String> {
    let bsdf = Bsdf::new(material, &EvalOptions::default());
    let dir = |theta: f64, phi: f64| {
        let (t, p) = (theta.to_radians(), phi.to_radians());
        DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
    };
    let pairs = [
        (dir(0.0, 0.0), dir(0.0, 0.0)),
        (dir(30.0, 0.0), dir(30.0, 180.0)),
        (dir(60.0, 0.0), dir(20.0, 90.0)),
        (dir(89.99, 0.0), dir(89.99, 180.0)),
        (dir(30.0, 0.0), dir(150.0, 180.0)),
    ];
    pairs.iter().find_map(|&(l, v)| {
        let value = bsdf.eval(l, v);
        (!value.iter().all(|x| x.is_finite())).then(|| format!("eval gives {value:?}"))
    })
}

/// Rejected when the message starts with `name:`, else an anomaly.
fn located(message: String, name: &str) -> Outcome {
    let prefix = format!("{name}:");
    if message.starts_with(&prefix) {
        Outcome::Rejected(message)
    } else {
        anomaly(
            "error does not start with the file name",
            format!("expected `{prefix}`: {message}"),
        )
    }
}

fn anomaly(class: &'static str, detail: String) -> Outcome {
    Outcome::Anomaly { class, detail }
}

/// Lines in `bytes`, counting `\n` (and, when `lone_cr`, `\r` not followed
/// by `\n`, as the measurement readers do) plus a last unterminated line.
fn line_count(bytes: &[u8], lone_cr: bool) -> usize {
    let mut ends = 0;
    for (i, &b) in bytes.iter().enumerate() {
        if b == b'\n' || (lone_cr && b == b'\r' && bytes.get(i + 1) != Some(&b'\n')) {
            ends += 1;
        }
    }
    ends + 1
}
