//! What the fitter consumes: per-incidence samples of a measured BSDF,
//! already selected and converted (by [`crate::Recipe`], or by a caller
//! that builds them itself; the fitter does no I/O).

use brtf_gonio::Gate;
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// One measured direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitSample {
    /// Unit direction towards the detector (local frame, z = front normal).
    pub view: DVec3,
    /// Measured value per channel: the BSDF in 1/sr, or a raw signal
    /// proportional to it when the fit has a free scale. Single-channel
    /// data uses index 0 only.
    pub value: [f64; 3],
    /// Quadrature weight, normally the sample's solid angle in sr.
    pub weight: f64,
}

/// A selection step that was applied, and how many samples it removed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GateCount {
    /// The selection.
    #[serde(flatten)]
    pub gate: Gate,
    /// How many samples it removed.
    pub removed: usize,
}

/// Which weights the samples carry.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Weighting {
    /// Solid angles: the file's Voronoi cells.
    FileSolidAngles,
    /// Solid angles computed from the sample directions.
    ComputedSolidAngles,
    /// Every sample weighs 1.
    Uniform,
    /// Weights set by the caller of the library.
    Caller,
}

impl std::fmt::Display for Weighting {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Weighting::FileSolidAngles => "solid angle (the file's Voronoi cells)",
            Weighting::ComputedSolidAngles => "solid angle (computed from the sample directions)",
            Weighting::Uniform => "uniform",
            Weighting::Caller => "set by the caller",
        })
    }
}

/// All samples of one incidence.
#[derive(Debug, Clone, PartialEq)]
pub struct IncidenceData {
    /// Where the data came from (a file name), for reports.
    pub source: String,
    /// Incident polar angle θ_in in degrees.
    pub theta_in: f64,
    /// Incident azimuth φ_in in degrees.
    pub phi_in: f64,
    /// 1 (CIE-Y, fitted grey) or 3 (RGB).
    pub channels: usize,
    /// The samples.
    pub samples: Vec<FitSample>,
    /// The selections applied before fitting.
    pub gates: Vec<GateCount>,
    /// Which weights the samples carry.
    pub weighting: Weighting,
    /// For patch-averaged data (Klems): the direction pairs the model is
    /// averaged over for each sample. `None`: the model is evaluated at
    /// each sample's own direction.
    pub patch_pairs: Option<Arc<PatchPairs>>,
    /// The file's values are the BSDF times |cos θ_out| (a DSF or raw
    /// signal): E1 weighs the samples' misfits by it, to compare in the
    /// file's own quantity.
    pub cosine_weighted: bool,
}

/// The (light, view) pairs over which the model is averaged for each
/// sample of patch-averaged data: Klems values are the BSDF averaged over
/// an outgoing patch (projected-solid-angle weighted) and an incident
/// patch, so the model must be averaged the same way to be compared with
/// them. Pairs are fixed when the data are prepared, so the objective is a
/// smooth function of the parameters.
///
/// A Klems side has ~10 million pairs but only a few thousand distinct
/// directions, so pairs are stored as two indices into a direction table
/// (8 bytes a pair instead of 48).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PatchPairs {
    /// Start of sample i's pairs is `offsets[i]`, its end `offsets[i + 1]`.
    pub offsets: Vec<usize>,
    /// The unit vectors the pairs use.
    pub directions: Vec<DVec3>,
    /// Per pair, the index in `directions` of the vector towards the light.
    pub light_index: Vec<u32>,
    /// Per pair, the index in `directions` of the vector towards the
    /// detector.
    pub view_index: Vec<u32>,
}

impl PatchPairs {
    /// No samples yet; pairs will index `directions`.
    pub fn new(directions: Vec<DVec3>) -> PatchPairs {
        PatchPairs {
            offsets: vec![0],
            directions,
            light_index: Vec::new(),
            view_index: Vec::new(),
        }
    }

    /// Appends one sample's pairs, as (light, view) indices into
    /// `directions`.
    ///
    /// # Panics
    /// If an index is outside `directions`.
    pub fn push(&mut self, pairs: impl IntoIterator<Item = (u32, u32)>) {
        let n = self.directions.len();
        for (light, view) in pairs {
            assert!(
                (light as usize) < n && (view as usize) < n,
                "PatchPairs::push: index outside the {n} directions"
            );
            self.light_index.push(light);
            self.view_index.push(view);
        }
        self.offsets.push(self.light_index.len());
    }

    /// How many samples.
    pub fn len(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// True when there are no samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// How many pairs in all.
    pub fn pair_count(&self) -> usize {
        self.light_index.len()
    }

    /// The pairs of sample `i`, as (light, view) vectors.
    #[inline]
    pub fn of(&self, i: usize) -> impl ExactSizeIterator<Item = (DVec3, DVec3)> + '_ {
        let range = self.offsets[i]..self.offsets[i + 1];
        self.light_index[range.clone()]
            .iter()
            .zip(&self.view_index[range])
            .map(|(&l, &v)| (self.directions[l as usize], self.directions[v as usize]))
    }

    /// The pairs of the samples `indices`, in that order.
    pub fn select(&self, indices: impl IntoIterator<Item = usize>) -> PatchPairs {
        let mut out = PatchPairs::new(self.directions.clone());
        for i in indices {
            let range = self.offsets[i]..self.offsets[i + 1];
            out.light_index
                .extend_from_slice(&self.light_index[range.clone()]);
            out.view_index.extend_from_slice(&self.view_index[range]);
            out.offsets.push(out.light_index.len());
        }
        out
    }

    /// The BSDF of sample `i` averaged over its pairs.
    pub fn average(&self, bsdf: &brtf_model::Bsdf, i: usize) -> [f64; 3] {
        let pairs = self.of(i);
        let n = pairs.len().max(1) as f64;
        let mut sum = [0.0; 3];
        for (l, v) in pairs {
            let f = bsdf.eval(l, v);
            for (s, x) in sum.iter_mut().zip(f) {
                *s += x;
            }
        }
        sum.map(|s| s / n)
    }
}

impl IncidenceData {
    /// The same incidence with other samples (no patch pairs: measured
    /// samples only).
    pub(crate) fn with_samples(&self, samples: Vec<FitSample>) -> IncidenceData {
        IncidenceData {
            source: self.source.clone(),
            theta_in: self.theta_in,
            phi_in: self.phi_in,
            channels: self.channels,
            samples,
            gates: self.gates.clone(),
            weighting: self.weighting,
            patch_pairs: None,
            cosine_weighted: self.cosine_weighted,
        }
    }

    /// Unit vector towards the light.
    pub fn light(&self) -> DVec3 {
        brtf_model::direction(self.theta_in, self.phi_in)
    }

    /// The model value for sample `i`: averaged over its pairs for
    /// patch-averaged data, else at its direction.
    pub fn model_value(&self, bsdf: &brtf_model::Bsdf, i: usize) -> [f64; 3] {
        match &self.patch_pairs {
            Some(pairs) => pairs.average(bsdf, i),
            None => bsdf.eval(self.light(), self.samples[i].view),
        }
    }
}
