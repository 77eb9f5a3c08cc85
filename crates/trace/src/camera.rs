//! A pinhole camera with Radiance's perspective view parameters
//! (`-vtv -vp -vd -vu -vh -vv`), so that an image from brtf-trace and one
//! from `rpict` with the same view line up pixel for pixel.
//!
//! As in Radiance's `setview`/`viewray`: `h = normalize(vd × vu)·2 tan(vh/2)`,
//! `w = normalize(h × vd)·2 tan(vv/2)`, and the ray through image
//! coordinates `(x, y) ∈ [0,1]²` (x to the right, y up) has direction
//! `vd + (x − ½) h + (y − ½) w`. Pixel `(i, j)` with `j` counted from the
//! top (Radiance's `-Y H +X W` scanline order) has its centre at
//! `x = (i + ½)/W`, `y = 1 − (j + ½)/H`.

use glam::DVec3;

use crate::scene::Ray;

/// A perspective pinhole camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Eye point (`-vp`).
    pub position: DVec3,
    /// Unit view direction (`-vd`).
    pub dir: DVec3,
    /// Horizontal image-plane vector, length `2 tan(vh/2)`.
    h: DVec3,
    /// Vertical image-plane vector, length `2 tan(vv/2)`.
    w: DVec3,
    /// The up vector as given (`-vu`).
    pub up: DVec3,
    /// Full horizontal angle in degrees (`-vh`).
    pub vh_deg: f64,
    /// Full vertical angle in degrees (`-vv`).
    pub vv_deg: f64,
}

impl Camera {
    /// A camera from Radiance's view parameters (angles in degrees).
    pub fn new(position: DVec3, dir: DVec3, up: DVec3, vh_deg: f64, vv_deg: f64) -> Camera {
        let dir = dir.normalize();
        let h = dir.cross(up).normalize() * 2.0 * (0.5 * vh_deg.to_radians()).tan();
        let w = h.cross(dir).normalize() * 2.0 * (0.5 * vv_deg.to_radians()).tan();
        Camera {
            position,
            dir,
            h,
            w,
            up,
            vh_deg,
            vv_deg,
        }
    }

    /// A camera at `position` looking at `target`, with the vertical angle
    /// chosen for the image's aspect ratio `width/height`.
    pub fn look_at(position: DVec3, target: DVec3, vh_deg: f64, aspect: f64) -> Camera {
        let half_v = ((0.5 * vh_deg.to_radians()).tan() / aspect).atan();
        Camera::new(
            position,
            target - position,
            DVec3::Z,
            vh_deg,
            2.0 * half_v.to_degrees(),
        )
    }

    /// The ray through image coordinates `(x, y)` (x right, y up, in [0, 1]).
    #[inline]
    pub fn ray(&self, x: f64, y: f64) -> Ray {
        let d = self.dir + self.h * (x - 0.5) + self.w * (y - 0.5);
        Ray {
            origin: self.position,
            dir: d.normalize(),
        }
    }

    /// The ray through pixel `(i, j)` (row `j` from the top) of a `W × H`
    /// image, offset by `(du, dv)` ∈ [0,1)² inside the pixel (½, ½ = centre).
    #[inline]
    pub fn pixel_ray(
        &self,
        i: usize,
        j: usize,
        width: usize,
        height: usize,
        du: f64,
        dv: f64,
    ) -> Ray {
        let x = (i as f64 + du) / width as f64;
        let y = 1.0 - (j as f64 + dv) / height as f64;
        self.ray(x, y)
    }

    /// The Radiance view options for `rpict -vf` (one line).
    pub fn view_options(&self) -> String {
        let p = self.position;
        let d = self.dir;
        let u = self.up;
        format!(
            "rview -vtv -vp {} {} {} -vd {} {} {} -vu {} {} {} -vh {} -vv {} -vo 0 -va 0 -vs 0 -vl 0",
            p.x, p.y, p.z, d.x, d.y, d.z, u.x, u.y, u.z, self.vh_deg, self.vv_deg
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_ray_is_the_view_direction_and_corners_span_the_angles() {
        let c = Camera::new(DVec3::ZERO, DVec3::Y, DVec3::Z, 60.0, 40.0);
        assert!((c.ray(0.5, 0.5).dir - DVec3::Y).length() < 1e-12);
        let right = c.ray(1.0, 0.5).dir;
        assert!((right.x.atan2(right.y).to_degrees() - 30.0).abs() < 1e-9);
        let top = c.ray(0.5, 1.0).dir;
        assert!((top.z.atan2(top.y).to_degrees() - 20.0).abs() < 1e-9);
        // Top-left pixel looks left and up.
        let r = c.pixel_ray(0, 0, 10, 10, 0.5, 0.5).dir;
        assert!(r.x < 0.0 && r.z > 0.0);
    }
}
