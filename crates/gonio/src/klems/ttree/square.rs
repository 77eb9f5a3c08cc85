//! The Shirley–Chiu map between the unit square and the unit disk, and
//! between the disk and a hemisphere, as Radiance's tensor trees use them.
//!
//! A point (x, y) of [0, 1)² goes to a = 2x − 1, b = 2y − 1, and then to
//! the disk by concentric squares → concentric circles: the four
//! triangles between the diagonals map to the four quarters around
//! φ = 0, 90°, 180°, 270°. The map keeps areas (up to the factor π), so a
//! square cell of side s covers π s² of the disk. A disk point (d_x, d_y)
//! is the direction (d_x, d_y, ±√(1 − d²)): θ = asin |d|. The disk's area
//! is projected solid angle, so a cell of side s has Λ = π s² and points
//! uniform in the cell are uniform in projected solid angle.

use std::f64::consts::{FRAC_PI_4, PI};

/// The disk point of square point (x, y) (both in [0, 1]).
pub fn square_to_disk(x: f64, y: f64) -> [f64; 2] {
    let a = 2.0 * x - 1.0;
    let b = 2.0 * y - 1.0;
    let (r, phi) = if a + b > 0.0 {
        if a - b > 0.0 {
            (a, FRAC_PI_4 * (b / a))
        } else {
            (b, FRAC_PI_4 * (2.0 - a / b))
        }
    } else if b - a > 0.0 {
        (-a, FRAC_PI_4 * (4.0 + b / a))
    } else if b != 0.0 {
        (-b, FRAC_PI_4 * (6.0 - a / b))
    } else {
        (0.0, 0.0)
    };
    [r * phi.cos(), r * phi.sin()]
}

/// The square point of disk point (d_x, d_y) (|d| ≤ 1): the inverse of
/// [`square_to_disk`].
pub fn disk_to_square(dx: f64, dy: f64) -> [f64; 2] {
    let r = (dx * dx + dy * dy).sqrt();
    let mut phi = dy.atan2(dx);
    if phi < -FRAC_PI_4 {
        phi += 2.0 * PI;
    }
    let (a, b) = match ((phi + FRAC_PI_4) / (PI / 2.0)).floor() as i32 {
        0 => (r, phi * r / FRAC_PI_4),
        1 => ((PI / 2.0 - phi) * r / FRAC_PI_4, r),
        2 => (-r, (PI - phi) * r / FRAC_PI_4),
        _ => ((phi - 1.5 * PI) * r / FRAC_PI_4, -r),
    };
    [0.5 * (a + 1.0), 0.5 * (b + 1.0)]
}

/// The unit vector of disk point `d` on the +z hemisphere.
pub fn disk_to_vector(d: [f64; 2]) -> [f64; 3] {
    let z = (1.0 - d[0] * d[0] - d[1] * d[1]).max(0.0).sqrt();
    [d[0], d[1], z]
}

/// θ (0–90°) and φ ([0, 360)) in degrees of disk point `d`.
pub fn disk_to_angles(d: [f64; 2]) -> (f64, f64) {
    let r = (d[0] * d[0] + d[1] * d[1]).sqrt().min(1.0);
    let theta = r.asin().to_degrees();
    let phi = crate::normalize_phi_deg(d[1].atan2(d[0]).to_degrees());
    (theta, phi)
}

/// The disk point of direction (θ, φ) in degrees (θ from the side's
/// normal, 0–90°).
pub fn angles_to_disk(theta_deg: f64, phi_deg: f64) -> [f64; 2] {
    let s = theta_deg.to_radians().sin();
    let p = phi_deg.to_radians();
    [s * p.cos(), s * p.sin()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn square_and_disk_maps_invert_each_other_and_keep_quarters() {
        for i in 0..41 {
            for j in 0..41 {
                let (x, y) = (i as f64 / 40.0, j as f64 / 40.0);
                let d = square_to_disk(x, y);
                assert!(d[0].hypot(d[1]) <= 1.0 + 1e-12);
                let back = disk_to_square(d[0], d[1]);
                if (x - 0.5).abs() + (y - 0.5).abs() > 1e-9 {
                    assert!((back[0] - x).abs() < 1e-9 && (back[1] - y).abs() < 1e-9);
                }
            }
        }
        // The right edge's middle is φ = 0, the top's φ = 90°.
        let d = square_to_disk(1.0, 0.5);
        assert!((d[0] - 1.0).abs() < 1e-12 && d[1].abs() < 1e-12);
        let d = square_to_disk(0.5, 1.0);
        assert!(d[0].abs() < 1e-12 && (d[1] - 1.0).abs() < 1e-12);
        // Point symmetry: (1 − x, 1 − y) is the opposite disk point.
        let (d, e) = (square_to_disk(0.8, 0.3), square_to_disk(0.2, 0.7));
        assert!((d[0] + e[0]).abs() < 1e-12 && (d[1] + e[1]).abs() < 1e-12);
    }

    #[test]
    fn equal_square_areas_are_equal_disk_areas() {
        // A quarter of the square (x < 0.5, y < 0.5 corner excluded from
        // the rest) holds a quarter of the disk: count a fine grid.
        let n = 400;
        let mut inner = 0;
        for i in 0..n {
            for j in 0..n {
                let d = square_to_disk((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
                if d[0].hypot(d[1]) < 0.5 {
                    inner += 1;
                }
            }
        }
        // r < 0.5 is a quarter of the disk's area.
        let fraction = inner as f64 / (n * n) as f64;
        assert!((fraction - 0.25).abs() < 0.005, "{fraction}");
    }
}
