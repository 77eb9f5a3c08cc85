//! Rendering one chart to SVG and PNG, with the embedded font, and writing
//! files atomically.
//!
//! This module owns the plotters backends. A [`Chart`] draws itself on any
//! backend; [`write_chart`] renders it twice (SVG text, PNG pixels) and
//! writes `<name>.svg` and `<name>.png`.
//!
//! * **Fonts.** plotters is built without its system-font feature: the
//!   DejaVu Sans faces embedded by the `dejavu` crate are registered for the
//!   `sans-serif` family before anything is drawn ([`register_fonts`]), so
//!   charts render on a machine without fontconfig or any font installed.
//!   SVG files keep text as `<text>` elements for the viewer's own fonts.
//! * **Rasters.** Dense images (the residual maps) are copied into the
//!   PNG's pixel buffer in one go (one plotters call, not one per pixel),
//!   and embedded once as a base64 PNG `<image>` into SVGs (an SVG
//!   rectangle per pixel would be megabytes): the chart draws a
//!   placeholder rectangle in a reserved colour, which is then replaced.

use crate::error::PlotError;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The font family every chart uses.
pub(crate) const FONT: &str = "sans-serif";

/// A region of a chart's backend, in pixels: the whole chart or a part.
pub(crate) type Area<DB> = DrawingArea<DB, Shift>;

/// Registers the embedded DejaVu Sans faces (once per process).
pub(crate) fn register_fonts() {
    static DONE: OnceLock<()> = OnceLock::new();
    DONE.get_or_init(|| {
        // Both faces are valid TrueType files shipped inside the binary.
        let _ = plotters::style::register_font(FONT, FontStyle::Normal, dejavu::sans::regular());
        let _ = plotters::style::register_font(FONT, FontStyle::Bold, dejavu::sans::bold());
    });
}

/// Which backend a chart is being drawn on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// SVG text.
    Svg,
    /// PNG pixels.
    Png,
}

/// An RGBA image to place on a chart.
#[derive(Debug, Clone)]
pub struct Raster {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Row-major RGBA bytes; alpha 0 leaves the chart visible.
    pub rgba: Vec<u8>,
}

/// A raster waiting to replace its placeholder: id, upper-left pixel, image.
type Pending = (u8, (i32, i32), Raster);

/// Drawing context: the backend kind and the rasters waiting to be
/// embedded into an SVG.
pub struct Canvas {
    mode: Mode,
    pending: RefCell<Vec<Pending>>,
}

/// Turns any displayable error into the message [`PlotError::Draw`] carries.
pub(crate) trait OrMsg<T> {
    /// The error's text.
    fn msg(self) -> Result<T, String>;
}

impl<T, E: std::fmt::Display> OrMsg<T> for Result<T, E> {
    fn msg(self) -> Result<T, String> {
        self.map_err(|e| e.to_string())
    }
}

impl Canvas {
    /// The backend kind.
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// Draws `raster` with its upper-left corner at backend pixel
    /// `upper_left` (on the root area). Draw it before anything else in
    /// its rectangle: it is blended with white, not with what is there.
    pub fn place<DB: DrawingBackend>(
        &self,
        root: &Area<DB>,
        upper_left: (i32, i32),
        raster: Raster,
    ) -> Result<(), String> {
        match self.mode {
            Mode::Png => {
                // One copy into the pixel buffer (not a plotters call per
                // pixel). The area under a raster is still the white of
                // the background, so transparent pixels become white.
                let mut rgb = Vec::with_capacity(raster.rgba.len() / 4 * 3);
                for px in raster.rgba.chunks_exact(4) {
                    match px[3] {
                        // Opaque and transparent pixels (all a map has),
                        // without the arithmetic: the same bytes.
                        255 => rgb.extend_from_slice(&px[..3]),
                        0 => rgb.extend_from_slice(&[255; 3]),
                        a => {
                            let a = u32::from(a);
                            for &c in &px[..3] {
                                rgb.push(((u32::from(c) * a + 255 * (255 - a) + 127) / 255) as u8);
                            }
                        }
                    }
                }
                let image = BitMapElement::with_owned_buffer(
                    upper_left,
                    (raster.width, raster.height),
                    rgb,
                )
                .ok_or("raster size does not match its pixels")?;
                root.draw(&image).msg()
            }
            Mode::Svg => {
                let mut pending = self.pending.borrow_mut();
                let id = u8::try_from(pending.len() + 1).map_err(|_| "too many rasters")?;
                let (w, h) = (raster.width as i32, raster.height as i32);
                root.draw(&Rectangle::new(
                    [upper_left, (upper_left.0 + w, upper_left.1 + h)],
                    placeholder(id).filled(),
                ))
                .msg()?;
                pending.push((id, upper_left, raster));
                Ok(())
            }
        }
    }
}

/// The reserved colour of raster placeholder `id`.
fn placeholder(id: u8) -> RGBColor {
    RGBColor(1, 2, id)
}

/// A chart that draws itself on any plotters backend.
pub trait Chart: Sync {
    /// File stem (`map-t30`, `params`, ...).
    fn name(&self) -> String;
    /// Size in pixels (the SVG's view box); landscape unless the chart's
    /// content asks for another shape.
    fn size(&self) -> (u32, u32) {
        (1000, 640)
    }
    /// Draws on `root`, already filled white.
    fn draw<DB: DrawingBackend>(&self, root: &Area<DB>, canvas: &Canvas) -> Result<(), String>;
}

fn draw_error(chart: &impl Chart, message: String) -> PlotError {
    PlotError::Draw {
        name: chart.name(),
        message,
    }
}

/// Renders `chart` as SVG text.
pub fn render_svg(chart: &impl Chart) -> Result<String, PlotError> {
    register_fonts();
    let canvas = Canvas {
        mode: Mode::Svg,
        pending: RefCell::new(Vec::new()),
    };
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, chart.size()).into_drawing_area();
        root.fill(&WHITE)
            .msg()
            .and_then(|_| chart.draw(&root, &canvas))
            .and_then(|_| root.present().msg())
            .map_err(|m| draw_error(chart, m))?;
    }
    for (id, (x, y), raster) in canvas.pending.into_inner() {
        let image = format!(
            r#"<image x="{x}" y="{y}" width="{}" height="{}" preserveAspectRatio="none" href="data:image/png;base64,{}"/>"#,
            raster.width,
            raster.height,
            base64(
                &encode_png(
                    raster.width,
                    raster.height,
                    png::ColorType::Rgba,
                    &raster.rgba
                )
                .map_err(|m| draw_error(chart, m))?
            )
        );
        let marker = format!(
            "fill=\"#{:02X}{:02X}{:02X}\"",
            placeholder(id).0,
            placeholder(id).1,
            placeholder(id).2
        );
        let at = text
            .find(&marker)
            .ok_or_else(|| draw_error(chart, "raster placeholder not found".into()))?;
        let start = text[..at]
            .rfind("<rect")
            .ok_or_else(|| draw_error(chart, "raster placeholder not found".into()))?;
        let end = at + text[at..].find("/>").unwrap_or(0) + 2;
        text.replace_range(start..end, &image);
    }
    Ok(text)
}

/// Renders `chart` as PNG bytes.
pub fn render_png(chart: &impl Chart) -> Result<Vec<u8>, PlotError> {
    register_fonts();
    let (w, h) = chart.size();
    // The thread's pixel buffer of the last chart, reused: a fresh one of a
    // few MB is faulted in page by page, which cost more than the drawing.
    let mut pixels = PIXELS.with(|p| std::mem::take(&mut *p.borrow_mut()));
    pixels.clear();
    pixels.resize((w * h * 3) as usize, 255);
    let canvas = Canvas {
        mode: Mode::Png,
        pending: RefCell::new(Vec::new()),
    };
    let drawn = {
        let root = BitMapBackend::with_buffer(&mut pixels, (w, h)).into_drawing_area();
        root.fill(&WHITE)
            .msg()
            .and_then(|_| chart.draw(&root, &canvas))
            .and_then(|_| root.present().msg())
            .map_err(|m| draw_error(chart, m))
    };
    let encoded = drawn.and_then(|()| {
        encode_png(w, h, png::ColorType::Rgb, &pixels).map_err(|m| draw_error(chart, m))
    });
    PIXELS.with(|p| {
        let mut kept = p.borrow_mut();
        if pixels.capacity() > kept.capacity() {
            *kept = pixels;
        }
    });
    encoded
}

thread_local! {
    /// The pixel buffer [`render_png`] reuses on this thread (the largest
    /// so far, at most a chart's: a few MB per thread).
    static PIXELS: RefCell<Vec<u8>> = const { RefCell::new(Vec::new()) };
}

/// Encodes 8-bit pixels as PNG.
pub(crate) fn encode_png(
    w: u32,
    h: u32,
    colour: png::ColorType,
    data: &[u8],
) -> Result<Vec<u8>, String> {
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, w, h);
    encoder.set_color(colour);
    encoder.set_depth(png::BitDepth::Eight);
    // Fast: fdeflate. The Paeth filter on every row: on the charts of a
    // 127k-point scan, within 6% of the adaptive filter's size (which
    // tries all five per row) in 55-75% of its time; Up or Sub alone are
    // a little faster but make PNGs up to twice as large.
    encoder.set_compression(png::Compression::Fast);
    encoder.set_filter(png::Filter::Paeth);
    let mut writer = encoder.write_header().msg()?;
    writer.write_image_data(data).msg()?;
    writer.finish().msg()?;
    Ok(out)
}

/// Standard base64 with padding.
pub(crate) fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[((n >> (18 - 6 * k)) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// Writes `bytes` to `path` atomically (see [`brtf_io::write_atomic`]).
/// Creates the folder when missing.
pub(crate) fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), PlotError> {
    let folder = path.parent().filter(|p| !p.as_os_str().is_empty());
    folder
        .map_or(Ok(()), brtf_io::ensure_folder)
        .and_then(|()| brtf_io::write_atomic(path, bytes))
        .map_err(|e| PlotError::Io {
            path: e.path,
            what: e.what,
            source: e.source,
        })
}

/// Renders `chart` as `<dir>/<name>.svg` and `<dir>/<name>.png`: each
/// path with its bytes, not yet written.
pub(crate) fn render_files(
    chart: &impl Chart,
    dir: &Path,
) -> Result<Vec<(PathBuf, Vec<u8>)>, PlotError> {
    let (svg, png) = rayon::join(|| render_svg(chart), || render_png(chart));
    Ok(vec![
        (dir.join(format!("{}.svg", chart.name())), svg?.into_bytes()),
        (dir.join(format!("{}.png", chart.name())), png?),
    ])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A filled square on white, `size` pixels wide.
    struct Square {
        size: (u32, u32),
        colour: RGBColor,
    }

    impl Chart for Square {
        fn name(&self) -> String {
            "square".into()
        }
        fn size(&self) -> (u32, u32) {
            self.size
        }
        fn draw<DB: DrawingBackend>(&self, root: &Area<DB>, _: &Canvas) -> Result<(), String> {
            root.draw(&Rectangle::new([(10, 10), (40, 30)], self.colour.filled()))
                .msg()
        }
    }

    #[test]
    fn a_reused_pixel_buffer_draws_what_a_fresh_one_draws() {
        let small = Square {
            size: (60, 50),
            colour: RGBColor(200, 30, 10),
        };
        let fresh = std::thread::spawn(|| {
            render_png(&Square {
                size: (60, 50),
                colour: RGBColor(200, 30, 10),
            })
            .unwrap()
        })
        .join()
        .unwrap();
        // A larger chart of another colour first leaves its pixels in the
        // thread's buffer.
        let large = Square {
            size: (300, 200),
            colour: RGBColor(0, 0, 250),
        };
        render_png(&large).unwrap();
        let reused = render_png(&small).unwrap();
        assert_eq!(reused, fresh);
        let decoder = png::Decoder::new(std::io::Cursor::new(reused));
        let mut reader = decoder.read_info().unwrap();
        let mut pixels = vec![0; reader.output_buffer_size().unwrap()];
        reader.next_frame(&mut pixels).unwrap();
        let at = |x: usize, y: usize| &pixels[(y * 60 + x) * 3..(y * 60 + x) * 3 + 3];
        assert_eq!(at(20, 20), &[200, 30, 10]);
        assert_eq!(at(50, 40), &[255, 255, 255]);
    }

    #[test]
    fn base64_matches_the_rfc_examples() {
        assert_eq!(base64(b""), "");
        assert_eq!(base64(b"f"), "Zg==");
        assert_eq!(base64(b"fo"), "Zm8=");
        assert_eq!(base64(b"foo"), "Zm9v");
        assert_eq!(base64(b"foobar"), "Zm9vYmFy");
    }
}
