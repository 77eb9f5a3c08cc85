//! A colour measured elsewhere, given to a fit for its exports
//! (`--colour R,G,B`): one-channel scans measure luminance only.

use crate::FitResult;
use brtf_model::ShapeArg;

/// Why a colour cannot be given.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("--colour {},{},{}: give three reflectances ≥ 0, not all 0", .0[0], .0[1], .0[2])]
pub struct ColourError(pub [f64; 3]);

impl FitResult {
    /// This fit with every material's colour set to `rgb`'s chromaticity
    /// at the material's own luminance (CIE Y, about `0.265 R + 0.670 G +
    /// 0.065 B`),
    /// so what the measurement fixed (the luminance, hence the energy the
    /// one-channel data saw) is unchanged.
    pub fn with_colour(&self, rgb: [f64; 3]) -> Result<FitResult, ColourError> {
        let luminance = brtf_model::luminance(rgb);
        if rgb.iter().any(|c| !c.is_finite() || *c < 0.0) || luminance <= 0.0 {
            return Err(ColourError(rgb));
        }
        let shape = self.config.shape();
        let at = [0, 1, 2].map(|c| shape.index_of(ShapeArg::Colour(c)));
        let [Some(r), Some(g), Some(b)] = at else {
            return Ok(self.clone());
        };
        let recolour = |args: &mut Vec<f64>| {
            if args.len() > r.max(g).max(b) {
                let own = brtf_model::luminance([args[r], args[g], args[b]]);
                for (index, c) in [r, g, b].into_iter().zip(rgb) {
                    args[index] = own * c / luminance;
                }
            }
        };
        let mut out = self.clone();
        for report in out.incidences.iter_mut().chain(out.global.as_mut()) {
            recolour(&mut report.material_args);
        }
        if let Some(table) = &mut out.table {
            table.args.iter_mut().for_each(&recolour);
            for ring in table.azimuth.iter_mut().flatten() {
                ring.args.iter_mut().for_each(&recolour);
            }
        }
        Ok(out)
    }
}
