//! Radiance HDR pictures (RGBE, `FORMAT=32-bit_rle_rgbe`).
//!
//! The writer emits flat (uncompressed) scanlines in the standard `-Y H +X W`
//! orientation, which every Radiance tool reads. The reader takes flat
//! and new-style run-length encoded scanlines, so it reads `rpict` output.
//! Pixels are stored row by row from the top.

use std::io::{self, BufRead, Write};

/// Why a picture could not be read.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum HdrError {
    /// Reading failed.
    #[error("cannot read the picture: {0}")]
    Io(#[from] io::Error),
    /// Not a Radiance picture, or an unsupported variant of one.
    #[error("not a Radiance RGBE picture: {0}")]
    Format(String),
}

/// An RGB floating-point picture, rows from the top.
#[derive(Debug, Clone, PartialEq)]
pub struct Picture {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// `width × height` RGB values, row-major from the top-left.
    pub pixels: Vec<[f32; 3]>,
    /// The `EXPOSURE=` factors found in the header (multiplied; 1 if none).
    pub exposure: f64,
}

impl Picture {
    /// Pixel `(i, j)`, `j` from the top.
    pub fn at(&self, i: usize, j: usize) -> [f32; 3] {
        self.pixels[j * self.width + i]
    }
}

/// Encodes one colour as RGBE.
pub fn to_rgbe(c: [f32; 3]) -> [u8; 4] {
    let m = c[0].max(c[1]).max(c[2]);
    if m.is_nan() || m < 1e-32 {
        return [0; 4];
    }
    // m = f · 2^e with f in [0.5, 1).
    let e = m.log2().floor() as i32 + 1;
    let scale = 256.0 / 2f32.powi(e);
    let q = |x: f32| (x.max(0.0) * scale).min(255.0) as u8;
    [q(c[0]), q(c[1]), q(c[2]), (e + 128).clamp(0, 255) as u8]
}

/// Decodes RGBE (pixel centre of the quantisation bin, as Radiance does).
pub fn from_rgbe(p: [u8; 4]) -> [f32; 3] {
    if p[3] == 0 {
        return [0.0; 3];
    }
    let f = 2f32.powi(p[3] as i32 - (128 + 8));
    [
        (p[0] as f32 + 0.5) * f,
        (p[1] as f32 + 0.5) * f,
        (p[2] as f32 + 0.5) * f,
    ]
}

/// Writes a picture with optional extra header lines (e.g. `VIEW= ...`).
pub fn write(out: &mut impl Write, picture: &Picture, header: &[String]) -> io::Result<()> {
    let mut buf = Vec::with_capacity(picture.pixels.len() * 4 + 256);
    buf.extend_from_slice(b"#?RADIANCE\n");
    for line in header {
        buf.extend_from_slice(line.as_bytes());
        buf.push(b'\n');
    }
    buf.extend_from_slice(b"FORMAT=32-bit_rle_rgbe\n\n");
    buf.extend_from_slice(format!("-Y {} +X {}\n", picture.height, picture.width).as_bytes());
    for p in &picture.pixels {
        buf.extend_from_slice(&to_rgbe(*p));
    }
    out.write_all(&buf)
}

/// Reads a Radiance picture (`-Y H +X W` orientation only).
pub fn read(input: &mut impl BufRead) -> Result<Picture, HdrError> {
    let mut exposure = 1.0;
    let mut first = true;
    loop {
        let mut line = String::new();
        if input.read_line(&mut line)? == 0 {
            return Err(HdrError::Format("header without an end".into()));
        }
        let line = line.trim_end_matches(['\n', '\r']);
        if first && !line.starts_with("#?") {
            return Err(HdrError::Format("no `#?` magic line".into()));
        }
        first = false;
        if line.is_empty() {
            break;
        }
        if let Some(v) = line.strip_prefix("EXPOSURE=") {
            exposure *= v.trim().parse::<f64>().unwrap_or(1.0);
        }
        if let Some(f) = line.strip_prefix("FORMAT=")
            && f.trim() != "32-bit_rle_rgbe"
        {
            return Err(HdrError::Format(format!("unsupported format {f}")));
        }
    }
    let mut res = String::new();
    input.read_line(&mut res)?;
    let parts: Vec<&str> = res.split_whitespace().collect();
    let (height, width) = match parts.as_slice() {
        ["-Y", h, "+X", w] => (
            h.parse::<usize>()
                .map_err(|_| HdrError::Format(res.clone()))?,
            w.parse::<usize>()
                .map_err(|_| HdrError::Format(res.clone()))?,
        ),
        _ => {
            return Err(HdrError::Format(format!(
                "unsupported resolution line `{}`",
                res.trim()
            )));
        }
    };
    let mut data = Vec::new();
    input.read_to_end(&mut data)?;
    let mut pixels = Vec::with_capacity(width * height);
    let mut pos = 0usize;
    let short = || HdrError::Format("picture data ends early".into());
    let mut scan = vec![[0u8; 4]; width];
    for _ in 0..height {
        let rle = (8..32768).contains(&width)
            && data.len() >= pos + 4
            && data[pos] == 2
            && data[pos + 1] == 2
            && data[pos + 2] & 0x80 == 0;
        if rle {
            let w = ((data[pos + 2] as usize) << 8) | data[pos + 3] as usize;
            if w != width {
                return Err(HdrError::Format("scanline length mismatch".into()));
            }
            pos += 4;
            for c in 0..4 {
                let mut i = 0;
                while i < width {
                    let count = *data.get(pos).ok_or_else(short)? as usize;
                    pos += 1;
                    if count > 128 {
                        let run = count - 128;
                        let v = *data.get(pos).ok_or_else(short)?;
                        pos += 1;
                        if i + run > width {
                            return Err(HdrError::Format("run overflows scanline".into()));
                        }
                        for px in &mut scan[i..i + run] {
                            px[c] = v;
                        }
                        i += run;
                    } else {
                        if count == 0 || i + count > width {
                            return Err(HdrError::Format("bad run count".into()));
                        }
                        let src = data.get(pos..pos + count).ok_or_else(short)?;
                        for (px, &v) in scan[i..i + count].iter_mut().zip(src) {
                            px[c] = v;
                        }
                        pos += count;
                        i += count;
                    }
                }
            }
        } else {
            // Flat scanline (old-style run-length pixels are not supported).
            for px in scan.iter_mut() {
                let src = data.get(pos..pos + 4).ok_or_else(short)?;
                px.copy_from_slice(src);
                pos += 4;
            }
        }
        pixels.extend(scan.iter().map(|p| from_rgbe(*p)));
    }
    Ok(Picture {
        width,
        height,
        pixels,
        exposure,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rgbe_round_trip_is_within_quantisation() {
        for c in [[1.0f32, 0.5, 0.25], [1e-3, 2e-3, 0.0], [123.0, 45.0, 6.0]] {
            let d = from_rgbe(to_rgbe(c));
            let m = c[0].max(c[1]).max(c[2]);
            for k in 0..3 {
                assert!((d[k] - c[k]).abs() <= m / 128.0, "{c:?} -> {d:?}");
            }
        }
        assert_eq!(from_rgbe(to_rgbe([0.0; 3])), [0.0; 3]);
    }

    #[test]
    fn write_then_read() {
        let pic = Picture {
            width: 3,
            height: 2,
            pixels: vec![[1.0, 2.0, 3.0]; 6],
            exposure: 1.0,
        };
        let mut buf = Vec::new();
        write(&mut buf, &pic, &["SOFTWARE= brtf".into()]).unwrap();
        let back = read(&mut &buf[..]).unwrap();
        assert_eq!((back.width, back.height), (3, 2));
        assert!((back.pixels[5][2] - 3.0).abs() < 3.0 / 128.0);
    }

    #[test]
    fn reads_run_length_encoded_scanlines() {
        // One 8-pixel scanline: a run of 8 for each component.
        let mut data = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 8\n".to_vec();
        data.extend_from_slice(&[2, 2, 0, 8]);
        for v in [128u8, 64, 32, 129] {
            data.extend_from_slice(&[128 + 8, v]);
        }
        let pic = read(&mut &data[..]).unwrap();
        assert_eq!(pic.pixels.len(), 8);
        let expect = from_rgbe([128, 64, 32, 129]);
        assert_eq!(pic.pixels[7], expect);
    }
}
