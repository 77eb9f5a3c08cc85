//! Colours: the diverging scale of the residual maps and the series
//! palette.
//!
//! The diverging scale is ColorBrewer's 11-class RdBu, linearly
//! interpolated in sRGB: blue where the model is below the data, white
//! where they agree, red where the model is above. The series palette is
//! Okabe and Ito's colour-blind-safe set (without its yellow, which is
//! unreadable on white).

use plotters::style::RGBColor;

/// RdBu anchors from t = −1 (blue) to t = +1 (red).
pub(crate) const RDBU: [(u8, u8, u8); 11] = [
    (5, 48, 97),
    (33, 102, 172),
    (67, 147, 195),
    (146, 197, 222),
    (209, 229, 240),
    (247, 247, 247),
    (253, 219, 199),
    (244, 165, 130),
    (214, 96, 77),
    (178, 24, 43),
    (103, 0, 31),
];

/// Diverging colour for `t` in [−1, 1] (clamped; NaN gives grey).
pub(crate) fn diverging(t: f64) -> RGBColor {
    if t.is_nan() {
        return MASKED;
    }
    let x = (t.clamp(-1.0, 1.0) + 1.0) * 0.5 * (RDBU.len() - 1) as f64;
    // x and the mixed channels are never negative: truncation is floor,
    // and + 0.5 then truncation is round (no libm calls; a map colours
    // every sample).
    let i = (x as usize).min(RDBU.len() - 2);
    let f = x - i as f64;
    let (a, b) = (RDBU[i], RDBU[i + 1]);
    let mix = |p: u8, q: u8| (p as f64 + f * (q as f64 - p as f64) + 0.5) as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// Samples that were not fitted (masked by a selection).
pub(crate) const MASKED: RGBColor = RGBColor(190, 190, 190);

/// Shading of masked ranges.
pub(crate) const SHADE: RGBColor = RGBColor(228, 228, 228);

/// Grid and guide lines.
pub(crate) const GUIDE: RGBColor = RGBColor(120, 120, 120);

/// The data colour of single-series charts.
pub(crate) const DATA: RGBColor = RGBColor(0, 0, 0);

/// The model colour of single-series charts.
pub(crate) const MODEL: RGBColor = RGBColor(213, 94, 0);

/// Marks things that need attention (parameters at a bound).
pub(crate) const ALERT: RGBColor = RGBColor(204, 0, 0);

const PALETTE: [RGBColor; 7] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
];

/// The colour of series `k` (cycling).
pub(crate) fn series(k: usize) -> RGBColor {
    PALETTE[k % PALETTE.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn diverging_ends_and_middle() {
        assert_eq!(diverging(-1.0), RGBColor(5, 48, 97));
        assert_eq!(diverging(0.0), RGBColor(247, 247, 247));
        assert_eq!(diverging(1.0), RGBColor(103, 0, 31));
        assert_eq!(diverging(7.0), diverging(1.0));
        assert_eq!(diverging(f64::NAN), MASKED);
    }
}
