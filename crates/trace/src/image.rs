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
use crate::direct::DirectRows;
use crate::hdr::Picture;
use crate::integrator::{ImageOptions, RayCounts, Tracer};
use crate::scene::Scene;
use brtf_model::Rng;

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
    // Direct light only: whole rows through the vectorised pipeline.
    let direct_rows = tracer.direct_batch_applies();
    let (w, h) = (options.width, options.height);
    let n = options.samples.max(1);
    let mut pixels = vec![[0.0f32; 3]; w * h];
    let rays = pixels
        .par_chunks_mut(w.max(1))
        .enumerate()
        // One set of row buffers per worker, reused row after row.
        .map_init(DirectRows::default, |direct, (j, row)| {
            let mut counts = RayCounts::default();
            if direct_rows {
                direct.row(&tracer, camera, options, j, &mut counts, row);
                return counts;
            }
            for (i, pixel) in row.iter_mut().enumerate() {
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
                *pixel = sum.map(|s| (s / n as f64) as f32);
            }
            counts
        })
        .reduce(RayCounts::default, |mut a, b| {
            a.add(&b);
            a
        });
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

/// Luminance-like brightness of an RGB value (Radiance's `bright()`).
pub(crate) fn brightness(c: [f32; 3]) -> f64 {
    brtf_model::luminance(c.map(f64::from))
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
pub(crate) fn tone_map(picture: &Picture, exposure: f64) -> Vec<u8> {
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
