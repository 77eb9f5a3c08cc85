//! A lobe sum (or an anisotropic type with its orientation fitted) in the
//! fitter's kernel: each lobe through brtf-model's vectorised per-pair
//! kernel, their terms combined into the value and the derivatives with
//! respect to the shape's flat arguments ([`brtf_model::Shape`]).
//!
//! With weights `w_k` from the splits, `f = Σ w_k f_k`, so
//!
//! * colour, `spec`, `trans`, `tspec` (shared): `Σ w_k ∂f_k/∂a`;
//! * lobe k's roughness: `w_k ∂f_k/∂rough`;
//! * split j: `Σ (∂w_k/∂s_j) f_k`;
//! * `orient`: a central difference over ±[`ORIENT_STEP_DEG`], from the
//!   lobes built at the turned orientation (the tangent frame enters the
//!   pairs' geometry, which the per-pair kernel takes as given).

use brtf_model::{
    Bsdf, Composite, EvalOptions, GeometryBatch, PairTerms, Shape, ShapeArg, lobe_weights,
};
use glam::DVec3;
use std::ops::Range;

/// Step of the orientation's central difference, degrees: its error
/// (~step² f''') is far below the data's noise, its cancellation far
/// below the step.
pub(crate) const ORIENT_STEP_DEG: f64 = 1e-3;

/// Lobes and their weights.
type Lobes = Vec<(f64, Bsdf)>;

/// The lobes of one point of a fit, ready for the kernel.
#[derive(Debug, Clone)]
pub(crate) struct LobeModel {
    /// `(w_k, lobe k)`.
    pub parts: Vec<(f64, Bsdf)>,
    /// `∂w_k/∂s_j`, `[k][j]`.
    dweights: Vec<Vec<f64>>,
    /// Flat index of each split.
    splits: Vec<usize>,
    /// Flat index of each lobe's roughness along u, and along v.
    rough: Vec<(usize, Option<usize>)>,
    /// Flat indices of `trans` and `tspec`.
    trans: Option<(usize, usize)>,
    /// The orientation: flat index and the lobes turned by ∓ the step.
    orient: Option<(usize, [Lobes; 2])>,
    n_args: usize,
}

/// `∂w_k/∂s_j` of stick-breaking weights (see [`lobe_weights`]).
fn weight_derivatives(splits: &[f64]) -> Vec<Vec<f64>> {
    let n = splits.len() + 1;
    (0..n)
        .map(|k| {
            (0..splits.len())
                .map(|j| {
                    if j > k {
                        return 0.0;
                    }
                    // w_k = [s_k] Π_{i<k} (1 − s_i), without the s_k factor for the last.
                    let mut d = if j == k { 1.0 } else { -1.0 };
                    for (i, &s) in splits.iter().enumerate().take(k) {
                        if i != j {
                            d *= 1.0 - s;
                        }
                    }
                    if k < splits.len() && j != k {
                        d *= splits[k];
                    }
                    d
                })
                .collect()
        })
        .collect()
}

impl LobeModel {
    /// The lobes of `material` (of `shape`) under `options`.
    pub(crate) fn new(shape: Shape, material: &Composite, options: &EvalOptions) -> LobeModel {
        let args = material.args().expect("a fitted material has a shape");
        let index = |a: ShapeArg| shape.index_of(a).expect("the shape's argument");
        let splits: Vec<usize> = (0..shape.lobes - 1)
            .map(|j| index(ShapeArg::Split(j)))
            .collect();
        let split_values: Vec<f64> = splits.iter().map(|&i| args[i]).collect();
        let parts = |m: &Composite| -> Vec<(f64, Bsdf)> {
            m.components()
                .iter()
                .map(|(w, c)| (*w, Bsdf::new(c, options)))
                .collect()
        };
        let orient = shape.oriented.then(|| {
            let i = index(ShapeArg::Orient);
            let turned = |sign: f64| {
                let mut a = args.to_vec();
                a[i] += sign * ORIENT_STEP_DEG;
                parts(&Composite::new(shape, &a, None).expect("a turned material is valid"))
            };
            (i, [turned(-1.0), turned(1.0)])
        });
        debug_assert_eq!(lobe_weights(&split_values).len(), shape.lobes);
        LobeModel {
            parts: parts(material),
            dweights: weight_derivatives(&split_values),
            splits,
            rough: (0..shape.lobes)
                .map(|k| {
                    (
                        index(ShapeArg::RoughU(k)),
                        shape.index_of(ShapeArg::RoughV(k)),
                    )
                })
                .collect(),
            trans: shape
                .kind
                .is_transmitting()
                .then(|| (index(ShapeArg::Trans), index(ShapeArg::Tspec))),
            orient,
            n_args: shape.n_args(),
        }
    }

    /// The pairs' geometry from `light` to each sample's `views`, under
    /// this point's orientation (`turn`: −1, 0 or +1 steps).
    pub(crate) fn geometry(
        &self,
        turn: i32,
        light: DVec3,
        views: &[DVec3],
        out: &mut GeometryBatch,
    ) {
        let bsdf = match (turn, &self.orient) {
            (-1, Some((_, [minus, _]))) => &minus[0].1,
            (1, Some((_, [_, plus]))) => &plus[0].1,
            _ => &self.parts[0].1,
        };
        out.clear();
        out.extend(views.iter().map(|&v| bsdf.geometry(light, v)));
    }

    /// True when the geometry depends on the point (a fitted orientation).
    pub(crate) fn oriented(&self) -> bool {
        self.orient.is_some()
    }
}

/// The terms of a run of pairs for a [`LobeModel`]: `f` and, with
/// gradients, `∂f/∂(flat argument)` per channel, in columns.
#[derive(Debug, Default)]
pub(crate) struct LobeTerms {
    len: usize,
    channels: usize,
    n_args: usize,
    /// `f` of channel ch at `ch · len + i`.
    values: Vec<f64>,
    /// `∂f_ch/∂a` at `(a · 3 + ch) · len + i`.
    derivatives: Vec<f64>,
    /// Which `(a, ch)` columns hold anything.
    present: Vec<bool>,
    /// One lobe's terms.
    scratch: PairTerms,
}

impl LobeTerms {
    /// Evaluates `model` on the pairs `range` of `geometry` (and, with
    /// `GRAD` and a fitted orientation, on `turned`: the same pairs'
    /// geometry at −1 and +1 steps).
    pub(crate) fn evaluate<const GRAD: bool, const CH: usize>(
        &mut self,
        model: &LobeModel,
        geometry: &GeometryBatch,
        range: Range<usize>,
        turned: Option<[&GeometryBatch; 2]>,
    ) {
        let n = range.len();
        self.len = n;
        self.channels = CH;
        self.n_args = model.n_args;
        self.values.clear();
        self.values.resize(CH * n, 0.0);
        if GRAD {
            self.derivatives.clear();
            self.derivatives.resize(model.n_args * 3 * n, 0.0);
            self.present.clear();
            self.present.resize(model.n_args * 3, false);
        }
        for (k, (w, bsdf)) in model.parts.iter().enumerate() {
            if GRAD {
                bsdf.eval_geometry_each_with_gradient::<CH>(
                    geometry,
                    range.clone(),
                    &mut self.scratch,
                );
            } else {
                bsdf.eval_geometry_each::<CH>(geometry, range.clone(), &mut self.scratch);
            }
            let terms = &self.scratch;
            for ch in 0..CH {
                let column = terms.value_column(ch);
                for (o, v) in self.values[ch * n..(ch + 1) * n].iter_mut().zip(column) {
                    *o += w * v;
                }
            }
            if !GRAD {
                continue;
            }
            let (rough_u, rough_v) = model.rough[k];
            // (flat index, the lobe's own argument index): colours and spec
            // lead both.
            let mut shared = vec![(0, 0), (1, 1), (2, 2), (3, 3)];
            if let Some((t, s)) = model.trans {
                // The trans types' own argument positions (one lobe).
                let (own_t, own_s) = if rough_v.is_some() { (6, 7) } else { (5, 6) };
                shared.extend([(t, own_t), (s, own_s)]);
            }
            let mut own = vec![(rough_u, 4)];
            if let Some(v) = rough_v {
                own.push((v, 5));
            }
            let mut out = Columns {
                len: n,
                derivatives: &mut self.derivatives,
                present: &mut self.present,
            };
            for ch in 0..CH {
                for &(flat, arg) in shared.iter().chain(&own) {
                    out.add(flat, ch, terms.derivative_column(arg, ch), *w);
                }
                for (j, &flat) in model.splits.iter().enumerate() {
                    let d = model.dweights[k][j];
                    out.add(flat, ch, Some(terms.value_column(ch)), d);
                }
            }
        }
        if let (true, Some((flat, [minus, plus])), Some([g_minus, g_plus])) =
            (GRAD, &model.orient, turned)
        {
            // Central difference over the turned lobes, per degree.
            let scale = 0.5 / ORIENT_STEP_DEG;
            for (parts, g, sign) in [(minus, g_minus, -1.0), (plus, g_plus, 1.0)] {
                for (w, bsdf) in parts {
                    bsdf.eval_geometry_each::<CH>(g, range.clone(), &mut self.scratch);
                    let mut out = Columns {
                        len: n,
                        derivatives: &mut self.derivatives,
                        present: &mut self.present,
                    };
                    for ch in 0..CH {
                        let column = Some(self.scratch.value_column(ch));
                        out.add(*flat, ch, column, sign * w * scale);
                    }
                }
            }
        }
    }

    /// `f` of every pair, channel `ch`.
    pub(crate) fn value_column(&self, ch: usize) -> &[f64] {
        &self.values[ch * self.len..(ch + 1) * self.len]
    }

    /// `f` of pair `i`, channel `ch` (0 beyond the channels evaluated).
    pub(crate) fn value(&self, i: usize, ch: usize) -> f64 {
        if ch < self.channels {
            self.values[ch * self.len + i]
        } else {
            0.0
        }
    }

    /// `∂f_ch/∂(flat argument a)` of every pair, or `None` where it is 0.
    pub(crate) fn derivative_column(&self, a: usize, ch: usize) -> Option<&[f64]> {
        let column = a * 3 + ch;
        (a < self.n_args && ch < self.channels && self.present.get(column) == Some(&true))
            .then(|| &self.derivatives[column * self.len..(column + 1) * self.len])
    }
}

/// The derivative columns of a [`LobeTerms`], borrowed apart from its
/// scratch terms.
struct Columns<'a> {
    len: usize,
    derivatives: &'a mut [f64],
    present: &'a mut [bool],
}

impl Columns<'_> {
    /// Adds `factor × source` to column `(flat, ch)`.
    fn add(&mut self, flat: usize, ch: usize, source: Option<&[f64]>, factor: f64) {
        let Some(source) = source else {
            return;
        };
        if factor == 0.0 {
            return;
        }
        let column = flat * 3 + ch;
        self.present[column] = true;
        let out = &mut self.derivatives[column * self.len..(column + 1) * self.len];
        for (o, s) in out.iter_mut().zip(source) {
            *o += factor * s;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use brtf_model::{Composite, MaterialKind, direction};

    #[test]
    fn weight_derivatives_match_differences() {
        for splits in [vec![0.3], vec![0.25, 0.6], vec![0.9, 0.1]] {
            let d = weight_derivatives(&splits);
            for j in 0..splits.len() {
                let h = 1e-7;
                let (mut up, mut down) = (splits.clone(), splits.clone());
                up[j] += h;
                down[j] -= h;
                let (wu, wd) = (lobe_weights(&up), lobe_weights(&down));
                for k in 0..=splits.len() {
                    let numeric = (wu[k] - wd[k]) / (2.0 * h);
                    assert!((d[k][j] - numeric).abs() < 1e-7, "{splits:?} k {k} j {j}");
                }
            }
        }
    }

    /// Every derivative column of a two-lobe anisotropic metal with its
    /// orientation fitted against central differences of `f`.
    #[test]
    fn lobe_terms_match_finite_differences() {
        let shape = Shape::new(MaterialKind::Metal2, 2, true).unwrap();
        let args = [0.8, 0.7, 0.6, 0.6, 0.35, 0.05, 0.12, 0.2, 0.3, 25.0];
        let options = EvalOptions::default();
        let material = Composite::new(shape, &args, None).unwrap();
        let model = LobeModel::new(shape, &material, &options);
        let light = direction(35.0, 10.0);
        let views: Vec<DVec3> = [(30.0, 180.0), (40.0, 200.0), (20.0, 150.0), (50.0, 185.0)]
            .iter()
            .map(|&(t, p)| direction(t, p))
            .collect();
        let mut geometry = GeometryBatch::new();
        let mut turned = [GeometryBatch::new(), GeometryBatch::new()];
        model.geometry(0, light, &views, &mut geometry);
        model.geometry(-1, light, &views, &mut turned[0]);
        model.geometry(1, light, &views, &mut turned[1]);
        let mut terms = LobeTerms::default();
        terms.evaluate::<true, 3>(
            &model,
            &geometry,
            0..views.len(),
            Some([&turned[0], &turned[1]]),
        );
        let f = |a: &[f64]| -> Vec<[f64; 3]> {
            let m =
                brtf_model::CompositeBsdf::new(&Composite::new(shape, a, None).unwrap(), &options);
            views.iter().map(|&v| m.eval(light, v)).collect()
        };
        for a in 0..args.len() {
            let h = if a == 9 { 1e-3 } else { 1e-6 };
            let (mut up, mut down) = (args.to_vec(), args.to_vec());
            up[a] += h;
            down[a] -= h;
            let (fu, fd) = (f(&up), f(&down));
            for ch in 0..3 {
                for i in 0..views.len() {
                    let numeric = (fu[i][ch] - fd[i][ch]) / (2.0 * h);
                    let analytic = terms.derivative_column(a, ch).map_or(0.0, |c| c[i]);
                    let tolerance = 1e-5 * numeric.abs().max(1e-3);
                    assert!(
                        (analytic - numeric).abs() <= tolerance,
                        "arg {a} ch {ch} pair {i}: {analytic} vs {numeric}"
                    );
                }
            }
        }
        for (i, value) in f(&args).iter().enumerate() {
            for (ch, v) in value.iter().enumerate() {
                assert!((terms.value(i, ch) - v).abs() <= 1e-12 * v.abs());
            }
        }
    }
}
