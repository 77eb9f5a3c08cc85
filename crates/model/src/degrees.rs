//! Sine and cosine of angles given in degrees.
//!
//! Every direction brtf reads arrives as (θ, φ) in degrees, and a 127k-point
//! scan needs two sine–cosine pairs per sample for its directions alone.
//! libm's `sin_cos` of `x.to_radians()` costs ~20 ns per pair and rounds
//! the argument twice (to radians, then its own reduction by π/2). Here the
//! argument is reduced by whole quarter turns **in degrees**, which is
//! exact, so only the conversion of the remainder (|r| ≤ 45°) to radians
//! rounds; then a polynomial gives sin and cos on [−π/4, π/4]. Results are
//! within about an ulp of the true values, exact at multiples of 90°
//! (`cos 90° = 0`, not libm's 6.1e-17), and branch-free, so that loops
//! over many angles vectorise.

use std::f64::consts::PI;

/// Taylor coefficients (−1)ᵏ/(2k+1)! of sin t = t + t³ Σ S[k] t²ᵏ. On
/// |t| ≤ π/4 the first omitted term, t¹⁹/19!, is below 1e-19.
const SIN: [f64; 8] = [
    -1.0 / 6.0,
    1.0 / 120.0,
    -1.0 / 5040.0,
    1.0 / 362_880.0,
    -1.0 / 39_916_800.0,
    1.0 / 6_227_020_800.0,
    -1.0 / 1_307_674_368_000.0,
    1.0 / 355_687_428_096_000.0,
];

/// Taylor coefficients of cos t = 1 − t²/2 + t⁴ Σ C[k] t²ᵏ, from 1/4! to
/// 1/18! (the first omitted term, t²⁰/20!, is below 1e-20 on |t| ≤ π/4).
const COS: [f64; 8] = [
    1.0 / 24.0,
    -1.0 / 720.0,
    1.0 / 40_320.0,
    -1.0 / 3_628_800.0,
    1.0 / 479_001_600.0,
    -1.0 / 87_178_291_200.0,
    1.0 / 20_922_789_888_000.0,
    -1.0 / 6_402_373_705_728_000.0,
];

/// Adding and subtracting 1.5·2⁵² rounds a double of magnitude below 2⁵¹ to
/// the nearest integer (ties to even), with its low bits left in the sum.
const ROUNDER: f64 = 6_755_399_441_055_744.0;

/// Beyond this magnitude (degrees) the quarter-turn count no longer fits
/// the rounding trick; such angles go to libm.
const REDUCIBLE: f64 = 1e14;

/// `(sin x°, cos x°)` for `x` in degrees (see the module docs). NaN or an
/// infinite `x` gives NaNs, as libm does.
#[inline]
pub fn sin_cos_degrees(x: f64) -> (f64, f64) {
    if x.abs() >= REDUCIBLE || x.is_nan() {
        return x.to_radians().sin_cos();
    }
    // The nearest quarter turn q: its low two bits are the quadrant.
    let shifted = x * (1.0 / 90.0) + ROUNDER;
    let quadrant = shifted.to_bits() & 3;
    let q = shifted - ROUNDER;
    // Exact: 90q is exact, and x lies within a factor 2 of it (Sterbenz),
    // or q = 0.
    let r = x - 90.0 * q;
    let t = r * (PI / 180.0);
    let t2 = t * t;
    let sin_poly = SIN.iter().rev().fold(0.0, |acc, &c| acc * t2 + c);
    let cos_poly = COS.iter().rev().fold(0.0, |acc, &c| acc * t2 + c);
    let s = t + t * t2 * sin_poly;
    let c = 1.0 - 0.5 * t2 + t2 * t2 * cos_poly;
    // Quarter turns: (s, c) → (c, −s) → (−s, −c) → (−c, s).
    let (sin, cos) = if quadrant & 1 == 0 { (s, c) } else { (c, s) };
    let sin_sign = if quadrant & 2 == 0 { 1.0 } else { -1.0 };
    let cos_sign = if (quadrant + 1) & 2 == 0 { 1.0 } else { -1.0 };
    (sin_sign * sin, cos_sign * cos)
}

/// `cos x°` for `x` in degrees, as [`sin_cos_degrees`] gives it.
#[inline]
pub fn cos_degrees(x: f64) -> f64 {
    sin_cos_degrees(x).1
}

#[cfg(test)]
mod tests {
    use super::*;

    /// libm's sin and cos of `x` degrees after an exact reduction to
    /// (−180°, 180°], so that the only error of the reference is libm's
    /// own (≤ 1 ulp) and the rounding of the argument to radians.
    fn reference(x: f64) -> (f64, f64) {
        let reduced = x - 360.0 * (x / 360.0).round();
        reduced.to_radians().sin_cos()
    }

    #[test]
    fn agrees_with_libm_to_an_ulp_or_two() {
        let mut worst: f64 = 0.0;
        let mut k = 0u64;
        let mut x = -1080.0;
        while x <= 1080.0 {
            let (s, c) = sin_cos_degrees(x);
            let (rs, rc) = reference(x);
            worst = worst.max((s - rs).abs()).max((c - rc).abs());
            // An irregular step, so that the angles are not all on a grid.
            k += 1;
            x += 0.0137 + 1e-6 * (k % 7) as f64;
        }
        // The reference's argument rounds to radians with an error of up to
        // ~3.4e-16 rad at 180°: that bounds the difference.
        assert!(worst < 5e-16, "largest difference from libm {worst:e}");
        assert!(worst > 0.0, "the comparison did compare something");
    }

    #[test]
    fn quarter_turns_are_exact() {
        let cases: [(f64, f64, f64); 8] = [
            (0.0, 0.0, 1.0),
            (90.0, 1.0, 0.0),
            (180.0, 0.0, -1.0),
            (270.0, -1.0, 0.0),
            (360.0, 0.0, 1.0),
            (-90.0, -1.0, 0.0),
            (-180.0, 0.0, -1.0),
            (450.0, 1.0, 0.0),
        ];
        for (x, sin, cos) in cases {
            // (−0.0 equals 0.0 here.)
            assert_eq!(sin_cos_degrees(x), (sin, cos), "at {x}°");
        }
        assert_eq!(cos_degrees(90.0), 0.0);
    }

    #[test]
    fn small_angles_keep_their_relative_precision() {
        for x in [1e-300, 1e-12, 1e-6, 0.01, 0.04] {
            let (s, c) = sin_cos_degrees(x);
            let (rs, rc) = x.to_radians().sin_cos();
            assert!(((s - rs) / rs).abs() < 3e-16, "sin {x}°: {s:e} vs {rs:e}");
            assert!((c - rc).abs() <= f64::EPSILON, "cos {x}°: {c} vs {rc}");
            let (s, _) = sin_cos_degrees(-x);
            assert!(((s + rs) / rs).abs() < 3e-16, "sin −{x}° odd");
        }
    }

    #[test]
    fn sine_squared_plus_cosine_squared_is_one() {
        for k in 0..10_000 {
            let x = -400.0 + 0.0809 * k as f64;
            let (s, c) = sin_cos_degrees(x);
            assert!((s * s + c * c - 1.0).abs() < 4.5e-16, "at {x}°");
        }
    }

    #[test]
    fn huge_and_non_finite_angles_follow_libm() {
        let x = 3.7e15;
        assert_eq!(sin_cos_degrees(x), x.to_radians().sin_cos());
        for x in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let (s, c) = sin_cos_degrees(x);
            assert!(s.is_nan() && c.is_nan(), "{x}");
        }
    }
}
