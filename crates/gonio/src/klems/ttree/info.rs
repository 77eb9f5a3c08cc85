//! What `brtf info` prints for a tensor tree.

use std::fmt;

use serde::Serialize;

use super::TensorTree;
use crate::klems::{KlemsDirection, PatchTotals, Side};

/// The θ_in (degrees) at which `brtf info` lists the totals: the Klems
/// Full basis's ring centres, at φ_in = 0.
pub const INFO_THETAS: [f64; 9] = [0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 82.5];

/// One block as `brtf info` lists it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TreeBlockInfo {
    /// The band.
    pub band: String,
    /// The direction.
    pub direction: KlemsDirection,
    /// Radiance's name for it.
    pub radiance_component: &'static str,
    /// Where the light arrives from, in Radiance's frame.
    pub light_from: Side,
    /// The number of leaf cells.
    pub leaves: usize,
    /// The deepest halving of the unit square.
    pub depth: u32,
    /// The smallest leaf's side on the unit square, 2^−depth.
    pub smallest_leaf: f64,
    /// The largest hemispherical total over the input cells
    /// (`checkBSDF`'s "Max. Tot. Dir").
    pub max_total: f64,
    /// The Lambertian part Radiance splits off (`checkBSDF`'s
    /// "Lambertian").
    pub lambertian: f64,
    /// Values between −1e-3 and 0 read as 0.
    pub clipped_negative: usize,
}

/// What `brtf info tree.xml` prints (text via `Display`, or JSON).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TreeInfo {
    /// `TensorTree3 (isotropic tensor tree)` or `TensorTree4 (…)`.
    pub format: String,
    /// `Name`.
    pub name: Option<String>,
    /// `Manufacturer`.
    pub manufacturer: Option<String>,
    /// `DeviceType`.
    pub device_type: Option<String>,
    /// `TensorTree3` or `TensorTree4`.
    pub incident_data_structure: &'static str,
    /// The bands, in file order.
    pub bands: Vec<String>,
    /// Every block.
    pub blocks: Vec<TreeBlockInfo>,
    /// The band the totals come from (Visible when present).
    pub totals_band: String,
    /// Per side and θ_in of [`INFO_THETAS`] (φ_in = 0): ρ_dh, τ_dh.
    pub incidences: Vec<PatchTotals>,
}

impl TensorTree {
    /// The summary `brtf info` prints.
    pub fn info(&self) -> TreeInfo {
        let mut bands: Vec<String> = Vec::new();
        for b in &self.blocks {
            if !bands.iter().any(|n| n == b.band.name()) {
                bands.push(b.band.name().to_string());
            }
        }
        let band = self.totals_band();
        let mut incidences = Vec::new();
        for side in Side::BOTH {
            if self.block(&band, side.reflection()).is_none()
                && self.block(&band, side.transmission()).is_none()
            {
                continue;
            }
            for (k, &theta) in INFO_THETAS.iter().enumerate() {
                let (rho, tau) = self.totals(side, theta, 0.0);
                incidences.push(PatchTotals {
                    side,
                    patch: k,
                    theta_in_deg: side.theta_in_frame(theta),
                    phi_in_deg: 0.0,
                    rho_dh: rho,
                    tau_dh: tau,
                });
            }
        }
        let kind = match self.rank {
            super::TreeRank::Isotropic => "isotropic",
            super::TreeRank::Anisotropic => "anisotropic",
        };
        TreeInfo {
            format: format!("{} ({kind} tensor tree)", self.rank.name()),
            name: self.header.name.clone(),
            manufacturer: self.header.manufacturer.clone(),
            device_type: self.header.device_type.clone(),
            incident_data_structure: self.rank.name(),
            bands,
            blocks: self
                .blocks
                .iter()
                .map(|b| TreeBlockInfo {
                    band: b.band.name().to_string(),
                    direction: b.direction,
                    radiance_component: b.direction.radiance_component(),
                    light_from: b.direction.incident_side(),
                    leaves: b.cells.len(),
                    depth: b.depth,
                    smallest_leaf: 0.5f64.powi(b.depth as i32),
                    max_total: b.max_total(self.rank),
                    lambertian: b.lambertian(self.rank),
                    clipped_negative: b.clipped_negative,
                })
                .collect(),
            totals_band: band.name().to_string(),
            incidences,
        }
    }
}

impl fmt::Display for TreeInfo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let text = |v: &Option<String>| v.clone().unwrap_or_else(|| "(empty)".into());
        writeln!(f, "format        {}", self.format)?;
        writeln!(f, "name          {}", text(&self.name))?;
        writeln!(f, "manufacturer  {}", text(&self.manufacturer))?;
        writeln!(f, "device type   {}", text(&self.device_type))?;
        writeln!(f, "bands         {}", self.bands.join(", "))?;
        writeln!(
            f,
            "blocks (leaves; resolution = smallest leaf on the Shirley-Chiu square; max total and Lambertian as checkBSDF)"
        )?;
        for b in &self.blocks {
            let side = if b.light_from == Side::Front {
                "+z"
            } else {
                "-z"
            };
            write!(
                f,
                "  {:<8} {:<19} Radiance {}, light from {side}: {} leaves, depth {} (1/{}), max total {:.4}, Lambertian {:.4}",
                b.band,
                b.direction.name(),
                b.radiance_component,
                b.leaves,
                b.depth,
                1u64 << b.depth.min(63),
                b.max_total,
                b.lambertian
            )?;
            if b.clipped_negative > 0 {
                write!(
                    f,
                    ", {} small negative values read as 0",
                    b.clipped_negative
                )?;
            }
            writeln!(f)?;
        }
        writeln!(
            f,
            "per incidence ({} totals, sum of BSDF x pi s^2 over the outgoing leaves; theta_in > 90 = lit from the back)",
            self.totals_band
        )?;
        writeln!(f, "  side   theta_in  phi_in   rho_dh   tau_dh")?;
        let number =
            |v: Option<f64>| v.map_or_else(|| "       -".to_string(), |v| format!("{v:8.4}"));
        for p in &self.incidences {
            writeln!(
                f,
                "  {:<5} {:>9.2} {:>7.2} {} {}",
                p.side.name(),
                p.theta_in_deg,
                p.phi_in_deg,
                number(p.rho_dh),
                number(p.tau_dh)
            )?;
        }
        Ok(())
    }
}
