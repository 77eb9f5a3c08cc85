//! The argument-free geometry of patch-averaged samples' (light, view)
//! pairs, computed once per fit instead of on every pass.
//!
//! A Klems incidence averages the model over ~50 000 pairs, and LM needs
//! ~80 passes: recomputing each pair's half vector and cosines on every
//! pass was half the work. [`brtf_model::Geometry`] holds exactly the part
//! of `f(l, v)` that does not depend on the material's arguments, so it is
//! valid for every parameter set the fit tries (same type, orientation and
//! options).

use crate::data::PatchPairs;
use brtf_model::{Bsdf, Geometry};

/// Every pair's geometry, sample by sample (the offsets of the
/// [`PatchPairs`] it was made from).
#[derive(Debug, Clone, Default)]
pub(crate) struct PairGeometry {
    /// Sample i's pairs are `geometry[offsets[i]..offsets[i + 1]]`.
    offsets: Vec<usize>,
    geometry: Vec<Geometry>,
}

impl PairGeometry {
    /// The geometry of every pair of `pairs` under `bsdf`'s type,
    /// orientation and options (its arguments do not matter).
    pub(crate) fn new(pairs: &PatchPairs, bsdf: &Bsdf) -> PairGeometry {
        let geometry = pairs
            .lights
            .iter()
            .zip(&pairs.views)
            .map(|(&l, &v)| bsdf.geometry(l, v))
            .collect();
        PairGeometry {
            offsets: pairs.offsets.clone(),
            geometry,
        }
    }

    /// Sample `i`'s pairs.
    #[inline]
    pub(crate) fn of(&self, i: usize) -> &[Geometry] {
        &self.geometry[self.offsets[i]..self.offsets[i + 1]]
    }

    /// The geometry of the samples `indices`, in that order.
    pub(crate) fn select(&self, indices: impl IntoIterator<Item = usize>) -> PairGeometry {
        let mut out = PairGeometry {
            offsets: vec![0],
            geometry: Vec::new(),
        };
        for i in indices {
            out.geometry.extend_from_slice(self.of(i));
            out.offsets.push(out.geometry.len());
        }
        out
    }
}
