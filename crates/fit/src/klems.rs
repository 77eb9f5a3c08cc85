//! Klems BSDF XML as fitted data: each incident patch of one side becomes
//! one incidence whose samples are the outgoing patches, and the model is
//! averaged over the patches before it is compared with them.
//!
//! A Klems value is the BSDF averaged over the outgoing patch (projected
//! solid angle weighted) and, for files made by `bsdf2klems`, over the
//! incident patch too. Evaluating the model at the patch centres is wrong
//! by up to 50× for narrow lobes (`../shared/spec/klems-xml.md`), so each
//! sample gets a fixed set of (light, view) pairs ([`PatchPairs`]):
//!
//! - the light directions are `incident_samples` stratified directions of
//!   the incident patch, the view directions `outgoing_samples` stratified
//!   directions of the outgoing patch, both uniform in projected solid
//!   angle ([`KlemsPatch::stratified_directions`]);
//! - near the mirror and straight-through directions, where a narrow lobe
//!   makes the value depend on where within both patches the directions
//!   fall, every light is paired with every view;
//! - elsewhere, where the BSDF varies slowly, the views are paired one to
//!   one with the lights in turn.
//!
//! The pairs are drawn once, from a fixed seed, so the fitted objective is
//! a smooth, deterministic function of the parameters, and plots and
//! checks that rebuild the data get the same pairs.

use crate::data::PatchPairs;
use crate::recipe::{PatchAveraging, PreparedMeasurement, Recipe, RecipeError};
use brtf_gonio::klems::{KlemsBasis, KlemsBsdf, Side};
use brtf_model::Rng;
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// Which incident patch of a Klems file an incidence is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct KlemsPatchRef {
    /// The side the light comes from (Radiance's front = +z).
    pub side: Side,
    /// The incident patch, in basis order.
    pub patch: usize,
}

/// Lowest roughness of a Klems fit: a lobe narrower than this fits inside
/// one Full-basis patch (5° to 30° across), so its width cannot be told
/// from patch averages (`../shared/spec/klems-xml.md`), and stratified
/// averages of so narrow a lobe are too coarse for a smooth objective.
pub const MIN_KLEMS_ROUGHNESS: f64 = 0.05;

/// Stream numbers of the incident patches' directions start here, far
/// from the outgoing patches' (numbered by patch).
const INCIDENT_STREAM: u64 = 1 << 32;

/// Incident patch `patch` of `side` of `bsdf`, prepared by `recipe`, in
/// the side's own frame (the light on +z; see
/// [`KlemsBsdf::measurement`]), with its patch pairs when the recipe
/// averages over patches. `None` when the side has no Visible data.
pub fn prepare_patch(
    recipe: &Recipe,
    bsdf: &KlemsBsdf,
    at: KlemsPatchRef,
    source: &str,
) -> Result<Option<PreparedMeasurement>, RecipeError> {
    let directions = recipe
        .patch_average
        .map(|rule| PatchDirections::new(&bsdf.basis, &rule));
    prepare_patch_sharing(recipe, bsdf, at, source, directions.as_ref())
}

/// [`prepare_patch`] with the basis's [`PatchDirections`] made already
/// (required when the recipe averages over patches, else made here).
pub fn prepare_patch_sharing(
    recipe: &Recipe,
    bsdf: &KlemsBsdf,
    at: KlemsPatchRef,
    source: &str,
    directions: Option<&PatchDirections>,
) -> Result<Option<PreparedMeasurement>, RecipeError> {
    let Some(measurement) = bsdf.measurement(at.side, at.patch, true) else {
        return Ok(None);
    };
    let mut prepared = recipe.prepare(measurement, source)?;
    if let Some(rule) = recipe.patch_average {
        let made;
        let directions = match directions {
            Some(d) => d,
            None => {
                made = PatchDirections::new(&bsdf.basis, &rule);
                &made
            }
        };
        prepared.patch_pairs = Some(Arc::new(patch_pairs(
            &bsdf.basis,
            at.patch,
            &prepared,
            &rule,
            directions,
        )));
    }
    Ok(Some(prepared))
}

/// Every direction the pairs of one basis use, made once and shared by
/// every incidence of a side: per patch, its stratified lights and its
/// stratified views on each side of the surface.
#[derive(Debug, Clone)]
pub struct PatchDirections {
    table: Arc<Vec<DVec3>>,
    lights: Vec<std::ops::Range<u32>>,
    reflected: Vec<std::ops::Range<u32>>,
    transmitted: Vec<std::ops::Range<u32>>,
}

impl PatchDirections {
    /// The directions of `basis`'s patches under `rule`.
    pub fn new(basis: &KlemsBasis, rule: &PatchAveraging) -> PatchDirections {
        let mut table = Vec::new();
        let mut add = |directions: Vec<DVec3>| {
            let first = table.len() as u32;
            table.extend(directions);
            first..table.len() as u32
        };
        let patches = basis.patches();
        let draw = |n: usize, stream: u64, o: usize| {
            patches[o].stratified_directions(n, &mut Rng::new(rule.seed, stream))
        };
        // Incident patch (θ, φ) is the direction of travel: the light is
        // at φ + 180°.
        let lights = (0..patches.len())
            .map(|i| {
                add(draw(rule.incident_samples, INCIDENT_STREAM + i as u64, i)
                    .into_iter()
                    .map(|v| DVec3::new(-v.x, -v.y, v.z))
                    .collect())
            })
            .collect();
        let views: Vec<Vec<DVec3>> = (0..patches.len())
            .map(|o| draw(rule.outgoing_samples, o as u64, o))
            .collect();
        let reflected = views.iter().map(|v| add(v.clone())).collect();
        let transmitted = views
            .iter()
            .map(|v| add(v.iter().map(|v| DVec3::new(v.x, v.y, -v.z)).collect()))
            .collect();
        PatchDirections {
            table: Arc::new(table),
            lights,
            reflected,
            transmitted,
        }
    }
}

/// The pairs of every sample of `prepared` (file order), incident patch
/// `incident` of `basis`, in `directions` (made for `basis` and `rule`).
fn patch_pairs(
    basis: &KlemsBasis,
    incident: usize,
    prepared: &PreparedMeasurement,
    rule: &PatchAveraging,
    directions: &PatchDirections,
) -> PatchPairs {
    let light_centre = prepared.measurement.incidence.direction();
    let mirror = DVec3::new(-light_centre.x, -light_centre.y, light_centre.z);
    let near_cosine = rule.near_lobe_deg.to_radians().cos();
    let lights = directions.lights.get(incident).cloned().unwrap_or(0..0);
    let mut pairs = PatchPairs::sharing(Arc::clone(&directions.table));
    for sample in &prepared.measurement.samples {
        let transmitted = sample.theta_deg > 90.0;
        let theta = if transmitted {
            180.0 - sample.theta_deg
        } else {
            sample.theta_deg
        };
        let Some(o) = basis.patch_index(theta, sample.phi_deg) else {
            pairs.push_zip(0..0, 0..0);
            continue;
        };
        let to_side = |v: DVec3| {
            if transmitted {
                DVec3::new(v.x, v.y, -v.z)
            } else {
                v
            }
        };
        let views = if transmitted {
            directions.transmitted[o].clone()
        } else {
            directions.reflected[o].clone()
        };
        // The lobe's centre for this side: the mirror direction, or the
        // straight-through direction (the mirror's reflection through the
        // surface).
        let lobe = to_side(mirror);
        let near = sample.direction().dot(lobe) >= near_cosine;
        if near || lights.is_empty() {
            pairs.push_product(lights.clone(), views);
        } else {
            pairs.push_zip(lights.clone(), views);
        }
    }
    pairs
}

/// Which incidences of a Klems file to fit: `theta<=60`, `theta>=10`,
/// `theta<60`, `theta>10`, joined by commas (all must hold).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct IncidenceFilter {
    /// The conditions, each `(operator, degrees)`.
    pub conditions: Vec<(String, f64)>,
}

impl IncidenceFilter {
    /// True when θ_in (degrees, in the side's frame) passes every condition.
    pub fn keeps(&self, theta_in: f64) -> bool {
        self.conditions.iter().all(|(op, value)| match op.as_str() {
            "<=" => theta_in <= *value + 1e-9,
            "<" => theta_in < *value - 1e-9,
            ">=" => theta_in >= *value - 1e-9,
            ">" => theta_in > *value + 1e-9,
            _ => false,
        })
    }
}

impl std::str::FromStr for IncidenceFilter {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, String> {
        let mut conditions = Vec::new();
        for part in text.split(',').map(str::trim).filter(|p| !p.is_empty()) {
            let rest = part.strip_prefix("theta").ok_or_else(|| {
                format!("`{part}`: expected a condition on theta, such as theta<=60")
            })?;
            let rest = rest.trim_start();
            let op = ["<=", ">=", "<", ">"]
                .into_iter()
                .find(|op| rest.starts_with(op))
                .ok_or_else(|| format!("`{part}`: expected <=, >=, < or > after theta"))?;
            let number = rest[op.len()..].trim();
            let value: f64 = number
                .parse()
                .ok()
                .filter(|v: &f64| v.is_finite())
                .ok_or_else(|| format!("`{part}`: `{number}` is not a number of degrees"))?;
            conditions.push((op.to_string(), value));
        }
        if conditions.is_empty() {
            return Err("expected at least one condition, such as theta<=60".into());
        }
        Ok(IncidenceFilter { conditions })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use brtf_gonio::klems::{KlemsBand, KlemsDirection, KlemsHeader, KlemsMatrix};
    use brtf_model::{Bsdf, EvalOptions, Material, MaterialKind};

    /// A Klems Full file lit from the front whose values do not matter.
    fn front_file() -> KlemsBsdf {
        let basis = KlemsBasis::full();
        let n = basis.len();
        let matrix = |direction| KlemsMatrix {
            band: KlemsBand::Visible,
            direction,
            n,
            values: vec![0.1; n * n],
            clipped_negative: 0,
            line: 1,
        };
        KlemsBsdf {
            source: "test".into(),
            header: KlemsHeader::default(),
            incident_data_structure: "Columns".into(),
            basis,
            matrices: vec![
                matrix(KlemsDirection::ReflectionBack),
                matrix(KlemsDirection::TransmissionBack),
            ],
        }
    }

    /// Averaging matters: for a lobe of roughness 0.05 the model averaged
    /// over the incident and outgoing patch is far from the model at the
    /// patch centres, and the fit's fixed pairs give the double patch
    /// average that a dense independent quadrature gives.
    #[test]
    fn patch_averages_differ_from_centre_values_and_match_dense_quadrature() {
        let file = front_file();
        let recipe = Recipe::for_klems(MaterialKind::Trans);
        let material = Material::new(
            MaterialKind::Trans,
            &[0.7, 0.7, 0.7, 0.05, 0.05, 0.5, 0.4],
            None,
        )
        .unwrap();
        let bsdf = Bsdf::new(&material, &EvalOptions::default());
        let basis = &file.basis;
        // Incident patch 49: the 40° ring (rings 0-4 hold 1 + 8 + 16 + 20).
        let incident = 49;
        let at = KlemsPatchRef {
            side: Side::Front,
            patch: incident,
        };
        let prepared = prepare_patch(&recipe, &file, at, "test").unwrap().unwrap();
        let p_in = basis.patch(incident).unwrap();
        assert_eq!(p_in.theta_deg, 40.0);
        // The diagonal reflection sample (mirror) and transmission sample
        // (straight through) are outgoing patch `incident` of each block.
        for (sample, transmitted) in [(incident, false), (basis.len() + incident, true)] {
            let averaged = prepared.model_value(&bsdf, sample)[1];
            let s = &prepared.measurement.samples[sample];
            let centre = bsdf.eval(prepared.measurement.incident_direction(), s.direction())[1];
            // Dense quadrature: 24 × 24 strata of each patch, every pairing.
            let lights: Vec<DVec3> = p_in
                .stratified_directions(576, &mut Rng::new(99, 1))
                .into_iter()
                .map(|v| DVec3::new(-v.x, -v.y, v.z))
                .collect();
            let views: Vec<DVec3> = p_in
                .stratified_directions(576, &mut Rng::new(99, 2))
                .into_iter()
                .map(|v| {
                    if transmitted {
                        DVec3::new(v.x, v.y, -v.z)
                    } else {
                        v
                    }
                })
                .collect();
            let mut sum = 0.0;
            for l in lights.iter().step_by(4) {
                for v in &views {
                    sum += bsdf.eval(*l, *v)[1];
                }
            }
            let dense = sum / (144.0 * 576.0);
            eprintln!(
                "transmitted {transmitted}: centre {centre:.4}, fit average {averaged:.4}, dense {dense:.4}"
            );
            assert!(
                centre > 1.5 * averaged,
                "transmitted {transmitted}: centre {centre} vs average {averaged}"
            );
            assert!(
                (averaged / dense - 1.0).abs() < 0.03,
                "transmitted {transmitted}: fit's average {averaged} vs dense {dense}"
            );
        }
    }

    #[test]
    fn filters_parse_and_keep() {
        let f: IncidenceFilter = "theta<=60, theta>5".parse().unwrap();
        assert!(f.keeps(60.0) && f.keeps(10.0));
        assert!(!f.keeps(70.0) && !f.keeps(5.0) && !f.keeps(0.0));
        for bad in ["", "phi<3", "theta=4", "theta<=x"] {
            assert!(bad.parse::<IncidenceFilter>().is_err(), "{bad}");
        }
    }
}
