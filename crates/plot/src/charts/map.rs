//! The residual map of one incidence: model ÷ data over the hemisphere on
//! an equal-area disk ([`crate::disk`]), coloured on a diverging log scale,
//! with the light and mirror directions, the beam mask, the θ cap and the
//! samples that were not fitted marked.
//!
//! The colour of a sample is `ln((m + floor)/(d + floor))` divided by
//! `ln k`, where `k` is the ratio at the ends of the colour bar (the same
//! for every incidence of a fit) and `floor` is the fit's floor for
//! relative residuals: below it, values count as noise.

use super::{LABEL, SMALL, TICK, fmt, left, text, titled};
use crate::colour::{self, GUIDE, MASKED};
use crate::disk::{self, RADIUS};
use crate::figure::{Area, Canvas, Chart, OrMsg, Raster};
use crate::prepare::{DataUnit, Incidence};
use brtf_gonio::Hemisphere;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};
use rayon::prelude::*;
use std::sync::{Arc, Mutex, OnceLock};

/// Side of one hemisphere's square in pixels.
const DISK: u32 = 640;
/// Width of the colour bar and legend column.
const PANEL: u32 = 350;
/// Extent of the map's coordinates (the rim is at √2).
const EXTENT: f64 = RADIUS * 1.2;

/// Which raster: hemisphere and side in pixels.
type RasterKey = (Hemisphere, u32);

/// RGBA pixels made once by whichever rendering needs them first.
type SharedRaster = Arc<OnceLock<Vec<u8>>>;

/// The residual map of one incidence.
pub struct MapChart<'a> {
    /// The incidence.
    pub inc: &'a Incidence,
    /// Chart title.
    pub title: String,
    /// Ratio `k > 1` at the ends of the colour bar.
    pub ratio: f64,
    /// The fit's RMS relative error of this incidence.
    pub rms_rel: f64,
    /// The rasters drawn so far, by hemisphere and size: the SVG and the
    /// PNG (drawn at the same time) share them.
    rasters: Mutex<Vec<(RasterKey, SharedRaster)>>,
    /// Every sample's colour, made once for all rasters.
    colours: OnceLock<Vec<[u8; 3]>>,
    /// The panel's numbers, made once for the SVG and the PNG.
    stats: OnceLock<Stats>,
}

/// The panel's numbers of the fitted samples.
#[derive(Debug, Clone, Copy)]
struct Stats {
    /// How many.
    used: usize,
    /// The median |log ratio| (the upper median: element n/2 in order).
    median: f64,
    /// How many are within ±10 % (|log ratio| ≤ ln 1.1).
    within: usize,
}

impl Stats {
    fn of(inc: &Incidence) -> Stats {
        let mut used: Vec<f64> = inc
            .samples
            .iter()
            .filter(|s| s.used())
            .map(|s| inc.log_ratio(s).abs())
            .collect();
        let within = used.iter().filter(|a| **a <= 1.1f64.ln()).count();
        let k = used.len() / 2;
        // The same element a full sort would put at k, without the sort.
        let median = if used.is_empty() {
            f64::NAN
        } else {
            *used.select_nth_unstable_by(k, f64::total_cmp).1
        };
        Stats {
            used: used.len(),
            median,
            within,
        }
    }
}

impl<'a> MapChart<'a> {
    /// The map of `inc` with colour-bar ratio `ratio`.
    pub fn new(inc: &'a Incidence, title: String, ratio: f64, rms_rel: f64) -> MapChart<'a> {
        MapChart {
            inc,
            title,
            ratio,
            rms_rel,
            rasters: Mutex::new(Vec::new()),
            colours: OnceLock::new(),
            stats: OnceLock::new(),
        }
    }

    fn hemispheres(&self) -> Vec<Hemisphere> {
        let h = self.inc.hemispheres();
        if h.is_empty() {
            vec![Hemisphere::Front]
        } else {
            h
        }
    }

    /// Colour of a sample, `ln_ratio` being `ln` of [`MapChart::ratio`].
    fn colour_of(&self, s: &crate::prepare::PlotSample, ln_ratio: f64) -> [u8; 3] {
        let c = if s.used() {
            colour::diverging(self.inc.log_ratio(s) / ln_ratio)
        } else {
            MASKED
        };
        [c.0, c.1, c.2]
    }

    /// One colour per sample, looked up per pixel (made once).
    fn colours(&self) -> &[[u8; 3]] {
        self.colours.get_or_init(|| {
            // Once, not per sample (a libm call).
            let ln_ratio = self.ratio.ln();
            self.inc
                .samples
                .par_iter()
                .with_min_len(4096)
                .map(|s| self.colour_of(s, ln_ratio))
                .collect()
        })
    }

    /// Makes what the map needs besides the nearest-sample grids (the
    /// samples' colours and the panel's numbers), so that it can be made
    /// while the grids are.
    pub fn prepare(&self) {
        rayon::join(
            || self.colours(),
            || self.stats.get_or_init(|| Stats::of(self.inc)),
        );
    }

    /// The RGBA raster of one hemisphere, `size` pixels square (made once).
    fn raster(&self, hemisphere: Hemisphere, size: u32) -> Vec<u8> {
        let slot = {
            let mut rasters = self.rasters.lock().unwrap_or_else(|e| e.into_inner());
            let key = (hemisphere, size);
            match rasters.iter().find(|(k, _)| *k == key) {
                Some((_, slot)) => Arc::clone(slot),
                None => {
                    let slot = Arc::new(OnceLock::new());
                    rasters.push((key, Arc::clone(&slot)));
                    slot
                }
            }
        };
        slot.get_or_init(|| self.paint(hemisphere, size)).clone()
    }

    /// Colours the pixels of one hemisphere by their nearest sample.
    fn paint(&self, hemisphere: Hemisphere, size: u32) -> Vec<u8> {
        let owner = self.inc.coverage(hemisphere).resampled(size);
        let colours = self.colours();
        let mut rgba = vec![0u8; owner.len() * 4];
        for (px, &o) in rgba.chunks_exact_mut(4).zip(&owner) {
            if o != disk::NONE {
                px[..3].copy_from_slice(&colours[o as usize]);
                px[3] = 255;
            }
        }
        rgba
    }

    fn draw_disk<DB: DrawingBackend>(
        &self,
        root: &Area<DB>,
        area: &Area<DB>,
        hemisphere: Hemisphere,
        canvas: &Canvas,
    ) -> Result<(), String> {
        let caption = match hemisphere {
            Hemisphere::Front => "front hemisphere (reflection)",
            Hemisphere::Back => "back hemisphere (transmission), seen from the front",
        };
        let (aw, _) = area.dim_in_pixel();
        let sub = area
            .titled(caption, (crate::figure::FONT, LABEL).into_font())
            .msg()?;
        let (sw, sh) = sub.dim_in_pixel();
        let side = sw.min(sh);
        let sub = sub.shrink(((aw - side) / 2, 0), (side, side));
        let chart = ChartBuilder::on(&sub)
            .margin(6)
            .build_cartesian_2d(-EXTENT..EXTENT, -EXTENT..EXTENT)
            .msg()?;
        let plot = chart.plotting_area();

        // The raster: every sample of this hemisphere by its nearest pixel.
        let (x0, y0) = chart.backend_coord(&(-RADIUS, RADIUS));
        let (x1, y1) = chart.backend_coord(&(RADIUS, -RADIUS));
        let size = (x1 - x0).min(y1 - y0).max(1) as u32;
        let rgba = self.raster(hemisphere, size);
        canvas.place(
            root,
            (x0, y0),
            Raster {
                width: size,
                height: size,
                rgba,
            },
        )?;

        // Guides: rim, θ rings, φ spokes and labels.
        let circle = |r: f64| -> Vec<(f64, f64)> {
            (0..=240)
                .map(|k| {
                    let a = k as f64 * std::f64::consts::TAU / 240.0;
                    (r * a.cos(), r * a.sin())
                })
                .collect()
        };
        let guide = GUIDE.stroke_width(1);
        for theta in [30.0, 60.0] {
            let r = disk::radius_of(theta);
            plot.draw(&DashedPathElement::new(circle(r), 3, 4, guide))
                .msg()?;
            let a = 100f64.to_radians();
            plot.draw(&Text::new(
                format!("{theta}°"),
                (r * a.cos(), r * a.sin()),
                text(SMALL, &GUIDE, HPos::Right, VPos::Bottom),
            ))
            .msg()?;
        }
        for k in 0..4 {
            let a = k as f64 * std::f64::consts::FRAC_PI_2;
            plot.draw(&DashedPathElement::new(
                vec![(0.0, 0.0), (RADIUS * a.cos(), RADIUS * a.sin())],
                3,
                4,
                guide,
            ))
            .msg()?;
        }
        plot.draw(&PathElement::new(circle(RADIUS), BLACK.stroke_width(1)))
            .msg()?;
        let r = RADIUS * 1.04;
        for (phi, h, v) in [
            (0.0, HPos::Left, VPos::Center),
            (90.0, HPos::Center, VPos::Bottom),
            (180.0, HPos::Right, VPos::Center),
            (270.0, HPos::Center, VPos::Top),
        ] {
            let a = f64::to_radians(phi);
            plot.draw(&Text::new(
                format!("φ {phi}°"),
                (r * a.cos(), r * a.sin()),
                text(TICK, &BLACK, h, v),
            ))
            .msg()?;
        }

        // Selections: θ cap and beam mask.
        if let Some(cap) = self.inc.theta_cap().filter(|c| *c < 90.0) {
            plot.draw(&DashedPathElement::new(
                circle(disk::radius_of(cap)),
                6,
                4,
                BLACK.stroke_width(2),
            ))
            .msg()?;
        }
        let beam = match hemisphere {
            Hemisphere::Front => self.inc.light,
            Hemisphere::Back => -self.inc.light,
        };
        if let Some(mask) = self.inc.beam_mask() {
            for run in disk::cone_outline(self.inc.light, mask, hemisphere) {
                plot.draw(&PathElement::new(run, BLACK.stroke_width(2)))
                    .msg()?;
            }
        }

        // Directions: the light (front) and the mirror / straight-through.
        if hemisphere == Hemisphere::Front && beam.z >= 0.0 {
            let p = disk::project(beam, hemisphere);
            plot.draw(&TriangleMarker::new(p, 7, WHITE.filled()))
                .msg()?;
            plot.draw(&TriangleMarker::new(p, 6, BLACK.filled()))
                .msg()?;
        }
        let (target, name) = match hemisphere {
            Hemisphere::Front => (self.inc.mirror(), "mirror"),
            Hemisphere::Back => (-self.inc.light, "straight through"),
        };
        let p = disk::project(target, hemisphere);
        plot.draw(&Circle::new(p, 7, WHITE.stroke_width(4))).msg()?;
        plot.draw(&Circle::new(p, 7, BLACK.stroke_width(2))).msg()?;
        let (px, py) = chart.backend_coord(&p);
        root.draw(&Text::new(
            name.to_string(),
            (px + 11, py - 11),
            text(SMALL, &BLACK, HPos::Left, VPos::Bottom),
        ))
        .msg()?;
        Ok(())
    }

    fn draw_panel<DB: DrawingBackend>(
        &self,
        root: &Area<DB>,
        area: &Area<DB>,
    ) -> Result<(), String> {
        let (bx, by) = area.get_base_pixel();
        let (x, top) = (bx + 24, by + 62);
        let (w, h) = (26, 300);
        root.draw(&Text::new(
            "model ÷ data".to_string(),
            (x, by + 34),
            text(LABEL, &BLACK, HPos::Left, VPos::Center),
        ))
        .msg()?;
        let steps = 150;
        for i in 0..steps {
            let t = 1.0 - 2.0 * (i as f64 + 0.5) / steps as f64;
            let y0 = top + (i * h) / steps;
            let y1 = top + ((i + 1) * h) / steps;
            root.draw(&Rectangle::new(
                [(x, y0), (x + w, y1)],
                colour::diverging(t).filled(),
            ))
            .msg()?;
        }
        root.draw(&Rectangle::new(
            [(x, top), (x + w, top + h)],
            BLACK.stroke_width(1),
        ))
        .msg()?;
        let k = self.ratio;
        for r in bar_ticks(k) {
            let t = r.ln() / k.ln();
            let y = top + ((1.0 - t) * 0.5 * h as f64).round() as i32;
            root.draw(&PathElement::new(
                vec![(x + w, y), (x + w + 6, y)],
                BLACK.stroke_width(1),
            ))
            .msg()?;
            root.draw(&Text::new(fmt(r), (x + w + 10, y), left(TICK)))
                .msg()?;
        }
        root.draw(&Text::new(
            "model above data".to_string(),
            (x + w + 70, top + 8),
            left(SMALL),
        ))
        .msg()?;
        root.draw(&Text::new(
            "model below data".to_string(),
            (x + w + 70, top + h - 8),
            left(SMALL),
        ))
        .msg()?;

        // Legend: a symbol in front of each entry's text.
        let mut y = top + h + 36;
        let step = 24;
        let entry = |y: i32, label: &str| -> Result<(), String> {
            root.draw(&Text::new(label.to_string(), (x + 32, y), left(SMALL)))
                .msg()
        };
        let swatch = |c: RGBColor, y: i32| -> Result<(), String> {
            root.draw(&Rectangle::new([(x, y - 7), (x + 22, y + 7)], c.filled()))
                .msg()?;
            root.draw(&Rectangle::new(
                [(x, y - 7), (x + 22, y + 7)],
                BLACK.stroke_width(1),
            ))
            .msg()
        };
        swatch(MASKED, y)?;
        entry(y, "not fitted (masked)")?;
        y += step;
        swatch(WHITE, y)?;
        entry(y, "no sample")?;
        y += step;
        root.draw(&TriangleMarker::new((x + 11, y), 6, BLACK.filled()))
            .msg()?;
        entry(y, "light (incident direction)")?;
        y += step;
        root.draw(&Circle::new((x + 11, y), 7, BLACK.stroke_width(2)))
            .msg()?;
        let target = if self.hemispheres().contains(&Hemisphere::Back) {
            "mirror / straight-through direction"
        } else {
            "mirror direction"
        };
        entry(y, target)?;
        // The selections' outlines, solid and dashed as on the disks.
        let outlines = [
            self.inc
                .beam_mask()
                .map(|m| (format!("beam mask ({}°)", crate::prepare::num(m)), None)),
            self.inc
                .theta_cap()
                .filter(|c| *c < 90.0)
                .map(|c| (format!("θ cap ({}°)", crate::prepare::num(c)), Some((6, 4)))),
        ];
        for (label, dashes) in outlines.into_iter().flatten() {
            y += step;
            let ends = vec![(x, y), (x + 22, y)];
            let style = BLACK.stroke_width(2);
            match dashes {
                None => root.draw(&PathElement::new(ends, style)),
                Some((dash, gap)) => root.draw(&DashedPathElement::new(ends, dash, gap, style)),
            }
            .msg()?;
            entry(y, &label)?;
        }

        // Numbers.
        let Stats {
            used,
            median,
            within,
        } = *self.stats.get_or_init(|| Stats::of(self.inc));
        let unit = match &self.inc.unit {
            DataUnit::Bsdf => "1/sr".to_string(),
            DataUnit::RawPerCos(u) => u.clone(),
        };
        let lines = [
            format!("fitted samples: {} of {}", used, self.inc.samples.len()),
            format!(
                "median |model ÷ data − 1|: {:.1} %",
                100.0 * (median.exp() - 1.0)
            ),
            format!(
                "within ±10 %: {:.0} % of the fitted",
                100.0 * within as f64 / used.max(1) as f64
            ),
            format!("RMS relative error: {}", fmt(self.rms_rel)),
            format!("floor added to both: {} {unit}", fmt(self.inc.floor)),
        ];
        y += 40;
        for line in lines {
            root.draw(&Text::new(line, (x, y), left(SMALL))).msg()?;
            y += 21;
        }
        Ok(())
    }
}

/// Ratios labelled on a colour bar that ends at `k` and `1/k`: round
/// numbers, spread out on the log scale, mirrored below 1.
pub(crate) fn bar_ticks(k: f64) -> Vec<f64> {
    const NICE: [f64; 13] = [
        1.05, 1.1, 1.2, 1.5, 2.0, 3.0, 5.0, 10.0, 20.0, 30.0, 50.0, 100.0, 1000.0,
    ];
    let t = |r: f64| r.ln() / k.ln();
    let mut above = vec![k];
    for r in NICE.into_iter().rev().filter(|r| *r < k) {
        let last = *above.last().expect("k is first");
        if t(last) - t(r) >= 0.22 && t(r) >= 0.15 {
            above.push(r);
        }
    }
    let mut ticks: Vec<f64> = above.iter().map(|r| 1.0 / r).collect();
    ticks.push(1.0);
    ticks.extend(above.iter().rev());
    ticks
}

impl Chart for MapChart<'_> {
    fn name(&self) -> String {
        format!("map-{}", self.inc.tag)
    }

    fn size(&self) -> (u32, u32) {
        (DISK * self.hemispheres().len() as u32 + PANEL, DISK + 44)
    }

    fn draw<DB: DrawingBackend>(&self, root: &Area<DB>, canvas: &Canvas) -> Result<(), String> {
        let area = titled(root, &self.title)?;
        let hemispheres = self.hemispheres();
        let (w, h) = area.dim_in_pixel();
        for (i, hemisphere) in hemispheres.iter().enumerate() {
            let sub = area.clone().shrink((DISK * i as u32, 0), (DISK, h));
            self.draw_disk(root, &sub, *hemisphere, canvas)?;
        }
        let used = DISK * hemispheres.len() as u32;
        let panel = area.clone().shrink((used, 0), (w.saturating_sub(used), h));
        self.draw_panel(root, &panel)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colour_bar_ticks_are_round_and_symmetric() {
        assert_eq!(
            bar_ticks(2.0),
            vec![0.5, 1.0 / 1.5, 1.0 / 1.2, 1.0, 1.2, 1.5, 2.0]
        );
        let t = bar_ticks(5.0);
        assert_eq!(t.first(), Some(&0.2));
        assert_eq!(t.last(), Some(&5.0));
        assert_eq!(t, vec![0.2, 1.0 / 3.0, 0.5, 1.0, 2.0, 3.0, 5.0]);
    }
}
