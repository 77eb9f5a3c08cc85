//! What the fitter consumes: per-incidence samples of a measured BSDF,
//! already selected and converted (by [`crate::Recipe`], or by a caller
//! that builds them itself; the fitter does no I/O).

use brtf_gonio::Gate;
use brtf_model::{Bsdf, GeometryBatch};
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
/// directions, and each sample's pairs follow a pattern over them (every
/// light with every view, or each view with one light in turn), so a
/// sample is stored as its pattern and two index ranges into a direction
/// table: a side's pairs take kilobytes, not the 80 MB of listed indices.
/// Pairs without a pattern are listed as (light, view) indices.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PatchPairs {
    /// The unit vectors the pairs use, shared by selections.
    directions: Arc<Vec<DVec3>>,
    /// Per sample, its pairs.
    samples: Vec<SamplePairs>,
    /// Listed pairs' indices in `directions`: towards the light, towards
    /// the detector.
    listed_lights: Vec<u32>,
    listed_views: Vec<u32>,
    pair_count: usize,
}

/// One sample's pairs.
#[derive(Debug, Clone, Copy, PartialEq)]
enum SamplePairs {
    /// Every light of `lights` with every view of `views` (light-major).
    Product {
        lights: IndexRange,
        views: IndexRange,
    },
    /// View k of `views` with light k mod |lights| of `lights`.
    Zip {
        lights: IndexRange,
        views: IndexRange,
    },
    /// View k of `views` with light (k · 7 + 3) mod |lights| of `lights`:
    /// a product's coarse stand-in. Lights and views are drawn from
    /// strata in the same order, so pairing stratum k with stratum k
    /// would pair nearly aligned directions on a straight-through patch.
    Shuffled {
        lights: IndexRange,
        views: IndexRange,
    },
    /// Listed pairs `start..end` of the listed indices.
    Listed { start: usize, end: usize },
}

/// `start..start + len` of the direction table.
#[derive(Debug, Clone, Copy, PartialEq)]
struct IndexRange {
    start: u32,
    len: u32,
}

impl IndexRange {
    fn new(range: std::ops::Range<u32>) -> IndexRange {
        IndexRange {
            start: range.start,
            len: range.end.saturating_sub(range.start),
        }
    }

    /// The indices, as a range of the direction table.
    fn range(self) -> std::ops::Range<usize> {
        self.start as usize..self.start as usize + self.len as usize
    }
}

impl SamplePairs {
    fn count(&self) -> usize {
        match *self {
            SamplePairs::Product { lights, views } => lights.len as usize * views.len as usize,
            // No light, no pair.
            SamplePairs::Zip { lights, views } | SamplePairs::Shuffled { lights, views } => {
                views.len as usize * usize::from(lights.len > 0)
            }
            SamplePairs::Listed { start, end } => end - start,
        }
    }
}

/// The pairs of one sample in order, with running indices (a pass over
/// every pair of a Klems side takes them one by one: no division per
/// pair).
struct PairIter<'a> {
    pairs: &'a PatchPairs,
    sample: SamplePairs,
    k: usize,
    n: usize,
    /// The light's and the view's place in their ranges.
    light: usize,
    step: usize,
    view: usize,
}

impl Iterator for PairIter<'_> {
    type Item = (DVec3, DVec3);

    #[inline(always)]
    fn next(&mut self) -> Option<(DVec3, DVec3)> {
        if self.k >= self.n {
            return None;
        }
        let directions = &self.pairs.directions;
        let item = match self.sample {
            SamplePairs::Product { lights, views } => {
                let item = (
                    directions[lights.start as usize + self.light],
                    directions[views.start as usize + self.view],
                );
                self.view += 1;
                if self.view == views.len as usize {
                    self.view = 0;
                    self.light += 1;
                }
                item
            }
            SamplePairs::Zip { lights, views } | SamplePairs::Shuffled { lights, views } => {
                let item = (
                    directions[lights.start as usize + self.light],
                    directions[views.start as usize + self.k],
                );
                self.light += self.step;
                while self.light >= lights.len as usize {
                    self.light -= lights.len as usize;
                }
                item
            }
            SamplePairs::Listed { start, .. } => (
                directions[self.pairs.listed_lights[start + self.k] as usize],
                directions[self.pairs.listed_views[start + self.k] as usize],
            ),
        };
        self.k += 1;
        Some(item)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = self.n - self.k;
        (left, Some(left))
    }
}

impl ExactSizeIterator for PairIter<'_> {}

/// Pairs gathered at a time by [`PatchPairs::geometry`] (on the stack).
const GATHER: usize = 64;

/// Most pairs per sample in [`PatchPairs::coarse`].
const COARSE_PAIRS: usize = 32;

impl PatchPairs {
    /// No samples yet; pairs will index `directions`.
    pub fn new(directions: Vec<DVec3>) -> PatchPairs {
        PatchPairs {
            directions: Arc::new(directions),
            ..PatchPairs::default()
        }
    }

    /// No samples yet; pairs will index `directions`, shared with other
    /// pairs.
    pub fn sharing(directions: Arc<Vec<DVec3>>) -> PatchPairs {
        PatchPairs {
            directions,
            ..PatchPairs::default()
        }
    }

    /// The unit vectors the pairs index.
    pub fn directions(&self) -> &[DVec3] {
        &self.directions
    }

    /// Appends `directions` to the table; their indices.
    pub fn add_directions(
        &mut self,
        directions: impl IntoIterator<Item = DVec3>,
    ) -> std::ops::Range<u32> {
        let table = Arc::make_mut(&mut self.directions);
        let first = table.len() as u32;
        table.extend(directions);
        first..table.len() as u32
    }

    fn check(&self, range: &std::ops::Range<u32>) {
        assert!(
            range.start <= range.end && range.end as usize <= self.directions.len(),
            "PatchPairs: index outside the {} directions",
            self.directions.len()
        );
    }

    /// Appends one sample's pairs, as (light, view) indices into
    /// `directions`.
    ///
    /// # Panics
    /// If an index is outside `directions`.
    pub fn push(&mut self, pairs: impl IntoIterator<Item = (u32, u32)>) {
        let n = self.directions.len();
        let start = self.listed_lights.len();
        for (light, view) in pairs {
            assert!(
                (light as usize) < n && (view as usize) < n,
                "PatchPairs::push: index outside the {n} directions"
            );
            self.listed_lights.push(light);
            self.listed_views.push(view);
        }
        let end = self.listed_lights.len();
        self.add(SamplePairs::Listed { start, end });
    }

    /// Appends a sample averaged over every light of `lights` with every
    /// view of `views` (index ranges of `directions`).
    ///
    /// # Panics
    /// If a range reaches outside `directions`.
    pub fn push_product(&mut self, lights: std::ops::Range<u32>, views: std::ops::Range<u32>) {
        self.check(&lights);
        self.check(&views);
        self.add(SamplePairs::Product {
            lights: IndexRange::new(lights),
            views: IndexRange::new(views),
        });
    }

    /// Appends a sample averaged over each view of `views` with one light
    /// of `lights` in turn.
    ///
    /// # Panics
    /// If a range reaches outside `directions`.
    pub fn push_zip(&mut self, lights: std::ops::Range<u32>, views: std::ops::Range<u32>) {
        self.check(&lights);
        self.check(&views);
        self.add(SamplePairs::Zip {
            lights: IndexRange::new(lights),
            views: IndexRange::new(views),
        });
    }

    fn add(&mut self, sample: SamplePairs) {
        self.pair_count += sample.count();
        self.samples.push(sample);
    }

    /// How many samples.
    pub fn len(&self) -> usize {
        self.samples.len()
    }

    /// True when there are no samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// How many pairs in all.
    pub fn pair_count(&self) -> usize {
        self.pair_count
    }

    /// How many pairs sample `i` has.
    pub fn count(&self, i: usize) -> usize {
        self.samples[i].count()
    }

    /// The pairs of sample `i`, as (light, view) vectors.
    #[inline]
    pub fn of(&self, i: usize) -> impl ExactSizeIterator<Item = (DVec3, DVec3)> + '_ {
        let sample = self.samples[i];
        let (light, step) = match sample {
            SamplePairs::Shuffled { lights, .. } => (3 % lights.len.max(1) as usize, 7),
            _ => (0, 1),
        };
        PairIter {
            pairs: self,
            sample,
            k: 0,
            n: sample.count(),
            light,
            step,
            view: 0,
        }
    }

    /// Writes the geometry of sample `i`'s pairs under `bsdf` as pairs
    /// `at..at + count(i)` of `out` (`at = out.len()` appends; `at = 0`
    /// refills a scratch batch without clearing it: its pairs past the
    /// sample's stay, see [`Bsdf::geometry_product`]), in the order of
    /// [`PatchPairs::of`]:
    /// what mapping [`Bsdf::geometry`] over them gives, bit for bit, from
    /// brtf-model's vectorised geometry (a product's lights each over its
    /// views; other patterns gathered a few dozen pairs at a time).
    ///
    /// # Panics
    /// If `at > out.len()`.
    pub fn geometry(&self, bsdf: &Bsdf, i: usize, out: &mut GeometryBatch, at: usize) {
        let sample = self.samples[i];
        if let SamplePairs::Product { lights, views } = sample {
            let table = &self.directions;
            bsdf.geometry_product(&table[lights.range()], &table[views.range()], out, at);
            return;
        }
        // Written piece by piece.
        let mut end = at;
        out.reserve((at + sample.count()).saturating_sub(out.len()));
        let mut pairs = self.of(i);
        let mut l = [[0.0; GATHER]; 3];
        let mut v = [[0.0; GATHER]; 3];
        loop {
            let mut m = 0;
            for (light, view) in pairs.by_ref().take(GATHER) {
                [l[0][m], l[1][m], l[2][m]] = light.to_array();
                [v[0][m], v[1][m], v[2][m]] = view.to_array();
                m += 1;
            }
            if m == 0 {
                return;
            }
            bsdf.geometry_soa(
                [&l[0][..m], &l[1][..m], &l[2][..m]],
                [&v[0][..m], &v[1][..m], &v[2][..m]],
                out,
                end,
            );
            end += m;
        }
    }

    /// The pairs of the samples `indices`, in that order.
    pub fn select(&self, indices: impl IntoIterator<Item = usize>) -> PatchPairs {
        let mut out = PatchPairs {
            directions: Arc::clone(&self.directions),
            listed_lights: self.listed_lights.clone(),
            listed_views: self.listed_views.clone(),
            ..PatchPairs::default()
        };
        for i in indices {
            out.add(self.samples[i]);
        }
        out
    }

    /// The same samples with at most a few dozen pairs each: every view of
    /// a product with one light in turn (as the samples far from a lobe
    /// are averaged), listed pairs thinned evenly. Its averages are
    /// coarser but cost a fraction: the starts of a fit run on them.
    pub fn coarse(&self) -> PatchPairs {
        let mut out = PatchPairs {
            directions: Arc::clone(&self.directions),
            ..PatchPairs::default()
        };
        for sample in &self.samples {
            match *sample {
                SamplePairs::Product { lights, views } => {
                    out.add(SamplePairs::Shuffled { lights, views });
                }
                SamplePairs::Zip { .. } | SamplePairs::Shuffled { .. } => out.add(*sample),
                SamplePairs::Listed { start, end } => {
                    let step = (end - start).div_ceil(COARSE_PAIRS).max(1);
                    let first = out.listed_lights.len();
                    for k in (start..end).step_by(step) {
                        out.listed_lights.push(self.listed_lights[k]);
                        out.listed_views.push(self.listed_views[k]);
                    }
                    let last = out.listed_lights.len();
                    out.add(SamplePairs::Listed {
                        start: first,
                        end: last,
                    });
                }
            }
        }
        out
    }

    /// The BSDF of sample `i` averaged over its pairs, summed in
    /// brtf-model's vectorised kernel as the fitter sums it.
    pub fn average(&self, bsdf: &Bsdf, i: usize) -> [f64; 3] {
        thread_local! {
            static SCRATCH: std::cell::RefCell<GeometryBatch> =
                std::cell::RefCell::new(GeometryBatch::new());
        }
        SCRATCH.with_borrow_mut(|scratch| {
            self.geometry(bsdf, i, scratch, 0);
            let n = self.count(i);
            let inverse = 1.0 / n.max(1) as f64;
            bsdf.sum_geometry::<3>(scratch, 0..n).map(|s| s * inverse)
        })
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Direction i of the table is (i, 0, 1): a pair's vectors give back
    /// their indices.
    fn table(n: usize) -> Vec<DVec3> {
        (0..n).map(|i| DVec3::new(i as f64, 0.0, 1.0)).collect()
    }

    fn indices(pairs: &PatchPairs, i: usize) -> Vec<(usize, usize)> {
        pairs
            .of(i)
            .map(|(l, v)| (l.x as usize, v.x as usize))
            .collect()
    }

    /// Each pattern yields exactly the pairs it describes, in order, and
    /// selections and the coarse stand-in share the direction table.
    #[test]
    fn patterns_yield_their_pairs() {
        let mut pairs = PatchPairs::new(table(12));
        pairs.push_product(0..3, 5..9);
        pairs.push_zip(0..3, 5..10);
        pairs.push((0..4).map(|k| (11 - k, k)));
        pairs.push_zip(0..0, 5..9);
        let product: Vec<_> = (0..3).flat_map(|l| (5..9).map(move |v| (l, v))).collect();
        let zip: Vec<_> = (0..5).map(|k| (k % 3, 5 + k)).collect();
        let listed: Vec<_> = (0..4).map(|k| (11 - k, k)).collect();
        assert_eq!(indices(&pairs, 0), product);
        assert_eq!(indices(&pairs, 1), zip);
        assert_eq!(indices(&pairs, 2), listed);
        assert!(indices(&pairs, 3).is_empty(), "no light, no pair");
        assert_eq!(pairs.pair_count(), 12 + 5 + 4);
        assert_eq!(pairs.of(0).len(), 12);

        let selected = pairs.select([2, 0]);
        assert_eq!(indices(&selected, 0), listed);
        assert_eq!(indices(&selected, 1), product);
        assert!(Arc::ptr_eq(&selected.directions, &pairs.directions));

        // A product becomes each view with a shuffled light; zips stay;
        // listed pairs are thinned to at most COARSE_PAIRS.
        let coarse = pairs.coarse();
        let shuffled: Vec<_> = (0..4).map(|k| ((k * 7 + 3) % 3, 5 + k)).collect();
        assert_eq!(indices(&coarse, 0), shuffled);
        assert_eq!(indices(&coarse, 1), zip);
        assert_eq!(indices(&coarse, 2), listed);
        let mut many = PatchPairs::new(table(2));
        many.push((0..100).map(|_| (0, 1)));
        assert_eq!(many.coarse().count(0), 25);
    }

    /// Each pattern's geometry (vectorised) is the scalar geometry of its
    /// pairs in order, bit for bit, appended after what the batch holds;
    /// long samples are gathered in several pieces.
    #[test]
    fn pattern_geometry_is_the_scalar_geometry() {
        use brtf_model::{EvalOptions, Material, MaterialKind, direction};
        let table: Vec<DVec3> = (0..300)
            .map(|k| direction((k as f64 * 7.7) % 180.0, k as f64 * 13.1))
            .collect();
        let mut pairs = PatchPairs::new(table);
        pairs.push_product(0..5, 100..233);
        pairs.push_zip(0..7, 10..150);
        pairs.push((0..150).map(|k| (299 - k, 2 * k)));
        pairs.push_zip(0..0, 5..9);
        pairs.push_product(3..3, 5..9);
        let coarse = pairs.coarse();
        let material = Material::new(
            MaterialKind::Trans2,
            &[0.6, 0.7, 0.8, 0.04, 0.05, 0.2, 0.6, 0.4],
            Some(DVec3::new(0.3, 1.0, 0.2)),
        )
        .unwrap();
        let bsdf = Bsdf::new(&material, &EvalOptions::default());
        for set in [&pairs, &coarse] {
            for i in 0..set.len() {
                // Appended after one pair, over a stale longer batch.
                let mut out = GeometryBatch::new();
                for _ in 0..700 {
                    out.push(bsdf.geometry(DVec3::Z, DVec3::Z));
                }
                set.geometry(&bsdf, i, &mut out, 1);
                assert_eq!(out.len(), 700.max(1 + set.count(i)));
                for (k, (l, v)) in set.of(i).enumerate() {
                    let (got, want) = (out.get(1 + k), bsdf.geometry(l, v));
                    assert_eq!(
                        format!("{got:?}"),
                        format!("{want:?}"),
                        "sample {i}, pair {k}"
                    );
                }
            }
        }
    }
}
