//! The totals Radiance's libBSDF reports for a tree block (what
//! `checkBSDF` prints): the largest directional total and the Lambertian
//! part it splits off.

use std::f64::consts::PI;

use super::{TreeBlock, TreeRank};

impl TreeBlock {
    /// The largest total over input cells of side max(smallest leaf,
    /// 1/32), each averaged over its cell, as Radiance's libBSDF computes
    /// it (`checkBSDF`'s "Max. Tot. Dir").
    pub fn max_total(&self, rank: TreeRank) -> f64 {
        let width = 0.5f64.powi(self.depth as i32).max(1.0 / 32.0);
        let n = (1.0 / width).round() as usize;
        let inputs = rank.dimensions() - 2;
        // TensorTree3 uses x₀ < ½ only.
        let n0 = if inputs == 1 { n / 2 } else { n };
        let n1 = if inputs == 1 { 1 } else { n };
        let mut sums = vec![0.0; n0 * n1];
        for c in &self.cells {
            let energy = c.value * PI * c.size * c.size;
            let range = |i: usize, count: usize| {
                let lo = ((c.min[i] / width).floor() as usize).min(count);
                let hi = (((c.min[i] + c.size) / width).ceil() as usize).min(count);
                (lo, hi)
            };
            let overlap = |i: usize, k: usize| {
                let (a, b) = (k as f64 * width, (k + 1) as f64 * width);
                ((c.min[i] + c.size).min(b) - c.min[i].max(a)).max(0.0) / width
            };
            let (a0, b0) = range(0, n0);
            let (a1, b1) = if inputs == 2 { range(1, n1) } else { (0, 1) };
            for k0 in a0..b0 {
                for k1 in a1..b1 {
                    let w1 = if inputs == 2 { overlap(1, k1) } else { 1.0 };
                    sums[k0 * n1 + k1] += energy * overlap(0, k0) * w1;
                }
            }
        }
        sums.into_iter().fold(0.0, f64::max)
    }

    /// The Lambertian part Radiance splits off: π × the smallest value
    /// (of the used half for `TensorTree3`), 0 when that is at most 0.01
    /// or at least 1.5 (`checkBSDF`'s "Lambertian").
    pub fn lambertian(&self, rank: TreeRank) -> f64 {
        let min = self
            .cells
            .iter()
            .filter(|c| rank == TreeRank::Anisotropic || c.min[0] < 0.5)
            .map(|c| c.value)
            .fold(f64::INFINITY, f64::min);
        let part = PI * min;
        if part.is_finite() && part > 0.01 && part < 1.5 {
            part
        } else {
            0.0
        }
    }
}
