//! The charts, one module per kind, and the styling they share.
//!
//! * [`map`]: per incidence, model ÷ data over the hemisphere.
//! * [`cut`]: per incidence, the in-plane cut; and all cuts in one chart.
//! * [`theta`]: over θ_in, the parameters, ρ_dh and the RMS error.
//! * [`azimuth`]: over φ_in, the parameters of each θ_in ring, for tables
//!   that follow φ_in (anisotropic types fitted to Klems XML).

pub(crate) mod azimuth;
pub(crate) mod cut;
pub(crate) mod map;
pub(crate) mod theta;

use crate::figure::{Area, FONT, OrMsg};
use plotters::chart::{MeshStyle, SeriesLabelStyle};
use plotters::coord::CoordTranslate;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// Font sizes in pixels.
pub(crate) const TITLE: f64 = 22.0;
pub(crate) const LABEL: f64 = 17.0;
pub(crate) const TICK: f64 = 14.0;
pub(crate) const SMALL: f64 = 13.0;

/// Grid lines: light enough not to compete with the data.
const GRID: RGBColor = RGBColor(226, 226, 226);
/// Length in pixels of the line sample in front of a legend entry.
const LEGEND_SAMPLE: i32 = 20;

/// A Cartesian chart over coordinates `X` × `Y`, being drawn.
pub(crate) type CartesianChart<'a, DB, X, Y> = ChartContext<'a, DB, Cartesian2d<X, Y>>;

/// Margins and label areas around the plot of a Cartesian chart, in pixels.
pub(crate) struct Frame {
    margin: u32,
    /// Wider than `margin`, so that the last x tick label fits.
    margin_right: u32,
    x_label_area: u32,
    y_label_area: u32,
}

impl Frame {
    /// A chart that fills its file.
    pub(crate) const FULL: Frame = Frame {
        margin: 14,
        margin_right: 28,
        x_label_area: 52,
        y_label_area: 84,
    };
    /// One of several panels in a file: tighter, as they sit side by side.
    pub(crate) const PANEL: Frame = Frame {
        margin: 12,
        margin_right: 24,
        x_label_area: 46,
        y_label_area: 76,
    };

    /// A Cartesian chart over `x` × `y` in `area`, within this frame.
    pub(crate) fn chart<'a, DB: DrawingBackend, X: AsRangedCoord, Y: AsRangedCoord>(
        &self,
        area: &'a Area<DB>,
        x: X,
        y: Y,
    ) -> Result<CartesianChart<'a, DB, X::CoordDescType, Y::CoordDescType>, String> {
        ChartBuilder::on(area)
            .margin(self.margin)
            .margin_right(self.margin_right)
            .x_label_area_size(self.x_label_area)
            .y_label_area_size(self.y_label_area)
            .build_cartesian_2d(x, y)
            .msg()
    }
}

/// [`fmt`] as a tick formatter.
fn tick(v: &f64) -> String {
    fmt(*v)
}

/// The mesh of `chart` in the shared style: the axis titles, ticks labelled
/// by [`fmt`], and a grid at the labelled ticks only. The caller adds what
/// is particular (tick count, a linear axis's formatter) and draws it.
pub(crate) fn mesh<'a, 'b, DB, X, Y>(
    chart: &'b mut CartesianChart<'a, DB, X, Y>,
    x_desc: &str,
    y_desc: &str,
) -> MeshStyle<'a, 'b, X, Y, DB>
where
    DB: DrawingBackend,
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let mut mesh = chart.configure_mesh();
    mesh.x_desc(x_desc)
        .y_desc(y_desc)
        .x_label_formatter(&tick)
        .y_label_formatter(&tick)
        .axis_desc_style((FONT, LABEL))
        .label_style((FONT, TICK))
        .bold_line_style(GRID)
        .light_line_style(TRANSPARENT);
    mesh
}

/// The legend of `chart`'s labelled series: upper left, framed, on white
/// that lets the data show through a little. The caller may move or
/// restyle it, then draws it.
pub(crate) fn series_legend<'a, 'b, DB, CT>(
    chart: &'b mut ChartContext<'a, DB, CT>,
) -> SeriesLabelStyle<'a, 'b, DB, CT>
where
    DB: DrawingBackend + 'a,
    CT: CoordTranslate,
{
    let mut legend = chart.configure_series_labels();
    legend
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .label_font((FONT, SMALL))
        .legend_area_size(LEGEND_SYMBOLS)
        .margin(LEGEND_MARGIN);
    legend
}

/// Width in pixels of the symbol column of a legend.
const LEGEND_SYMBOLS: i32 = 30;
/// Margin in pixels inside a legend's frame.
const LEGEND_MARGIN: i32 = 10;

/// Width and height in pixels of the legend [`series_legend`] draws for
/// `labels`, laid out as plotters lays it out: a line every 1.25 font
/// sizes, the symbol column, the margins.
pub(crate) fn legend_size(labels: &[String]) -> (i32, i32) {
    crate::figure::register_fonts();
    let font = (FONT, SMALL).into_font();
    let (mut w, mut h) = (0, 0);
    for (k, label) in labels.iter().enumerate() {
        let (lw, lh) = font.box_size(label).unwrap_or_else(|_| {
            let chars = label.chars().count() as f64;
            ((chars * 0.62 * SMALL) as u32, SMALL as u32)
        });
        let top = (k as f64 * SMALL * 1.25).round() as i32;
        w = w.max(lw as i32);
        h = h.max(top + lh as i32);
    }
    (
        w + LEGEND_SYMBOLS + 2 * LEGEND_MARGIN,
        h + 2 * LEGEND_MARGIN,
    )
}

/// A legend entry's symbol for a line series: a short line in `style`.
pub(crate) fn legend_line(style: ShapeStyle) -> impl Fn((i32, i32)) -> PathElement<(i32, i32)> {
    move |(x, y)| PathElement::new(vec![(x, y), (x + LEGEND_SAMPLE, y)], style)
}

/// A legend entry's symbol for a dashed line series (6-pixel dashes, 4
/// apart, as the series).
pub(crate) fn legend_dashes(
    style: ShapeStyle,
) -> impl Fn((i32, i32)) -> DashedPathElement<std::vec::IntoIter<(i32, i32)>, u32> {
    move |(x, y)| DashedPathElement::new(vec![(x, y), (x + LEGEND_SAMPLE, y)], 6, 4, style)
}

/// A legend entry's symbol for shaded ranges: a swatch as long as a line
/// sample.
pub(crate) fn legend_swatch(style: ShapeStyle) -> impl Fn((i32, i32)) -> Rectangle<(i32, i32)> {
    move |(x, y)| Rectangle::new([(x, y - 6), (x + LEGEND_SAMPLE, y + 6)], style)
}

/// A legend entry's symbol for circle markers of `radius` pixels, centred
/// where a line sample would be.
pub(crate) fn legend_circle(
    radius: i32,
    style: ShapeStyle,
) -> impl Fn((i32, i32)) -> Circle<(i32, i32), i32> {
    move |(x, y)| Circle::new((x + LEGEND_SAMPLE / 2, y), radius, style)
}

/// A legend entry's symbol for triangle markers of `size` pixels, centred
/// where a line sample would be.
pub(crate) fn legend_triangle(
    size: i32,
    style: ShapeStyle,
) -> impl Fn((i32, i32)) -> TriangleMarker<(i32, i32), i32> {
    move |(x, y)| TriangleMarker::new((x + LEGEND_SAMPLE / 2, y), size, style)
}

/// A text style of `size` pixels in `colour`, anchored at `h`, `v`.
pub(crate) fn text(size: f64, colour: &RGBColor, h: HPos, v: VPos) -> TextStyle<'static> {
    (FONT, size).into_font().color(colour).pos(Pos::new(h, v))
}

/// Plain black text anchored at its left and vertical centre.
pub(crate) fn left(size: f64) -> TextStyle<'static> {
    text(size, &BLACK, HPos::Left, VPos::Center)
}

/// Room in pixels left free at either end of a title: SVG viewers draw it
/// in their own sans-serif, which may run a little wider than DejaVu Sans.
const TITLE_MARGIN: u32 = 20;
/// What stands for the characters left out of a title.
const ELLIPSIS: char = '…';

/// Width in pixels of `text` in the title font (the embedded DejaVu Sans),
/// or an estimate of 0.62 of the font size per character if the font is
/// not at hand.
pub(crate) fn title_width(text: &str) -> u32 {
    crate::figure::register_fonts();
    (FONT, TITLE)
        .into_font()
        .box_size(text)
        .map(|(w, _)| w)
        .unwrap_or_else(|_| (text.chars().count() as f64 * 0.62 * TITLE).ceil() as u32)
}

/// The widest a title may be on a chart `chart_width` pixels wide.
pub(crate) fn title_room(chart_width: u32) -> u32 {
    chart_width.saturating_sub(2 * TITLE_MARGIN)
}

/// The title `name` then `rest` for a chart `chart_width` pixels wide.
/// When too wide, the name (a sample name may be any length) loses
/// characters from its middle, where an ellipsis stands for them, so
/// that its start and its end (often a sample number) stay, and so does
/// `rest`, which says what the chart shows. If even that is too wide, the
/// end of the whole title goes.
pub(crate) fn fit_title(name: &str, rest: &str, chart_width: u32) -> String {
    let room = title_room(chart_width);
    let whole = format!("{name}{rest}");
    if title_width(&whole) <= room {
        return whole;
    }
    let chars: Vec<char> = name.chars().collect();
    // The name cut to `keep` characters: the first half and the last.
    let cut = |keep: usize| -> String {
        let head = keep.div_ceil(2);
        let tail = keep - head;
        let mut s: String = chars[..head].iter().collect();
        s.push(ELLIPSIS);
        s.extend(&chars[chars.len() - tail..]);
        s.push_str(rest);
        s
    };
    if title_width(&cut(0)) > room {
        return fit_end(&whole, room);
    }
    cut(most_that_fit(chars.len(), room, cut))
}

/// The most characters of `len` that `cut` keeps within `room` pixels:
/// the width grows with the count, so a bisection finds it.
fn most_that_fit(len: usize, room: u32, cut: impl Fn(usize) -> String) -> usize {
    let (mut fits, mut too_wide) = (0, len);
    while too_wide - fits > 1 {
        let mid = (fits + too_wide) / 2;
        if title_width(&cut(mid)) <= room {
            fits = mid;
        } else {
            too_wide = mid;
        }
    }
    fits
}

/// `text`, or as much of its start as fits in `room` pixels with an
/// ellipsis after it.
pub(crate) fn fit_end(text: &str, room: u32) -> String {
    if title_width(text) <= room {
        return text.to_string();
    }
    let chars: Vec<char> = text.chars().collect();
    let cut = |keep: usize| -> String {
        let mut s: String = chars[..keep].iter().collect();
        s.push(ELLIPSIS);
        s
    };
    cut(most_that_fit(chars.len(), room, cut))
}

/// Draws the chart's title centred at the top and returns the area below.
/// A title too wide for the chart (the callers fit theirs already, see
/// [`fit_title`]) loses its end rather than run off the image.
pub(crate) fn titled<DB: DrawingBackend>(root: &Area<DB>, title: &str) -> Result<Area<DB>, String> {
    let (w, _) = root.dim_in_pixel();
    let title = fit_end(title, title_room(w));
    root.titled(&title, (FONT, TITLE).into_font().color(&BLACK))
        .msg()
}

/// A tick label: integers as such, otherwise up to three significant
/// digits, with an exponent outside [1e-3, 1e4).
pub(crate) fn fmt(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let a = v.abs();
    if !(1e-3..1e4).contains(&a) {
        let s = format!("{v:.1e}");
        return s.replace(".0e", "e");
    }
    if (v - v.round()).abs() < 1e-9 * a.max(1.0) {
        return format!("{}", v.round() as i64);
    }
    let digits = (2 - a.log10().floor() as i32).clamp(0, 6) as usize;
    let s = format!("{v:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// A tick formatter for a linear axis over `[lo, hi]`: as many decimals
/// as the tick spacing needs, trailing zeros trimmed; an exponent for very
/// large or very small magnitudes.
pub(crate) fn lin_fmt(lo: f64, hi: f64) -> impl Fn(&f64) -> String {
    let step = ((hi - lo).abs() / 10.0).max(1e-300);
    let big = lo.abs().max(hi.abs());
    let decimals = (-step.log10()).ceil().max(0.0) as usize + 1;
    move |v: &f64| {
        if *v == 0.0 {
            return "0".into();
        }
        if !(1e-3..1e5).contains(&big) {
            return format!("{v:.2e}").replace(".00e", "e");
        }
        let s = format!("{v:.decimals$}");
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    }
}

/// Range `[lo, hi]` of a log axis that shows every positive value in
/// `values`, with a margin, and at most `decades` decades below the top.
pub(crate) fn log_range(values: impl Iterator<Item = f64>, decades: f64) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for v in values.filter(|v| v.is_finite() && *v > 0.0) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if hi <= 0.0 {
        return (0.1, 10.0);
    }
    let hi = hi * 2.0;
    let lo = (lo * 0.5).max(hi * 10f64.powf(-decades));
    if hi / lo < 10.0 {
        (hi / 10.0, hi)
    } else {
        (lo, hi)
    }
}

/// Range of a linear axis over `values` with 8% margins (never empty).
pub(crate) fn lin_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let span = hi - lo;
    let pad = if span > 1e-12 * hi.abs().max(lo.abs()) {
        0.08 * span
    } else {
        0.05 * hi.abs().max(1e-3)
    };
    (lo - pad, hi + pad)
}

/// The θ_in axis range over `thetas` (at least 10° wide).
pub(crate) fn theta_range(thetas: &[f64]) -> (f64, f64) {
    let lo = thetas.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = thetas.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if !lo.is_finite() {
        return (0.0, 90.0);
    }
    let pad = (0.06 * (hi - lo)).max(5.0);
    (lo - pad, hi + pad)
}

/// `θ_in = 30°` (φ_in appended when not 0).
pub(crate) fn incidence_label(theta_in: f64, phi_in: f64) -> String {
    if phi_in == 0.0 {
        format!("θ_in = {}°", crate::prepare::num(theta_in))
    } else {
        format!(
            "θ_in = {}°, φ_in = {}°",
            crate::prepare::num(theta_in),
            crate::prepare::num(phi_in)
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_labels_are_short() {
        assert_eq!(fmt(100.0), "100");
        assert_eq!(fmt(0.5), "0.5");
        assert_eq!(fmt(0.123456), "0.123");
        assert_eq!(fmt(1.2345), "1.23");
        assert_eq!(fmt(1e-5), "1e-5");
        assert_eq!(fmt(2.5e5), "2.5e5");
    }

    #[test]
    fn linear_labels_resolve_the_ticks() {
        let f = lin_fmt(0.1527, 0.1538);
        assert_ne!(f(&0.1530), f(&0.1531));
        assert_eq!(f(&0.1530), "0.153");
        assert_eq!(f(&0.1531), "0.1531");
        let f = lin_fmt(0.0, 60.0);
        assert_eq!(f(&20.0), "20");
    }

    /// An 82-character sample name.
    const LONG: &str =
        "Golden_glossy_paper_measured_on_the_pgII_goniophotometer_at_EPFL_sample_0042_front";

    #[test]
    fn a_short_name_keeps_its_title() {
        let rest = " (metal), θ_in = 30°: cut through the plane of incidence";
        let title = fit_title("alu-ggx", rest, 1000);
        assert_eq!(title, format!("alu-ggx{rest}"));
        assert!(title_width(&title) <= title_room(1000));
    }

    #[test]
    fn a_long_name_is_shortened_in_the_middle_to_fit() {
        let rest = " (metal), θ_in = 30°: model ÷ data over the hemisphere";
        for width in [990, 1000, 900, 1300, 700] {
            let whole = format!("{LONG}{rest}");
            assert!(title_width(&whole) > title_room(width), "{width}");
            let title = fit_title(LONG, rest, width);
            let w = title_width(&title);
            assert!(w <= title_room(width), "{title}: {w} px on {width}");
            // Nearly all the room is used: not shortened more than needed.
            assert!(w + 3 * TITLE as u32 > title_room(width), "{title}: {w} px");
            assert!(title.ends_with(rest), "{title}");
            let head = if width >= 900 {
                "Golden_glossy"
            } else {
                "Gold"
            };
            assert!(title.starts_with(head), "{title}");
            assert!(
                title.contains("…") && title.contains("front (metal)"),
                "{title}"
            );
        }
        // No room even for the rest: its end goes too.
        let title = fit_title(LONG, rest, 300);
        assert!(title_width(&title) <= title_room(300), "{title}");
        assert!(title.starts_with("Gold") && title.ends_with('…'), "{title}");
    }

    #[test]
    fn log_range_spans_a_decade_at_least() {
        let (lo, hi) = log_range([1.0, 2.0].into_iter(), 6.0);
        assert!(hi / lo >= 10.0 - 1e-9);
        let (lo, hi) = log_range([1e-9, 1.0].into_iter(), 4.0);
        assert!((hi / lo - 1e4).abs() < 1e-6);
        assert_eq!(log_range([0.0, -1.0].into_iter(), 3.0), (0.1, 10.0));
    }
}
