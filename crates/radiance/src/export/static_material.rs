//! The static material `<name>.rad`: one Ward-type primitive (or a lobe
//! sum: its primitives and the constant `mixfunc` tree named `<name>`)
//! with a comment header that says where its parameters come from, how
//! well they fit, which formula set was fitted, and what to watch out for.

use super::num::sig;
use super::report::{self, ascii};
use super::{ExportError, composite_of};
use crate::composite::composite_primitives;
use crate::primitive::format_primitive;
use brtf_fit::{FitReport, FitResult};
use brtf_model::{Composite, Variant};

/// Where the static parameters come from.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Origin<'a> {
    /// The all-incidence fit.
    Global(&'a FitReport),
    /// One incidence's own fit.
    Incidence(&'a FitReport),
    /// The θ_in table at a chosen incidence.
    Interpolated { theta: f64, clamped: bool },
}

/// The static material and its origin.
#[derive(Debug, Clone)]
pub(crate) struct Chosen<'a> {
    pub material: Composite,
    pub origin: Origin<'a>,
}

/// The text and the notes for the user.
pub(crate) struct Text {
    pub text: String,
    pub notes: Vec<String>,
}

/// Picks the static parameters: the all-incidence fit by default, else
/// the table (or the matching incidence) at `at`.
pub(crate) fn choose(result: &FitResult, at: Option<f64>) -> Result<Chosen<'_>, ExportError> {
    let Some(theta) = at else {
        if let Some(global) = &result.global {
            return Ok(Chosen {
                material: composite_of(result, global, "the all-incidence fit")?,
                origin: Origin::Global(global),
            });
        }
        let first = result.incidences.first().ok_or(ExportError::NoParameters)?;
        return Ok(Chosen {
            material: composite_of(result, first, "the first incidence")?,
            origin: Origin::Incidence(first),
        });
    };
    if !(theta.is_finite() && (0.0..90.0).contains(&theta)) {
        return Err(ExportError::At {
            theta,
            reason: "θ_in must be in [0, 90) degrees".into(),
        });
    }
    if let Some(report) = result
        .incidences
        .iter()
        .find(|r| (r.theta_in - theta).abs() < 1e-9)
    {
        return Ok(Chosen {
            material: composite_of(result, report, &format!("θ_in = {theta}"))?,
            origin: Origin::Incidence(report),
        });
    }
    let Some(table) = &result.table else {
        let measured: Vec<String> = result
            .incidences
            .iter()
            .map(|r| format!("{}", r.theta_in))
            .collect();
        return Err(ExportError::At {
            theta,
            reason: format!(
                "no θ_in table to interpolate (needs two incidences); measured: {}",
                if measured.is_empty() {
                    "none".into()
                } else {
                    measured.join(", ")
                }
            ),
        });
    };
    let (material, clamped) = table.composite_at(theta).map_err(|e| ExportError::At {
        theta,
        reason: e.to_string(),
    })?;
    Ok(Chosen {
        material,
        origin: Origin::Interpolated { theta, clamped },
    })
}

/// The file text.
pub(crate) fn text(
    result: &FitResult,
    chosen: &Chosen,
    name: &str,
    file: &str,
    with_theta: bool,
    colour: Option<[f64; 3]>,
) -> Text {
    let material = &chosen.material;
    let kind = material.kind();
    let shape = result.config.shape();
    let lobes = material.components().len();
    let options = result.options();
    let mut notes = Vec::new();
    let what = if lobes > 1 {
        format!("lobe sum ({} {kind} primitives in a mixfunc)", lobes)
    } else {
        kind.to_string()
    };
    let mut h: Vec<String> = Vec::new();
    if result.config.free_scale {
        h.push(
            "NOT RENDERABLE AS IS: fitted with a free scale (raw signal of unknown scale), so \
             its reflectance is relative; refit with --rho VALUE@THETA or --beam-integral B."
                .into(),
        );
    }
    h.extend([
        format!(
            "{}: static Radiance {what} \"{name}\", written by brtf {} (brtf export).",
            file,
            env!("CARGO_PKG_VERSION")
        ),
        String::new(),
    ]);
    h.extend(report::provenance(result));
    h.extend(report::colour_line(result, colour));
    h.extend(report::verdict(result));
    h.push(String::new());
    let (lo, hi) = result
        .table
        .as_ref()
        .map(|t| t.range())
        .or_else(|| result.incidences.first().map(|r| (r.theta_in, r.theta_in)))
        .unwrap_or((0.0, 0.0));
    let mut caveats: Vec<String> = report::scale_caveat(result).into_iter().collect();
    if !caveats.is_empty() {
        notes.push(format!(
            "{}: not renderable as is: the fit had a free scale, so its reflectance is relative (see its header)",
            file
        ));
    }
    match chosen.origin {
        Origin::Global(r) => {
            h.push(match result.incidences.as_slice() {
                [one] => format!(
                    "Parameters: the fit of the one incidence, theta_in = {} deg ({}).",
                    one.theta_in,
                    ascii(&one.source)
                ),
                all => format!(
                    "Parameters: the all-incidence fit ({} incidences, theta_in {lo}-{hi} deg).",
                    all.len()
                ),
            });
            h.push(format!("Fit quality: {}.", report::quality(r)));
            caveats.extend(report::fit_caveats(r));
        }
        Origin::Incidence(r) => {
            h.push(format!(
                "Parameters: the fit of the incidence theta_in = {} deg ({}).",
                r.theta_in,
                ascii(&r.source)
            ));
            h.push(format!("Fit quality: {}.", report::quality(r)));
            caveats.extend(report::fit_caveats(r));
            if result.incidences.len() > 1 {
                caveats.push(format!(
                    "these parameters reproduce the measurement at theta_in = {} deg only.",
                    r.theta_in
                ));
                if result.global.is_none() {
                    notes.push(format!(
                        "{}: no all-incidence fit, so the static material is the fit at θ_in = {}°",
                        file, r.theta_in
                    ));
                }
            }
        }
        Origin::Interpolated { theta, clamped } => {
            h.push(format!(
                "Parameters: the theta_in table ({:?}) at theta_in = {theta} deg.",
                result.interpolation
            ));
            h.push("Fit quality: see the per-incidence fits below.".into());
            caveats.push(format!(
                "these parameters reproduce the measurements near theta_in = {theta} deg only."
            ));
            if clamped {
                caveats.push(format!(
                    "theta_in = {theta} deg is outside the measured {lo}-{hi} deg: the end \
                     incidence's parameters are used."
                ));
            }
        }
    }
    if !result.incidences.is_empty() {
        h.push("Per-incidence fits (arguments in Radiance order):".into());
        h.extend(report::incidences(result));
    }
    h.push(String::new());
    let thetas = sample_thetas(result, chosen);
    h.extend(report::variant_warning(material, &options, &thetas));
    if options.variant != Variant::Radiance {
        notes.push(format!(
            "{}: fitted with variant {}, which current rtrace does not compute (see its header)",
            file, options.variant
        ));
        if with_theta {
            h.push(format!(
                "The theta_in-dependent material {} evaluates the {} formulas itself.",
                super::theta_file_name(name),
                options.variant
            ));
        }
    }
    caveats.extend(report::range_caveats(material, result.config.free_scale));
    caveats.extend(report::energy_caveats(material, &options));
    if kind.is_anisotropic() {
        let o = material.orientation();
        let fitted = if shape.oriented {
            let angle = o.y.atan2(o.x).to_degrees();
            format!(
                " (the fitted angle orient = {} deg from +x towards +y)",
                sig(angle, 6)
            )
        } else {
            String::new()
        };
        caveats.push(format!(
            "the orientation vector ({} {} {}){fitted} is in the coordinates of the surface: \
             the u roughness applies along its projection onto the surface.",
            o.x, o.y, o.z
        ));
    }
    h.push(String::new());
    if caveats.is_empty() {
        h.push("Caveats: none.".into());
    } else {
        h.push("Caveats:".into());
        for c in &caveats {
            h.push(format!("  - {c}"));
        }
    }
    h.push(String::new());
    h.push(format!(
        "Use: give this file to oconv before the geometry that uses the modifier \"{name}\"."
    ));
    if with_theta {
        h.push(format!(
            "{} defines the same identifier with theta_in-dependent parameters: use one or the other.",
            super::theta_file_name(name)
        ));
    }
    h.push(format!(
        "Preview: {} (docs/radiance.md explains both materials).",
        super::preview_file_name(name)
    ));
    if lobes > 1 {
        h.extend(lobe_sum_lines(material, name));
    } else {
        h.push(format!(
            "Real arguments: {}.",
            report::argument_names(brtf_model::Shape::single(kind))
        ));
    }
    let mut text = comment_block(&h);
    let primitives: Vec<String> = composite_primitives(material, name)
        .iter()
        .map(format_primitive)
        .collect();
    text += &primitives.join("\n");
    Text { text, notes }
}

/// How a lobe sum is written: its primitives, their weights, the tree.
fn lobe_sum_lines(material: &Composite, name: &str) -> Vec<String> {
    let parts = material.components();
    let kind = material.kind();
    let n = parts.len();
    let mut h = vec![
        format!(
            "Lobe sum: {name}.1 to {name}.{n} are {kind} primitives, one per specular lobe; the \
             mixfunc \"{name}\""
        ),
        "(last) mixes them with constant weights, which rtrace adds linearly:".into(),
    ];
    for (k, (w, m)) in parts.iter().enumerate() {
        h.push(format!(
            "  {name}.{}  weight {}  ({})",
            k + 1,
            sig(*w, 6),
            m.args()
                .iter()
                .map(|a| sig(*a, 6))
                .collect::<Vec<_>>()
                .join(" ")
        ));
    }
    if let (Some(shape), Some(args)) = (material.shape(), material.args()) {
        h.push(format!(
            "Fitted arguments ({}): {}.",
            report::argument_names(shape),
            args.iter()
                .map(|a| sig(*a, 6))
                .collect::<Vec<_>>()
                .join(" ")
        ));
    }
    h.push(format!(
        "Real arguments of each primitive: {}.",
        report::argument_names(brtf_model::Shape::single(kind))
    ));
    h
}

/// The incidences the variant comparison is shown at.
fn sample_thetas(result: &FitResult, chosen: &Chosen) -> Vec<f64> {
    match chosen.origin {
        Origin::Interpolated { theta, .. } => vec![theta],
        _ => {
            let mut t: Vec<f64> = result.incidences.iter().map(|r| r.theta_in).collect();
            t.sort_by(f64::total_cmp);
            t.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
            if t.is_empty() {
                return vec![0.0, 30.0, 60.0];
            }
            if t.len() > 8 {
                let n = t.len();
                t = (0..8).map(|i| t[i * (n - 1) / 7]).collect();
            }
            t
        }
    }
}

/// `# ` before every line (a bare `#` for empty ones).
pub(crate) fn comment_block(lines: &[String]) -> String {
    let mut out = String::new();
    for line in lines {
        if line.is_empty() {
            out += "#\n";
        } else {
            out += "# ";
            out += line;
            out += "\n";
        }
    }
    out
}
