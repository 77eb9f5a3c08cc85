//! Rendering pictures: one camera ray stream per pixel, in parallel over
//! rows with rayon, each pixel seeded from `(seed, pixel index)` so the
//! picture is the same on any number of threads.
//!
//! Output: Radiance HDR ([`crate::hdr`]) for the numbers and a tone-mapped
//! 8-bit sRGB PNG for the eye.

use brtf_model::Rgb;
use rayon::prelude::*;
use std::io::Write;
use std::time::{Duration, Instant};

use crate::camera::Camera;
use crate::hdr::Picture;
use crate::integrator::{DirectBatch, RayCounts, Settings, Tracer};
use crate::rng::Rng;
use crate::scene::Scene;

/// How to render a picture.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImageOptions {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Camera rays per pixel.
    pub samples: u32,
    /// Jitter the rays inside each pixel (else: pixel centres, like
    /// `rpict -pj 0`; then all samples share the centre).
    pub jitter: bool,
    /// Random seed.
    pub seed: u64,
    /// Sample counts of the integrator.
    pub settings: Settings,
}

impl Default for ImageOptions {
    fn default() -> Self {
        ImageOptions {
            width: 320,
            height: 240,
            samples: 16,
            jitter: true,
            seed: 1,
            settings: Settings::default(),
        }
    }
}

/// A rendered picture and what it cost.
#[derive(Debug, Clone)]
pub struct Rendered {
    /// The picture (radiance per pixel).
    pub picture: Picture,
    /// Rays traced.
    pub rays: RayCounts,
    /// Wall time.
    pub elapsed: Duration,
}

/// Renders `scene` through `camera`.
pub fn render(scene: &Scene, camera: &Camera, options: &ImageOptions) -> Rendered {
    let start = Instant::now();
    let tracer = Tracer::new(scene, options.settings);
    // Direct light only: a row's BSDF values in one vectorised batch.
    let direct_batch = tracer.direct_batch_applies();
    let (w, h) = (options.width, options.height);
    let n = options.samples.max(1);
    let rows: Vec<(Vec<[f32; 3]>, RayCounts)> = (0..h)
        .into_par_iter()
        // One batch buffer per worker, reused row after row.
        .map_init(DirectRow::default, |direct, j| {
            let mut counts = RayCounts::default();
            if direct_batch {
                return (direct.row(&tracer, camera, options, j, &mut counts), counts);
            }
            let row = (0..w)
                .map(|i| {
                    let mut rng = Rng::new(options.seed, (j * w + i) as u64);
                    let mut sum: Rgb = [0.0; 3];
                    for _ in 0..n {
                        let (du, dv) = if options.jitter {
                            (rng.uniform(), rng.uniform())
                        } else {
                            (0.5, 0.5)
                        };
                        let ray = camera.pixel_ray(i, j, w, h, du, dv);
                        let l = tracer.radiance(&ray, &mut rng, &mut counts);
                        for k in 0..3 {
                            sum[k] += l[k];
                        }
                    }
                    sum.map(|s| (s / n as f64) as f32)
                })
                .collect();
            (row, counts)
        })
        .collect();
    let mut rays = RayCounts::default();
    let mut pixels = Vec::with_capacity(w * h);
    for (row, counts) in rows {
        pixels.extend(row);
        rays.add(&counts);
    }
    Rendered {
        picture: Picture {
            width: w,
            height: h,
            pixels,
            exposure: 1.0,
        },
        rays,
        elapsed: start.elapsed(),
    }
}

/// The buffers of [`DirectRow::row`], kept between rows.
#[derive(Debug, Default)]
struct DirectRow {
    batch: Option<DirectBatch>,
    radiance: Vec<Rgb>,
}

impl DirectRow {
    /// Row `j` when the picture is direct light only: every camera ray of
    /// the row is traced and its source samples queued, then their BSDF
    /// values come from one batch evaluation and the shadow rays follow.
    /// Draws the same random numbers in the same order as the per-ray loop.
    fn row(
        &mut self,
        tracer: &Tracer,
        camera: &Camera,
        options: &ImageOptions,
        j: usize,
        counts: &mut RayCounts,
    ) -> Vec<[f32; 3]> {
        let (w, h) = (options.width, options.height);
        let n = options.samples.max(1) as usize;
        let batch = self.batch.get_or_insert_with(|| tracer.direct_batch());
        let radiance = &mut self.radiance;
        radiance.clear();
        radiance.resize(w * n, [0.0; 3]);
        for i in 0..w {
            let mut rng = Rng::new(options.seed, (j * w + i) as u64);
            for s in 0..n {
                let (du, dv) = if options.jitter {
                    (rng.uniform(), rng.uniform())
                } else {
                    (0.5, 0.5)
                };
                let ray = camera.pixel_ray(i, j, w, h, du, dv);
                let slot = i * n + s;
                radiance[slot] = tracer.direct_start(&ray, slot, &mut rng, counts, batch);
            }
        }
        tracer.direct_finish(batch, radiance, counts);
        radiance
            .chunks_exact(n)
            .map(|samples| {
                let mut sum: Rgb = [0.0; 3];
                for l in samples {
                    for k in 0..3 {
                        sum[k] += l[k];
                    }
                }
                sum.map(|s| (s / n as f64) as f32)
            })
            .collect()
    }
}

/// Luminance-like brightness of an RGB value (Radiance's `bright()`).
pub fn brightness(c: [f32; 3]) -> f64 {
    brtf_model::colour::luminance(c.map(f64::from))
}

/// The exposure that maps the 97th percentile of the non-zero pixel
/// brightness to 0.9 (so highlights may clip a little).
pub fn auto_exposure(picture: &Picture) -> f64 {
    let mut b: Vec<f64> = picture
        .pixels
        .iter()
        .map(|&p| brightness(p))
        .filter(|&x| x > 0.0 && x.is_finite())
        .collect();
    if b.is_empty() {
        return 1.0;
    }
    b.sort_by(f64::total_cmp);
    let p = b[((b.len() - 1) as f64 * 0.97) as usize];
    0.9 / p
}

/// sRGB transfer function of a linear value in [0, 1].
fn srgb(x: f64) -> f64 {
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// Tone-maps to 8-bit sRGB: multiply by `exposure`, clip, sRGB gamma.
pub fn tone_map(picture: &Picture, exposure: f64) -> Vec<u8> {
    let mut out = Vec::with_capacity(picture.pixels.len() * 3);
    for p in &picture.pixels {
        for &c in p {
            let x = (c as f64 * exposure).clamp(0.0, 1.0);
            out.push((srgb(x) * 255.0 + 0.5) as u8);
        }
    }
    out
}

/// Writes a tone-mapped 8-bit RGB PNG.
pub fn write_png(
    out: impl Write,
    picture: &Picture,
    exposure: f64,
) -> Result<(), png::EncodingError> {
    let mut encoder = png::Encoder::new(out, picture.width as u32, picture.height as u32);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    let mut writer = encoder.write_header()?;
    writer.write_image_data(&tone_map(picture, exposure))?;
    writer.finish()
}
