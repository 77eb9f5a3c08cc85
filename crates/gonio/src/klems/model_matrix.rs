//! Klems matrices of a model BSDF: the patch averages a Klems file holds,
//! computed from `brtf_model::Bsdf` (what the Klems writer exports).
//!
//! Entry (o, i) is the BSDF averaged over outgoing patch o (weighted by
//! projected solid angle, as a Klems value is defined) **and** over
//! incident patch i (as `bsdf2klems` does): the mean of f(l, v) over
//! every pair of a light point l of patch i and a view point v of patch
//! o, each set from [`KlemsPatch::stratified_directions`](super::KlemsPatch::stratified_directions)
//! ([`split_samples`] splits the sample count between them). Both sets
//! are uniform in projected solid angle, so the plain mean is the double
//! patch average. Roughness-0 (delta)
//! mirror and straight-through parts add E/Λ_i to the diagonal, E averaged
//! over the incident patch.
//!
//! Everything is computed in the frame of the lit side: light from +z.
//! [`light_vector`] and [`view_vector`] say how a point of a patch
//! becomes brtf's light and view vectors for either side.

use brtf_model::rng::Rng;
use brtf_model::{Bsdf, Rgb};
use glam::DVec3;
use rayon::prelude::*;

use super::{KlemsBasis, Side};

/// The default number of samples per matrix entry. Measured (`docs/klems.md`,
/// "Writing Klems XML"): doubling it from here changes no entry of the
/// test materials by more than 1 % of the entry (entries below 1e-3 of
/// their column's largest value excepted).
pub const DEFAULT_SAMPLES: usize = 256;

/// The default seed of the stratified samples.
pub const DEFAULT_SEED: u64 = 0x006b_6c65_6d73;

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
pub fn view_vector(side: Side, transmission: bool, p: DVec3) -> DVec3 {
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
    let (n_light, n_view) = split_samples(samples);
    let patches = basis.patches();
    // Per patch one stratified point set for the outgoing side and one
    // (other streams) for the incident side. An entry averages f over
    // every pair: n_light incident points × n_view outgoing points. For
    // each incident point the outgoing sets of all patches together
    // integrate the whole hemisphere, so column totals (ρ_dh, τ_dh) are
    // good even where single entries are noisy.
    let points = |stream_base: u64, count: usize| -> Vec<Vec<DVec3>> {
        patches
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let mut rng = Rng::new(options.seed, stream_base + k as u64);
                p.stratified_directions(count, &mut rng)
            })
            .collect()
    };
    let outgoing = points(0, n_view);
    let incident = points(1 << 32, n_light);
    let lambda = basis.projected_solid_angles();
    let weight = 1.0 / (n_light * n_view) as f64;

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
                for &p in &outgoing[o] {
                    let v_r = view_vector(Side::Front, false, p);
                    let v_t = view_vector(Side::Front, true, p);
                    for &l in &lights {
                        add(&mut sum_r, bsdf.eval(l, v_r));
                        if transmission {
                            add(&mut sum_t, bsdf.eval(l, v_t));
                        }
                    }
                }
                reflection[o] = sum_r.map(|s| s * weight);
                if transmission {
                    through[o] = sum_t.map(|s| s * weight);
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
                let scale = 1.0 / (n_light as f64 * lambda[i]);
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

/// `samples` as incident points × outgoing points per entry: the
/// largest divisor not above √samples incident points (256 → 16 × 16,
/// 512 → 16 × 32).
pub fn split_samples(samples: usize) -> (usize, usize) {
    let samples = samples.max(1);
    let n_light = (1..=samples)
        .take_while(|a| a * a <= samples)
        .filter(|a| samples.is_multiple_of(*a))
        .last()
        .unwrap_or(1);
    (n_light, samples / n_light)
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
            .map(|&v| brtf_model::colour::rgb_to_xyz(v)[channel])
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
