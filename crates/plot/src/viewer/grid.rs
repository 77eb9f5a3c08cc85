//! The model surfaces of the 3D view: model values on a square grid over
//! each hemisphere's unit disk, only where the scan has samples nearby
//! (a surface where nothing was measured would show the model alone).

use super::{NONE, encode};
use crate::prepare::Incidence;
use brtf_fit::FitResult;
use brtf_gonio::Hemisphere;
use brtf_model::CompositeBsdf;
use glam::DVec3;
use rayon::prelude::*;

/// Nodes per side of the grid of an incidence of `samples` samples: odd
/// (one node at the centre), about 1.2 √n, from 25 (a Klems basis) to 97
/// (a dense scan), so that a sparse scan's surfaces stay small.
pub(crate) fn size(samples: usize) -> usize {
    let side = (1.2 * (samples as f64).sqrt()).round() as usize;
    side.clamp(25, 97) | 1
}

/// The direction at unit-disk position `(u, v)` of `hemisphere` (the
/// inverse of the equal-area projection), `None` outside the disk.
fn direction(u: f64, v: f64, hemisphere: Hemisphere) -> Option<DVec3> {
    let rho2 = u * u + v * v;
    if rho2 > 1.0 {
        return None;
    }
    // Disk radius √2·ρ: cos θ = 1 − r²/2 = 1 − ρ².
    let cos = 1.0 - rho2;
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    let rho = rho2.sqrt();
    let (x, y) = if rho > 1e-12 {
        (u / rho * sin, v / rho * sin)
    } else {
        (0.0, 0.0)
    };
    let z = match hemisphere {
        Hemisphere::Front => cos,
        Hemisphere::Back => -cos,
    };
    Some(DVec3::new(x, y, z))
}

/// Which cells of a coarse grid over `hemisphere`'s disk hold a sample,
/// widened by one cell: `(cells per side, occupied)`.
fn occupancy(inc: &Incidence, hemisphere: Hemisphere) -> (usize, Vec<bool>) {
    let back = hemisphere == Hemisphere::Back;
    let count = inc
        .samples
        .iter()
        .filter(|s| (s.dir.z < 0.0) == back)
        .count();
    // About one sample per cell of the widened grid: a sparse scan (a
    // Klems basis) still gets a closed surface.
    let side = ((count as f64).sqrt() * 0.6).round().clamp(6.0, 96.0) as usize;
    let cell = |u: f64| (((u + 1.0) * 0.5 * side as f64) as usize).min(side - 1);
    let mut hit = vec![false; side * side];
    for s in inc.samples.iter().filter(|s| (s.dir.z < 0.0) == back) {
        let (x, y, _) = super::disk_xy(s.dir);
        hit[cell(y) * side + cell(x)] = true;
    }
    let mut wide = hit.clone();
    for j in 0..side {
        for i in 0..side {
            if !hit[j * side + i] {
                continue;
            }
            for (dj, di) in [
                (0, 1),
                (2, 1),
                (1, 0),
                (1, 2),
                (0, 0),
                (0, 2),
                (2, 0),
                (2, 2),
            ] {
                let (jj, ii) = ((j + dj).wrapping_sub(1), (i + di).wrapping_sub(1));
                if jj < side && ii < side {
                    wide[jj * side + ii] = true;
                }
            }
        }
    }
    (side, wide)
}

/// `model` on the grid of each of `hemispheres` (in that order), as
/// little-endian u16 codes on `[lo, hi]`; [`NONE`] where no sample is
/// near or outside the disk.
pub(crate) fn surface(
    inc: &Incidence,
    hemispheres: &[Hemisphere],
    model: impl Fn(DVec3) -> f64 + Sync,
    lo: f64,
    hi: f64,
) -> Vec<u8> {
    let size = size(inc.samples.len());
    let mut bytes = Vec::with_capacity(2 * size * size * hemispheres.len());
    for &hemisphere in hemispheres {
        let (side, occupied) = occupancy(inc, hemisphere);
        let at = |k: usize| -> u16 {
            let (i, j) = (k % size, k / size);
            let u = -1.0 + 2.0 * i as f64 / (size - 1) as f64;
            let v = -1.0 + 2.0 * j as f64 / (size - 1) as f64;
            let cell = |w: f64| (((w + 1.0) * 0.5 * side as f64) as usize).min(side - 1);
            match direction(u, v, hemisphere) {
                Some(dir) if occupied[cell(v) * side + cell(u)] => encode(model(dir), lo, hi),
                _ => NONE,
            }
        };
        let codes: Vec<u16> = (0..size * size).into_par_iter().map(at).collect();
        bytes.extend(codes.iter().flat_map(|c| c.to_le_bytes()));
    }
    bytes
}

/// A model's value at a direction (scale × channel mean).
pub(crate) type ModelAt = Box<dyn Fn(DVec3) -> f64 + Sync>;

/// Every `--model auto` candidate other than the chosen one, with its
/// model for this incidence (scale × channel mean), when the fit kept its
/// fitted arguments.
pub(crate) fn candidates(result: &FitResult, inc: &Incidence) -> Vec<(String, ModelAt)> {
    let Some(auto) = &result.auto else {
        return Vec::new();
    };
    let channels = inc.channels;
    let light = inc.light;
    auto.candidates
        .iter()
        .enumerate()
        .filter(|(k, c)| *k != auto.chosen && c.fitted.len() == result.incidences.len())
        .filter_map(|(_, c)| {
            let (args, scale) = c.fitted.get(inc.index)?.clone();
            let shape = brtf_model::Shape::new(c.kind, c.lobes, c.oriented).ok()?;
            let orientation = Some(DVec3::from_array(result.config.orientation));
            let material = brtf_model::Composite::new(shape, &args, orientation).ok()?;
            let bsdf = CompositeBsdf::new(&material, &result.options());
            let model = move |v: DVec3| {
                let f = bsdf.eval(light, v);
                scale * f[..channels].iter().sum::<f64>() / channels as f64
            };
            Some((c.model.clone(), Box::new(model) as ModelAt))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_grid_inverts_the_disk_projection() {
        for (theta, phi) in [(0.0f64, 0.0f64), (30.0, 45.0), (60.0, 200.0), (89.0, 300.0)] {
            let (t, p) = (theta.to_radians(), phi.to_radians());
            let dir = DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
            let (u, v, h) = super::super::disk_xy(dir);
            assert_eq!(h, Hemisphere::Front);
            let back = direction(u, v, h).unwrap();
            assert!(
                (back - dir).length() < 1e-9,
                "{theta} {phi}: {back} vs {dir}"
            );
            let below = direction(u, v, Hemisphere::Back).unwrap();
            assert!((below.z + dir.z).abs() < 1e-12);
        }
        assert!(direction(0.8, 0.7, Hemisphere::Front).is_none());
    }
}
