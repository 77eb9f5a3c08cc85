//! Directional-hemispherical reflectance ρ_dh and transmittance τ_dh.
//!
//! ρ_dh(l) = ∫ f(l, v) |cos θ_v| dω_v over the front hemisphere, τ_dh the
//! same over the back. The integral is taken in polar coordinates (δ, ψ)
//! centred on the lobe: δ is the angle from the mirror direction of `l`
//! (for the back hemisphere, the straight-through direction, which is the
//! mirror direction reflected through the surface). For every azimuth ψ
//! the great circle leaves the hemisphere at a δ_max(ψ) known in closed
//! form, so the horizon is a boundary of the domain, never a jump inside
//! it. Radial panels double in width from a quarter of the lobe width,
//! each integrated by Gauss–Legendre; the periodic ψ integral uses the
//! trapezoid rule, doubled until it converges.
//!
//! Roughness-0 surfaces have delta mirror and straight-through components
//! that are not part of f; they are returned separately as "spikes".

use crate::bsdf::{Bsdf, Rgb};
use glam::DVec3;
use std::f64::consts::PI;
use std::sync::OnceLock;

/// Gauss–Legendre order per radial panel.
const PANEL_ORDER: usize = 10;

/// Result of a hemispherical integration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Albedo {
    /// ρ_dh of the non-delta part, per channel.
    pub rho: Rgb,
    /// τ_dh of the non-delta part, per channel.
    pub tau: Rgb,
    /// Mirror delta reflectance (roughness-0 surfaces only).
    pub rho_spike: Rgb,
    /// Straight-through delta transmittance (roughness-0 surfaces only).
    pub tau_spike: Rgb,
    /// Largest change in any channel at the last azimuth doubling: an
    /// estimate of the quadrature error.
    pub error_estimate: f64,
    /// Number of BSDF evaluations used.
    pub evaluations: usize,
}

/// Integrates `bsdf` over both hemispheres for light from direction `l`
/// (unit, local frame). `tolerance` is the target absolute error per
/// channel (1e-5 gives results good to about 1e-5).
pub fn albedo(bsdf: &Bsdf, l: DVec3, tolerance: f64) -> Albedo {
    // Two-sided materials: light from the back behaves as from the front.
    let l = if l.z < 0.0 {
        DVec3::new(l.x, l.y, -l.z)
    } else {
        l
    };
    let l = DVec3::new(l.x, l.y, l.z.max(1e-4)).normalize();
    let mirror = DVec3::new(-l.x, -l.y, l.z);
    let (rho_spike, tau_spike) = bsdf.delta_coefficients(l.z);
    let transmitting = bsdf.kind().is_transmitting();
    let scale = lobe_scale(bsdf);
    let frame = LobeFrame::new(mirror);
    let nodes = gauss_legendre();

    let mut evaluations = 0usize;
    // Radial integral of f·|cos|·sin δ along azimuth ψ, for both hemispheres.
    let mut radial = |psi: f64| -> [f64; 6] {
        let (sin_psi, cos_psi) = psi.sin_cos();
        let axis = frame.e1 * cos_psi + frame.e2 * sin_psi;
        let delta_max = axis.z.atan2(mirror.z) + 0.5 * PI;
        let mut sums = [0.0; 6];
        let mut lo = 0.0;
        let mut hi = (0.25 * scale).min(delta_max);
        loop {
            let half = 0.5 * (hi - lo);
            let mid = 0.5 * (hi + lo);
            for &(x, w) in nodes {
                let delta = mid + half * x;
                let (sin_d, cos_d) = delta.sin_cos();
                let dir = mirror * cos_d + axis * sin_d;
                let weight = w * half * sin_d * dir.z.max(0.0);
                let front = bsdf.eval(l, dir);
                for ch in 0..3 {
                    sums[ch] += weight * front[ch];
                }
                if transmitting {
                    let back = bsdf.eval(l, DVec3::new(dir.x, dir.y, -dir.z));
                    for ch in 0..3 {
                        sums[3 + ch] += weight * back[ch];
                    }
                }
            }
            evaluations += nodes.len() * if transmitting { 2 } else { 1 };
            if hi >= delta_max {
                break;
            }
            lo = hi;
            hi = (2.0 * hi).min(delta_max);
            if delta_max - hi < 0.25 * (hi - lo) {
                hi = delta_max;
            }
        }
        sums
    };

    // Trapezoid rule in ψ, doubling the number of azimuths.
    let mut n = 16usize;
    let mut total = [0.0; 6];
    for k in 0..n {
        let s = radial(2.0 * PI * k as f64 / n as f64);
        for i in 0..6 {
            total[i] += s[i];
        }
    }
    let mut estimate = total.map(|t| t * 2.0 * PI / n as f64);
    let mut error = f64::INFINITY;
    while n < 4096 {
        for k in 0..n {
            let s = radial(2.0 * PI * (k as f64 + 0.5) / n as f64);
            for i in 0..6 {
                total[i] += s[i];
            }
        }
        n *= 2;
        let refined = total.map(|t| t * 2.0 * PI / n as f64);
        error = refined
            .iter()
            .zip(estimate.iter())
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        estimate = refined;
        if error < tolerance && n >= 32 {
            break;
        }
    }
    Albedo {
        rho: [estimate[0], estimate[1], estimate[2]],
        tau: [estimate[3], estimate[4], estimate[5]],
        rho_spike,
        tau_spike,
        error_estimate: error,
        evaluations,
    }
}

/// Angular width (radians, in δ) of the narrowest specular lobe; wide
/// when there is none.
fn lobe_scale(bsdf: &Bsdf) -> f64 {
    if bsdf.is_pure() {
        return 1.0;
    }
    let args = bsdf.material().args();
    let mut alpha = args[4];
    if bsdf.kind().is_anisotropic() {
        alpha = alpha.min(args[5]);
    }
    let omega = bsdf.options().source_omega.max(0.0);
    // Reflection: exp(-tan²θ_h/α²) with θ_h ≈ δ/2; transmission: exp(-δ²/β).
    let reflect = 2.0 * alpha.hypot((omega / (4.0 * PI)).sqrt());
    let transmit = alpha.hypot((omega / PI).sqrt());
    reflect.min(transmit).clamp(1e-4, 1.0)
}

/// An orthonormal frame around the lobe centre `p`: e1 points from `p`
/// towards the normal, e2 is horizontal.
struct LobeFrame {
    e1: DVec3,
    e2: DVec3,
}

impl LobeFrame {
    fn new(p: DVec3) -> LobeFrame {
        let up = DVec3::Z - p * p.z;
        let e1 = if up.length_squared() > 1e-20 {
            up.normalize()
        } else {
            DVec3::X
        };
        let e2 = p.cross(e1).normalize();
        LobeFrame { e1, e2 }
    }
}

/// Gauss–Legendre nodes and weights on [-1, 1], computed once.
fn gauss_legendre() -> &'static [(f64, f64)] {
    static NODES: OnceLock<Vec<(f64, f64)>> = OnceLock::new();
    NODES.get_or_init(|| gauss_legendre_rule(PANEL_ORDER))
}

/// The n-point Gauss–Legendre rule on [−1, 1] as (node, weight) pairs, by
/// Newton iteration on the Legendre polynomial P_n.
pub fn gauss_legendre_rule(n: usize) -> Vec<(f64, f64)> {
    let mut rule = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut derivative = 1.0;
        for _ in 0..100 {
            // Recurrence for P_n(x) and P_{n-1}(x).
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            derivative = n as f64 * (x * p1 - p0) / (x * x - 1.0);
            let step = p1 / derivative;
            x -= step;
            if step.abs() < 1e-15 {
                break;
            }
        }
        rule.push((x, 2.0 / ((1.0 - x * x) * derivative * derivative)));
    }
    rule
}
