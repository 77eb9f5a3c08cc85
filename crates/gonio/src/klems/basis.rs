//! Klems angle bases: rings of patches over one hemisphere.
//!
//! A basis is a list of θ rings, each split into `n_phis` equal azimuth
//! patches; patch j of a ring is centred at φ = 360 j / n and spans
//! ±180 / n. Patches are numbered ring by ring from the pole, as the
//! matrices of a Klems file are. This module owns the geometry the reader
//! and the (later) writer share: patch centres and bounds, solid angles,
//! projected solid angles Λ, and the patch holding a direction. Angles are
//! degrees, as everywhere in brtf's interfaces.

use std::f64::consts::PI;

use brtf_model::Rng;
use glam::DVec3;
use serde::Serialize;

/// One θ ring of a basis.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct KlemsRing {
    /// The ring's centre θ (the file's `Theta`), degrees.
    pub theta_deg: f64,
    /// Lower θ bound, degrees.
    pub lower_theta_deg: f64,
    /// Upper θ bound, degrees.
    pub upper_theta_deg: f64,
    /// Number of azimuth patches (`nPhis`).
    pub n_phis: usize,
}

/// One patch of a basis, with its geometry.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct KlemsPatch {
    /// Index of the ring (0 = the polar cap).
    pub ring: usize,
    /// Centre θ, degrees.
    pub theta_deg: f64,
    /// Centre φ = 360 j / n, degrees.
    pub phi_deg: f64,
    /// θ bounds, degrees.
    pub theta_bounds_deg: (f64, f64),
    /// φ bounds, degrees (the first may be negative: the patch at φ = 0
    /// spans the 0° line).
    pub phi_bounds_deg: (f64, f64),
    /// Solid angle Ω = 2π (cos θ_lo − cos θ_hi) / n, sr.
    pub solid_angle_sr: f64,
    /// Projected solid angle Λ = π (cos² θ_lo − cos² θ_hi) / n, sr.
    pub projected_solid_angle_sr: f64,
}

impl KlemsPatch {
    /// The weight that makes a centre sample carry the patch's projected
    /// solid angle: Λ / cos θ_centre, so Σ BSDF · dΩ · cos θ_centre over
    /// the patches equals Σ BSDF · Λ, the column total Radiance computes.
    pub fn centre_weight_sr(&self) -> f64 {
        let cos = self.theta_deg.to_radians().cos();
        if cos > 1e-9 {
            self.projected_solid_angle_sr / cos
        } else {
            // A ring centred on the horizon: Λ / cos is unbounded; the true
            // solid angle is the sensible weight there.
            self.solid_angle_sr
        }
    }

    /// `n` directions spread over the patch uniformly in projected solid
    /// angle, as unit vectors on the +z hemisphere
    /// (sin θ cos φ, sin θ sin φ, cos θ).
    ///
    /// The patch is cut into an `a × b` grid of equal strata in
    /// (cos² θ, φ), with `a · b = n` and `a` the largest divisor of `n` not
    /// above √n (16 → 4 × 4, 32 → 4 × 8), and one point is drawn in each
    /// stratum from `rng`. Equal cells in cos² θ carry equal Λ, so the
    /// plain mean of f over the points estimates the patch average
    /// (1/Λ) ∫ f cos θ dω that Klems values are. The same `rng` state
    /// gives the same points: averages are deterministic.
    pub fn stratified_directions(&self, n: usize, rng: &mut Rng) -> Vec<DVec3> {
        let n = n.max(1);
        let rows = (1..=n)
            .take_while(|a| a * a <= n)
            .filter(|a| n.is_multiple_of(*a))
            .last()
            .unwrap_or(1);
        let columns = n / rows;
        let (lo, hi) = self.theta_bounds_deg;
        // cos² θ runs from its value at the lower bound (larger) down to
        // the upper bound.
        let c2_top = lo.to_radians().cos().powi(2);
        let c2_bottom = hi.to_radians().cos().powi(2);
        let (phi_lo, phi_hi) = self.phi_bounds_deg;
        let mut out = Vec::with_capacity(n);
        for r in 0..rows {
            for c in 0..columns {
                let [ju, jv] = rng.uniform2();
                let t = (r as f64 + ju) / rows as f64;
                let cos2 = c2_top + (c2_bottom - c2_top) * t;
                let cos_theta = cos2.max(0.0).sqrt();
                let sin_theta = (1.0 - cos2).max(0.0).sqrt();
                let phi =
                    (phi_lo + (phi_hi - phi_lo) * (c as f64 + jv) / columns as f64).to_radians();
                out.push(DVec3::new(
                    sin_theta * phi.cos(),
                    sin_theta * phi.sin(),
                    cos_theta,
                ));
            }
        }
        out
    }
}

/// A Klems basis: its name, its rings and the patches they make.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct KlemsBasis {
    /// `LBNL/Klems Full`, `LBNL/Klems Half`, `LBNL/Klems Quarter`, or the
    /// name a file gave its own basis.
    pub name: String,
    /// The θ rings, from the pole outwards.
    pub rings: Vec<KlemsRing>,
    #[serde(skip)]
    patches: Vec<KlemsPatch>,
}

/// The built-in bases: name, ring bounds, patches per ring.
const BUILT_IN: [(&str, &[f64], &[usize]); 3] = [
    (
        "LBNL/Klems Full",
        &[0.0, 5.0, 15.0, 25.0, 35.0, 45.0, 55.0, 65.0, 75.0, 90.0],
        &[1, 8, 16, 20, 24, 24, 24, 16, 12],
    ),
    (
        "LBNL/Klems Half",
        &[0.0, 6.5, 19.5, 32.5, 46.5, 61.5, 76.5, 90.0],
        &[1, 8, 12, 16, 20, 12, 4],
    ),
    (
        "LBNL/Klems Quarter",
        &[0.0, 9.0, 27.0, 46.0, 66.0, 90.0],
        &[1, 8, 12, 12, 8],
    ),
];

/// More patches than any real basis has; refusing larger ones keeps a
/// hostile file from asking for a huge matrix.
pub(super) const MAX_PATCHES: usize = 4096;

/// The three built-in Klems bases by size.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum BasisSize {
    /// `LBNL/Klems Full`: 145 patches.
    #[default]
    Full,
    /// `LBNL/Klems Half`: 73 patches.
    Half,
    /// `LBNL/Klems Quarter`: 41 patches.
    Quarter,
}

brtf_model::option_words!(BasisSize { Full => "full", Half => "half", Quarter => "quarter" });

impl BasisSize {
    /// The basis.
    pub fn basis(self) -> KlemsBasis {
        let (name, _, _) = BUILT_IN[self as usize];
        KlemsBasis::built_in(name).expect("a built-in basis")
    }
}

impl KlemsBasis {
    /// The Klems Full basis (145 patches).
    pub fn full() -> Self {
        Self::built_in("LBNL/Klems Full").expect("a built-in basis")
    }

    /// A built-in basis by name (`LBNL/Klems Full`, `… Half`, `… Quarter`;
    /// case and surrounding blanks ignored), or `None`.
    pub fn built_in(name: &str) -> Option<Self> {
        let name = name.trim();
        let (canonical, bounds, counts) = BUILT_IN
            .iter()
            .find(|(n, _, _)| n.eq_ignore_ascii_case(name))?;
        let rings = counts
            .iter()
            .enumerate()
            .map(|(k, &n_phis)| {
                let (lower, upper) = (bounds[k], bounds[k + 1]);
                KlemsRing {
                    // The polar cap is centred on the pole, the others midway.
                    theta_deg: if k == 0 { 0.0 } else { 0.5 * (lower + upper) },
                    lower_theta_deg: lower,
                    upper_theta_deg: upper,
                    n_phis,
                }
            })
            .collect();
        Self::from_rings(canonical, rings).ok()
    }

    /// A basis from explicit rings (a file's `AngleBasisBlock`s), checked:
    /// bounds from 0° to 90° without gaps or overlaps, centres inside their
    /// bounds, at least one patch per ring, at most [`MAX_PATCHES`] in all.
    pub fn from_rings(name: &str, rings: Vec<KlemsRing>) -> Result<Self, String> {
        const EPS: f64 = 1e-6;
        if rings.is_empty() {
            return Err("the basis has no rings".into());
        }
        let mut expected_lower = 0.0;
        let mut total = 0usize;
        for (k, ring) in rings.iter().enumerate() {
            let values = [ring.theta_deg, ring.lower_theta_deg, ring.upper_theta_deg];
            if values.iter().any(|v| !v.is_finite()) {
                return Err(format!("ring {}: angles must be finite numbers", k + 1));
            }
            if (ring.lower_theta_deg - expected_lower).abs() > EPS {
                return Err(format!(
                    "ring {}: LowerTheta {} should be {expected_lower} (rings must tile 0-90 degrees in order)",
                    k + 1,
                    ring.lower_theta_deg
                ));
            }
            if ring.upper_theta_deg <= ring.lower_theta_deg || ring.upper_theta_deg > 90.0 + EPS {
                return Err(format!(
                    "ring {}: UpperTheta {} must lie above LowerTheta {} and at most at 90",
                    k + 1,
                    ring.upper_theta_deg,
                    ring.lower_theta_deg
                ));
            }
            if ring.theta_deg < ring.lower_theta_deg - EPS
                || ring.theta_deg > ring.upper_theta_deg + EPS
            {
                return Err(format!(
                    "ring {}: Theta {} lies outside its bounds [{}, {}]",
                    k + 1,
                    ring.theta_deg,
                    ring.lower_theta_deg,
                    ring.upper_theta_deg
                ));
            }
            if ring.n_phis == 0 {
                return Err(format!("ring {}: nPhis must be at least 1", k + 1));
            }
            total = total.saturating_add(ring.n_phis);
            if total > MAX_PATCHES {
                return Err(format!("more than {MAX_PATCHES} patches"));
            }
            expected_lower = ring.upper_theta_deg;
        }
        if (expected_lower - 90.0).abs() > EPS {
            return Err(format!(
                "the rings end at {expected_lower} degrees, not at 90"
            ));
        }
        let mut patches = Vec::with_capacity(total);
        for (k, ring) in rings.iter().enumerate() {
            let (cos_lo, cos_hi) = (
                ring.lower_theta_deg.to_radians().cos(),
                ring.upper_theta_deg.to_radians().cos().max(0.0),
            );
            let n = ring.n_phis as f64;
            let half_width = 180.0 / n;
            for j in 0..ring.n_phis {
                let phi = 360.0 * j as f64 / n;
                patches.push(KlemsPatch {
                    ring: k,
                    theta_deg: ring.theta_deg,
                    phi_deg: phi,
                    theta_bounds_deg: (ring.lower_theta_deg, ring.upper_theta_deg),
                    phi_bounds_deg: (phi - half_width, phi + half_width),
                    solid_angle_sr: 2.0 * PI * (cos_lo - cos_hi) / n,
                    projected_solid_angle_sr: PI * (cos_lo * cos_lo - cos_hi * cos_hi) / n,
                });
            }
        }
        Ok(Self {
            name: name.trim().to_string(),
            rings,
            patches,
        })
    }

    /// Number of patches.
    pub fn len(&self) -> usize {
        self.patches.len()
    }

    /// True for a basis without patches (never, once built).
    pub fn is_empty(&self) -> bool {
        self.patches.is_empty()
    }

    /// The patches, ring by ring from the pole.
    pub fn patches(&self) -> &[KlemsPatch] {
        &self.patches
    }

    /// Patch `index`, if it exists.
    pub fn patch(&self, index: usize) -> Option<&KlemsPatch> {
        self.patches.get(index)
    }

    /// The projected solid angles Λ of all patches, in patch order.
    pub fn projected_solid_angles(&self) -> Vec<f64> {
        self.patches
            .iter()
            .map(|p| p.projected_solid_angle_sr)
            .collect()
    }

    /// True when both bases have the same rings (names may differ).
    pub fn same_geometry(&self, other: &KlemsBasis) -> bool {
        self.rings.len() == other.rings.len()
            && self.rings.iter().zip(&other.rings).all(|(a, b)| {
                a.n_phis == b.n_phis
                    && (a.lower_theta_deg - b.lower_theta_deg).abs() < 1e-6
                    && (a.upper_theta_deg - b.upper_theta_deg).abs() < 1e-6
            })
    }

    /// The patch holding the direction at polar angle `theta_deg` from the
    /// hemisphere's normal (0-90°) and azimuth `phi_deg`: the ring whose
    /// bounds hold θ (upper bound exclusive, 90° belongs to the last ring),
    /// then the azimuth patch nearest φ. `None` for θ outside 0-90° or a
    /// non-finite angle.
    pub fn patch_index(&self, theta_deg: f64, phi_deg: f64) -> Option<usize> {
        if !(0.0..=90.0).contains(&theta_deg) || !phi_deg.is_finite() {
            return None;
        }
        let last = self.rings.len().checked_sub(1)?;
        let ring = self
            .rings
            .iter()
            .position(|r| theta_deg < r.upper_theta_deg)
            .unwrap_or(last);
        let first: usize = self.rings[..ring].iter().map(|r| r.n_phis).sum();
        let n = self.rings[ring].n_phis;
        let phi = phi_deg.rem_euclid(360.0);
        let j = ((phi * n as f64 / 360.0 + 0.5).floor() as usize) % n;
        Some(first + j)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn built_in_bases_have_their_sizes_and_sum_to_pi() {
        for (name, n) in [
            ("LBNL/Klems Full", 145),
            ("lbnl/klems half", 73),
            (" LBNL/Klems Quarter ", 41),
        ] {
            let basis = KlemsBasis::built_in(name).unwrap();
            assert_eq!(basis.len(), n, "{name}");
            let sum: f64 = basis.projected_solid_angles().iter().sum();
            assert!((sum - PI).abs() < 1e-12, "{name}: {sum}");
            let omega: f64 = basis.patches().iter().map(|p| p.solid_angle_sr).sum();
            assert!((omega - 2.0 * PI).abs() < 1e-12, "{name}: {omega}");
        }
        assert!(KlemsBasis::built_in("LBNL/Klems Eighth").is_none());
    }

    #[test]
    fn full_basis_centres_and_lookup() {
        let basis = KlemsBasis::full();
        let centres: Vec<f64> = basis.rings.iter().map(|r| r.theta_deg).collect();
        assert_eq!(
            centres,
            [0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 82.5]
        );
        for (i, p) in basis.patches().iter().enumerate() {
            assert_eq!(basis.patch_index(p.theta_deg, p.phi_deg), Some(i));
        }
        // Patch 1 (10°, 0°) spans φ ∈ [−22.5°, 22.5°).
        assert_eq!(basis.patch_index(10.0, 359.0), Some(1));
        assert_eq!(basis.patch_index(10.0, 22.4), Some(1));
        assert_eq!(basis.patch_index(10.0, 22.6), Some(2));
        assert_eq!(basis.patch_index(90.0, 0.0), Some(133));
        assert_eq!(basis.patch_index(90.5, 0.0), None);
    }

    #[test]
    fn stratified_directions_stay_in_their_patch_and_average_cos_theta() {
        let basis = KlemsBasis::full();
        let mut rng = Rng::new(7, 0);
        for (i, p) in basis.patches().iter().enumerate() {
            let points = p.stratified_directions(64, &mut rng);
            assert_eq!(points.len(), 64);
            for v in &points {
                assert!((v.length() - 1.0).abs() < 1e-12);
                let theta = v.z.clamp(-1.0, 1.0).acos().to_degrees();
                let phi = v.y.atan2(v.x).to_degrees();
                assert_eq!(basis.patch_index(theta, phi), Some(i), "{theta} {phi}");
            }
            // Uniform in projected solid angle: the mean of 1/cos θ over
            // the points estimates Ω/Λ.
            let mean: f64 = points.iter().map(|v| 1.0 / v.z).sum::<f64>() / 64.0;
            let exact = p.solid_angle_sr / p.projected_solid_angle_sr;
            if p.theta_bounds_deg.1 < 80.0 {
                assert!(
                    (mean / exact - 1.0).abs() < 0.01,
                    "patch {i}: {mean} vs {exact}"
                );
            }
        }
        // Deterministic for a given seed.
        let p = basis.patch(40).unwrap();
        assert_eq!(
            p.stratified_directions(16, &mut Rng::new(3, 1)),
            p.stratified_directions(16, &mut Rng::new(3, 1))
        );
    }
}
