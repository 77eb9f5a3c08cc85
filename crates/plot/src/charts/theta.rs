//! Charts over θ_in: every fitted parameter with its standard error and
//! the θ_in interpolation, the hemispherical reflectance (and
//! transmittance) of the data against the model, and the error of every
//! incidence's fit.
//!
//! ρ_dh of the data is `∫ d(ω) |cos θ| dω` over the directions the fitted
//! samples cover, with `d(ω)` the value of the nearest sample: the sum over
//! the pixels of the map's equal-area grid ([`crate::disk::Coverage`]).
//! The model's is the same integral of the model values at the same
//! samples, so the two see the same gaps and masks; and the model's full
//! integral over the hemisphere (brtf-model's [`brtf_model::composite_albedo`],
//! the lobes' integrals weighted) is what a renderer will reflect. τ_dh is the same over the back hemisphere.

use super::{
    CartesianChart, Frame, TICK, legend_circle, legend_dashes, legend_line, legend_triangle,
    lin_fmt, lin_range, mesh, series_legend, theta_range, titled,
};
use crate::colour::{ALERT, DATA, GUIDE, MODEL};
use crate::figure::{Area, Canvas, Chart, OrMsg};
use crate::prepare::{DataUnit, Incidence};
use brtf_fit::{FitReport, FitResult, Interpolation};
use brtf_gonio::Hemisphere;
use brtf_model::{Composite, CompositeBsdf};
use plotters::coord::types::RangedCoordf64;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use rayon::prelude::*;
use std::sync::OnceLock;

/// Points along θ_in for the interpolation and all-incidence curves.
const CURVE_STEPS: usize = 60;
/// Absolute tolerance of the model's hemispherical integrals.
const ALBEDO_TOLERANCE: f64 = 1e-5;

/// A chart over θ_in with a linear y axis.
type ThetaAxes<'a, DB> = CartesianChart<'a, DB, RangedCoordf64, RangedCoordf64>;

/// The axes of a chart over θ_in in `area`, drawn: `x` the θ_in range,
/// `y` the linear value range titled `y_desc`.
fn theta_axes<'a, DB: DrawingBackend>(
    area: &'a Area<DB>,
    frame: &Frame,
    x: (f64, f64),
    y: (f64, f64),
    y_desc: &str,
) -> Result<ThetaAxes<'a, DB>, String> {
    let mut chart = frame.chart(area, x.0..x.1, y.0..y.1)?;
    mesh(&mut chart, "θ_in [°]", y_desc)
        .y_label_formatter(&lin_fmt(y.0, y.1))
        .draw()
        .msg()?;
    Ok(chart)
}

/// Model ρ_dh and τ_dh (non-delta + delta parts) of `material` (one
/// primitive or a lobe sum) for light from (θ, φ), channel mean over
/// `channels`, times `scale`.
pub(crate) fn model_integrals(
    material: &Composite,
    result: &FitResult,
    theta: f64,
    phi: f64,
    scale: f64,
    channels: usize,
) -> [f64; 2] {
    let bsdf = CompositeBsdf::new(material, &result.options());
    let a =
        brtf_model::composite_albedo(&bsdf, brtf_model::direction(theta, phi), ALBEDO_TOLERANCE);
    let mean = |x: [f64; 3], y: [f64; 3]| {
        (0..channels).map(|c| x[c] + y[c]).sum::<f64>() / channels as f64 * scale
    };
    [mean(a.rho, a.rho_spike), mean(a.tau, a.tau_spike)]
}

/// Hemispherical integrals of one incidence (index 0: front, 1: back).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Integrals {
    /// θ_in, degrees.
    pub theta: f64,
    /// Data over the fitted samples (None without data or samples there).
    pub data: [Option<f64>; 2],
    /// Model over the same samples.
    pub model_same: [Option<f64>; 2],
    /// Model over the whole hemisphere.
    pub model_full: [f64; 2],
}

/// The integrals of every incidence; `incs[k]` is incidence k's data, if read.
pub(crate) fn integrals(result: &FitResult, incs: &[Option<&Incidence>]) -> Vec<Integrals> {
    // In parallel: each incidence's model integral and a patch-averaged
    // incidence's grids take milliseconds.
    let patch_averaged = result.recipe.patch_average.is_some();
    result
        .incidences
        .par_iter()
        .zip(incs)
        .map(|(report, inc)| {
            let channels = inc.map_or(1, |i| i.channels);
            let model_full = result.composite_of(report).map_or([f64::NAN; 2], |m| {
                model_integrals(
                    &m,
                    result,
                    report.theta_in,
                    report.phi_in,
                    report.scale,
                    channels,
                )
            });
            let mut data = [None; 2];
            let mut model_same = [None; 2];
            if let Some(inc) = inc {
                let used = inc.hemispheres();
                for (h, hemisphere) in [Hemisphere::Front, Hemisphere::Back].iter().enumerate() {
                    if !used.contains(hemisphere) {
                        continue;
                    }
                    let coverage = inc.integration_grid(*hemisphere, patch_averaged);
                    let (mut d, mut m) = (0.0, 0.0);
                    for j in 0..coverage.size {
                        for i in 0..coverage.size {
                            let o = coverage.owner[(j * coverage.size + i) as usize];
                            if o == crate::disk::NONE || !inc.samples[o as usize].used() {
                                continue;
                            }
                            let s = &inc.samples[o as usize];
                            let w = coverage.cosine_at(i, j);
                            d += s.data * w;
                            m += s.model * w;
                        }
                    }
                    data[h] = Some(d * coverage.pixel_sr());
                    model_same[h] = Some(m * coverage.pixel_sr());
                }
            }
            Integrals {
                theta: report.theta_in,
                data,
                model_same,
                model_full,
            }
        })
        .collect()
}

/// One panel of the parameter chart.
struct Panel {
    /// Axis title.
    y_desc: String,
    /// `(legend name, parameter name, colour)`.
    series: Vec<(String, String, RGBColor)>,
}

/// The axis title of parameter `name` (a flat argument of any shape, or
/// `scale`), with its unit.
fn axis_title(name: &str, unit: &DataUnit) -> String {
    // A lobe sum numbers its lobes' arguments: `rough2`, `rough_u1`, `split1`.
    let digits = name.trim_start_matches(|c: char| !c.is_ascii_digit());
    let (base, lobe) = match digits.parse::<usize>() {
        Ok(k) if !digits.is_empty() => (&name[..name.len() - digits.len()], Some(k)),
        _ => (name, None),
    };
    match (base, lobe) {
        ("spec", None) => "spec: specularity [–]".to_string(),
        ("rough", None) => "rough: roughness (RMS slope) [–]".into(),
        ("rough_u", None) => "rough_u: roughness along u [–]".into(),
        ("rough_v", None) => "rough_v: roughness along v [–]".into(),
        ("rough", Some(k)) => format!("{name}: roughness of lobe {k} [–]"),
        ("rough_u", Some(k)) => format!("{name}: lobe {k}'s roughness along u [–]"),
        ("rough_v", Some(k)) => format!("{name}: lobe {k}'s roughness along v [–]"),
        ("split", Some(1)) => format!("{name}: lobe 1's share of the lobes [–]"),
        ("split", Some(k)) => format!("{name}: lobe {k}'s share of the rest [–]"),
        ("trans", None) => "trans: transmissivity [–]".into(),
        ("tspec", None) => "tspec: transmitted specular fraction [–]".into(),
        ("orient", None) => "orient: orientation of u from +x [°]".into(),
        ("scale", None) => match unit {
            DataUnit::RawPerCos(u) => format!("scale: free scale [{u}·sr]"),
            DataUnit::Bsdf => "scale: free scale [–]".into(),
        },
        _ => format!("{name} [–]"),
    }
}

/// Parameters over θ_in, one panel per parameter (colour channels share one).
pub(crate) struct ParamsChart<'a> {
    /// The fit.
    pub result: &'a FitResult,
    /// The data unit (for the free scale's unit).
    pub unit: DataUnit,
    /// Chart title.
    pub title: String,
}

impl ParamsChart<'_> {
    fn panels(&self) -> Vec<Panel> {
        let Some(first) = self.result.incidences.first() else {
            return Vec::new();
        };
        let free = |name: &str| first.params.iter().any(|p| p.name == name && !p.fixed);
        let mut panels = Vec::new();
        let colours: Vec<&str> = ["red", "green", "blue"]
            .into_iter()
            .filter(|n| free(n))
            .collect();
        if !colours.is_empty() {
            let tied = colours.len() == 3
                && self.result.incidences.iter().all(|r| {
                    let v = |n| r.value(n).unwrap_or(f64::NAN);
                    v("red") == v("green") && v("green") == v("blue")
                });
            let series = if tied {
                vec![("red = green = blue".into(), "red".into(), DATA)]
            } else {
                colours
                    .iter()
                    .map(|n| {
                        let c = match *n {
                            "red" => RGBColor(200, 0, 0),
                            "green" => RGBColor(0, 140, 0),
                            _ => RGBColor(0, 0, 210),
                        };
                        (n.to_string(), n.to_string(), c)
                    })
                    .collect()
            };
            panels.push(Panel {
                y_desc: "colour (red, green, blue) [–]".into(),
                series,
            });
        }
        for p in first
            .params
            .iter()
            .filter(|p| !p.fixed && !["red", "green", "blue"].contains(&p.name.as_str()))
        {
            panels.push(Panel {
                y_desc: axis_title(&p.name, &self.unit),
                series: vec![(p.name.clone(), p.name.clone(), DATA)],
            });
        }
        panels
    }

    /// Draws one panel; true when a parameter ended at a bound.
    fn draw_panel<DB: DrawingBackend>(
        &self,
        area: &Area<DB>,
        panel: &Panel,
    ) -> Result<bool, String> {
        let result = self.result;
        let thetas: Vec<f64> = result.incidences.iter().map(|r| r.theta_in).collect();
        let (x0, x1) = theta_range(&thetas);
        let column = |name: &str| {
            let table = result.table.as_ref()?;
            let j = table.shape().param_names().iter().position(|n| n == name)?;
            Some((table, j))
        };
        let curve = |name: &str| -> Option<Vec<(f64, f64)>> {
            let (table, j) = column(name)?;
            let (lo, hi) = table.range();
            Some(
                (0..=CURVE_STEPS)
                    .map(|k| {
                        let t = lo + (hi - lo) * k as f64 / CURVE_STEPS as f64;
                        (t, table.args_at(t).0[j])
                    })
                    .collect(),
            )
        };
        // A fitted orientation is an angle modulo 180°, which the θ_in
        // table unwraps: each fit's is drawn on the table's branch (at its
        // θ_in; the all-incidence fit's nearest the table's mean).
        let orient_reference = |r: &FitReport| -> Option<f64> {
            let (table, j) = column("orient")?;
            if result.global.as_ref().is_some_and(|g| std::ptr::eq(g, r)) {
                let line = curve("orient")?;
                Some(line.iter().map(|p| p.1).sum::<f64>() / line.len() as f64)
            } else {
                Some(table.args_at(r.theta_in).0[j])
            }
        };
        let param = |r: &FitReport, name: &str| {
            let mut p = r.params.iter().find(|p| p.name == name).cloned()?;
            if name == "orient"
                && let Some(reference) = orient_reference(r)
            {
                p.value += 180.0 * ((reference - p.value) / 180.0).round();
            }
            Some(p)
        };
        let mut ys = Vec::new();
        for (_, name, _) in &panel.series {
            for r in &result.incidences {
                if let Some(p) = param(r, name) {
                    let se = p.uncertainty().filter(|_| !p.at_bound).unwrap_or(0.0);
                    ys.extend([p.value - se, p.value + se]);
                }
            }
            if let Some(g) = result.global.as_ref().and_then(|g| param(g, name)) {
                ys.push(g.value);
            }
            ys.extend(curve(name).unwrap_or_default().into_iter().map(|p| p.1));
        }
        let mut chart = theta_axes(
            area,
            &Frame::PANEL,
            (x0, x1),
            lin_range(ys.into_iter()),
            &panel.y_desc,
        )?;
        let cap = 0.008 * (x1 - x0);
        let mut any_bound = false;
        for (label, name, colour) in &panel.series {
            let colour = *colour;
            if let Some(line) = curve(name) {
                chart
                    .draw_series(LineSeries::new(line, colour.mix(0.6).stroke_width(2)))
                    .msg()?;
            }
            if let Some(g) = result.global.as_ref().and_then(|g| param(g, name)) {
                chart
                    .draw_series(DashedLineSeries::new(
                        vec![(x0, g.value), (x1, g.value)],
                        6,
                        4,
                        colour.mix(0.5).stroke_width(1),
                    ))
                    .msg()?;
            }
            let points: Vec<_> = result
                .incidences
                .iter()
                .filter_map(|r| param(r, name).map(|p| (r.theta_in, p)))
                .collect();
            for (t, p) in &points {
                let se = p.uncertainty().unwrap_or(0.0);
                if se.is_finite() && se > 0.0 && !p.at_bound {
                    let (lo, hi) = (p.value - se, p.value + se);
                    let style = colour.stroke_width(1);
                    for seg in [
                        vec![(*t, lo), (*t, hi)],
                        vec![(t - cap, lo), (t + cap, lo)],
                        vec![(t - cap, hi), (t + cap, hi)],
                    ] {
                        chart
                            .plotting_area()
                            .draw(&PathElement::new(seg, style))
                            .msg()?;
                    }
                }
            }
            let anno = chart
                .draw_series(
                    points
                        .iter()
                        .filter(|(_, p)| !p.at_bound)
                        .map(|(t, p)| Circle::new((*t, p.value), 4, colour.filled())),
                )
                .msg()?;
            if panel.series.len() > 1 {
                anno.label(label.as_str())
                    .legend(legend_circle(4, colour.filled()));
            }
            let bound: Vec<_> = points.iter().filter(|(_, p)| p.at_bound).collect();
            if !bound.is_empty() {
                any_bound = true;
                chart
                    .draw_series(
                        bound
                            .iter()
                            .map(|(t, p)| Circle::new((*t, p.value), 6, ALERT.stroke_width(2))),
                    )
                    .msg()?;
            }
        }
        if panel.series.len() > 1 {
            // Lighter than a whole chart's legend, as it sits inside a small panel.
            series_legend(&mut chart)
                .background_style(WHITE.mix(0.85))
                .border_style(GUIDE)
                .draw()
                .msg()?;
        }
        Ok(any_bound)
    }

    /// The legend shared by every panel, drawn in the strip `area`.
    fn draw_legend<DB: DrawingBackend>(
        &self,
        root: &Area<DB>,
        area: &Area<DB>,
        any_bound: bool,
    ) -> Result<(), String> {
        let (bx, by) = area.get_base_pixel();
        let (_, h) = area.dim_in_pixel();
        let y = by + h as i32 / 2;
        let mut x = bx + 90;
        let label = |x: i32, s: &str| -> Result<i32, String> {
            root.draw(&Text::new(s.to_string(), (x, y), super::left(TICK)))
                .msg()?;
            let (w, _) = root.estimate_text_size(s, &super::left(TICK)).msg()?;
            Ok(x + w as i32 + 36)
        };
        root.draw(&PathElement::new(
            vec![(x, y - 8), (x, y + 8)],
            DATA.stroke_width(1),
        ))
        .msg()?;
        root.draw(&Circle::new((x, y), 4, DATA.filled())).msg()?;
        x = label(x + 12, "fit per incidence ± 1 standard error")?;
        if let Some(table) = &self.result.table {
            let method = match table.method {
                Interpolation::Linear => "linear",
                Interpolation::Pchip => "PCHIP",
            };
            root.draw(&PathElement::new(
                vec![(x, y), (x + 26, y)],
                DATA.mix(0.6).stroke_width(2),
            ))
            .msg()?;
            x = label(x + 34, &format!("{method} interpolation (the θ_in table)"))?;
        }
        if self.result.global.is_some() {
            root.draw(&DashedPathElement::new(
                vec![(x, y), (x + 26, y)],
                6,
                4,
                DATA.mix(0.5).stroke_width(1),
            ))
            .msg()?;
            x = label(x + 34, "all-incidence fit")?;
        }
        if any_bound {
            root.draw(&Circle::new((x + 6, y), 6, ALERT.stroke_width(2)))
                .msg()?;
            label(x + 18, "at a bound (standard error meaningless)")?;
        }
        Ok(())
    }
}

/// Columns and rows of the parameter chart for `n` panels.
fn grid(n: usize) -> (usize, usize) {
    let cols = if n <= 1 { 1 } else { 2 };
    (cols, n.div_ceil(cols).max(1))
}

impl Chart for ParamsChart<'_> {
    fn name(&self) -> String {
        "params".into()
    }

    fn size(&self) -> (u32, u32) {
        let (cols, rows) = grid(self.panels().len());
        (if cols == 1 { 900 } else { 1300 }, 84 + 420 * rows as u32)
    }

    fn draw<DB: DrawingBackend>(&self, root: &Area<DB>, _canvas: &Canvas) -> Result<(), String> {
        let area = titled(root, &self.title)?;
        let (strip, body) = area.split_vertically(34);
        let panels = self.panels();
        let (cols, rows) = grid(panels.len());
        let cells = body.split_evenly((rows, cols));
        let mut any_bound = false;
        for (panel, cell) in panels.iter().zip(&cells) {
            any_bound |= self.draw_panel(cell, panel)?;
        }
        self.draw_legend(root, &strip, any_bound)
    }
}

/// θ_in, then ρ_dh and τ_dh of the interpolated material and of the
/// all-incidence fit at that θ_in.
type CurvePoint = (f64, Option<[f64; 2]>, Option<[f64; 2]>);

/// ρ_dh (and τ_dh) over θ_in: data against model.
pub(crate) struct RhoChart<'a> {
    /// The fit.
    pub result: &'a FitResult,
    /// Incidence k's data, if read.
    pub incs: Vec<Option<&'a Incidence>>,
    /// The integrals, computed on first use (SVG and PNG share them).
    pub integrals: OnceLock<Vec<Integrals>>,
    /// The data unit.
    pub unit: DataUnit,
    /// Channels of the data (1 or 3).
    pub channels: usize,
    /// Chart title.
    pub title: String,
}

impl RhoChart<'_> {
    /// The interpolated material's and the all-incidence fit's integrals
    /// along θ_in: `(θ, table, global)`.
    fn curves(&self) -> Vec<CurvePoint> {
        let result = self.result;
        let thetas: Vec<f64> = result.incidences.iter().map(|r| r.theta_in).collect();
        let phi = result.incidences.first().map_or(0.0, |r| r.phi_in);
        let (lo, hi) = match &result.table {
            Some(t) => t.range(),
            None => (
                thetas.iter().copied().fold(f64::INFINITY, f64::min),
                thetas.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            ),
        };
        if !lo.is_finite() || hi <= lo {
            return Vec::new();
        }
        // The free scale is not part of the table: interpolate it linearly.
        let scale_at = |t: f64| -> f64 {
            let rs = &result.incidences;
            let i = rs
                .windows(2)
                .position(|w| t <= w[1].theta_in)
                .unwrap_or(rs.len().saturating_sub(2));
            match (rs.get(i), rs.get(i + 1)) {
                (Some(a), Some(b)) if b.theta_in > a.theta_in => {
                    let f = ((t - a.theta_in) / (b.theta_in - a.theta_in)).clamp(0.0, 1.0);
                    a.scale + f * (b.scale - a.scale)
                }
                (Some(a), _) => a.scale,
                _ => 1.0,
            }
        };
        let global = result
            .global
            .as_ref()
            .and_then(|g| result.composite_of(g).map(|m| (m, g.scale)));
        (0..=CURVE_STEPS)
            .map(|k| {
                let t = lo + (hi - lo) * k as f64 / CURVE_STEPS as f64;
                let table = result
                    .table
                    .as_ref()
                    .and_then(|tab| tab.composite_at(t).ok())
                    .map(|(m, _)| model_integrals(&m, result, t, phi, scale_at(t), self.channels));
                let g = global
                    .as_ref()
                    .map(|(m, s)| model_integrals(m, result, t, phi, *s, self.channels));
                (t, table, g)
            })
            .collect()
    }
}

impl Chart for RhoChart<'_> {
    fn name(&self) -> String {
        "rho".into()
    }

    fn draw<DB: DrawingBackend>(&self, root: &Area<DB>, _canvas: &Canvas) -> Result<(), String> {
        let ints = self
            .integrals
            .get_or_init(|| integrals(self.result, &self.incs));
        let curves = self.curves();
        let back = ints.iter().any(|i| i.data[1].is_some());
        let hemis: &[usize] = if back { &[0, 1] } else { &[0] };
        let mut ys = vec![0.0];
        for i in ints {
            for &h in hemis {
                ys.extend(i.data[h]);
                ys.extend(i.model_same[h]);
                ys.push(i.model_full[h]);
            }
        }
        for (_, t, g) in &curves {
            for &h in hemis {
                ys.extend(t.map(|v| v[h]));
                ys.extend(g.map(|v| v[h]));
            }
        }
        let top = ys
            .iter()
            .copied()
            .filter(|v| v.is_finite())
            .fold(0.0, f64::max);
        let thetas: Vec<f64> = ints.iter().map(|i| i.theta).collect();
        let (x0, x1) = theta_range(&thetas);
        let y_desc = if back {
            self.unit.integral_axis().replace("ρ_dh", "ρ_dh, τ_dh")
        } else {
            self.unit.integral_axis()
        };
        let area = titled(root, &self.title)?;
        let mut chart = theta_axes(
            &area,
            &Frame::FULL,
            (x0, x1),
            (0.0, (top * 1.25).max(1e-12)),
            &y_desc,
        )?;
        for &h in hemis {
            let (sym, data_c, model_c) = if h == 0 {
                ("ρ", DATA, MODEL)
            } else {
                ("τ", RGBColor(0, 90, 160), RGBColor(0, 158, 115))
            };
            let table: Vec<(f64, f64)> = curves
                .iter()
                .filter_map(|(t, v, _)| v.map(|v| (*t, v[h])))
                .collect();
            if !table.is_empty() {
                chart
                    .draw_series(LineSeries::new(table, model_c.mix(0.7).stroke_width(2)))
                    .msg()?
                    .label(format!(
                        "{sym} model, interpolated material, whole hemisphere"
                    ))
                    .legend(legend_line(model_c.mix(0.7).stroke_width(2)));
            }
            let global: Vec<(f64, f64)> = curves
                .iter()
                .filter_map(|(t, _, g)| g.map(|v| (*t, v[h])))
                .collect();
            if !global.is_empty() {
                chart
                    .draw_series(DashedLineSeries::new(global, 6, 4, GUIDE.stroke_width(2)))
                    .msg()?
                    .label(format!("{sym} model, all-incidence fit, whole hemisphere"))
                    .legend(legend_dashes(GUIDE.stroke_width(2)));
            }
            chart
                .draw_series(
                    ints.iter()
                        .filter(|i| i.model_full[h].is_finite())
                        .map(|i| {
                            Circle::new((i.theta, i.model_full[h]), 6, model_c.stroke_width(2))
                        }),
                )
                .msg()?
                .label(format!("{sym} model, per-incidence fit, whole hemisphere"))
                .legend(legend_circle(6, model_c.stroke_width(2)));
            let data: Vec<(f64, f64)> = ints
                .iter()
                .filter_map(|i| i.data[h].map(|v| (i.theta, v)))
                .collect();
            chart
                .draw_series(LineSeries::new(data.clone(), data_c.stroke_width(1)))
                .msg()?;
            chart
                .draw_series(data.iter().map(|&p| Circle::new(p, 4, data_c.filled())))
                .msg()?
                .label(format!(
                    "{sym} data, ∫ over the directions of the fitted samples"
                ))
                .legend(legend_circle(4, data_c.filled()));
            let same: Vec<(f64, f64)> = ints
                .iter()
                .filter_map(|i| i.model_same[h].map(|v| (i.theta, v)))
                .collect();
            chart
                .draw_series(
                    same.iter()
                        .map(|&p| TriangleMarker::new(p, 8, model_c.stroke_width(2))),
                )
                .msg()?
                .label(format!("{sym} model, same directions"))
                .legend(legend_triangle(8, model_c.stroke_width(2)));
        }
        // Lower left: the axis starts at 0, well below the reflectances.
        series_legend(&mut chart)
            .position(SeriesLabelPosition::LowerLeft)
            .draw()
            .msg()
    }
}

/// The error of every incidence's fit.
pub(crate) struct RmsChart<'a> {
    /// The fit.
    pub result: &'a FitResult,
    /// Median |model ÷ data − 1| per incidence (None without data).
    pub medians: Vec<Option<f64>>,
    /// Chart title.
    pub title: String,
}

impl Chart for RmsChart<'_> {
    fn name(&self) -> String {
        "rms".into()
    }

    fn size(&self) -> (u32, u32) {
        (1000, 560)
    }

    fn draw<DB: DrawingBackend>(&self, root: &Area<DB>, _canvas: &Canvas) -> Result<(), String> {
        let result = self.result;
        let rms: Vec<(f64, f64)> = result
            .incidences
            .iter()
            .map(|r| (r.theta_in, r.rms_rel))
            .collect();
        let medians: Vec<(f64, f64)> = result
            .incidences
            .iter()
            .zip(&self.medians)
            .filter_map(|(r, m)| m.map(|m| (r.theta_in, m)))
            .collect();
        let top = rms
            .iter()
            .chain(&medians)
            .map(|p| p.1)
            .chain(result.global.iter().map(|g| g.rms_rel))
            .filter(|v| v.is_finite())
            .fold(0.0, f64::max);
        let thetas: Vec<f64> = rms.iter().map(|p| p.0).collect();
        let (x0, x1) = theta_range(&thetas);
        let area = titled(root, &self.title)?;
        let mut chart = theta_axes(
            &area,
            &Frame::FULL,
            (x0, x1),
            (0.0, (top * 1.3).max(1e-6)),
            "relative error [–]",
        )?;
        if let Some(g) = &result.global {
            chart
                .draw_series(DashedLineSeries::new(
                    vec![(x0, g.rms_rel), (x1, g.rms_rel)],
                    6,
                    4,
                    GUIDE.stroke_width(2),
                ))
                .msg()?
                .label("RMS relative error, all-incidence fit")
                .legend(legend_dashes(GUIDE.stroke_width(2)));
        }
        chart
            .draw_series(LineSeries::new(rms.clone(), MODEL.stroke_width(1)))
            .msg()?;
        chart
            .draw_series(rms.iter().map(|&p| Circle::new(p, 5, MODEL.filled())))
            .msg()?
            .label("RMS of (model − data) ÷ √(data² + floor²), per incidence")
            .legend(legend_circle(5, MODEL.filled()));
        if !medians.is_empty() {
            chart
                .draw_series(LineSeries::new(medians.clone(), DATA.stroke_width(1)))
                .msg()?;
            chart
                .draw_series(
                    medians
                        .iter()
                        .map(|&p| TriangleMarker::new(p, 6, DATA.filled())),
                )
                .msg()?
                .label("median |model ÷ data − 1| over the fitted samples")
                .legend(legend_triangle(6, DATA.filled()));
        }
        series_legend(&mut chart).draw().msg()
    }
}
