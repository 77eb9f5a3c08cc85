//! Tensor trees as fitted data: each chosen incidence of one side becomes
//! one incidence whose samples are the tree's outgoing leaves, and the
//! model is averaged over each leaf before it is compared with it.
//!
//! A leaf's value is the BSDF over a square cell of the Shirley–Chiu map
//! (`bsdf2ttree` evaluates its centre, or averages 256 points over the
//! input and output cells where the BSDF changes fast; `rttree_reduce`
//! averages merged cells). The model is averaged the same way as a Klems
//! patch ([`crate::klems`]): view directions stratified over the leaf's
//! cell (uniform in projected solid angle, the map keeping areas), light
//! directions stratified over the incidence's finest input cell; leaves
//! near the mirror or straight-through direction average every light with
//! every view, the others pair them in turn. The pairs are drawn once from
//! a fixed seed.

use crate::data::PatchPairs;
use crate::recipe::{PatchAveraging, PreparedMeasurement, Recipe, RecipeError};
use brtf_gonio::klems::ttree::TreeSample;
use brtf_gonio::klems::{Side, TensorTree};
use brtf_model::Rng;
use glam::DVec3;
use std::sync::Arc;

/// The θ_in (degrees) fitted by default: the Klems Full basis's ring
/// centres (`brtf info` lists the totals at the same angles).
pub const DEFAULT_THETAS: [f64; 9] = brtf_gonio::klems::ttree::INFO_THETAS;

/// Light directions over the input cell.
const LIGHTS: usize = 8;

/// View directions per leaf of the finest size; larger leaves get more in
/// proportion to their area, up to [`MAX_VIEWS`].
const VIEWS: usize = 4;

/// The most view directions of one leaf.
const MAX_VIEWS: usize = 64;

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
    let incidence = measurement.incidence;
    let mut prepared = recipe.prepare(measurement, source)?;
    if let Some(rule) = recipe.patch_average {
        let lights = tree.input_cell_lights(
            incidence.theta_deg,
            incidence.phi_deg,
            LIGHTS,
            &mut Rng::new(rule.seed, 1 << 33),
        );
        let finest = 0.5f64.powi(tree.depth() as i32);
        prepared.patch_pairs = Some(Arc::new(leaf_pairs(
            &lights,
            incidence.direction(),
            &places,
            finest,
            &rule,
        )));
    }
    Ok(Some(prepared))
}

/// The pairs of every sample (one per leaf in `places`, file order).
fn leaf_pairs(
    lights: &[DVec3],
    light_centre: DVec3,
    places: &[TreeSample],
    finest: f64,
    rule: &PatchAveraging,
) -> PatchPairs {
    let mirror = DVec3::new(-light_centre.x, -light_centre.y, light_centre.z);
    let through = DVec3::new(mirror.x, mirror.y, -mirror.z);
    let near_cosine = rule.near_lobe_deg.to_radians().cos();
    let n_lights = lights.len() as u32;
    let mut pairs = PatchPairs::new(lights.to_vec());
    for (k, place) in places.iter().enumerate() {
        let ratio = place.size / finest;
        let n = ((VIEWS as f64 * ratio * ratio).round() as usize).clamp(VIEWS, MAX_VIEWS);
        let views = place.stratified_directions(n, &mut Rng::new(rule.seed, k as u64));
        let first = pairs.directions.len() as u32;
        pairs.directions.extend(views);
        let n_views = pairs.directions.len() as u32 - first;
        let centre = place.direction_at(0.5, 0.5);
        let lobe = if place.transmitted { through } else { mirror };
        if centre.dot(lobe) >= near_cosine || n_lights == 0 {
            pairs.push((0..n_lights).flat_map(|l| (first..first + n_views).map(move |v| (l, v))));
        } else {
            pairs.push((0..n_views).map(|j| (j % n_lights, first + j)));
        }
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
