//! Tensor trees as fitted data: each chosen incidence of one side becomes
//! one incidence whose samples are the tree's outgoing leaves, and the
//! model is averaged over each leaf before it is compared with it.
//!
//! A leaf's value is the BSDF over a hypercube of the Shirley–Chiu maps:
//! `bsdf2ttree` evaluates the centre of each finest leaf (or averages 256
//! points over it where the BSDF changes fast), and `rttree_reduce` merges
//! similar leaves by averaging them, input dimensions included. So the
//! model is averaged over each leaf's hypercube: (light, view) pairs
//! stratified over its outgoing cell and its input range
//! ([`TreeSample::stratified_pairs`]), uniform in projected solid angle
//! (the map keeps areas). The pairs are drawn once from a fixed seed, so
//! the fitted objective is a smooth, deterministic function of the
//! parameters.

use crate::data::PatchPairs;
use crate::recipe::{PreparedMeasurement, Recipe, RecipeError};
use brtf_gonio::klems::ttree::TreeSample;
use brtf_gonio::klems::{Side, TensorTree};
use brtf_model::Rng;
use std::sync::Arc;

/// The θ_in (degrees) fitted by default: the Klems Full basis's ring
/// centres (`brtf info` lists the totals at the same angles).
pub const DEFAULT_THETAS: [f64; 9] = brtf_gonio::klems::ttree::INFO_THETAS;

/// Pairs per leaf of the finest size; larger leaves get more in
/// proportion to their outgoing area, up to [`MAX_PAIRS`]. (A single light
/// at the input cell's centre, or eight spread over the finest input cell
/// for every leaf, left merged leaves' lobes too narrow or too wide: on a
/// `TensorTree4` at `-g 5` of a `trans` with α 0.2 the diffuse τ came out
/// 2.4 % and 2.7 % high.)
const PAIRS: usize = 4;

/// The most pairs of one leaf.
const MAX_PAIRS: usize = 64;

/// Incidence (θ_in, φ_in) (degrees, towards the source, in the lit side's
/// frame) of `tree` lit from `side`, prepared by `recipe` with its leaf
/// pairs when the recipe averages over patches. The incidence moves to the
/// centre of the tree's finest input cell holding it
/// ([`TensorTree::cell_centre_incidence`]). `None` when the side has no
/// Visible data.
pub fn prepare_incidence(
    recipe: &Recipe,
    tree: &TensorTree,
    side: Side,
    theta_in_deg: f64,
    phi_in_deg: f64,
    source: &str,
) -> Result<Option<PreparedMeasurement>, RecipeError> {
    let Some((measurement, places)) = tree.measurement(side, theta_in_deg, phi_in_deg) else {
        return Ok(None);
    };
    let mut prepared = recipe.prepare(measurement, source)?;
    if let Some(rule) = recipe.patch_average {
        let finest = 0.5f64.powi(tree.depth() as i32);
        prepared.patch_pairs = Some(Arc::new(leaf_pairs(&places, finest, rule.seed)));
    }
    Ok(Some(prepared))
}

/// The pairs of every sample (one per leaf in `places`, file order); the
/// direction table holds each pair's light and view.
fn leaf_pairs(places: &[TreeSample], finest: f64, seed: u64) -> PatchPairs {
    let mut pairs = PatchPairs::new(Vec::new());
    for (k, place) in places.iter().enumerate() {
        let ratio = place.size / finest;
        let n = ((PAIRS as f64 * ratio * ratio).round() as usize).clamp(PAIRS, MAX_PAIRS);
        let drawn = place.stratified_pairs(n, &mut Rng::new(seed, k as u64));
        let count = drawn.len() as u32;
        let first = pairs
            .add_directions(drawn.into_iter().flat_map(|(light, view)| [light, view]))
            .start;
        pairs.push((0..count).map(|j| (first + 2 * j, first + 2 * j + 1)));
    }
    pairs
}

#[cfg(test)]
mod tests {
    use super::*;
    use brtf_gonio::klems::{BsdfXml, read_any_path};
    use brtf_model::{Bsdf, EvalOptions, Material, MaterialKind};

    /// A Lambertian model averages to its constant, and every leaf gets
    /// pairs: the pairs' mean of a constant BSDF is exactly the constant.
    #[test]
    fn every_leaf_gets_pairs_and_constants_average_exactly() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../gonio/tests/fixtures/ttree/asym-t3-g4.xml");
        let BsdfXml::TensorTree(tree) = read_any_path(&path).unwrap() else {
            panic!("not a tree");
        };
        let recipe = Recipe::for_klems(MaterialKind::Plastic);
        let prepared = prepare_incidence(&recipe, &tree, Side::Front, 40.0, 0.0, "t")
            .unwrap()
            .unwrap();
        let m = Material::new(MaterialKind::Plastic, &[0.5, 0.5, 0.5, 0.0, 0.0], None).unwrap();
        let bsdf = Bsdf::new(&m, &EvalOptions::default());
        let reflected = prepared
            .measurement
            .samples
            .iter()
            .filter(|s| s.theta_deg <= 90.0)
            .count();
        assert!(reflected > 10);
        for i in 0..reflected {
            let v = prepared.model_value(&bsdf, i)[1];
            assert!((v - 0.5 / std::f64::consts::PI).abs() < 1e-12, "{i}: {v}");
        }
    }
}
