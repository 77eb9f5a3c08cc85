//! Tensor-tree BSDF XML (`TensorTree3`, `TensorTree4`): Radiance's
//! variable-resolution format (`bsdf_t.c`, written by `bsdf2ttree` and
//! `rttree_reduce`).
//!
//! Each block's `ScatteringData` is a tree of cells over a unit hypercube:
//! 4-D for `TensorTree4` (the incident direction's Shirley–Chiu square,
//! then the outgoing one's), 3-D for the isotropic `TensorTree3` (one
//! input coordinate x₀ = ½ − ½ sin θ_in, then the outgoing square with the
//! source turned to φ = 180°; x₀ ≥ ½ is unused). The incident direction
//! points towards the source; its square point is that of its reverse,
//! (−l_x, −l_y). A cell's value is the BSDF (1/sr) over the cell. Sides
//! and blocks follow the Klems names (`Reflection Back` = Radiance's rf,
//! light from +z; see [`super`]). `docs/klems.md` gives the checks.

mod info;
mod measure;
mod parse;
#[cfg(test)]
mod parse_tests;
mod read;
pub mod square;
mod totals;

use std::f64::consts::PI;

use serde::Serialize;

use super::{KlemsBand, KlemsDirection, KlemsHeader, Side};

pub use info::{INFO_THETAS, TreeBlockInfo, TreeInfo};
pub use measure::TreeSample;
pub use parse::MAX_DEPTH;
pub(super) use read::read_tree;

/// One leaf cell: its lower corner, its side and its BSDF value (1/sr).
/// Only the first `rank` coordinates of `min` are used.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TreeCell {
    /// Lower corner in the unit hypercube.
    pub min: [f64; 4],
    /// Side length (a power of ½).
    pub size: f64,
    /// BSDF, 1/sr.
    pub value: f64,
}

/// `TensorTree3` (isotropic) or `TensorTree4` (anisotropic).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum TreeRank {
    /// `TensorTree3`: θ_in only; the outgoing square turns with φ_in.
    #[serde(rename = "TensorTree3")]
    Isotropic,
    /// `TensorTree4`: the full incident direction.
    #[serde(rename = "TensorTree4")]
    Anisotropic,
}

impl TreeRank {
    /// The number of dimensions: 3 or 4.
    pub fn dimensions(self) -> usize {
        match self {
            TreeRank::Isotropic => 3,
            TreeRank::Anisotropic => 4,
        }
    }

    /// The file's spelling.
    pub fn name(self) -> &'static str {
        match self {
            TreeRank::Isotropic => "TensorTree3",
            TreeRank::Anisotropic => "TensorTree4",
        }
    }
}

/// One `WavelengthDataBlock`: a band, a direction and its tree's leaves.
#[derive(Clone, Debug, PartialEq)]
pub struct TreeBlock {
    /// The band.
    pub band: KlemsBand,
    /// The direction (which side is lit, reflection or transmission).
    pub direction: KlemsDirection,
    /// The leaves (for `TensorTree3`, only those of the used half).
    pub cells: Vec<TreeCell>,
    /// The deepest halving of the unit square: the smallest leaf is 2^−depth.
    pub depth: u32,
    /// Values between −1e-3 and 0 read as 0.
    pub clipped_negative: usize,
    /// The line of the `ScatteringData` element.
    pub line: usize,
}

/// One outgoing cell of a block at a given incidence, on the outgoing
/// Shirley–Chiu square.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OutCell {
    /// Lower corner on the square.
    pub x: f64,
    /// Lower corner on the square.
    pub y: f64,
    /// Side length.
    pub size: f64,
    /// BSDF, 1/sr.
    pub value: f64,
    /// The leaf's lower corner in the input dimensions.
    pub input_min: [f64; 2],
}

impl OutCell {
    /// Its projected solid angle, π s².
    pub fn projected_solid_angle(&self) -> f64 {
        PI * self.size * self.size
    }
}

impl TreeBlock {
    /// The outgoing cells lit from square input point `input` (x₀ only for
    /// `TensorTree3`).
    pub fn slice(&self, rank: TreeRank, input: [f64; 2]) -> Vec<OutCell> {
        let inputs = rank.dimensions() - 2;
        self.cells
            .iter()
            .filter(|c| (0..inputs).all(|i| c.min[i] <= input[i] && input[i] < c.min[i] + c.size))
            .map(|c| OutCell {
                x: c.min[inputs],
                y: c.min[inputs + 1],
                size: c.size,
                value: c.value,
                input_min: [c.min[0], if inputs == 2 { c.min[1] } else { 0.0 }],
            })
            .collect()
    }

    /// The hemispherical total of a slice: Σ value · π s².
    pub fn total(&self, rank: TreeRank, input: [f64; 2]) -> f64 {
        self.slice(rank, input)
            .iter()
            .map(|c| c.value * c.projected_solid_angle())
            .sum()
    }
}

/// A tensor-tree BSDF XML file, read.
#[derive(Clone, Debug, PartialEq)]
pub struct TensorTree {
    /// The file's display path.
    pub source: String,
    /// The header fields.
    pub header: KlemsHeader,
    /// 3 or 4 dimensions.
    pub rank: TreeRank,
    /// Every block, in file order.
    pub blocks: Vec<TreeBlock>,
}

impl TensorTree {
    /// The block of `band` and `direction`, if present.
    pub fn block(&self, band: &KlemsBand, direction: KlemsDirection) -> Option<&TreeBlock> {
        self.blocks
            .iter()
            .find(|b| &b.band == band && b.direction == direction)
    }

    /// The sides with Visible data, front first.
    pub fn sides_present(&self) -> Vec<Side> {
        Side::BOTH
            .into_iter()
            .filter(|&side| {
                self.blocks
                    .iter()
                    .any(|b| b.band == KlemsBand::Visible && b.direction.incident_side() == side)
            })
            .collect()
    }

    /// The deepest halving of any block.
    pub fn depth(&self) -> u32 {
        self.blocks.iter().map(|b| b.depth).max().unwrap_or(0)
    }

    /// The input point of incidence (θ, φ) towards the source, in the lit
    /// side's own frame (θ 0–90° from that side's normal).
    pub fn input_point(&self, theta_deg: f64, phi_deg: f64) -> [f64; 2] {
        let below_half = 0.5 - 1e-12;
        match self.rank {
            TreeRank::Isotropic => {
                let s = theta_deg.to_radians().sin().clamp(0.0, 1.0);
                [(0.5 - 0.5 * s).clamp(0.0, below_half), 0.0]
            }
            TreeRank::Anisotropic => {
                let d = square::angles_to_disk(theta_deg, phi_deg);
                let p = square::disk_to_square(-d[0], -d[1]);
                [p[0].clamp(0.0, 1.0 - 1e-12), p[1].clamp(0.0, 1.0 - 1e-12)]
            }
        }
    }

    /// ρ_dh and τ_dh (Visible, or the first band) of incidence (θ, φ) lit
    /// from `side`, in that side's frame; `None` where a block is absent.
    pub fn totals(&self, side: Side, theta_deg: f64, phi_deg: f64) -> (Option<f64>, Option<f64>) {
        let band = self.totals_band();
        let input = self.input_point(theta_deg, phi_deg);
        let total = |d| self.block(&band, d).map(|b| b.total(self.rank, input));
        (total(side.reflection()), total(side.transmission()))
    }

    /// Visible when present, else the first block's band.
    pub fn totals_band(&self) -> KlemsBand {
        if self.blocks.iter().any(|b| b.band == KlemsBand::Visible) {
            KlemsBand::Visible
        } else {
            self.blocks
                .first()
                .map_or(KlemsBand::Visible, |b| b.band.clone())
        }
    }
}
