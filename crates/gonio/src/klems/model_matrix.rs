//! Klems matrices of a model BSDF: the patch averages a Klems file holds,
//! computed from `brtf_model::Bsdf` (what the Klems writer exports).
//!
//! Entry (o, i) is the BSDF averaged over outgoing patch o (weighted by
//! projected solid angle, as a Klems value is defined) **and** over
//! incident patch i (as `bsdf2klems` does): the mean of f(l, v) over
//! n points (v, l) of the product of the two patches: a 4-D Halton set,
//! randomly shifted (per outgoing and per incident patch), mapped to each
//! patch uniformly in projected solid angle ([`patch_point`]), so the
//! plain mean is the double patch average. Roughness-0 (delta)
//! mirror and straight-through parts add E/Λ_i to the diagonal, E averaged
//! over the incident patch.
//!
//! Everything is computed in the frame of the lit side: light from +z.
//! [`light_vector`] and [`view_vector`] say how a point of a patch
//! becomes brtf's light and view vectors for either side.

use brtf_model::Rng;
use brtf_model::{Bsdf, Rgb};
use glam::DVec3;
use rayon::prelude::*;

use super::{KlemsBasis, Side};

/// The default number of samples per matrix entry (before
/// [`grazing_boost`]). Measured (`docs/klems.md`, "Writing Klems XML";
/// the test `default_sample_count_is_converged_to_one_percent`): doubling
/// it changes no entry of a rough trans (α 0.15) or plastic (α 0.1) by
/// more than 1 % of the entry (0.91 %, 0.83 %; entries below 1e-3 of
/// their column's largest value are not counted). 2048 gave 1.45 %.
pub const DEFAULT_SAMPLES: usize = 4096;

/// The largest [`grazing_boost`].
pub(super) const HORIZON_BOOST: usize = 16;

/// How many times the samples a patch gets: 16 for patches that reach
/// the horizon, 4 for those that reach 75°, else 1. An entry uses the
/// smaller of its two patches' counts. Near the horizon the reflected
/// lobe grows as 1/cos² θ (and the transmitted one as 1/√cos θ): heavy
/// tails that converge slowly. In the Full basis 144 of the 21 025
/// entries get 16×, 640 more 4×: the whole matrix costs about 1.3× the
/// base count.
pub(super) fn grazing_boost(patch: &super::KlemsPatch) -> usize {
    let upper = patch.theta_bounds_deg.1;
    if upper >= 90.0 - 1e-9 {
        HORIZON_BOOST
    } else if upper >= 75.0 - 1e-9 {
        4
    } else {
        1
    }
}

/// The default seed of the samples.
pub(super) const DEFAULT_SEED: u64 = 0x006b_6c65_6d73;

/// brtf's light vector (pointing towards the source) for the point `p`
/// of an incident patch, `p` on the +z hemisphere as
/// [`KlemsPatch::stratified_directions`](super::KlemsPatch::stratified_directions)
/// gives it. A Klems incident patch (θ, φ) is the direction of travel, so
/// the source sits at (θ, φ + 180°): lit from the front (+z) that is
/// (−x, −y, z); lit from the back the same with z mirrored.
pub fn light_vector(side: Side, p: DVec3) -> DVec3 {
    match side {
        Side::Front => DVec3::new(-p.x, -p.y, p.z),
        Side::Back => DVec3::new(-p.x, -p.y, -p.z),
    }
}

/// brtf's view vector for the point `p` (+z hemisphere) of an outgoing
/// patch: reflection leaves on the lit side, transmission on the other,
/// at the same azimuth. Lit from the front, reflection (θ, φ) is `p` and
/// transmission is (180° − θ, φ); lit from the back, both mirrored.
pub(super) fn view_vector(side: Side, transmission: bool, p: DVec3) -> DVec3 {
    let on_front = (side == Side::Front) != transmission;
    if on_front {
        p
    } else {
        DVec3::new(p.x, p.y, -p.z)
    }
}

/// How to sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SampleOptions {
    /// Samples per matrix entry (at least 1).
    pub samples: usize,
    /// Seed of every random stream.
    pub seed: u64,
}

impl Default for SampleOptions {
    fn default() -> Self {
        SampleOptions {
            samples: DEFAULT_SAMPLES,
            seed: DEFAULT_SEED,
        }
    }
}

/// The RGB matrices of one lit side: `values[o * n + i]`, BSDF in 1/sr.
#[derive(Debug, Clone, PartialEq)]
pub struct SideMatrices {
    /// Number of patches.
    pub n: usize,
    /// Reflection (leaving on the lit side).
    pub reflection: Vec<Rgb>,
    /// Transmission (leaving on the other side), when asked for.
    pub transmission: Option<Vec<Rgb>>,
}

/// The Klems matrices of one lit side. `bsdf_of_patch[i]` is the model
/// for light in incident patch i (one per patch, so parameters may depend
/// on θ_in); it is evaluated in the lit side's frame (light from +z), so a
/// fit of the back side described as a front fit goes in unchanged.
/// `transmission` asks for the transmission matrix too.
///
/// Panics when `bsdf_of_patch` does not hold one model per patch (a
/// caller's bug).
pub fn side_matrices(
    basis: &KlemsBasis,
    bsdf_of_patch: &[Bsdf],
    transmission: bool,
    options: SampleOptions,
) -> SideMatrices {
    let n = basis.len();
    assert_eq!(bsdf_of_patch.len(), n, "one BSDF per incident patch");
    let samples = options.samples.max(1);
    let patches = basis.patches();
    // A 4-D Halton set (bases 2, 3 for the outgoing patch, 5, 7 for the
    // incident one), shifted modulo 1 by a random vector per outgoing
    // patch (first two coordinates) and per incident patch (last two):
    // entry (o, i) then averages f over a randomly shifted quasi-random
    // point set of the product of the two patches, which is unbiased and
    // converges about as 1/n for smooth f (plain stratified pairs: 1/√n).
    let halton: Vec<[f64; 4]> = (0..samples * HORIZON_BOOST)
        .map(|k| [2, 3, 5, 7].map(|b| radical_inverse(k as u64 + 1, b)))
        .collect();
    let points = |stream_base: u64, dims: [usize; 2]| -> Vec<Vec<DVec3>> {
        patches
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let mut rng = Rng::new(options.seed, stream_base + k as u64);
                let shift = rng.uniform2();
                let count = samples * grazing_boost(p);
                halton[..count]
                    .iter()
                    .map(|h| {
                        patch_point(
                            p,
                            (h[dims[0]] + shift[0]).fract(),
                            (h[dims[1]] + shift[1]).fract(),
                        )
                    })
                    .collect()
            })
            .collect()
    };
    let outgoing = points(0, [0, 1]);
    let incident = points(1 << 32, [2, 3]);
    let lambda = basis.projected_solid_angles();

    // Column by column (incident patch), in parallel.
    let columns: Vec<(Vec<Rgb>, Vec<Rgb>)> = (0..n)
        .into_par_iter()
        .map(|i| {
            let bsdf = &bsdf_of_patch[i];
            let lights: Vec<DVec3> = incident[i]
                .iter()
                .map(|&p| light_vector(Side::Front, p))
                .collect();
            let mut reflection = vec![[0.0; 3]; n];
            let mut through = vec![[0.0; 3]; if transmission { n } else { 0 }];
            for o in 0..n {
                let mut sum_r = [0.0; 3];
                let mut sum_t = [0.0; 3];
                // Near the horizon, the longer prefix both patches have.
                let count = outgoing[o].len().min(lights.len());
                for (&p, &l) in outgoing[o][..count].iter().zip(&lights) {
                    add(&mut sum_r, bsdf.eval(l, view_vector(Side::Front, false, p)));
                    if transmission {
                        add(&mut sum_t, bsdf.eval(l, view_vector(Side::Front, true, p)));
                    }
                }
                reflection[o] = sum_r.map(|s| s / count as f64);
                if transmission {
                    through[o] = sum_t.map(|s| s / count as f64);
                }
            }
            // Delta parts: E averaged over the incident patch, spread
            // over the diagonal patch's projected solid angle.
            if bsdf.is_pure() {
                let mut mirror = [0.0; 3];
                let mut straight = [0.0; 3];
                for l in &lights {
                    let (m, t) = bsdf.delta_coefficients(l.z);
                    add(&mut mirror, m);
                    add(&mut straight, t);
                }
                let scale = 1.0 / (lights.len() as f64 * lambda[i]);
                add(&mut reflection[i], mirror.map(|e| e * scale));
                if transmission {
                    add(&mut through[i], straight.map(|e| e * scale));
                }
            }
            (reflection, through)
        })
        .collect();

    let mut reflection = vec![[0.0; 3]; n * n];
    let mut through = vec![[0.0; 3]; if transmission { n * n } else { 0 }];
    for (i, (r, t)) in columns.iter().enumerate() {
        for o in 0..n {
            reflection[o * n + i] = r[o];
            if transmission {
                through[o * n + i] = t[o];
            }
        }
    }
    SideMatrices {
        n,
        reflection,
        transmission: transmission.then_some(through),
    }
}

/// The radical inverse of `k` in base `base` (the Halton sequence).
fn radical_inverse(mut k: u64, base: u64) -> f64 {
    let inv = 1.0 / base as f64;
    let (mut value, mut scale) = (0.0, inv);
    while k > 0 {
        value += (k % base) as f64 * scale;
        k /= base;
        scale *= inv;
    }
    value
}

/// The point of `patch` at (u, v) in the unit square, uniform in
/// projected solid angle: cos² θ linear in u, φ linear in v (the mapping
/// of [`KlemsPatch::stratified_directions`](super::KlemsPatch::stratified_directions)).
pub(super) fn patch_point(patch: &super::KlemsPatch, u: f64, v: f64) -> DVec3 {
    let (lo, hi) = patch.theta_bounds_deg;
    let c2_top = lo.to_radians().cos().powi(2);
    let c2_bottom = hi.to_radians().cos().powi(2);
    let cos2 = c2_top + (c2_bottom - c2_top) * u;
    let (phi_lo, phi_hi) = patch.phi_bounds_deg;
    let phi = (phi_lo + (phi_hi - phi_lo) * v).to_radians();
    let sin_theta = (1.0 - cos2).max(0.0).sqrt();
    DVec3::new(
        sin_theta * phi.cos(),
        sin_theta * phi.sin(),
        cos2.max(0.0).sqrt(),
    )
}

fn add(sum: &mut Rgb, value: Rgb) {
    for (s, v) in sum.iter_mut().zip(value) {
        *s += v;
    }
}

/// One band of an RGB matrix: `Visible` is CIE Y, `CIE-X`/`CIE-Z` the
/// other tristimulus values (Radiance's RGB primaries, `brtf_model::colour`).
pub fn band_values(rgb: &[Rgb], band: &super::KlemsBand) -> Option<Vec<f64>> {
    let channel = match band {
        super::KlemsBand::CieX => 0,
        super::KlemsBand::Visible => 1,
        super::KlemsBand::CieZ => 2,
        _ => return None,
    };
    Some(
        rgb.iter()
            .map(|&v| brtf_model::rgb_to_xyz(v)[channel])
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use brtf_model::{EvalOptions, Material, MaterialKind};

    #[test]
    fn vectors_follow_the_klems_conventions() {
        let p = brtf_model::direction(30.0, 45.0);
        // Lit from the front, the source is at φ + 180° on +z.
        let l = light_vector(Side::Front, p);
        assert!((l - brtf_model::direction(30.0, 225.0)).length() < 1e-12);
        // Lit from the back: θ_in = 180° − θ, φ + 180°.
        let l = light_vector(Side::Back, p);
        assert!((l - brtf_model::direction(150.0, 225.0)).length() < 1e-12);
        assert!((view_vector(Side::Front, false, p) - p).length() < 1e-12);
        let t = view_vector(Side::Front, true, p);
        assert!((t - brtf_model::direction(150.0, 45.0)).length() < 1e-12);
        assert!((view_vector(Side::Back, false, p) - t).length() < 1e-12);
        assert!((view_vector(Side::Back, true, p) - p).length() < 1e-12);
        // The mirror direction of the light is the same patch (diagonal).
        let mirror = {
            let l = light_vector(Side::Front, p);
            DVec3::new(-l.x, -l.y, l.z)
        };
        assert!((mirror - view_vector(Side::Front, false, p)).length() < 1e-12);
    }

    #[test]
    fn lambertian_columns_total_its_reflectance() {
        let basis = KlemsBasis::built_in("LBNL/Klems Quarter").unwrap();
        let m = Material::new(MaterialKind::Plastic, &[0.5, 0.5, 0.5, 0.0, 0.0], None).unwrap();
        let bsdf = Bsdf::new(&m, &EvalOptions::default());
        let s = side_matrices(
            &basis,
            &vec![bsdf; basis.len()],
            false,
            SampleOptions::default(),
        );
        for v in &s.reflection {
            assert!((v[0] - 0.5 / std::f64::consts::PI).abs() < 1e-12);
        }
        assert!(s.transmission.is_none());
    }
}
