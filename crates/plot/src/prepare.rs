//! Re-reading the measurements of a fit and putting the fitted model next to
//! them, sample by sample, exactly as `brtf fit` compared them.
//!
//! The data are rebuilt by the fit's own [`brtf_fit::Recipe`] (stored in
//! `fit.json`), through [`brtf_fit::Recipe::prepare`], the function the
//! fitter's data came from: the same conversion (BSDF, DSF ÷ |cos θ_out|,
//! raw signal ÷ beam integral or the `--rho` scale K, or in the file's unit
//! with the fitted free scale on the model) and the same selections, each
//! sample remembering which gate removed it.
//!
//! The rebuild is checked: the number of fitted samples must equal
//! [`FitReport::n_points`] and the RMS relative error recomputed here must
//! equal [`FitReport::rms_rel`]. A mismatch becomes a warning in the report,
//! so a plot never silently shows other data than the fit used.
//!
//! For three-channel data every plotted value (data and model) is the mean
//! of the three channels.

use crate::disk::{self, Coverage};
pub(crate) use brtf_fit::{DataUnit, Gate};
use brtf_fit::{FitReport, FitResult, InputFile, PreparedMeasurement, Recipe};
use brtf_gonio::Hemisphere;
use brtf_model::CompositeBsdf;
use glam::DVec3;
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// One sample of the file, with the model next to it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlotSample {
    /// θ_out in degrees.
    pub theta: f64,
    /// φ_out in degrees.
    pub phi: f64,
    /// Unit direction towards the detector.
    pub dir: DVec3,
    /// Measured value after conversion (channel mean); NaN if not available.
    pub data: f64,
    /// Model value `scale × f(l, v)` in the same unit (channel mean).
    pub model: f64,
    /// Index into [`Incidence::gates`] of the gate that removed the
    /// sample, `None` when it was fitted.
    pub removed_by: Option<usize>,
    /// `ln((model + floor)/(data + floor))` (data clamped at 0), with the
    /// incidence's floor: see [`Incidence::log_ratio`].
    pub log_ratio: f64,
}

impl PlotSample {
    /// The sample was fitted.
    pub fn used(&self) -> bool {
        self.removed_by.is_none()
    }

    /// Front or back hemisphere.
    pub fn hemisphere(&self) -> Hemisphere {
        Hemisphere::of_theta(self.theta)
    }
}

/// One incidence: the report, the samples and what the plots need.
#[derive(Debug, Clone)]
pub struct Incidence {
    /// Position in [`FitResult::incidences`].
    pub index: usize,
    /// File-name tag (`t30`, or `t30-p90` when θ_in repeats).
    pub tag: String,
    /// Incident polar angle, degrees.
    pub theta_in: f64,
    /// Incident azimuth, degrees.
    pub phi_in: f64,
    /// Unit vector towards the light.
    pub light: DVec3,
    /// Every sample of the file.
    pub samples: Vec<PlotSample>,
    /// The selections, in the order they were applied.
    pub gates: Vec<Gate>,
    /// Unit of [`PlotSample::data`] and [`PlotSample::model`].
    pub unit: DataUnit,
    /// The floor of relative residuals and log ratios (the report's).
    pub floor: f64,
    /// The fitted material (one primitive or a lobe sum), prepared for
    /// evaluation.
    pub bsdf: CompositeBsdf,
    /// The free scale (1 when not fitted).
    pub scale: f64,
    /// Channels in the file (1 or 3); plotted values are their mean.
    pub channels: usize,
    /// Things the reader should know about this incidence's plots.
    pub warnings: Vec<String>,
    /// Nearest-sample grids of the front and back disks, made on first
    /// use or handed over by [`Incidence::set_grids`] (`write_plots` makes
    /// them from the fitted data while the model values are computed, or
    /// while the charts that do not need them render).
    coverage: [OnceLock<Coverage>; 2],
    /// [`Incidence::hemispheres`], found on first use.
    hemispheres: OnceLock<Vec<Hemisphere>>,
    /// The samples near the plane of incidence, for the cuts.
    near_plane: OnceLock<Vec<(f64, f64, usize)>>,
    /// The cut of the first requested plane tolerance, with that request:
    /// the cut's SVG and PNG and the chart of all cuts share it.
    cut: OnceLock<(Option<f64>, CutCache)>,
}

/// A cut of one incidence as [`crate::charts::cut::CutData`] shows it, with
/// samples as indices into [`Incidence::samples`].
#[derive(Debug, Clone)]
pub(crate) struct CutCache {
    /// Plane tolerance in degrees.
    pub tolerance: f64,
    /// `(x, sample index)` for the samples drawn.
    pub points: Vec<(f64, usize)>,
    /// The model along the plane: `(x, value)`.
    pub curve: Vec<(f64, f64)>,
    /// The x range.
    pub range: (f64, f64),
}

impl Incidence {
    /// Every pixel of the `hemisphere`'s equal-area disk and the sample
    /// that owns it (fitted or not; an index into `samples`), made on
    /// first use. The maps draw it, the hemispherical
    /// integrals sum over it.
    pub fn coverage(&self, hemisphere: Hemisphere) -> &Coverage {
        let slot = match hemisphere {
            Hemisphere::Front => 0,
            Hemisphere::Back => 1,
        };
        self.coverage[slot].get_or_init(|| {
            disk_grid(hemisphere, self.samples.len(), |k| {
                let s = &self.samples[k];
                (s.theta, s.dir, s.used(), s.data)
            })
        })
    }

    /// The grid the hemispherical integrals sum over: the maps' grid for
    /// measured scans; for patch-averaged data (a few hundred patches,
    /// each many pixels wide) a 128² grid made for the caller alone and
    /// not kept, the same whether the maps are drawn or not (a Klems
    /// side's 512² grids took seconds and hundreds of MB).
    pub(crate) fn integration_grid(
        &self,
        hemisphere: Hemisphere,
        patch_averaged: bool,
    ) -> std::borrow::Cow<'_, Coverage> {
        if !patch_averaged {
            return std::borrow::Cow::Borrowed(self.coverage(hemisphere));
        }
        std::borrow::Cow::Owned(disk_grid_of_size(
            hemisphere,
            self.samples.len(),
            disk::COVERAGE_SIZE / 4,
            |k| {
                let s = &self.samples[k];
                (s.theta, s.dir, s.used(), s.data)
            },
        ))
    }

    /// The grid of `hemisphere` is made.
    pub(crate) fn has_grid(&self, hemisphere: Hemisphere) -> bool {
        let slot = match hemisphere {
            Hemisphere::Front => 0,
            Hemisphere::Back => 1,
        };
        self.coverage[slot].get().is_some()
    }

    /// Takes the grids made by [`grids_of_prepared`] from the data this
    /// incidence was built from (index 0 front, 1 back); a grid already
    /// made is kept.
    pub(crate) fn set_grids(&self, grids: [Option<Coverage>; 2]) {
        for (slot, grid) in self.coverage.iter().zip(grids) {
            if let Some(grid) = grid {
                let _ = slot.set(grid);
            }
        }
    }

    /// The samples near the plane of incidence, `(offset from the plane,
    /// in-plane angle, index into samples)` as the cuts define them
    /// ([`crate::charts::cut::CutData`]): made by `make` on first use.
    pub(crate) fn near_plane(
        &self,
        make: impl FnOnce() -> Vec<(f64, f64, usize)>,
    ) -> &[(f64, f64, usize)] {
        self.near_plane.get_or_init(make)
    }

    /// The cut for plane tolerance `tolerance` (`None`: automatic), made
    /// by `make`: once for the first tolerance asked for (every chart of a
    /// run asks for the same), afresh for any other.
    pub(crate) fn cut(
        &self,
        tolerance: Option<f64>,
        make: impl Fn() -> CutCache,
    ) -> std::borrow::Cow<'_, CutCache> {
        let (key, made) = self.cut.get_or_init(|| (tolerance, make()));
        if *key == tolerance {
            std::borrow::Cow::Borrowed(made)
        } else {
            std::borrow::Cow::Owned(make())
        }
    }

    /// Model value `scale × f` (channel mean) for direction `v`.
    pub fn model_at(&self, v: DVec3) -> f64 {
        let f = self.bsdf.eval(self.light, v);
        self.scale * f[..self.channels].iter().sum::<f64>() / self.channels as f64
    }

    /// The θ cap, if one was applied.
    pub fn theta_cap(&self) -> Option<f64> {
        self.gates.iter().find_map(|g| match g {
            Gate::ThetaCap { max_deg } => Some(*max_deg),
            _ => None,
        })
    }

    /// The beam-mask half-angle, if one was applied.
    pub fn beam_mask(&self) -> Option<f64> {
        self.gates.iter().find_map(|g| match g {
            Gate::BeamMask { half_angle_deg } if *half_angle_deg > 0.0 => Some(*half_angle_deg),
            _ => None,
        })
    }

    /// Hemispheres that hold fitted samples (front first), found once
    /// (the maps and the integrals ask several times).
    pub fn hemispheres(&self) -> Vec<Hemisphere> {
        self.hemispheres
            .get_or_init(|| {
                used_hemispheres(self.samples.len(), |k| {
                    let s = &self.samples[k];
                    (s.theta, s.used())
                })
            })
            .clone()
    }

    /// The hemispheres a map or the 3D view's surface draws: those
    /// holding fitted samples, or the front alone when none does.
    pub fn drawn_hemispheres(&self) -> Vec<Hemisphere> {
        let mut hemispheres = self.hemispheres();
        if hemispheres.is_empty() {
            hemispheres.push(Hemisphere::Front);
        }
        hemispheres
    }

    /// Mirror direction (θ_in, φ_in + 180°).
    pub fn mirror(&self) -> DVec3 {
        DVec3::new(-self.light.x, -self.light.y, self.light.z)
    }

    /// `ln((model + floor)/(data + floor))` of a sample (data clamped at
    /// 0), with [`Incidence::floor`]; made once per sample when the
    /// incidence is built (the maps, the colour bar and the statistics all
    /// read it).
    pub fn log_ratio(&self, s: &PlotSample) -> f64 {
        s.log_ratio
    }
}

/// Hemispheres that hold fitted samples (front first) among `n` samples,
/// sample `k` given by `sample(k)` as `(θ_out in degrees, fitted)`.
fn used_hemispheres(n: usize, sample: impl Fn(usize) -> (f64, bool)) -> Vec<Hemisphere> {
    let mut found = [false; 2];
    for k in 0..n {
        let (theta, used) = sample(k);
        if used {
            match Hemisphere::of_theta(theta) {
                Hemisphere::Front => found[0] = true,
                Hemisphere::Back => found[1] = true,
            }
            if found == [true; 2] {
                break;
            }
        }
    }
    [Hemisphere::Front, Hemisphere::Back]
        .into_iter()
        .zip(found)
        .filter_map(|(h, f)| f.then_some(h))
        .collect()
}

/// The nearest-sample grids the plots of one incidence draw (index 0
/// front, 1 back: the hemispheres with fitted samples, else the front),
/// made from the data the fit fitted, before the incidence is built: they
/// need only the directions and which samples were fitted with data. The
/// same grids [`Incidence::coverage`] makes from the built incidence (none
/// when the selection does not match the samples).
pub(crate) fn grids_of_prepared(prepared: &PreparedMeasurement) -> [Option<Coverage>; 2] {
    let m = &prepared.measurement;
    let channels = prepared.channels();
    let n = m.samples.len();
    if prepared.removed_by.len() != n || prepared.directions.len() != n {
        // Not data `build` accepts as it is: the grids are made from the
        // built incidence instead.
        return [None, None];
    }
    let mut hemispheres = used_hemispheres(n, |k| {
        (m.samples[k].theta_deg, prepared.removed_by[k].is_none())
    });
    if hemispheres.is_empty() {
        hemispheres.push(Hemisphere::Front);
    }
    let mut grids = [None, None];
    for hemisphere in hemispheres {
        let slot = match hemisphere {
            Hemisphere::Front => 0,
            Hemisphere::Back => 1,
        };
        grids[slot] = Some(disk_grid(hemisphere, n, |k| {
            let s = &m.samples[k];
            (
                s.theta_deg,
                prepared.directions[k],
                prepared.removed_by[k].is_none(),
                channel_mean(&s.values, channels),
            )
        }));
    }
    grids
}

/// The mean of the first `channels` values, summed in order (as
/// [`PlotSample::data`] is).
fn channel_mean(values: &[f64], channels: usize) -> f64 {
    let mut sum = 0.0;
    for &v in values.iter().take(channels) {
        sum += v;
    }
    sum / channels as f64
}

/// The nearest-sample grid of one hemisphere over `n` samples, sample
/// `k` given by `sample(k)` as `(θ_out in degrees, direction, fitted,
/// data)`: every sample of that hemisphere with a finite direction, except
/// fitted ones without data. Owners are sample indices. The samples are
/// picked and projected in parallel.
fn disk_grid(
    hemisphere: Hemisphere,
    n: usize,
    sample: impl Fn(usize) -> (f64, DVec3, bool, f64) + Sync,
) -> Coverage {
    disk_grid_of_size(hemisphere, n, disk::COVERAGE_SIZE, sample)
}

/// [`disk_grid`] of `size` pixels a side.
fn disk_grid_of_size(
    hemisphere: Hemisphere,
    n: usize,
    size: u32,
    sample: impl Fn(usize) -> (f64, DVec3, bool, f64) + Sync,
) -> Coverage {
    // In pieces of their own, then joined once into vectors of the exact
    // size (no growing, no list of partial vectors).
    const PIECE: usize = 8192;
    type Piece = (Vec<u32>, Vec<(f64, f64)>);
    let pieces: Vec<Piece> = (0..n.div_ceil(PIECE))
        .into_par_iter()
        .map(|p| {
            let range = p * PIECE..((p + 1) * PIECE).min(n);
            let mut ids = Vec::with_capacity(range.len());
            let mut points = Vec::with_capacity(range.len());
            for k in range {
                let (theta, dir, used, data) = sample(k);
                if Hemisphere::of_theta(theta) == hemisphere
                    && dir.is_finite()
                    && (!used || data.is_finite())
                {
                    ids.push(k as u32);
                    points.push(disk::project(dir, hemisphere));
                }
            }
            (ids, points)
        })
        .collect();
    let total = pieces.iter().map(|(ids, _)| ids.len()).sum();
    let mut ids = Vec::with_capacity(total);
    let mut points = Vec::with_capacity(total);
    for (i, p) in &pieces {
        ids.extend_from_slice(i);
        points.extend_from_slice(p);
    }
    Coverage::new(&points, &ids, size, disk::radius_of(disk::FILL_DEG))
}

/// The model value the fit compares with sample `index` of `prepared`
/// ([`PreparedMeasurement::model_value`]) for a lobe sum: its lobes'
/// values weighted (one lobe: that lobe's value as it is).
pub(crate) fn model_value(
    prepared: &PreparedMeasurement,
    bsdf: &CompositeBsdf,
    index: usize,
) -> [f64; 3] {
    if let [(_, lobe)] = bsdf.parts() {
        return prepared.model_value(lobe, index);
    }
    let mut sum = [0.0; 3];
    for (w, lobe) in bsdf.parts() {
        let f = prepared.model_value(lobe, index);
        for (s, v) in sum.iter_mut().zip(f) {
            *s += w * v;
        }
    }
    sum
}

/// `ln((model + floor)/(data + floor))`, data clamped at 0.
fn log_ratio(data: f64, model: f64, floor: f64) -> f64 {
    ((model.max(0.0) + floor) / (data.max(0.0) + floor)).ln()
}

/// Reads the file of `report`, applies the fit's recipe and builds the
/// incidence, or says why not.
pub fn load(
    result: &FitResult,
    index: usize,
    tag: String,
    fit_dir: &Path,
    search: &[PathBuf],
) -> Result<Incidence, String> {
    let report = &result.incidences[index];
    let input = result
        .input_of(index)
        .ok_or_else(|| format!("{}: not listed in the provenance", report.source))?;
    let path = brtf_io::locate_input(&input.path, fit_dir, search).ok_or_else(|| {
        format!(
            "{}: measurement file not found (looked relative to the current folder and {}); \
             its map and cut are not drawn",
            input.path,
            fit_dir.display()
        )
    })?;
    let bytes =
        brtf_io::read_input(&path).map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
    let mut warnings = Vec::new();
    if !input.sha256.is_empty() && brtf_io::sha256_hex(&bytes) != input.sha256 {
        warnings.push(format!(
            "{}: the file changed since the fit (SHA-256 differs); the plots show the new contents",
            input.path
        ));
    }
    let prepared = rebuild(&result.recipe, input, &bytes, &path)?;
    build(result, index, tag, input, &prepared, warnings)
}

/// Builds incidence `index` of `result` from the data the fit itself
/// fitted (`prepared`, from [`brtf_fit::fit_set_with_data`]), without
/// reading the file again. The same checks as [`load`] apply.
pub(crate) fn from_prepared(
    result: &FitResult,
    index: usize,
    tag: String,
    prepared: &PreparedMeasurement,
) -> Result<Incidence, String> {
    let report = &result.incidences[index];
    let input = result
        .input_of(index)
        .ok_or_else(|| format!("{}: not listed in the provenance", report.source))?;
    build(result, index, tag, input, prepared, Vec::new())
}

/// The incidence `index` of `result` on its fitted data `prepared` (read
/// from `input`), with the `warnings` found so far.
fn build(
    result: &FitResult,
    index: usize,
    tag: String,
    input: &InputFile,
    prepared: &PreparedMeasurement,
    mut warnings: Vec<String>,
) -> Result<Incidence, String> {
    let report = &result.incidences[index];
    let channels = prepared.channels();
    let unit = prepared.conversion.unit();
    let material = result
        .composite_of(report)
        .ok_or_else(|| format!("{}: the fitted arguments are not a material", input.path))?;
    let bsdf = CompositeBsdf::new(&material, &result.options());
    let light = brtf_model::direction(report.theta_in, report.phi_in);
    let gates: Vec<Gate> = result.recipe.selections.clone();
    let removed_by = &prepared.removed_by;
    let m = &prepared.measurement;

    let floor = report.floor;
    let floor2 = floor * floor;
    let incident = m.incident_direction();
    // Every sample with the model next to it, in parallel blocks; the
    // squared relative errors of the fitted ones (per channel) are summed
    // afterwards in sample order.
    const BLOCK: usize = 4096;
    // Each block: its samples, and the errors of its fitted ones in order.
    // Written in place, block by block (no second copy of every sample).
    let unset = PlotSample {
        theta: f64::NAN,
        phi: f64::NAN,
        dir: DVec3::ZERO,
        data: f64::NAN,
        model: f64::NAN,
        removed_by: None,
        log_ratio: f64::NAN,
    };
    let mut samples: Vec<PlotSample> = vec![unset; m.samples.len()];
    let rels_of_blocks: Vec<Vec<[f64; 3]>> = samples
        .par_chunks_mut(BLOCK)
        .zip(m.samples.par_chunks(BLOCK))
        .zip(removed_by.par_chunks(BLOCK))
        .zip(prepared.directions.par_chunks(BLOCK))
        .enumerate()
        .map(|(b, (((out, block), removed), dirs))| {
            // The block's directions, made once by the recipe.
            // Patch-averaged (Klems) data are compared with the averaged
            // model ([`PreparedMeasurement::model_value`]); else the model
            // is the BSDF at each direction, evaluated for the whole block
            // at once (brtf-model's batch kernel, equal to `Bsdf::eval` to
            // about 1e-15).
            let mut values = brtf_model::RgbBatch::default();
            match prepared.patch_pairs {
                Some(_) => {
                    values.resize(0);
                    for k in 0..block.len() {
                        let f = model_value(prepared, &bsdf, b * BLOCK + k);
                        values.r.push(f[0]);
                        values.g.push(f[1]);
                        values.b.push(f[2]);
                    }
                }
                None => {
                    let light = brtf_model::Directions::repeated(incident, block.len());
                    bsdf.eval_batch(
                        &light,
                        &brtf_model::Directions::from_vectors(dirs),
                        &mut values,
                    );
                }
            }
            let mut rels = Vec::new();
            for (k, (((s, removed), dir), slot)) in
                block.iter().zip(removed).zip(dirs).zip(out).enumerate()
            {
                let f = values.get(k);
                let mut data = 0.0;
                let mut model = 0.0;
                let mut rel = [0.0; 3];
                for (c, (&y, &fc)) in s.values.iter().zip(&f).take(channels).enumerate() {
                    let mv = report.scale * fc;
                    if removed.is_none() {
                        let e = mv - y;
                        rel[c] = e * e / (y * y + floor2);
                    }
                    data += y;
                    model += mv;
                }
                let (data, model) = (data / channels as f64, model / channels as f64);
                let sample = PlotSample {
                    theta: s.theta_deg,
                    phi: s.phi_deg,
                    dir: *dir,
                    data,
                    model,
                    removed_by: *removed,
                    log_ratio: log_ratio(data, model, floor),
                };
                if removed.is_none() {
                    rels.push(rel);
                }
                *slot = sample;
            }
            rels
        })
        .collect();
    // The errors summed in sample order.
    let mut sum_rel = 0.0;
    let mut n_used = 0usize;
    for rels in &rels_of_blocks {
        for rel in rels {
            for r in rel.iter().take(channels) {
                sum_rel += r;
            }
        }
        n_used += rels.len();
    }
    if n_used != report.n_points {
        warnings.push(format!(
            "{}: {} samples are marked as fitted here but the fit used {}; \
             the plotted selection may differ from the fit's",
            input.label(),
            n_used,
            report.n_points
        ));
    } else {
        let rms = (sum_rel / (n_used * channels).max(1) as f64).sqrt();
        // Loose enough for the fitter's other summation order.
        let tolerance = 1e-5 * report.rms_rel.abs().max(1e-9);
        if (rms - report.rms_rel).abs() > tolerance.max(1e-9) {
            warnings.push(format!(
                "{}: the RMS relative error recomputed from the file ({rms:.6}) differs from \
                 the fit's ({:.6}); the plotted data may not be what was fitted",
                input.path, report.rms_rel
            ));
        }
    }
    let incidence = Incidence {
        index,
        tag,
        theta_in: report.theta_in,
        phi_in: report.phi_in,
        light,
        samples,
        gates,
        unit,
        floor,
        bsdf,
        scale: report.scale,
        channels,
        warnings,
        coverage: [OnceLock::new(), OnceLock::new()],
        hemispheres: OnceLock::new(),
        near_plane: OnceLock::new(),
        cut: OnceLock::new(),
    };
    Ok(incidence)
}

/// The fit's data of one input as [`brtf_fit::prepare_input`] makes them,
/// except the per-sample solid angles. The plots never use those (maps and
/// integrals have their own equal-area grid), and on a 127 000-point
/// scattered pgII scan their Voronoi cells were over half the time of all
/// plots. No gate or conversion depends on them, so the fitted selection
/// and values are the fit's ([`load`] checks the count and the RMS).
fn rebuild(
    recipe: &Recipe,
    input: &InputFile,
    bytes: &[u8],
    path: &Path,
) -> Result<PreparedMeasurement, String> {
    if input.klems.is_some() {
        return brtf_fit::prepare_input(recipe, input, bytes, path).map_err(|e| e.to_string());
    }
    let mut measurement = brtf_gonio::read_bytes(bytes, path).map_err(|e| e.to_string())?;
    // Valid solid angles on every sample: `Recipe::prepare` keeps them
    // instead of computing the cells.
    for sample in &mut measurement.samples {
        sample.solid_angle_sr = Some(0.0);
    }
    recipe
        .prepare(measurement, &input.path)
        .map_err(|e| e.to_string())
}

/// File-name tags for every incidence: `t<θ>`, plus `-p<φ>` when a θ_in
/// occurs more than once or φ_in is not 0, plus `-<k>` if still not unique.
pub(crate) fn tags(reports: &[FitReport]) -> Vec<String> {
    let mut tags: Vec<String> = reports
        .iter()
        .map(|r| {
            let repeated = reports.iter().filter(|o| o.theta_in == r.theta_in).count() > 1;
            if repeated || r.phi_in != 0.0 {
                format!("t{}-p{}", num(r.theta_in), num(r.phi_in))
            } else {
                format!("t{}", num(r.theta_in))
            }
        })
        .collect();
    for i in 0..tags.len() {
        if tags[..i].contains(&tags[i]) {
            tags[i] = format!("{}-{}", tags[i], i + 1);
        }
    }
    tags
}

/// A number for file names and labels: at most 4 decimals, no trailing zeros.
pub(crate) fn num(x: f64) -> String {
    let s = format!("{:.4}", x);
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_for_names_are_short() {
        assert_eq!(num(15.0), "15");
        assert_eq!(num(26.8421), "26.8421");
        assert_eq!(num(-0.0), "0");
        assert_eq!(num(2.5), "2.5");
    }
}
