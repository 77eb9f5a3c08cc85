//! The loops behind `Material.eval`, free of pyo3 so that the Rust
//! benchmark (`benches/eval_degrees.rs`) times exactly this code.

use brtf_model::{Bsdf, direction};

/// `out[3 i .. 3 i + 3]` = the BSDF (1/sr, RGB) for light from
/// (`theta_in[i]`, `phi_in[i]`) seen from (`theta_out[i]`, `phi_out[i]`),
/// all in degrees, as `brtf eval` computes it. All slices have the same
/// length; `out` is three times as long.
pub(crate) fn eval_degrees(
    bsdf: &Bsdf,
    theta_in: &[f64],
    phi_in: &[f64],
    theta_out: &[f64],
    phi_out: &[f64],
    out: &mut [f64],
) {
    let rows = theta_in
        .iter()
        .zip(phi_in)
        .zip(theta_out.iter().zip(phi_out));
    for (((ti, pi), (to, po)), rgb) in rows.zip(out.chunks_exact_mut(3)) {
        rgb.copy_from_slice(&bsdf.eval(direction(*ti, *pi), direction(*to, *po)));
    }
}

/// The same for one incidence and many outgoing directions: the light
/// direction is computed once (the common case, and `brtf eval`'s).
pub(crate) fn eval_degrees_one_incidence(
    bsdf: &Bsdf,
    theta_in: f64,
    phi_in: f64,
    theta_out: &[f64],
    phi_out: &[f64],
    out: &mut [f64],
) {
    let l = direction(theta_in, phi_in);
    for ((to, po), rgb) in theta_out.iter().zip(phi_out).zip(out.chunks_exact_mut(3)) {
        rgb.copy_from_slice(&bsdf.eval(l, direction(*to, *po)));
    }
}
