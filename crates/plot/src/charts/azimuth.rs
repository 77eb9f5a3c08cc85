//! Parameters over φ_in, one line per θ_in ring: for an anisotropic type
//! fitted to a Klems basis, whose table follows (θ_in, φ_in)
//! ([`brtf_fit::ParamTable::azimuth`]). Each ring's incidences are dots,
//! and the line is what the exports use between them (linear, periodic).

use super::{Frame, legend_line, lin_fmt, lin_range, mesh, series_legend, titled};
use crate::colour::series;
use crate::figure::{Area, Canvas, Chart, OrMsg};
use brtf_fit::{AzimuthRing, FitResult};
use plotters::prelude::*;

/// Points along φ_in of each ring's line.
const LINE_STEPS: usize = 180;

/// The fitted parameters over φ_in, a panel per parameter, a line per ring.
pub(crate) struct AzimuthChart<'a> {
    /// The fit; its table must follow φ_in ([`AzimuthChart::applies`]).
    pub result: &'a FitResult,
    /// Chart title.
    pub title: String,
}

impl AzimuthChart<'_> {
    /// True when the fit's table follows φ_in.
    pub(crate) fn applies(result: &FitResult) -> bool {
        result
            .table
            .as_ref()
            .is_some_and(|t| t.depends_on_azimuth())
    }

    /// The rings with their θ_in.
    fn rings(&self) -> Vec<(f64, &AzimuthRing)> {
        let Some(table) = &self.result.table else {
            return Vec::new();
        };
        let rings = table.azimuth.as_deref().unwrap_or_default();
        table.theta_in.iter().copied().zip(rings).collect()
    }

    /// `(argument index, axis title)` of each panel: the free parameters,
    /// one colour panel when grey.
    fn panels(&self) -> Vec<(usize, String)> {
        let Some(table) = &self.result.table else {
            return Vec::new();
        };
        let names = table.shape().param_names();
        let rings = self.rings();
        let varies = |j: usize| {
            rings
                .iter()
                .flat_map(|(_, r)| r.args.iter().map(move |a| a[j]))
                .any(|v| v != rings[0].1.args[0][j])
        };
        let grey = rings
            .iter()
            .all(|(_, r)| r.args.iter().all(|a| a[0] == a[1] && a[1] == a[2]));
        names
            .iter()
            .enumerate()
            .filter(|&(j, _)| !(grey && (j == 1 || j == 2)) && varies(j))
            .map(|(j, name)| {
                let title = if grey && j == 0 {
                    "colour (red = green = blue) [–]".to_string()
                } else if name == "orient" {
                    "orient: orientation of u from +x [°]".to_string()
                } else {
                    format!("{name} [–]")
                };
                (j, title)
            })
            .collect()
    }
}

impl Chart for AzimuthChart<'_> {
    fn name(&self) -> String {
        "params-phi".into()
    }

    fn size(&self) -> (u32, u32) {
        let rows = self.panels().len().div_ceil(2).max(1) as u32;
        (1300, 84 + 400 * rows)
    }

    fn draw<DB: DrawingBackend>(&self, root: &Area<DB>, _canvas: &Canvas) -> Result<(), String> {
        let area = titled(root, &self.title)?;
        let panels = self.panels();
        let rows = panels.len().div_ceil(2).max(1);
        let cells = area.split_evenly((rows, 2));
        let rings = self.rings();
        for (k, ((j, y_desc), cell)) in panels.iter().zip(&cells).enumerate() {
            let values = rings.iter().flat_map(|(_, r)| r.args.iter().map(|a| a[*j]));
            let (y0, y1) = lin_range(values);
            let mut chart = Frame::PANEL.chart(cell, 0.0..360.0, y0..y1)?;
            mesh(&mut chart, "φ_in from u [°]", y_desc)
                .x_labels(9)
                .y_label_formatter(&lin_fmt(y0, y1))
                .draw()
                .msg()?;
            for (n, (theta, ring)) in rings.iter().enumerate() {
                let colour = series(n);
                let line: Vec<(f64, f64)> = (0..=LINE_STEPS)
                    .map(|s| {
                        let phi = 360.0 * s as f64 / LINE_STEPS as f64;
                        (phi, ring.arg_at(*j, phi))
                    })
                    .collect();
                let drawn = chart
                    .draw_series(LineSeries::new(line, colour.mix(0.8).stroke_width(2)))
                    .msg()?;
                // One legend, in the first panel.
                if k == 0 {
                    drawn
                        .label(format!("θ_in {theta}°"))
                        .legend(legend_line(colour.stroke_width(2)));
                }
                chart
                    .draw_series(
                        ring.phi_in
                            .iter()
                            .zip(&ring.args)
                            .map(|(p, a)| Circle::new((*p, a[*j]), 3, colour.filled())),
                    )
                    .msg()?;
            }
            if k == 0 {
                series_legend(&mut chart)
                    .background_style(WHITE.mix(0.85))
                    .draw()
                    .msg()?;
            }
        }
        Ok(())
    }
}
