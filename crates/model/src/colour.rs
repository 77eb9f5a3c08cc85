//! Radiance's RGB and CIE XYZ.
//!
//! Radiance's RGB has the primaries of `color.h`: x,y = (0.640, 0.330),
//! (0.290, 0.600), (0.150, 0.060), and the white point (0.3333, 0.3333),
//! `color.h`'s rounding of the equal-energy white. With that white the Y
//! row is exactly rtrace's luminance weights (`CIE_rf` .265074126,
//! `CIE_gf` .670114631, `CIE_bf` .064811243), so Y = 1 for RGB (1, 1, 1)
//! up to that rounding.

use std::sync::OnceLock;

/// Chromaticities (x, y) of Radiance's red, green and blue primaries.
pub const PRIMARIES_XY: [[f64; 2]; 3] = [[0.640, 0.330], [0.290, 0.600], [0.150, 0.060]];
/// Chromaticity of Radiance's white, `CIE_x_w`, `CIE_y_w`.
pub const WHITE_XY: [f64; 2] = [0.3333, 0.3333];

type Matrix = [[f64; 3]; 3];

fn determinant(m: &Matrix) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

fn inverse(m: &Matrix) -> Matrix {
    let d = determinant(m);
    let c =
        |r0: usize, r1: usize, c0: usize, c1: usize| m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0];
    [
        [c(1, 2, 1, 2) / d, -c(0, 2, 1, 2) / d, c(0, 1, 1, 2) / d],
        [-c(1, 2, 0, 2) / d, c(0, 2, 0, 2) / d, -c(0, 1, 0, 2) / d],
        [c(1, 2, 0, 1) / d, -c(0, 2, 0, 1) / d, c(0, 1, 0, 1) / d],
    ]
}

fn apply(m: &Matrix, v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|r| m[r][0] * v[0] + m[r][1] * v[1] + m[r][2] * v[2])
}

/// XYZ of unit luminance (Y = 1) at chromaticity (x, y).
fn xyz_of(xy: [f64; 2]) -> [f64; 3] {
    let [x, y] = xy;
    [x / y, 1.0, (1.0 - x - y) / y]
}

/// The matrix taking Radiance RGB to CIE XYZ: columns are the primaries,
/// scaled so that RGB (1, 1, 1) is the white.
pub fn rgb_to_xyz_matrix() -> &'static Matrix {
    static MATRIX: OnceLock<Matrix> = OnceLock::new();
    MATRIX.get_or_init(|| {
        let columns = PRIMARIES_XY.map(xyz_of);
        let unscaled: Matrix = [0, 1, 2].map(|r| [0, 1, 2].map(|c| columns[c][r]));
        let scale = apply(&inverse(&unscaled), xyz_of(WHITE_XY));
        [0, 1, 2].map(|r| [0, 1, 2].map(|c| unscaled[r][c] * scale[c]))
    })
}

/// The matrix taking CIE XYZ to Radiance RGB.
pub fn xyz_to_rgb_matrix() -> &'static Matrix {
    static MATRIX: OnceLock<Matrix> = OnceLock::new();
    MATRIX.get_or_init(|| inverse(rgb_to_xyz_matrix()))
}

/// CIE XYZ of a Radiance RGB triple.
pub fn rgb_to_xyz(rgb: [f64; 3]) -> [f64; 3] {
    apply(rgb_to_xyz_matrix(), rgb)
}

/// Radiance RGB of a CIE XYZ triple.
pub fn xyz_to_rgb(xyz: [f64; 3]) -> [f64; 3] {
    apply(xyz_to_rgb_matrix(), xyz)
}

/// CIE Y (luminance) of a Radiance RGB triple, as rtrace weighs it.
pub fn luminance(rgb: [f64; 3]) -> f64 {
    rgb_to_xyz(rgb)[1]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_y_row_is_rtraces_luminance_weights() {
        let y = rgb_to_xyz_matrix()[1];
        for (got, want) in y.iter().zip([0.265_074_126, 0.670_114_631, 0.064_811_243]) {
            assert!((got - want).abs() < 1e-9, "{y:?}");
        }
    }

    #[test]
    fn primaries_and_white_have_their_chromaticities() {
        for (c, xy) in PRIMARIES_XY.iter().enumerate() {
            let mut rgb = [0.0; 3];
            rgb[c] = 1.0;
            let [x, y, z] = rgb_to_xyz(rgb);
            let sum = x + y + z;
            assert!((x / sum - xy[0]).abs() < 1e-12 && (y / sum - xy[1]).abs() < 1e-12);
        }
        let [x, y, z] = rgb_to_xyz([1.0; 3]);
        assert!((x / (x + y + z) - WHITE_XY[0]).abs() < 1e-12);
        assert!((y / (x + y + z) - WHITE_XY[1]).abs() < 1e-12);
    }

    #[test]
    fn the_conversions_are_inverse() {
        let rgb = [0.100, 0.401, 0.121];
        let back = xyz_to_rgb(rgb_to_xyz(rgb));
        for (a, b) in back.iter().zip(rgb) {
            assert!((a - b).abs() < 1e-14);
        }
    }
}
