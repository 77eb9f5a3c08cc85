//! Unit tests of brtf-fit from inside the crate, one module per area:
//! the recipe (conversions, colour, gates, weights), the θ_in table, the
//! solver's terminations and standard errors, the robust reweighting and
//! the adequacy diagnostics. Expected values come from formulas, hand
//! calculations or the parameters that generated the data.

mod diagnose;
mod energy;
mod recipe;
mod robust;
mod solve;
mod table;

use crate::data::{FitSample, IncidenceData, Weighting};
use crate::report::{FitReport, ParamEstimate, Termination};
use brtf_gonio::{Channels, Incidence, Measurement, Quantity, Sample, SourceFormat};
use brtf_model::{Bsdf, EvalOptions, Material, MaterialKind, Rng, direction};

/// A measurement at incidence (`theta_in`, 0) holding `samples`.
pub(crate) fn measurement(
    theta_in: f64,
    quantity: Quantity,
    channels: Channels,
    samples: Vec<Sample>,
) -> Measurement {
    Measurement::new(
        SourceFormat::Mountain,
        Incidence::new(theta_in, 0.0),
        quantity,
        channels,
        samples,
    )
}

/// Directions on rings of constant θ (degrees), `per_ring` equally spaced
/// azimuths each, starting at φ = 0; ring after ring.
pub(crate) fn ring_directions(thetas: &[f64], per_ring: usize) -> Vec<(f64, f64)> {
    thetas
        .iter()
        .flat_map(|&t| (0..per_ring).map(move |k| (t, 360.0 * k as f64 / per_ring as f64)))
        .collect()
}

/// The angle in degrees between directions (θ₁, φ₁) and (θ₂, φ₂), by the
/// spherical law of cosines (independent of the crates' vectors).
pub(crate) fn angle_between_deg(a: (f64, f64), b: (f64, f64)) -> f64 {
    let (t1, p1) = (a.0.to_radians(), a.1.to_radians());
    let (t2, p2) = (b.0.to_radians(), b.1.to_radians());
    let c = t1.cos() * t2.cos() + t1.sin() * t2.sin() * (p1 - p2).cos();
    c.clamp(-1.0, 1.0).acos().to_degrees()
}

/// A converged report of a `kind` fit with these material arguments and
/// scale (every argument free, no standard errors), for the consumers of
/// reports: the θ_in table and the diagnostics.
pub(crate) fn report(kind: MaterialKind, theta_in: f64, args: &[f64], scale: f64) -> FitReport {
    let params = kind
        .param_names()
        .iter()
        .zip(args)
        .map(|(name, &value)| ParamEstimate {
            name: (*name).into(),
            value,
            stderr: None,
            stderr_robust: None,
            at_bound: false,
            fixed: false,
        })
        .collect();
    FitReport {
        source: format!("hand-made θ_in = {theta_in}"),
        theta_in,
        phi_in: 0.0,
        params,
        material_args: args.to_vec(),
        scale,
        n_points: 0,
        gates: Vec::new(),
        weighting: Weighting::Caller,
        rms_rel: 0.0,
        e1: None,
        cost: 0.0,
        floor: 0.0,
        termination: Termination::Converged {
            ftol: true,
            xtol: false,
        },
        evaluations: 0,
        elapsed_ms: 0.0,
        starts: Vec::new(),
        warnings: Vec::new(),
        adequacy: None,
        robust: None,
    }
}

/// A `kind` material with these arguments (orientation +x).
pub(crate) fn material(kind: MaterialKind, args: &[f64]) -> Material {
    Material::new(kind, args, None).expect("a valid material")
}

/// The front-hemisphere samples of `material` lit from (`theta_in`, 0):
/// rings θ = 1°, 3°, …, 85° every 5° of azimuth (3 096 directions),
/// weighted by their cells' solid angles, with the exact BSDF times
/// `1 + noise · N(0, 1)` (seeded), in `channels` channels (1: red only).
pub(crate) fn synth(
    material: &Material,
    theta_in: f64,
    channels: usize,
    noise: f64,
    seed: u64,
) -> IncidenceData {
    let bsdf = Bsdf::new(material, &EvalOptions::default());
    let light = direction(theta_in, 0.0);
    let mut rng = Rng::new(seed, 0);
    let (d_theta, d_phi) = (2f64.to_radians(), 5f64.to_radians());
    let mut samples = Vec::new();
    for i in 0..43 {
        let theta = 1.0 + 2.0 * i as f64;
        for j in 0..72 {
            let view = direction(theta, 5.0 * j as f64);
            let k = 1.0 + noise * rng.normal();
            let mut value = bsdf.eval(light, view).map(|v| v * k);
            if channels == 1 {
                value = [value[0], 0.0, 0.0];
            }
            samples.push(FitSample {
                view,
                value,
                weight: theta.to_radians().sin() * d_theta * d_phi,
            });
        }
    }
    IncidenceData {
        source: format!("synthetic {} at θ_in = {theta_in}", material.kind()),
        theta_in,
        phi_in: 0.0,
        channels,
        samples,
        gates: Vec::new(),
        weighting: Weighting::Caller,
        patch_pairs: None,
        cosine_weighted: false,
    }
}
