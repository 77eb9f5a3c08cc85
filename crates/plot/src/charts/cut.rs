//! In-plane cuts: the data and the model along the plane of incidence, on
//! a log axis.
//!
//! The plane holds the incident and mirror directions (φ_in and
//! φ_in + 180°). A direction in it is drawn at its signed angle from the
//! front normal, `x = atan2(v·m̂, v_z)` with m̂ the horizontal unit vector
//! towards the mirror azimuth: the mirror direction is at `+θ_in`, the
//! light at `−θ_in`, the back hemisphere beyond ±90°. Data points are the
//! samples within a small angle of the plane: the smallest of 0.25°–3° that
//! gives at least 60 fitted samples and covers 90% of the 2° steps of θ_out
//! that 3° covers. The model is evaluated exactly in the plane.

use super::{
    CartesianChart, Frame, SMALL, fmt, incidence_label, legend_circle, legend_line, legend_size,
    legend_swatch, log_range, mesh, series_legend, titled,
};
use crate::colour::{self, DATA, GUIDE, MASKED, MODEL, SHADE};
use crate::figure::{Area, Canvas, Chart, FONT, OrMsg};
use crate::prepare::{CutCache, Incidence, PlotSample};
use glam::DVec3;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use rayon::prelude::*;

/// Plane tolerances tried, degrees.
const TOLERANCES: [f64; 6] = [0.25, 0.5, 1.0, 1.5, 2.0, 3.0];
/// Width of the x bins of a cut, degrees: each shows its sample nearest
/// the plane.
const CUT_BIN_DEG: f64 = 0.25;
/// Fitted samples a cut should hold.
const ENOUGH: usize = 60;
/// Decades shown below the top of the log axis.
const DECADES: f64 = 6.0;

/// A cut chart: signed in-plane θ_out against the BSDF on a log axis.
type CutAxes<'a, DB> = CartesianChart<'a, DB, RangedCoordf64, LogCoord<f64>>;

/// Both cut charts' axes in `area`, drawn: `x` the range of in-plane
/// angles, `(lo, hi)` that of the values, `y_desc` the data's unit.
fn cut_axes<'a, DB: DrawingBackend>(
    area: &'a Area<DB>,
    x: (f64, f64),
    (lo, hi): (f64, f64),
    y_desc: &str,
) -> Result<CutAxes<'a, DB>, String> {
    let mut chart = Frame::FULL.chart(area, x.0..x.1, (lo..hi).log_scale())?;
    mesh(
        &mut chart,
        "θ_out in the plane of incidence [°]  (− towards the light, + mirror side)",
        y_desc,
    )
    .x_labels(13)
    .draw()
    .msg()?;
    Ok(chart)
}

/// The cut geometry of one incidence.
pub(crate) struct Plane {
    /// Unit vector towards the mirror azimuth, horizontal.
    mirror_axis: DVec3,
    /// Normal of the plane of incidence.
    normal: DVec3,
}

impl Plane {
    /// The plane of incidence of `inc`.
    pub(crate) fn of(inc: &Incidence) -> Plane {
        let phi = inc.phi_in.to_radians();
        Plane {
            mirror_axis: DVec3::new(-phi.cos(), -phi.sin(), 0.0),
            normal: DVec3::new(-phi.sin(), phi.cos(), 0.0),
        }
    }

    /// Signed in-plane angle of `v`, degrees (see the module docs).
    pub(crate) fn x_of(&self, v: DVec3) -> f64 {
        v.dot(self.mirror_axis).atan2(v.z).to_degrees()
    }

    /// Angle between `v` and the plane, degrees.
    pub(crate) fn offset(&self, v: DVec3) -> f64 {
        v.dot(self.normal).abs().clamp(0.0, 1.0).asin().to_degrees()
    }

    /// The in-plane direction at signed angle `x_deg`.
    pub(crate) fn direction(&self, x_deg: f64) -> DVec3 {
        let (s, c) = x_deg.to_radians().sin_cos();
        self.mirror_axis * s + DVec3::Z * c
    }
}

/// The samples of a cut, with the tolerance used.
pub(crate) struct CutData<'a> {
    /// Plane tolerance in degrees.
    pub tolerance: f64,
    /// `(x, sample)` for samples within the tolerance.
    pub points: Vec<(f64, &'a PlotSample)>,
    /// The model along the plane: `(x, value)`.
    pub curve: Vec<(f64, f64)>,
    /// The x range: ±90° (front only) or ±180°.
    pub range: (f64, f64),
}

impl<'a> CutData<'a> {
    /// Picks the samples near the plane and evaluates the model along it.
    /// Made once per incidence and tolerance: the cut's SVG and PNG and the
    /// chart of all cuts share it.
    pub(crate) fn of(inc: &'a Incidence, tolerance: Option<f64>) -> CutData<'a> {
        let made = inc.cut(tolerance, || CutData::make(inc, tolerance));
        CutData {
            tolerance: made.tolerance,
            points: made
                .points
                .iter()
                .map(|&(x, k)| (x, &inc.samples[k]))
                .collect(),
            curve: made.curve.clone(),
            range: made.range,
        }
    }

    /// The cut of `inc` with samples as indices into `inc.samples`.
    fn make(inc: &Incidence, tolerance: Option<f64>) -> CutCache {
        let plane = Plane::of(inc);
        let near_limit = (TOLERANCES[TOLERANCES.len() - 1] + 0.01).to_radians().sin();
        // Made once per incidence: the cut's SVG and PNG and the chart of
        // all cuts each need them.
        let near: Vec<(f64, f64, usize, &PlotSample)> = inc
            .near_plane(|| {
                inc.samples
                    .par_iter()
                    .enumerate()
                    .with_min_len(4096)
                    // Most samples are far from the plane: a dot product
                    // (with a margin) rules them out before any asin/atan2.
                    .filter(|(_, s)| {
                        s.dir.is_finite() && s.dir.dot(plane.normal).abs() <= near_limit
                    })
                    .map(|(k, s)| (plane.offset(s.dir), plane.x_of(s.dir), k))
                    .filter(|(o, _, _)| *o <= TOLERANCES[TOLERANCES.len() - 1])
                    .collect()
            })
            .iter()
            .map(|&(o, x, k)| (o, x, k, &inc.samples[k]))
            .collect();
        // The smallest tolerance with enough fitted samples that also covers
        // (in 2° bins of x) nearly all of what the widest one covers.
        let coverage = |t: f64| -> (usize, usize) {
            let mut bins = std::collections::BTreeSet::new();
            let mut count = 0;
            for (o, x, _, s) in &near {
                if *o <= t && s.used() {
                    count += 1;
                    bins.insert((x / 2.0).floor() as i64);
                }
            }
            (count, bins.len())
        };
        let widest = coverage(TOLERANCES[TOLERANCES.len() - 1]).1;
        let tolerance = tolerance.unwrap_or_else(|| {
            TOLERANCES
                .into_iter()
                .find(|t| {
                    let (count, bins) = coverage(*t);
                    count >= ENOUGH && bins as f64 >= 0.9 * widest as f64
                })
                .unwrap_or(TOLERANCES[TOLERANCES.len() - 1])
        });
        let back = inc.samples.iter().any(|s| s.used() && s.dir.z < 0.0);
        let range = if back { (-180.0, 180.0) } else { (-90.0, 90.0) };
        // One sample per bin of x, the one nearest the plane: on dense
        // layouts (pgII rings) the samples a few degrees off the plane sit
        // below the in-plane values at the same x and draw a comb.
        let mut nearest: std::collections::BTreeMap<i64, (f64, f64, usize, &PlotSample)> =
            std::collections::BTreeMap::new();
        for (o, x, k, s) in near
            .into_iter()
            .filter(|(o, x, _, _)| *o <= tolerance && (range.0..=range.1).contains(x))
        {
            let bin = (x / CUT_BIN_DEG).floor() as i64;
            let slot = nearest.entry(bin).or_insert((o, x, k, s));
            // Fitted samples first, then the nearest to the plane.
            if (s.used(), -o) > (slot.3.used(), -slot.0) {
                *slot = (o, x, k, s);
            }
        }
        let points: Vec<(f64, usize)> = nearest.into_values().map(|(_, x, k, _)| (x, k)).collect();
        let steps = if back { 2880 } else { 1440 };
        let curve = (0..=steps)
            .map(|k| {
                let x = range.0 + (range.1 - range.0) * k as f64 / steps as f64;
                (x, inc.model_at(plane.direction(x)))
            })
            .collect();
        CutCache {
            tolerance,
            points,
            curve,
            range,
        }
    }

    /// x intervals that the selections removed from the fit.
    pub(crate) fn masked_ranges(&self, inc: &Incidence) -> Vec<(f64, f64)> {
        let mut ranges = Vec::new();
        if let Some(m) = inc.beam_mask() {
            ranges.push((-inc.theta_in - m, -inc.theta_in + m));
        }
        if let Some(cap) = inc.theta_cap().filter(|c| *c < 90.0) {
            if self.range.1 > 90.0 {
                ranges.push((cap, 180.0 - cap));
                ranges.push((-180.0 + cap, -cap));
            } else {
                ranges.push((cap, 90.0));
                ranges.push((-90.0, -cap));
            }
        }
        ranges
            .into_iter()
            .map(|(a, b)| (a.max(self.range.0), b.min(self.range.1)))
            .filter(|(a, b)| b > a)
            .collect()
    }
}

/// A corner of the plot, for a legend.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Corner {
    UpperLeft,
    UpperRight,
    LowerRight,
    LowerLeft,
}

impl Corner {
    /// In order of preference, when several are as good.
    const ALL: [Corner; 4] = [
        Corner::UpperLeft,
        Corner::UpperRight,
        Corner::LowerRight,
        Corner::LowerLeft,
    ];
}

/// Gap in pixels between a legend in a corner and the plot's edges.
const LEGEND_GAP: i32 = 5;

/// The rectangle `[x0, y0, x1, y1]` of a legend `legend` pixels large in
/// `corner` of a plot `plot` pixels large, relative to the plot's upper
/// left corner.
pub(crate) fn legend_rect(corner: Corner, plot: (i32, i32), legend: (i32, i32)) -> [i32; 4] {
    let x0 = match corner {
        Corner::UpperLeft | Corner::LowerLeft => LEGEND_GAP,
        Corner::UpperRight | Corner::LowerRight => plot.0 - legend.0 - LEGEND_GAP,
    };
    let y0 = match corner {
        Corner::UpperLeft | Corner::UpperRight => LEGEND_GAP,
        Corner::LowerLeft | Corner::LowerRight => plot.1 - legend.1 - LEGEND_GAP,
    };
    [x0, y0, x0 + legend.0, y0 + legend.1]
}

/// The corner of a plot `plot` pixels large for a legend `legend` pixels
/// large: one clear of the light's marker, a line down the whole plot
/// with its label, between the columns `light` (first, last); of those,
/// the one over the fewest of `points` (the data and the model, in
/// pixels). The light is what a reader looks for first on a cut, so it
/// is never hidden while a corner clear of it exists.
pub(crate) fn legend_corner(
    plot: (i32, i32),
    legend: (i32, i32),
    light: (i32, i32),
    points: &[(i32, i32)],
) -> Corner {
    let cost = |corner: Corner| {
        let [x0, y0, x1, y1] = legend_rect(corner, plot, legend);
        let on_light = light.0 <= x1 && light.1 >= x0;
        let covered = points
            .iter()
            .filter(|(x, y)| (x0..=x1).contains(x) && (y0..=y1).contains(y))
            .count();
        (on_light, covered)
    };
    // `min_by_key` keeps the first of equals: the preferred corner.
    Corner::ALL
        .into_iter()
        .min_by_key(|c| cost(*c))
        .unwrap_or(Corner::UpperLeft)
}

/// The in-plane cut of one incidence.
pub(crate) struct CutChart<'a> {
    /// The incidence.
    pub inc: &'a Incidence,
    /// Chart title.
    pub title: String,
    /// Forced plane tolerance, degrees.
    pub tolerance: Option<f64>,
}

impl Chart for CutChart<'_> {
    fn name(&self) -> String {
        format!("cut-{}", self.inc.tag)
    }

    fn draw<DB: DrawingBackend>(&self, root: &Area<DB>, _canvas: &Canvas) -> Result<(), String> {
        let inc = self.inc;
        let cut = CutData::of(inc, self.tolerance);
        let positive = |v: f64| v.is_finite() && v > 0.0;
        let (lo, hi) = log_range(
            cut.points
                .iter()
                .map(|(_, s)| s.data)
                .chain(cut.curve.iter().map(|(_, m)| *m)),
            DECADES,
        );
        let area = titled(root, &self.title)?;
        let mut chart = cut_axes(&area, cut.range, (lo, hi), &inc.unit.axis())?;

        // The legend's lines, in order, to place it.
        let mut labels: Vec<String> = Vec::new();
        let masked = cut.masked_ranges(inc);
        if !masked.is_empty() {
            labels.push("masked range (not fitted)".into());
            chart
                .draw_series(
                    masked
                        .iter()
                        .map(|&(a, b)| Rectangle::new([(a, lo), (b, hi)], SHADE.filled())),
                )
                .msg()?
                .label(&labels[0])
                .legend(legend_swatch(SHADE.filled()));
        }
        let mut marks = vec![(inc.theta_in, "mirror"), (-inc.theta_in, "light")];
        if cut.range.1 > 90.0 {
            marks.push((180.0 - inc.theta_in, "straight through"));
        }
        for (x, name) in marks {
            chart
                .draw_series(DashedLineSeries::new(
                    vec![(x, lo), (x, hi)],
                    5,
                    4,
                    GUIDE.stroke_width(1),
                ))
                .msg()?;
            chart
                .plotting_area()
                .draw(&Text::new(
                    name.to_string(),
                    (x + 1.0, hi / 1.25),
                    (FONT, SMALL).into_font().color(&GUIDE),
                ))
                .msg()?;
        }
        let not_shown = cut
            .points
            .iter()
            .filter(|(_, s)| s.used() && !positive(s.data))
            .count();
        let masked_points: Vec<(f64, f64)> = cut
            .points
            .iter()
            .filter(|(_, s)| !s.used() && positive(s.data))
            .map(|(x, s)| (*x, s.data))
            .collect();
        if !masked_points.is_empty() {
            labels.push("data, not fitted".into());
            chart
                .draw_series(
                    masked_points
                        .iter()
                        .map(|&p| Circle::new(p, 3, MASKED.stroke_width(1))),
                )
                .msg()?
                .label(&labels[labels.len() - 1])
                .legend(legend_circle(3, MASKED.stroke_width(1)));
        }
        let mut label = format!(
            "data, fitted (within ±{}° of the plane)",
            crate::prepare::num(cut.tolerance)
        );
        if not_shown > 0 {
            label.push_str(&format!("; {not_shown} values ≤ 0 not shown"));
        }
        chart
            .draw_series(
                cut.points
                    .iter()
                    .filter(|(_, s)| s.used() && positive(s.data))
                    .map(|(x, s)| Circle::new((*x, s.data), 2, DATA.filled())),
            )
            .msg()?
            .label(&label)
            .legend(legend_circle(3, DATA.filled()));
        labels.push(label);
        let model_label = if inc.scale != 1.0 {
            format!("model: {} × f (fitted free scale)", fmt(inc.scale))
        } else {
            "model f".to_string()
        };
        chart
            .draw_series(LineSeries::new(
                cut.curve.iter().map(|&(x, m)| (x, m.max(lo))),
                MODEL.stroke_width(2),
            ))
            .msg()?
            .label(&model_label)
            .legend(legend_line(MODEL.stroke_width(2)));
        labels.push(model_label);

        // Pixels relative to the plot, where the legend is placed.
        let (xs, ys) = chart.plotting_area().get_pixel_range();
        let px = |x: f64, y: f64| {
            let (a, b) = chart.backend_coord(&(x, y));
            (a - xs.start, b - ys.start)
        };
        let line = px(-inc.theta_in, hi).0;
        let label_at = px(-inc.theta_in + 1.0, hi).0;
        let (label_width, _) = root
            .estimate_text_size("light", &(FONT, SMALL).into_font().into())
            .msg()?;
        let points: Vec<(i32, i32)> = cut
            .points
            .iter()
            .filter(|(_, s)| positive(s.data))
            .map(|(x, s)| px(*x, s.data))
            .chain(cut.curve.iter().map(|&(x, m)| px(x, m.max(lo))))
            .collect();
        let plot = (xs.end - xs.start, ys.end - ys.start);
        let legend = legend_size(&labels);
        let light = (line - 2, label_at + label_width as i32 + 2);
        let corner = legend_corner(plot, legend, light, &points);
        let [x0, y0, _, _] = legend_rect(corner, plot, legend);
        series_legend(&mut chart)
            .position(SeriesLabelPosition::Coordinate(x0, y0))
            .draw()
            .msg()
    }
}

/// Every incidence's cut in one chart, one colour per incidence.
pub(crate) struct CutsChart<'a> {
    /// The incidences with data.
    pub incs: Vec<&'a Incidence>,
    /// Chart title.
    pub title: String,
    /// Forced plane tolerance, degrees.
    pub tolerance: Option<f64>,
}

impl Chart for CutsChart<'_> {
    fn name(&self) -> String {
        "cuts".into()
    }

    fn draw<DB: DrawingBackend>(&self, root: &Area<DB>, _canvas: &Canvas) -> Result<(), String> {
        let cuts: Vec<CutData> = self
            .incs
            .iter()
            .map(|i| CutData::of(i, self.tolerance))
            .collect();
        let range = cuts.iter().fold((-90.0f64, 90.0f64), |(a, b), c| {
            (a.min(c.range.0), b.max(c.range.1))
        });
        let (lo, hi) = log_range(
            cuts.iter().flat_map(|c| {
                c.points
                    .iter()
                    .filter(|(_, s)| s.used())
                    .map(|(_, s)| s.data)
                    .chain(c.curve.iter().map(|(_, m)| *m))
            }),
            DECADES,
        );
        let area = titled(root, &self.title)?;
        let unit = self.incs.first().map(|i| i.unit.axis()).unwrap_or_default();
        let mut chart = cut_axes(&area, range, (lo, hi), &unit)?;
        for (k, (inc, cut)) in self.incs.iter().zip(&cuts).enumerate() {
            let c = colour::series(k);
            chart
                .draw_series(
                    cut.points
                        .iter()
                        .filter(|(_, s)| s.used() && s.data > 0.0)
                        .map(|(x, s)| Circle::new((*x, s.data), 2, c.mix(0.55).filled())),
                )
                .msg()?;
            chart
                .draw_series(LineSeries::new(
                    cut.curve.iter().map(|&(x, m)| (x, m.max(lo))),
                    c.stroke_width(2),
                ))
                .msg()?
                .label(incidence_label(inc.theta_in, inc.phi_in))
                .legend(legend_line(c.stroke_width(2)));
        }
        series_legend(&mut chart).draw().msg()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cut's plot and legend, in pixels.
    const PLOT: (i32, i32) = (880, 520);
    const LEGEND: (i32, i32) = (390, 90);

    /// The light's marker at `x` pixels: the line and its label.
    fn light(x: i32) -> (i32, i32) {
        (x - 2, x + 40)
    }

    fn clear_of(corner: Corner, light: (i32, i32)) -> bool {
        let [x0, _, x1, _] = legend_rect(corner, PLOT, LEGEND);
        light.1 < x0 || light.0 > x1
    }

    #[test]
    fn the_legend_takes_the_side_away_from_the_light() {
        // θ_in = 30° on ±90°: the light at a third of the width, left.
        let left = light(290);
        let corner = legend_corner(PLOT, LEGEND, left, &[]);
        assert!(clear_of(corner, left), "{corner:?}");
        assert!(matches!(corner, Corner::UpperRight | Corner::LowerRight));
        // The light on the right (the mirror image).
        let right = light(PLOT.0 - 290);
        let corner = legend_corner(PLOT, LEGEND, right, &[]);
        assert!(clear_of(corner, right), "{corner:?}");
        assert_eq!(corner, Corner::UpperLeft);
        // A legend narrower than half the plot leaves the light visible
        // wherever it is.
        for x in (0..PLOT.0).step_by(10) {
            let corner = legend_corner(PLOT, LEGEND, light(x), &[]);
            assert!(clear_of(corner, light(x)), "light at {x}: {corner:?}");
        }
    }

    #[test]
    fn of_the_corners_clear_of_the_light_the_emptiest_is_taken() {
        // The mirror peak in the upper right, the light on the left: the
        // legend goes to the lower right.
        let peak: Vec<(i32, i32)> = (0..60).map(|k| (600 + k, 10 + k)).collect();
        let corner = legend_corner(PLOT, LEGEND, light(290), &peak);
        assert_eq!(corner, Corner::LowerRight);
        // Points alone never put the legend on the light.
        let everywhere: Vec<(i32, i32)> = (0..PLOT.0)
            .step_by(4)
            .flat_map(|x| [(x, 20), (x, PLOT.1 - 20)])
            .filter(|&(x, _)| x > 440)
            .collect();
        let corner = legend_corner(PLOT, LEGEND, light(290), &everywhere);
        assert!(clear_of(corner, light(290)), "{corner:?}");
    }

    #[test]
    fn the_legend_rectangle_sits_in_its_corner() {
        assert_eq!(
            legend_rect(Corner::UpperLeft, PLOT, LEGEND),
            [5, 5, 395, 95]
        );
        assert_eq!(
            legend_rect(Corner::LowerRight, PLOT, LEGEND),
            [485, 425, 875, 515]
        );
    }
}
