//! Orthonormal frames: world ↔ local (shading) coordinates.
//!
//! The shading frame has z along the surface normal on the viewer's side,
//! as every brtf-model function expects. For the anisotropic types its x
//! axis is the material's orientation vector projected into the tangent
//! plane (Radiance's `û`).

use glam::DVec3;

/// Three orthonormal axes, right- or left-handed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Local x (tangent).
    pub x: DVec3,
    /// Local y (tangent).
    pub y: DVec3,
    /// Local z (normal).
    pub z: DVec3,
}

impl Frame {
    /// The world frame.
    pub const WORLD: Frame = Frame {
        x: DVec3::X,
        y: DVec3::Y,
        z: DVec3::Z,
    };

    /// Any frame with `z` (unit) as its third axis, without branches on
    /// the direction (Duff et al., "Building an Orthonormal Basis, Revisited", 2017).
    #[inline]
    pub fn from_z(z: DVec3) -> Frame {
        debug_assert!((z.length() - 1.0).abs() < 1e-9, "frame axis is not unit");
        let sign = 1f64.copysign(z.z);
        let a = -1.0 / (sign + z.z);
        let b = z.x * z.y * a;
        let x = DVec3::new(1.0 + sign * z.x * z.x * a, sign * b, -sign * z.x);
        let y = DVec3::new(b, sign + z.y * z.y * a, -z.y);
        Frame { x, y, z }
    }

    /// The frame with normal `z` (unit) whose x axis is `u` projected into
    /// the tangent plane, or `None` when `u` is (nearly) along `z`.
    pub fn from_z_and_x(z: DVec3, u: DVec3) -> Option<Frame> {
        let t = u - z * z.dot(u);
        let len2 = t.length_squared();
        if len2 <= 1e-12 * u.length_squared() {
            return None;
        }
        let x = t / len2.sqrt();
        Some(Frame {
            x,
            y: z.cross(x),
            z,
        })
    }

    /// The same frame with z (and so the handedness) flipped: the view
    /// from the other side of the surface, as brtf-model's two-sided
    /// materials see it.
    pub fn flipped(&self) -> Frame {
        Frame {
            x: self.x,
            y: self.y,
            z: -self.z,
        }
    }

    /// World direction → local coordinates.
    #[inline]
    pub fn to_local(&self, d: DVec3) -> DVec3 {
        DVec3::new(d.dot(self.x), d.dot(self.y), d.dot(self.z))
    }

    /// Local coordinates → world direction.
    #[inline]
    pub fn to_world(&self, d: DVec3) -> DVec3 {
        self.x * d.x + self.y * d.y + self.z * d.z
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_orthonormal_and_round_trip() {
        for z in [
            DVec3::Z,
            -DVec3::Z,
            DVec3::new(0.3, -0.4, 0.5).normalize(),
            DVec3::new(-1e-9, 0.0, -1.0).normalize(),
        ] {
            let f = Frame::from_z(z);
            for (a, b) in [(f.x, f.y), (f.y, f.z), (f.x, f.z)] {
                assert!(a.dot(b).abs() < 1e-12);
            }
            for a in [f.x, f.y, f.z] {
                assert!((a.length() - 1.0).abs() < 1e-12);
            }
            let d = DVec3::new(0.1, 0.7, -0.2).normalize();
            assert!((f.to_world(f.to_local(d)) - d).length() < 1e-12);
        }
    }

    #[test]
    fn tangent_frame_follows_the_orientation() {
        let f = Frame::from_z_and_x(DVec3::Z, DVec3::new(1.0, 1.0, 3.0)).unwrap();
        assert!((f.x - DVec3::new(1.0, 1.0, 0.0).normalize()).length() < 1e-12);
        assert!(Frame::from_z_and_x(DVec3::Z, DVec3::Z * 2.0).is_none());
    }
}
