//! The side-by-side report of a two-sided Klems fit: per incident patch of
//! each side, measured against fitted ρ_dh, τ_dh and the diagonal
//! (normal-normal) transmittance, and Klems-patch residual maps: the
//! patches on a disk, as BSDF viewers show them, coloured by model ÷ data.
//!
//! The data are rebuilt from the Klems file with the fit's own recipe
//! ([`brtf_fit::prepare_input`]), and the model is averaged over the
//! patches exactly as the fit compared it.

use crate::colour::diverging;
use crate::report::esc;
use brtf_fit::{FitResult, PreparedMeasurement};
use brtf_model::CompositeBsdf;
use rayon::prelude::*;
use std::fmt::Write;
use std::path::Path;

/// One incident patch's figures.
struct PatchRow {
    patch: usize,
    theta_in: f64,
    phi_in: f64,
    rho: [f64; 2],
    tau: [f64; 2],
    /// Diagonal transmittance T[i][i] · Λ_i: data, model.
    diagonal: [f64; 2],
    rms_rel: f64,
    /// Per outgoing sample (file order): θ, φ, data, model.
    samples: Vec<(f64, f64, f64, f64)>,
}

/// The figures of every incidence of one side's fit (`None` with the
/// reason when the Klems file cannot be read). Each file is read once.
fn rows(result: &FitResult, fit_dir: &Path) -> Result<Vec<PatchRow>, String> {
    let mut inputs = Vec::with_capacity(result.incidences.len());
    for (index, report) in result.incidences.iter().enumerate() {
        let input = result
            .input_of(index)
            .ok_or_else(|| format!("{}: not listed in the provenance", report.source))?;
        let Some(at) = input.klems else {
            return Err(format!("{}: not a Klems patch", input.path));
        };
        inputs.push((input, at, report));
    }
    let mut rows = Vec::with_capacity(inputs.len());
    // Runs of incidences from one file (a side's fit has one).
    for run in inputs.chunk_by(|a, b| a.0.path == b.0.path) {
        let first = run[0].0;
        let path = brtf_io::locate_input(&first.path, fit_dir, &[])
            .ok_or_else(|| format!("{}: Klems file not found", first.path))?;
        let bytes = brtf_io::read_input(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        let files: Vec<&brtf_fit::InputFile> = run.iter().map(|(input, _, _)| *input).collect();
        let prepared = brtf_fit::prepare_inputs_of_xml(&result.recipe, &files, &bytes, &path)
            .map_err(|e| e.to_string())?;
        let built: Vec<Result<PatchRow, String>> = run
            .par_iter()
            .zip(&prepared)
            .map(|((input, at, report), prepared)| {
                let material = result.composite_of(report).ok_or_else(|| {
                    format!("{}: the fitted arguments are not a material", input.label())
                })?;
                let bsdf = CompositeBsdf::new(&material, &result.options());
                Ok(row(prepared, &bsdf, report.scale, at.patch, report))
            })
            .collect();
        for r in built {
            rows.push(r?);
        }
    }
    Ok(rows)
}

fn luminance(values: [f64; 3], channels: usize) -> f64 {
    if channels >= 3 {
        brtf_model::luminance(values)
    } else {
        values[0]
    }
}

fn row(
    prepared: &PreparedMeasurement,
    bsdf: &CompositeBsdf,
    scale: f64,
    patch: usize,
    report: &brtf_fit::FitReport,
) -> PatchRow {
    let channels = prepared.channels();
    let m = &prepared.measurement;
    let mut rho = [0.0; 2];
    let mut tau = [0.0; 2];
    let mut diagonal = [0.0; 2];
    let mut samples = Vec::with_capacity(m.samples.len());
    // Samples come as the reflection patches then the transmission
    // patches, each in basis order: the diagonal is patch `patch` of the
    // transmission block.
    let per_block = m.samples.iter().filter(|s| s.theta_deg <= 90.0).count();
    for (i, s) in m.samples.iter().enumerate() {
        let data = luminance(s.values, channels);
        let model = scale * luminance(crate::prepare::model_value(prepared, bsdf, i), channels);
        // Λ = dΩ · cos θ_centre.
        let lambda = s.solid_angle_sr.unwrap_or(0.0) * s.abs_cos_theta();
        let totals = if s.theta_deg > 90.0 {
            &mut tau
        } else {
            &mut rho
        };
        totals[0] += data * lambda;
        totals[1] += model * lambda;
        if s.theta_deg > 90.0 && i == per_block + patch {
            diagonal = [data * lambda, model * lambda];
        }
        samples.push((s.theta_deg, s.phi_deg, data, model));
    }
    PatchRow {
        patch,
        theta_in: m.incidence.theta_deg,
        phi_in: m.incidence.phi_deg,
        rho,
        tau,
        diagonal,
        rms_rel: report.rms_rel,
        samples,
    }
}

/// A disk of Klems patches (one hemisphere), coloured by log(model ÷
/// data) on ±log(`ratio`); patches where both are ≈ 0 are grey.
fn disk_svg(row: &PatchRow, transmitted: bool, ratio: f64) -> String {
    let per_block = row.samples.iter().filter(|s| s.0 <= 90.0).count();
    let per_block = if per_block == 0 {
        row.samples.len()
    } else {
        per_block
    };
    let name = match per_block {
        73 => "LBNL/Klems Half",
        41 => "LBNL/Klems Quarter",
        _ => "LBNL/Klems Full",
    };
    let basis = brtf_gonio::klems::KlemsBasis::built_in(name).expect("a built-in basis");
    let size = 150.0;
    let centre = size / 2.0;
    let scale = (size / 2.0 - 4.0) / crate::disk::radius_of(90.0);
    let mut svg = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{size}" height="{size}" viewBox="0 0 {size} {size}">"#
    );
    let peak = row
        .samples
        .iter()
        .map(|s| s.2.abs().max(s.3.abs()))
        .fold(0.0, f64::max);
    for &(theta, phi, data, model) in &row.samples {
        if (theta > 90.0) != transmitted {
            continue;
        }
        let theta = if transmitted { 180.0 - theta } else { theta };
        let Some(o) = basis.patch_index(theta, phi) else {
            continue;
        };
        let p = basis.patch(o).expect("index from the basis");
        let (t0, t1) = p.theta_bounds_deg;
        let (p0, p1) = p.phi_bounds_deg;
        let colour = if data.abs().max(model.abs()) <= 1e-6 * peak.max(1e-300) {
            "#dddddd".to_string()
        } else {
            let t = ((model.max(1e-300) / data.max(1e-300)).ln() / ratio.ln()).clamp(-1.0, 1.0);
            let c = diverging(t);
            format!("#{:02x}{:02x}{:02x}", c.0, c.1, c.2)
        };
        let point = |t: f64, f: f64| {
            let r = crate::disk::radius_of(t) * scale;
            let f = f.to_radians();
            // East = φ 0°, north = φ 90°, as the residual maps.
            (centre + r * f.cos(), centre - r * f.sin())
        };
        let mut d = String::new();
        let steps = 6;
        for k in 0..=steps {
            let f = p0 + (p1 - p0) * k as f64 / steps as f64;
            let (x, y) = point(t1, f);
            let _ = write!(d, "{}{x:.1},{y:.1} ", if k == 0 { "M" } else { "L" });
        }
        for k in (0..=steps).rev() {
            let f = p0 + (p1 - p0) * k as f64 / steps as f64;
            let (x, y) = point(t0, f);
            let _ = write!(d, "L{x:.1},{y:.1} ");
        }
        let _ = write!(
            svg,
            r##"<path d="{d}Z" fill="{colour}" stroke="#ffffff" stroke-width="0.3"><title>θ {theta:.1}° φ {phi:.0}°: data {data:.4}, model {model:.4}</title></path>"##
        );
    }
    svg.push_str("</svg>");
    svg
}

/// The side-by-side report of the fits of each side (`labels`: their
/// folder names, e.g. `front`, `back`), written into `dir`.
pub fn klems_sides_report(results: &[FitResult], labels: &[String], dir: &Path) -> String {
    let mut html = String::from(
        "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>brtf Klems fit</title>\
         <style>body{font-family:sans-serif;margin:1.5em}table{border-collapse:collapse;font-size:12px}\
         td,th{border:1px solid #ccc;padding:2px 6px;text-align:right}.sides{display:flex;gap:2em;align-items:flex-start}\
         .maps{display:flex;flex-wrap:wrap;gap:8px}figure{margin:0;font-size:11px;text-align:center}</style></head><body>",
    );
    let name = results.first().map_or("fit", |r| r.name.as_str());
    let _ = write!(html, "<h1>Klems fit of {}: both sides</h1>", esc(name));
    if let Some(r) = results.first() {
        let _ = write!(
            html,
            "<p>Model <code>{}</code>, fitted to Klems patch averages with the model averaged over the patches. \
             Each side is its own fit (measured fabrics are not reciprocal). \
             Input: {} (SHA-256 {}). Command: <code>{}</code>.</p>",
            esc(&r.config.kind.to_string()),
            esc(r.provenance.inputs.first().map_or("", |i| i.path.as_str())),
            esc(r
                .provenance
                .inputs
                .first()
                .map_or("", |i| i.sha256.as_str())),
            esc(&r.provenance.command_line.join(" "))
        );
    }
    html.push_str(
        "<p>Roughness below about 0.05 can hardly be identified from Klems data: \
         a lobe that narrow fits inside one patch.</p><div class=\"sides\">",
    );
    let mut all_rows = Vec::new();
    for (result, label) in results.iter().zip(labels) {
        let _ = write!(
            html,
            "<div><h2>{0} side</h2><p><a href=\"{0}/report.html\">full report</a> · \
             <a href=\"{0}/params.csv\">params.csv</a></p>",
            esc(label)
        );
        match rows(result, &dir.join(label)) {
            Ok(rows) => {
                html.push_str(
                    "<table><tr><th>patch</th><th>θ_in</th><th>φ_in</th><th>ρ_dh data</th><th>ρ_dh fit</th>\
                     <th>τ_dh data</th><th>τ_dh fit</th><th>diag. τ data</th><th>diag. τ fit</th><th>rms_rel</th></tr>",
                );
                for r in &rows {
                    let _ = write!(
                        html,
                        "<tr><td>{}</td><td>{:.1}</td><td>{:.1}</td><td>{:.4}</td><td>{:.4}</td><td>{:.4}</td>\
                         <td>{:.4}</td><td>{:.4}</td><td>{:.4}</td><td>{:.3}</td></tr>",
                        r.patch,
                        r.theta_in,
                        r.phi_in,
                        r.rho[0],
                        r.rho[1],
                        r.tau[0],
                        r.tau[1],
                        r.diagonal[0],
                        r.diagonal[1],
                        r.rms_rel
                    );
                }
                html.push_str("</table>");
                all_rows.push((label.clone(), rows));
            }
            Err(e) => {
                let _ = write!(html, "<p>The data cannot be shown: {}</p>", esc(&e));
            }
        }
        html.push_str("</div>");
    }
    html.push_str("</div><h2>Klems-patch maps: model ÷ data</h2><p>One incidence per θ ring (φ_in nearest 180°). \
        Each disk is one hemisphere of outgoing patches, θ from the centre (equal-area), φ = 0° to the right; \
        blue: model below data, red: model above, across ×/÷ 3; grey: both ≈ 0. Hover a patch for its values.</p>");
    for (label, rows) in &all_rows {
        let _ = write!(html, "<h3>{} side</h3><div class=\"maps\">", esc(label));
        let mut rings: Vec<f64> = rows.iter().map(|r| r.theta_in).collect();
        rings.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
        for theta in rings {
            let Some(r) = rows
                .iter()
                .filter(|r| (r.theta_in - theta).abs() < 1e-9)
                .min_by(|a, b| {
                    (a.phi_in - 180.0)
                        .abs()
                        .total_cmp(&(b.phi_in - 180.0).abs())
                })
            else {
                continue;
            };
            for transmitted in [false, true] {
                if !r.samples.iter().any(|s| (s.0 > 90.0) == transmitted) {
                    continue;
                }
                let _ = write!(
                    html,
                    "<figure>{}<figcaption>θ_in {:.1}° φ_in {:.0}°: {}</figcaption></figure>",
                    disk_svg(r, transmitted, 3.0),
                    r.theta_in,
                    r.phi_in,
                    if transmitted {
                        "transmission"
                    } else {
                        "reflection"
                    }
                );
            }
        }
        html.push_str("</div>");
    }
    html.push_str("</body></html>");
    html
}
