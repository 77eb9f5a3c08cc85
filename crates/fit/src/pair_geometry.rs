//! The argument-free geometry of patch-averaged samples' (light, view)
//! pairs, computed once per fit instead of on every pass.
//!
//! A Klems incidence averages the model over ~50 000 pairs, and LM needs
//! ~70 passes: recomputing each pair's half vector and cosines on every
//! pass was wasted work. [`brtf_model::Geometry`] holds exactly the part
//! of `f(l, v)` that does not depend on the material's arguments, so it is
//! valid for every parameter set the fit tries (same type, orientation and
//! options). Stored as a structure of arrays, the sums over a sample's
//! pairs run through brtf-model's vectorised kernel.

use crate::data::PatchPairs;
use brtf_model::{Bsdf, GeometryBatch};
use std::ops::Range;
use std::sync::Arc;

/// Every pair's geometry, and each sample's pairs in it. The batch is
/// shared: an incidence's per-incidence and all-incidence fits and their
/// subsamples all read the same one, so selecting samples copies only
/// their ranges.
#[derive(Debug, Clone, Default)]
pub(crate) struct PairGeometry {
    /// Sample i's pairs are `ranges[i]` of `geometry`.
    ranges: Vec<Range<usize>>,
    pub geometry: Arc<GeometryBatch>,
}

impl PairGeometry {
    /// The geometry of every pair of `pairs` under `bsdf`'s type,
    /// orientation and options (its arguments do not matter).
    pub(crate) fn new(pairs: &PatchPairs, bsdf: &Bsdf) -> PairGeometry {
        let mut geometry = GeometryBatch::with_capacity(pairs.pair_count());
        for i in 0..pairs.len() {
            let end = geometry.len();
            pairs.geometry(bsdf, i, &mut geometry, end);
        }
        let mut ranges = Vec::with_capacity(pairs.len());
        let mut start = 0;
        for i in 0..pairs.len() {
            let end = start + pairs.count(i);
            ranges.push(start..end);
            start = end;
        }
        PairGeometry {
            ranges,
            geometry: Arc::new(geometry),
        }
    }

    /// Sample `i`'s pairs in [`PairGeometry::geometry`].
    #[inline]
    pub(crate) fn range(&self, i: usize) -> Range<usize> {
        self.ranges[i].clone()
    }

    /// The geometry of the samples `indices`, in that order.
    pub(crate) fn select(&self, indices: impl IntoIterator<Item = usize>) -> PairGeometry {
        PairGeometry {
            ranges: indices.into_iter().map(|i| self.range(i)).collect(),
            geometry: Arc::clone(&self.geometry),
        }
    }
}
