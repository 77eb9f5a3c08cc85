//! A tensor tree at one incidence as a [`Measurement`]: one sample per
//! outgoing leaf cell, like a Klems column is one sample per patch.

use glam::DVec3;

use super::square::{disk_to_angles, square_to_disk};
use super::{TensorTree, TreeRank};
use crate::klems::{KlemsBand, Side};
use crate::measurement::{
    Channels, Incidence, IncidenceOrigin, Measurement, Quantity, Sample, SourceFormat,
};

/// Where one sample of a tree measurement lies: its outgoing cell on the
/// Shirley–Chiu square, turned by `turn_deg` about the normal (the
/// isotropic tree's frame has the source at φ = 180°), on the reflection
/// or the transmission side of the lit side's frame (light on +z).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TreeSample {
    /// Lower corner on the square.
    pub x: f64,
    /// Lower corner on the square.
    pub y: f64,
    /// Side length.
    pub size: f64,
    /// Azimuth added to the square's directions, degrees.
    pub turn_deg: f64,
    /// On the transmission side (z < 0).
    pub transmitted: bool,
    /// The leaf's lower corner in the input dimensions (x₀ only for
    /// `TensorTree3`).
    pub input_min: [f64; 2],
    /// The tree's rank.
    pub rank: TreeRank,
    /// The source's azimuth, degrees (the isotropic tree's light lies in
    /// this plane).
    pub phi_in_deg: f64,
}

impl TreeSample {
    /// The direction of square point (u, v) of the cell (each in [0, 1]).
    pub fn direction_at(&self, u: f64, v: f64) -> DVec3 {
        let d = square_to_disk(self.x + u * self.size, self.y + v * self.size);
        let (s, c) = self.turn_deg.to_radians().sin_cos();
        let (dx, dy) = (c * d[0] - s * d[1], s * d[0] + c * d[1]);
        let z = (1.0 - dx * dx - dy * dy).max(0.0).sqrt();
        DVec3::new(dx, dy, if self.transmitted { -z } else { z })
    }

    /// The light direction (towards the source, on +z) of input point
    /// (u, v) of the leaf (each in [0, 1]; v unused for `TensorTree3`).
    pub fn light_at(&self, u: f64, v: f64) -> DVec3 {
        match self.rank {
            TreeRank::Isotropic => {
                let x = self.input_min[0] + u * self.size;
                let s = (1.0 - 2.0 * x).clamp(0.0, 1.0);
                let (sp, cp) = self.phi_in_deg.to_radians().sin_cos();
                DVec3::new(s * cp, s * sp, (1.0 - s * s).sqrt())
            }
            TreeRank::Anisotropic => {
                let d = square_to_disk(
                    self.input_min[0] + u * self.size,
                    self.input_min[1] + v * self.size,
                );
                let z = (1.0 - d[0] * d[0] - d[1] * d[1]).max(0.0).sqrt();
                DVec3::new(-d[0], -d[1], z)
            }
        }
    }

    /// `n` (light, view) pairs spread over the leaf's whole hypercube: the
    /// views stratified over its outgoing cell
    /// ([`stratified_directions`](Self::stratified_directions)), the
    /// lights stratified in the first input coordinate (shuffled against
    /// the views) and jittered in the second. `rttree_reduce` merges
    /// finer leaves by averaging them, inputs included, so their mean
    /// estimates the leaf's value.
    pub fn stratified_pairs(&self, n: usize, rng: &mut brtf_model::Rng) -> Vec<(DVec3, DVec3)> {
        let views = self.stratified_directions(n, rng);
        let n = views.len();
        let mut order: Vec<usize> = (0..n).collect();
        for k in (1..n).rev() {
            let j = ((rng.uniform() * (k + 1) as f64) as usize).min(k);
            order.swap(k, j);
        }
        views
            .into_iter()
            .zip(order)
            .map(|(view, stratum)| {
                let [ju, jv] = rng.uniform2();
                (self.light_at((stratum as f64 + ju) / n as f64, jv), view)
            })
            .collect()
    }

    /// `n` directions stratified over the cell, one per stratum of an
    /// a × b grid on the square, jittered by `rng`: uniform in projected
    /// solid angle (the map keeps areas), so their plain mean of f is the
    /// cell's average.
    pub fn stratified_directions(&self, n: usize, rng: &mut brtf_model::Rng) -> Vec<DVec3> {
        let n = n.max(1);
        let rows = (1..=n)
            .take_while(|a| a * a <= n)
            .filter(|a| n.is_multiple_of(*a))
            .last()
            .unwrap_or(1);
        let columns = n / rows;
        let mut out = Vec::with_capacity(n);
        for r in 0..rows {
            for c in 0..columns {
                let [ju, jv] = rng.uniform2();
                let u = (r as f64 + ju) / rows as f64;
                let v = (c as f64 + jv) / columns as f64;
                out.push(self.direction_at(u, v));
            }
        }
        out
    }
}

/// The input cell side used to place incidences: the finest leaf.
fn finest(tree: &TensorTree) -> f64 {
    0.5f64.powi(tree.depth() as i32)
}

impl TensorTree {
    /// Incidence (θ, φ) (towards the source, in the lit side's frame)
    /// moved to the centre of the finest input cell holding it: where
    /// `bsdf2ttree` evaluates its function.
    pub fn cell_centre_incidence(&self, theta_deg: f64, phi_deg: f64) -> (f64, f64) {
        let w = finest(self);
        let p = self.input_point(theta_deg, phi_deg);
        let centre = |x: f64| ((x / w).floor() + 0.5) * w;
        let (theta, phi) = match self.rank {
            TreeRank::Isotropic => {
                let s = (1.0 - 2.0 * centre(p[0])).clamp(0.0, 1.0);
                (s.asin().to_degrees(), phi_deg)
            }
            TreeRank::Anisotropic => {
                let d = square_to_disk(centre(p[0]), centre(p[1]));
                disk_to_angles([-d[0], -d[1]])
            }
        };
        // To 1e-4°: readable, still inside the cell, and the same again
        // when a fit's incidence is placed a second time.
        let round = |a: f64| (a * 1e4).round() / 1e4;
        (round(theta), round(phi))
    }

    /// Incidence (θ, φ) lit from `side` as one [`Measurement`] in that
    /// side's frame (light on +z; reflection samples on +z, transmission
    /// on −z), at the centre of its finest input cell
    /// ([`cell_centre_incidence`](Self::cell_centre_incidence)), with where
    /// each sample lies. One sample per outgoing cell of the side's
    /// Visible blocks at the cell centre, valued the leaf's BSDF, with
    /// `solid_angle_sr` = Λ / cos θ_centre (Λ = π s²), so that brtf's
    /// integrals give the hemispherical totals. `None` when the side has
    /// no Visible block.
    pub fn measurement(
        &self,
        side: Side,
        theta_deg: f64,
        phi_deg: f64,
    ) -> Option<(Measurement, Vec<TreeSample>)> {
        let (theta, phi) = self.cell_centre_incidence(theta_deg, phi_deg);
        let input = self.input_point(theta, phi);
        let turn_deg = match self.rank {
            TreeRank::Isotropic => phi - 180.0,
            TreeRank::Anisotropic => 0.0,
        };
        let mut samples = Vec::new();
        let mut places = Vec::new();
        for (direction, transmitted) in [(side.reflection(), false), (side.transmission(), true)] {
            let Some(block) = self.block(&KlemsBand::Visible, direction) else {
                continue;
            };
            for cell in block.slice(self.rank, input) {
                let place = TreeSample {
                    x: cell.x,
                    y: cell.y,
                    size: cell.size,
                    turn_deg,
                    transmitted,
                    input_min: cell.input_min,
                    rank: self.rank,
                    phi_in_deg: phi,
                };
                let v = place.direction_at(0.5, 0.5);
                let cos = v.z.abs().max(1e-6);
                let theta_c = v.z.abs().clamp(0.0, 1.0).acos().to_degrees();
                samples.push(Sample {
                    theta_deg: if transmitted {
                        180.0 - theta_c
                    } else {
                        theta_c
                    },
                    phi_deg: crate::normalize_phi_deg(v.y.atan2(v.x).to_degrees()),
                    values: [cell.value, 0.0, 0.0],
                    solid_angle_sr: Some(cell.projected_solid_angle() / cos),
                });
                places.push(place);
            }
        }
        if samples.is_empty() {
            return None;
        }
        let mut m = Measurement::new(
            SourceFormat::KlemsXml,
            Incidence::new(theta, phi),
            Quantity::Bsdf,
            Channels::Y,
            samples,
        );
        m.sample_name = self.header.name.clone();
        m.incidence_origin = IncidenceOrigin::Header;
        m.header = vec![format!(
            "{} leaf averages at theta_in {theta:.4}, phi_in {phi:.4} (the finest input cell's centre), lit from the {side} (+z is front; described with the light on +z), from {}",
            self.rank.name(),
            self.source
        )];
        Some((m, places))
    }
}
