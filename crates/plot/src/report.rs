//! `report.html`: one self-contained page per fit folder that shows every
//! plot, the parameter table, the exported material text and the
//! provenance. Plain HTML and CSS, no web font, no remote resource: it
//! opens offline in any browser. One inlined script draws the 3D view
//! ([`crate::viewer`]); without it (or without WebGL2) the rest of the
//! page is unchanged. Plots are linked relative
//! to the fit folder (`plots/<name>.svg`, with the PNG one click away).

use crate::charts::{fmt, incidence_label};
use crate::prepare::{Incidence, num};
use brtf_fit::{FitReport, FitResult};
use std::fmt::Write as _;
use std::path::Path;

/// The largest material file embedded as text.
const MAX_EMBED: u64 = 256 * 1024;

/// What the report shows of one incidence.
pub(crate) struct IncidenceEntry<'a> {
    /// The fit report.
    pub report: &'a FitReport,
    /// File-name tag (`t30`).
    pub tag: String,
    /// The loaded data, or why there is none.
    pub data: Result<&'a Incidence, &'a str>,
    /// File stems of its charts (map, cut), when drawn.
    pub charts: Vec<(String, (u32, u32), &'static str)>,
}

/// Everything the report needs.
pub(crate) struct ReportInput<'a> {
    /// The fit folder (for the exported files).
    pub dir: &'a Path,
    /// The fit.
    pub result: &'a FitResult,
    /// Charts over θ_in: `(stem, size, caption)`; none for one incidence.
    pub overview: Vec<(String, (u32, u32), String)>,
    /// One entry per incidence.
    pub incidences: Vec<IncidenceEntry<'a>>,
    /// Warnings about the plots.
    pub warnings: &'a [String],
    /// Colour-bar ratio of the maps.
    pub ratio: f64,
    /// The 3D view ([`crate::viewer::html`]).
    pub view: String,
    /// Why each incidence's map and cut are not drawn, when they are not.
    pub no_incidence_charts: Option<String>,
}

/// HTML-escapes text.
pub fn esc(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// Escapes a relative path for an `href`/`src` attribute.
fn href(path: &str) -> String {
    let mut out = String::new();
    for b in path.bytes() {
        match b {
            b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'-' | b'_' | b'.' | b'/' | b'~' => {
                out.push(b as char)
            }
            _ => {
                let _ = write!(out, "%{b:02X}");
            }
        }
    }
    out
}

const STYLE: &str = r#"
body { font-family: system-ui, -apple-system, "Segoe UI", Roboto, "DejaVu Sans", sans-serif;
       margin: 0 auto; max-width: 1320px; padding: 0 20px 60px; color: #111; line-height: 1.45; }
h1 { margin: 24px 0 4px; font-size: 1.7em; }
h2 { margin-top: 38px; border-bottom: 2px solid #ddd; padding-bottom: 4px; }
h3 { margin: 28px 0 6px; }
nav a { margin-right: 14px; }
.muted { color: #555; }
table { border-collapse: collapse; margin: 10px 0; font-size: 0.92em; }
th, td { border: 1px solid #ccc; padding: 3px 8px; text-align: right; vertical-align: top; white-space: nowrap; }
td.l { white-space: normal; }
th { background: #f1f1f1; }
td.l, th.l { text-align: left; }
tr.global td { background: #f8f8f8; font-weight: 600; }
.bound { color: #c00; font-weight: 700; }
.err { color: #555; font-size: 0.88em; }
#param-table { font-size: 0.86em; }
#param-table th, #param-table td { padding: 3px 5px; }
#param-table th { white-space: normal; }
.warn { background: #fff4e0; border: 1px solid #e0a040; padding: 8px 14px; border-radius: 4px; }
.warn li { margin: 3px 0; }
.verdict { background: #eef5ff; border: 1px solid #7a9cd0; padding: 8px 14px; border-radius: 4px; margin-bottom: 10px; }
.verdict li { margin: 3px 0; }
figure { margin: 14px 0 22px; }
figure img { max-width: 100%; height: auto; border: 1px solid #e4e4e4; }
figcaption { font-size: 0.9em; color: #333; margin-top: 4px; }
.pair { display: flex; flex-wrap: wrap; gap: 18px; align-items: flex-start; }
.pair figure { flex: 1 1 560px; margin: 6px 0; }
pre { background: #f6f6f6; border: 1px solid #ddd; padding: 10px; overflow-x: auto; font-size: 0.88em; }
code { font-size: 0.95em; }
"#;

/// The styles of the `--model auto` table (only in reports that have it).
const AUTO_STYLE: &str = "tr.chosen td { background: #eaf6ea; font-weight: 600; }
tr.other td { color: #777; }
";

/// Incidences above which their maps and cuts load only when scrolled to
/// (a 145-incidence Klems side has 290 of them: loaded at once, the page
/// took over 10 s to finish loading in Chromium).
const LAZY_ABOVE: usize = 12;

fn figure(out: &mut String, stem: &str, size: (u32, u32), caption: &str, lazy: bool) {
    let svg = href(&format!("plots/{stem}.svg"));
    let png = href(&format!("plots/{stem}.png"));
    let _ = writeln!(
        out,
        "<figure id=\"fig-{id}\"><a href=\"{png}\"><img src=\"{svg}\" width=\"{w}\" height=\"{h}\"{lazy} \
         alt=\"{alt}\"></a><figcaption>{caption} \
         <span class=\"muted\">(<a href=\"{svg}\">SVG</a> · <a href=\"{png}\">PNG</a>)</span>\
         </figcaption></figure>",
        id = esc(stem),
        w = size.0,
        h = size.1,
        alt = esc(caption),
        lazy = if lazy { " loading=\"lazy\"" } else { "" },
    );
}

fn param_cell(r: &FitReport, name: &str) -> String {
    match r.params.iter().find(|p| p.name == name) {
        None => "–".into(),
        // The value, and what qualifies it on a line of its own, so that
        // a table of many parameters fits the page.
        Some(p) if p.fixed => format!("{}<br><span class=\"muted\">(fixed)</span>", fmt6(p.value)),
        Some(p) if p.at_bound => format!(
            "{}<br><span class=\"bound\" title=\"ended at a bound of its range: no standard error\">at bound</span>",
            fmt6(p.value)
        ),
        Some(p) => match p.uncertainty() {
            Some(e) => format!(
                "{}<br><span class=\"err\">± {}</span>",
                fmt6(p.value),
                fmt_err(e)
            ),
            None => format!(
                "{}<br><span class=\"muted\">(no standard error: {})</span>",
                fmt6(p.value),
                p.missing_error_reason().unwrap_or("singular")
            ),
        },
    }
}

fn fmt6(v: f64) -> String {
    format!("{v:.6}")
}

fn fmt_err(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.1e}")
    } else {
        "?".into()
    }
}

fn param_table(out: &mut String, result: &FitResult) {
    let Some(first) = result.incidences.first() else {
        return;
    };
    // A grey fit's colour is one number: one column, not three equal ones.
    let grey = result.config.gray || result.colour_measured() == Some(false);
    let columns: Vec<(&str, &str)> = first
        .params
        .iter()
        .map(|p| p.name.as_str())
        .filter(|n| !(grey && matches!(*n, "green" | "blue")))
        .map(|n| match n {
            "red" if grey => ("grey (R = G = B)", n),
            _ => (n, n),
        })
        .collect();
    out.push_str(
        "<table id=\"param-table\"><thead><tr><th>θ_in [°]</th><th>φ_in [°]</th><th>points</th>",
    );
    for (label, _) in &columns {
        let _ = write!(out, "<th>{}</th>", esc(label));
    }
    out.push_str(
        "<th>E1</th><th>RMS rel.</th><th class=\"l\">termination</th></tr></thead><tbody>\n",
    );
    let mut row = |r: &FitReport, label: String, phi: String, class: &str| {
        let _ = write!(
            out,
            "<tr class=\"{class}\"><td>{label}</td><td>{phi}</td><td>{}</td>",
            r.n_points
        );
        for (_, n) in &columns {
            let _ = write!(out, "<td>{}</td>", param_cell(r, n));
        }
        let _ = writeln!(
            out,
            "<td class=\"e1\">{}</td><td>{}</td><td class=\"l\">{}</td></tr>",
            r.e1.map_or_else(|| "–".to_string(), percent),
            fmt(r.rms_rel),
            esc(r.termination.label())
        );
    };
    for r in &result.incidences {
        row(r, num(r.theta_in), num(r.phi_in), "incidence");
    }
    if let Some(g) = &result.global {
        row(g, "all".into(), String::new(), "global");
    }
    out.push_str("</tbody></table>\n");
    out.push_str(
        "<p class=\"muted\">value ± the larger of the two standard errors, s²(JᵀJ)⁻¹ and the \
         sandwich (heteroscedasticity-consistent) one; \
         <span class=\"bound\">at bound</span> = ended at a physical bound (no standard error); \
         “all” = one parameter set fitted to every incidence at once. \
         E1 = Σ ω |model − data| ÷ Σ ω |data| over the fitted samples (ω their weights): \
         the share of the measured light the material puts in the wrong place. \
         RMS rel. = RMS of (model − data) ÷ √(data² + floor²).</p>\n",
    );
    lobe_note(out, result);
}

/// A percentage of a fraction (E1), two decimals.
fn percent(fraction: f64) -> String {
    format!("{:.2}%", 100.0 * fraction)
}

/// What a lobe sum's or a fitted orientation's parameters mean, with the
/// static material's lobe weights (nothing for one primitive).
fn lobe_note(out: &mut String, result: &FitResult) {
    let shape = result.config.shape();
    if shape.is_single() {
        return;
    }
    let mut parts = Vec::new();
    if shape.lobes > 1 {
        let weights = result
            .static_composite()
            .map(|m| {
                m.components()
                    .iter()
                    .map(|(w, _)| format!("{w:.4}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            })
            .unwrap_or_else(|| "–".into());
        parts.push(format!(
            "{} specular lobes of <code>{}</code> over one diffuse base, sharing colour and \
             <code>spec</code>; lobe k has the roughness numbered k and the weight \
             split<sub>k</sub> × Π<sub>j&lt;k</sub> (1 − split<sub>j</sub>) (the last lobe what is \
             left), lobes ordered from the sharpest; the weights of the {} are {}",
            shape.lobes,
            esc(shape.kind.name()),
            if result.global.is_some() {
                "all-incidence fit"
            } else {
                "first incidence's fit"
            },
            weights
        ));
    }
    if shape.oriented {
        parts.push(
            "<code>orient</code> is the fitted angle in degrees, in the surface plane from +x \
             towards +y, of the anisotropic types' u direction"
                .to_string(),
        );
    }
    let _ = writeln!(
        out,
        "<p class=\"muted\" id=\"lobes\">{}: {}.</p>",
        esc(&shape.label()),
        parts.join("; ")
    );
}

/// The candidates of `--model auto`, the chosen one marked, and why.
fn auto_section(out: &mut String, auto: &brtf_fit::AutoChoice) {
    out.push_str(
        "<section id=\"auto\"><h2>Model choice (<code>--model auto</code>)</h2>\n\
         <table id=\"auto-table\"><thead><tr><th class=\"l\"></th><th class=\"l\">model</th>\
         <th>parameters</th><th>E1</th><th>held-out E1</th><th>peak offset [°]</th><th>cost</th>\
         <th>time [ms]</th><th class=\"l\">collapsed</th></tr></thead><tbody>\n",
    );
    for (i, c) in auto.candidates.iter().enumerate() {
        let (class, mark) = if i == auto.chosen {
            ("chosen", "✔ chosen")
        } else if i < auto.first {
            ("other", "not a candidate")
        } else {
            ("candidate", "")
        };
        let _ = writeln!(
            out,
            "<tr class=\"{class}\"><td class=\"l\">{mark}</td><td class=\"l\">{}</td><td>{}</td>\
             <td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{:.0}</td><td class=\"l\">{}</td></tr>",
            esc(&c.model),
            c.parameters,
            percent(c.e1),
            percent(c.e1_heldout),
            c.peak_offset_deg
                .map_or_else(|| "–".to_string(), |p| format!("{p:.1}")),
            fmt(c.cost),
            c.elapsed_ms,
            if c.collapsed { "collapsed" } else { "–" }
        );
    }
    out.push_str("</tbody></table>\n");
    let _ = writeln!(
        out,
        "<p id=\"auto-reason\">Chosen: {}</p>\n<p class=\"muted\">held-out E1: every \
         incidence's samples dealt into {} folds, each fold fitted again without its samples and \
         judged on them. Parameters are counted per incidence. “not a candidate”: the other \
         family's one-lobe fit, which decided between plastic and metal.</p>\n</section>",
        esc(&auto.reason),
        brtf_fit::FOLDS
    );
}

/// The headline figure under the title: E1 of the all-incidence fit and
/// the range over the incidences (nothing when the fit has no E1).
fn e1_headline(out: &mut String, result: &FitResult) {
    let per: Vec<f64> = result.incidences.iter().filter_map(|r| r.e1).collect();
    let global = result
        .global
        .as_ref()
        .filter(|_| result.incidences.len() > 1)
        .and_then(|g| g.e1);
    if per.is_empty() && global.is_none() {
        return;
    }
    let mut parts = Vec::new();
    if let Some(g) = global {
        parts.push(format!(
            "<strong>{}</strong> for the all-incidence fit",
            percent(g)
        ));
    }
    if !per.is_empty() {
        let lo = per.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = per.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        parts.push(if per.len() == 1 || lo == hi {
            format!("<strong>{}</strong> per incidence", percent(lo))
        } else {
            format!(
                "<strong>{}</strong> to <strong>{}</strong> per incidence",
                percent(lo),
                percent(hi)
            )
        });
    }
    let _ = writeln!(
        out,
        "<p id=\"headline\">E1 {}: the share of the measured light the material puts in the \
         wrong place.</p>",
        parts.join(", ")
    );
}

fn material_section(out: &mut String, dir: &Path, result: &FitResult) {
    let mut files: Vec<String> = std::fs::read_dir(dir)
        .map(|rd| {
            rd.filter_map(|e| e.ok())
                .filter(|e| e.path().is_file())
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|n| n.ends_with(".rad") || n.ends_with(".cal"))
                .filter(|n| !n.starts_with('.'))
                .collect()
        })
        .unwrap_or_default();
    files.sort();
    let main = format!("{}.rad", result.name);
    if let Some(i) = files.iter().position(|f| *f == main) {
        let f = files.remove(i);
        files.insert(0, f);
    }
    if files.is_empty() {
        let _ = writeln!(
            out,
            "<p class=\"muted\">No exported material in this folder yet \
             (<code>brtf export {}</code> writes <code>{}</code>).</p>",
            esc(&dir.display().to_string()),
            esc(&main)
        );
        return;
    }
    for f in &files {
        let path = dir.join(f);
        let _ = writeln!(out, "<h3><a href=\"{}\">{}</a></h3>", href(f), esc(f));
        let small = std::fs::metadata(&path)
            .map(|m| m.len() <= MAX_EMBED)
            .unwrap_or(false);
        if f.ends_with(".rad") && small {
            match std::fs::read_to_string(&path) {
                Ok(text) => {
                    let _ = writeln!(out, "<pre class=\"material\">{}</pre>", esc(&text));
                }
                Err(e) => {
                    let _ = writeln!(
                        out,
                        "<p class=\"muted\">cannot read: {}</p>",
                        esc(&e.to_string())
                    );
                }
            }
        }
    }
}

fn provenance_section(out: &mut String, dir: &Path, result: &FitResult) {
    let p = &result.provenance;
    let _ = writeln!(
        out,
        "<p>Made by brtf {} on {}.</p>\n<p>Command:</p>\n<pre>{}</pre>",
        esc(&p.brtf_version),
        esc(&p.created),
        esc(&p.command_line.join(" "))
    );
    out.push_str(
        "<table id=\"inputs\"><thead><tr><th class=\"l\">file</th><th>θ_in [°]</th><th>φ_in [°]</th>\
         <th>samples</th><th class=\"l\">quantity (as fitted)</th><th class=\"l\">SHA-256</th></tr></thead><tbody>\n",
    );
    for i in &p.inputs {
        let _ = writeln!(
            out,
            "<tr><td class=\"l\"><code>{}</code></td><td>{}</td><td>{}</td><td>{}</td><td class=\"l\">{}</td>\
             <td class=\"l\"><code>{}</code></td></tr>",
            esc(&i.path),
            num(i.theta_in),
            num(i.phi_in),
            i.samples,
            esc(&format!(
                "{}{}{}",
                i.conversion,
                i.describe_turn(),
                i.shadows
                    .iter()
                    .map(|r| format!("; shadow masked: {r}"))
                    .collect::<String>()
            )),
            esc(&i.sha256)
        );
    }
    out.push_str("</tbody></table>\n");
    let c = &result.config;
    let _ = writeln!(
        out,
        "<table id=\"config\"><tbody>\
         <tr><th class=\"l\">model</th><td class=\"l\">{} ({} variant, Fresnel K {}, source ω {} sr)</td></tr>\
         <tr><th class=\"l\">colour</th><td class=\"l\">{}</td></tr>\
         <tr><th class=\"l\">free scale</th><td class=\"l\">{}</td></tr>\
         <tr><th class=\"l\">residuals</th><td class=\"l\">{:?}, floor {}</td></tr>\
         <tr><th class=\"l\">robust loss</th><td class=\"l\">{:?}</td></tr>\
         <tr><th class=\"l\">multi-start</th><td class=\"l\">{}</td></tr>\
         <tr><th class=\"l\">θ_in interpolation</th><td class=\"l\">{:?}</td></tr>\
         <tr><th class=\"l\">selections</th><td class=\"l\">{}</td></tr>\
         </tbody></table>",
        esc(&c.shape().label()),
        esc(c.options.variant.name()),
        c.options.fresnel_k,
        c.options.source_omega,
        match (result.colour_measured(), c.gray) {
            (Some(false), _) =>
                "colour not measured (one-channel CIE-Y data): grey, R = G = B (brtf export --colour R,G,B gives one)",
            (_, true) => "grey (R = G = B, --gray)",
            _ => "red, green and blue fitted",
        },
        c.free_scale,
        c.residual,
        c.floor.map_or("auto".into(), fmt),
        c.loss,
        c.multistart,
        result.interpolation,
        esc(&result
            .recipe
            .selections
            .iter()
            .map(|g| g.to_string())
            .collect::<Vec<_>>()
            .join("; "))
    );
    // fit.json is always linked: every fit folder has one, and `brtf
    // fit` writes it last, after this report (it lists the report).
    let link = |f: &str| format!("<a href=\"{}\">{}</a>", href(f), esc(f));
    let mut links = vec![link("fit.json")];
    if dir.join("params.csv").is_file() {
        links.push(link("params.csv"));
    }
    let _ = writeln!(out, "<p>Machine-readable: {}.</p>", links.join(" · "));
}

/// The page.
pub(crate) fn html(input: &ReportInput) -> String {
    let result = input.result;
    let mut out = String::new();
    let title = format!("{}: brtf fit report", result.name);
    let _ = write!(
        out,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <link rel=\"icon\" href=\"data:,\">\n<title>{}</title>\n<style>{STYLE}{}{}</style>\n</head>\n<body>\n",
        esc(&title),
        if result.auto.is_some() {
            AUTO_STYLE
        } else {
            ""
        },
        crate::viewer::STYLE
    );
    let _ = writeln!(out, "<h1>{}</h1>", esc(&title));
    let _ = writeln!(
        out,
        "<p class=\"muted\">Radiance <code>{}</code> ({} variant) fitted to {} incidence(s); made {} by brtf {}.</p>",
        esc(&result.config.shape().label()),
        esc(result.config.options.variant.name()),
        result.incidences.len(),
        esc(&result.provenance.created),
        esc(&result.provenance.brtf_version)
    );
    e1_headline(&mut out, result);
    let auto_link = if result.auto.is_some() {
        "<a href=\"#auto\">Model choice</a>"
    } else {
        ""
    };
    let _ = writeln!(
        out,
        "<nav><a href=\"#parameters\">Parameters</a>{auto_link}<a href=\"#view3d\">3D view</a><a href=\"#theta\">Over θ_in</a>\
         <a href=\"#incidences\">Per incidence</a><a href=\"#material\">Material</a>\
         <a href=\"#provenance\">Provenance</a></nav>",
    );

    if !result.incidences.is_empty() {
        let verdict = result.verdict();
        let _ = writeln!(
            out,
            "<section id=\"verdict\" class=\"verdict\"><strong>Verdict: {}</strong><ul>",
            esc(&verdict.headline())
        );
        for line in verdict.lines() {
            let _ = writeln!(out, "<li>{}</li>", esc(&line));
        }
        out.push_str("</ul></section>\n");
    }

    // One entry per kind (with one incidence the all-incidence fit is that
    // fit: its warnings once, not twice).
    let fit_warnings = brtf_fit::warning_lines(result);
    if !input.warnings.is_empty() || !fit_warnings.is_empty() {
        out.push_str(
            "<section id=\"warnings\" class=\"warn\"><strong>Read this first</strong><ul>\n",
        );
        for w in input.warnings.iter().chain(&fit_warnings) {
            let _ = writeln!(out, "<li>{}</li>", esc(w));
        }
        out.push_str("</ul></section>\n");
    }

    out.push_str("<section id=\"parameters\"><h2>Parameters</h2>\n");
    param_table(&mut out, result);
    out.push_str("</section>\n");
    if let Some(auto) = &result.auto {
        auto_section(&mut out, auto);
    }

    out.push_str(
        "<section id=\"view3d\"><h2>3D view</h2>\n<p class=\"muted\">Every sample of the \
         file as a point over the hemisphere, seen from the side: the disk is the equal-area \
         projection of the maps below (reflection above it, transmission below), the height \
         the value. The translucent surface is the fitted model over the directions the scan \
         covers. Colour shows the data, the model, or model ÷ data on the maps' scale; grey \
         points were removed by a selection.</p>\n",
    );
    out.push_str(&input.view);
    out.push_str("</section>\n");

    out.push_str("<section id=\"theta\"><h2>Over θ_in</h2>\n");
    if result.incidences.len() < 2 {
        out.push_str(
            "<p id=\"theta-note\" class=\"muted\">One incidence fitted: the charts over θ_in \
             need two or more.</p>\n",
        );
    }
    for (stem, size, caption) in &input.overview {
        figure(&mut out, stem, *size, caption, false);
    }
    out.push_str("</section>\n");

    out.push_str("<section id=\"incidences\"><h2>Per incidence</h2>\n");
    let _ = writeln!(
        out,
        "<p class=\"muted\">Maps: model ÷ data on an equal-area view of the hemisphere, blue where the model \
         is below the data, red where above; the colour bar ends at ×{} and ×1/{}; grey samples were \
         not fitted. Cuts: the plane of incidence, data as dots, the model as a line, masked ranges shaded.</p>",
        fmt(input.ratio),
        fmt(input.ratio)
    );
    if let Some(why) = &input.no_incidence_charts {
        let _ = writeln!(out, "<p>{}</p>", esc(why));
    }
    for entry in &input.incidences {
        let r = entry.report;
        let label = incidence_label(r.theta_in, r.phi_in);
        let _ = writeln!(
            out,
            "<h3 id=\"inc-{}\">{}</h3>",
            esc(&entry.tag),
            esc(&label)
        );
        let _ = write!(
            out,
            "<p><code>{}</code>: {} samples fitted, RMS rel. {}",
            esc(&r.source),
            r.n_points,
            fmt(r.rms_rel)
        );
        if let Some(e1) = r.e1 {
            let _ = write!(out, ", E1 {}", percent(e1));
        }
        if !r.gates.is_empty() {
            let gates: Vec<String> = r
                .gates
                .iter()
                .map(|g| format!("{} (−{})", esc(&g.gate.to_string()), g.removed))
                .collect();
            let _ = write!(out, "; selections: {}", gates.join(", "));
        }
        out.push_str(".</p>\n");
        if let Some(a) = &r.adequacy {
            adequacy_line(&mut out, a);
        }
        match &entry.data {
            Err(why) => {
                let _ = writeln!(out, "<p class=\"warn\">No map or cut: {}</p>", esc(why));
            }
            Ok(inc) => {
                for w in &inc.warnings {
                    let _ = writeln!(out, "<p class=\"warn\">{}</p>", esc(w));
                }
                if entry.charts.is_empty() {
                    continue;
                }
                out.push_str("<div class=\"pair\">\n");
                for (stem, size, what) in &entry.charts {
                    figure(
                        &mut out,
                        stem,
                        *size,
                        &format!("{label}: {what}"),
                        input.incidences.len() > LAZY_ABOVE,
                    );
                }
                out.push_str("</div>\n");
            }
        }
    }
    out.push_str("</section>\n");

    out.push_str("<section id=\"material\"><h2>Exported material</h2>\n");
    material_section(&mut out, input.dir, result);
    out.push_str("</section>\n");

    out.push_str("<section id=\"provenance\"><h2>Provenance</h2>\n");
    provenance_section(&mut out, input.dir, result);
    out.push_str("</section>\n</body>\n</html>\n");
    out
}

/// One incidence's adequacy diagnostics (see `docs/fitting.md`, "When not
/// to trust a fit"), each figure marked when it is past its threshold.
fn adequacy_line(out: &mut String, a: &brtf_fit::Adequacy) {
    let mark = |bad: bool, text: String| {
        if bad {
            format!("<span class=\"bound\">{text}</span>")
        } else {
            text
        }
    };
    let mut parts = Vec::new();
    if let (Some(figure), Some(ratio)) = (a.energy(), a.energy_ratio()) {
        let tolerance = brtf_fit::ENERGY_TOLERANCE;
        let bad = !(1.0 / (1.0 + tolerance)..=1.0 + tolerance).contains(&ratio);
        parts.push(mark(bad, format!("{figure} (ratio {ratio:.3})")));
    }
    if let Some(p) = a.peak_offset_deg {
        parts.push(mark(
            p > brtf_fit::PEAK_TOLERANCE_DEG,
            format!("model peak {p:.1}° from the data's"),
        ));
    }
    if let Some(c) = &a.residual_check {
        parts.push(mark(
            c.relative_change > brtf_fit::RESIDUAL_KIND_TOLERANCE,
            format!(
                "with {:?} residuals {} {} → {} ({:.0}%)",
                c.residual,
                esc(&c.param),
                fmt(c.values[0]),
                fmt(c.values[1]),
                100.0 * c.relative_change
            ),
        ));
    }
    if !parts.is_empty() {
        let _ = writeln!(
            out,
            "<p class=\"adequacy\">Adequacy: {}.</p>",
            parts.join("; ")
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escaping() {
        assert_eq!(
            esc("<a href=\"x\">&'"),
            "&lt;a href=&quot;x&quot;&gt;&amp;&#39;"
        );
        assert_eq!(href("plots/map-t26.8421.svg"), "plots/map-t26.8421.svg");
        assert_eq!(href("a b:c.rad"), "a%20b%3Ac.rad");
    }
}
