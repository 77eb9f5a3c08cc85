//! The report's 3D view: every incidence's samples as a point cloud over
//! the projected hemisphere (height = value) with the fitted model as a
//! translucent surface, drawn by WebGL2 in the page itself.
//!
//! The data travel inside the page as one JSON block per view: per
//! incidence a little metadata and one base64 string of quantised binary
//! arrays, decoded by the script only when that incidence is shown. Per
//! sample 9 bytes: disk position x and y (u16 each, the equal-area disk
//! of the maps scaled to the unit disk), data and model (u16 codes on a
//! log scale, [`encode`]) and one flag byte (bit 7: the back hemisphere;
//! bits 0–6: 0 when fitted, else 1 + the index of the gate that removed
//! it). A 127k-sample scan adds about 1.5 MB. The model surfaces are
//! u16 codes on a square grid over each hemisphere's disk, where the
//! scan has samples: the chosen model's and every `--model auto`
//! candidate's.

mod grid;

use crate::figure::base64;
use crate::prepare::Incidence;
use brtf_fit::FitResult;
use brtf_gonio::Hemisphere;
use serde_json::{Value, json};
use std::fmt::Write as _;

/// The script (plain JavaScript, no library).
const SCRIPT: &str = include_str!("viewer.js");
/// Its styles.
pub(crate) const STYLE: &str = include_str!("viewer.css");

/// Decades of the log scale below the largest value: smaller values get
/// the smallest code.
const DECADES: f64 = 9.0;
/// The code of "no value" (a surface node without samples near it).
const NONE: u16 = u16::MAX;
/// The largest code of a value.
const TOP: u16 = u16::MAX - 1;

/// `v` as a code: 0 for zero, negative or not finite, else 1 + its place
/// on the log scale `[lo, hi]` (log10) in `TOP - 1` steps.
pub(crate) fn encode(v: f64, lo: f64, hi: f64) -> u16 {
    if v.is_nan() || v <= 0.0 || v.is_infinite() {
        return 0;
    }
    let t = ((v.log10() - lo) / (hi - lo)).clamp(0.0, 1.0);
    1 + (t * f64::from(TOP - 1)).round() as u16
}

/// The value of `code` on `[lo, hi]` (the script's decoding).
#[cfg(test)]
fn decode(code: u16, lo: f64, hi: f64) -> f64 {
    if code == 0 {
        return 0.0;
    }
    10f64.powf(lo + f64::from(code - 1) / f64::from(TOP - 1) * (hi - lo))
}

/// Unit-disk position of `dir` on its hemisphere.
fn disk_xy(dir: glam::DVec3) -> (f64, f64, Hemisphere) {
    let hemisphere = if dir.z >= 0.0 {
        Hemisphere::Front
    } else {
        Hemisphere::Back
    };
    let (x, y) = crate::disk::project(dir, hemisphere);
    (
        x / std::f64::consts::SQRT_2,
        y / std::f64::consts::SQRT_2,
        hemisphere,
    )
}

fn quantise_position(u: f64) -> u16 {
    ((u.clamp(-1.0, 1.0) + 1.0) * 0.5 * 65535.0).round() as u16
}

/// The bottom (log10) of the log height and colour scales: the 2nd
/// percentile of the fitted data above zero, kept 1 to 4 decades below
/// the top `hi` (a few samples in a shadow would flatten the rest).
fn log_bottom(inc: &Incidence, hi: f64) -> f64 {
    let mut logs: Vec<f64> = inc
        .samples
        .iter()
        .filter(|s| s.used() && s.data > 0.0 && s.data.is_finite())
        .map(|s| s.data.log10())
        .collect();
    if logs.is_empty() {
        return hi - 3.0;
    }
    let k = (logs.len() - 1) / 50;
    let low = *logs.select_nth_unstable_by(k, f64::total_cmp).1;
    low.clamp(hi - 4.0, hi - 1.0)
}

/// The metadata and packed arrays of one incidence.
fn incidence_json(result: &FitResult, inc: &Incidence) -> Value {
    let report = &result.incidences[inc.index];
    let n = inc.samples.len();
    let top = inc
        .samples
        .iter()
        .flat_map(|s| [s.data, s.model])
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold(0.0f64, f64::max);
    let hi = if top > 0.0 { top.log10() } else { 0.0 };
    let lo = hi - DECADES;
    let bottom = log_bottom(inc, hi);
    let mut bytes: Vec<u8> = Vec::with_capacity(9 * n);
    let mut flags = Vec::with_capacity(n);
    let mut xs = Vec::with_capacity(n);
    let mut ys = Vec::with_capacity(n);
    for s in &inc.samples {
        let (x, y, hemisphere) = disk_xy(s.dir);
        xs.push(quantise_position(x));
        ys.push(quantise_position(y));
        let gate = s.removed_by.map_or(0, |g| (g + 1).min(127) as u8);
        flags.push(
            gate | if hemisphere == Hemisphere::Back {
                128
            } else {
                0
            },
        );
    }
    for column in [
        xs,
        ys,
        inc.samples.iter().map(|s| encode(s.data, lo, hi)).collect(),
        inc.samples
            .iter()
            .map(|s| encode(s.model, lo, hi))
            .collect(),
    ] {
        bytes.extend(column.iter().flat_map(|c| c.to_le_bytes()));
    }
    bytes.extend(&flags);

    let hemispheres = inc.drawn_hemispheres();
    let mut surfaces = vec![json!({
        "label": format!("{} (fitted)", result.config.shape().label()),
        "codes": base64(&grid::surface(inc, &hemispheres, |v| inc.model_at(v), lo, hi)),
    })];
    for (label, model) in grid::candidates(result, inc) {
        surfaces.push(json!({
            "label": label,
            "codes": base64(&grid::surface(inc, &hemispheres, &model, lo, hi)),
        }));
    }
    let marker = |dir: glam::DVec3| {
        let (x, y, h) = disk_xy(dir);
        json!([x, y, if h == Hemisphere::Back { -1 } else { 1 }])
    };
    let through = -inc.light;
    json!({
        "label": crate::charts::incidence_label(inc.theta_in, inc.phi_in),
        "thetaIn": inc.theta_in,
        "phiIn": inc.phi_in,
        "n": n,
        "fitted": report.n_points,
        "unit": inc.unit.axis(),
        "floor": inc.floor,
        "lo": lo,
        "hi": hi,
        "bottom": bottom,
        "gates": inc.gates.iter().map(|g| g.to_string()).collect::<Vec<_>>(),
        "light": marker(inc.light),
        "mirror": marker(inc.mirror()),
        "through": marker(through),
        "grid": grid::size(n),
        "hemispheres": hemispheres.iter().map(|h| if *h == Hemisphere::Back { -1 } else { 1 }).collect::<Vec<_>>(),
        "samples": base64(&bytes),
        "surfaces": surfaces,
    })
}

/// The view of `incs` (the incidences with data, in fit order) as one
/// HTML block: controls, canvas, data and script. `id` is unique in the
/// page; `ratio` is the maps' colour-bar ratio (the residual colours'
/// ends).
pub(crate) fn html(result: &FitResult, incs: &[&Incidence], ratio: f64, id: &str) -> String {
    let data: Vec<Value> = {
        use rayon::prelude::*;
        incs.par_iter()
            .map(|inc| incidence_json(result, inc))
            .collect()
    };
    let payload = json!({
        "name": result.name,
        "model": result.config.shape().label(),
        "ratio": ratio,
        "rdbu": crate::colour::RDBU.iter().map(|c| [c.0, c.1, c.2]).collect::<Vec<_>>(),
        "incidences": data,
    });
    // `</` cannot end the script block from inside a JSON string.
    let payload = payload.to_string().replace("</", "<\\/");
    let mut out = String::new();
    let _ = writeln!(
        out,
        "<div class=\"brtf-view\" id=\"{id}\">\
         <div class=\"bv-controls\"></div>\
         <div class=\"bv-stage\"><canvas class=\"bv-canvas\" tabindex=\"0\" \
         aria-label=\"3D view of data and model\"></canvas>\
         <div class=\"bv-tip\" hidden></div><div class=\"bv-legend\"></div></div>\
         <p class=\"bv-status\"></p>\
         <script type=\"application/json\" class=\"bv-data\">{payload}</script>\
         <script>{SCRIPT}</script></div>"
    );
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_keep_values_to_two_parts_in_ten_thousand() {
        let (lo, hi) = (-7.5, 1.5);
        assert_eq!(encode(0.0, lo, hi), 0);
        assert_eq!(encode(-1.0, lo, hi), 0);
        assert_eq!(encode(f64::NAN, lo, hi), 0);
        assert_eq!(encode(1e-12, lo, hi), 1);
        assert_eq!(encode(10f64.powf(hi), lo, hi), TOP);
        for v in [3.2e-7, 0.0123, 0.5, 1.0, 7.77, 31.0] {
            let back = decode(encode(v, lo, hi), lo, hi);
            assert!((back / v - 1.0).abs() < 2e-4, "{v} -> {back}");
        }
    }
}
