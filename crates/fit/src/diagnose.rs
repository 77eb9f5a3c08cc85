//! Whether a fitted model describes its data: energy, peak direction and
//! sensitivity to the residual kind, per incidence. A low cost does not
//! say the model is right; these say where it is not.
//!
//! * **Energy.** The data's directional-hemispherical reflectance (and
//!   transmittance) against the model's: over the measured directions from
//!   the data (Σ y |cos θ| ΔΩ over the fitted samples), the unmeasured rest
//!   from the model, so that a model that fits every measured sample has
//!   the data's ρ_dh exactly.
//! * **Peak.** The direction of the data's brightest samples against the
//!   model's, over the same fitted directions.
//! * **Residual kind.** The parameters fitted again with another residual
//!   kind (absolute ↔ log): a model that describes the data gives about the
//!   same parameters whichever way the misfit is weighed.
//!
//! Colour data are judged on their luminance (CIE Y), grey data as they are.

use crate::adequacy::{
    Adequacy, ENERGY_TOLERANCE, PEAK_TOLERANCE_DEG, RESIDUAL_KIND_TOLERANCE, ResidualCheck,
};
use crate::align::bright_centroid;
use crate::config::FitConfig;
use crate::data::IncidenceData;
use crate::recipe::PreparedMeasurement;
use crate::report::FitReport;
use brtf_gonio::Hemisphere;
use brtf_model::{Composite, CompositeBsdf, Directions, RgbBatch, composite_albedo};
use glam::DVec3;
use rayon::prelude::*;

/// The material of `report` with `config`'s orientation, ready to evaluate.
pub(crate) fn fitted_bsdf(config: &FitConfig, report: &FitReport) -> Option<CompositeBsdf> {
    let material = Composite::new(
        config.shape(),
        &report.material_args,
        Some(DVec3::from_array(config.orientation)),
    )
    .ok()?;
    Some(CompositeBsdf::new(&material, &config.options))
}

/// Luminance of the used channels of `values` (grey: the value itself).
fn luminance(values: [f64; 3], channels: usize) -> f64 {
    if channels >= 3 {
        brtf_model::luminance(values)
    } else {
        values[0]
    }
}

/// Hemispherical integrals of data and model over the fitted samples of
/// `prepared`, in the data's unit: `(data, model)` per hemisphere.
pub(crate) struct Measured {
    pub front: Option<(f64, f64)>,
    pub back: Option<(f64, f64)>,
}

/// Σ y |cos θ| ΔΩ and Σ scale·f |cos θ| ΔΩ over the fitted samples
/// (which `data`, the fitter's view of `prepared`, holds).
pub(crate) fn measured_integrals(
    prepared: &PreparedMeasurement,
    data: &IncidenceData,
    bsdf: &CompositeBsdf,
    scale: f64,
) -> Measured {
    measured_sums(prepared, data, &fitted_model(prepared, data, bsdf), scale)
}

/// The model's value (in luminance) at every fitted sample of `prepared`,
/// in the order of [`PreparedMeasurement::fitted`], at the directions of
/// the fitter's view of them (`data`), or averaged over their patch pairs.
/// Evaluated in parallel; the sums over them stay in sample order.
fn fitted_model(
    prepared: &PreparedMeasurement,
    data: &IncidenceData,
    bsdf: &CompositeBsdf,
) -> Vec<f64> {
    let channels = prepared.channels();
    if prepared.patch_pairs.is_some() {
        // Patch-averaged fits take one primitive.
        let bsdf = &bsdf.parts()[0].1;
        let indices: Vec<usize> = prepared.fitted().map(|(i, _)| i).collect();
        return indices
            .par_iter()
            .with_min_len(4096)
            .map(|&i| luminance(prepared.model_value(bsdf, i), channels))
            .collect();
    }
    // In pieces through the vectorised batch kernel (the same values as
    // `Bsdf::eval` to rounding).
    let light = prepared.measurement.incident_direction();
    let pieces: Vec<Vec<f64>> = data
        .samples
        .par_chunks(MODEL_PIECE)
        .map(|piece| {
            let n = piece.len();
            let lights = Directions::repeated(light, n);
            let mut views = Directions::with_capacity(n);
            for s in piece {
                views.push(s.view);
            }
            let mut values = RgbBatch::default();
            bsdf.eval_batch(&lights, &views, &mut values);
            (0..n).map(|i| luminance(values.get(i), channels)).collect()
        })
        .collect();
    pieces.concat()
}

/// Samples per piece of [`fitted_model`].
const MODEL_PIECE: usize = 4096;

/// [`measured_integrals`] with the model's values `model` from
/// [`fitted_model`]. |cos θ| comes from the fitter's directions `data`
/// (their z is the same `cos θ`), not from the angles again.
fn measured_sums(
    prepared: &PreparedMeasurement,
    data: &IncidenceData,
    model: &[f64],
    scale: f64,
) -> Measured {
    let channels = prepared.channels();
    let mut sums = [[0.0; 2]; 2];
    let mut seen = [false; 2];
    for (((_, s), fitted), &f) in prepared.fitted().zip(&data.samples).zip(model) {
        let weight = s.solid_angle_sr.unwrap_or(0.0) * fitted.view.z.abs();
        let side = usize::from(s.hemisphere() == Hemisphere::Back);
        sums[side][0] += weight * luminance(s.values, channels);
        sums[side][1] += weight * scale * f;
        seen[side] = true;
    }
    let pick = |side: usize| seen[side].then_some((sums[side][0], sums[side][1]));
    Measured {
        front: pick(0),
        back: pick(1),
    }
}

/// The model's ρ_dh and τ_dh at the incidence of `prepared`, in luminance.
pub(crate) fn model_albedo(prepared: &PreparedMeasurement, bsdf: &CompositeBsdf) -> (f64, f64) {
    let channels = prepared.channels();
    let a = composite_albedo(bsdf, prepared.measurement.incident_direction(), 1e-6);
    let total =
        |x: [f64; 3], spike: [f64; 3]| luminance([0, 1, 2].map(|c| x[c] + spike[c]), channels);
    (total(a.rho, a.rho_spike), total(a.tau, a.tau_spike))
}

/// The energy and peak diagnostics of `report`, fitted to `prepared`
/// (whose fitted samples `data` holds; the residual-kind check is added
/// by the caller).
pub(crate) fn diagnose(
    prepared: &PreparedMeasurement,
    data: &IncidenceData,
    report: &FitReport,
    config: &FitConfig,
) -> Option<Adequacy> {
    let bsdf = fitted_bsdf(config, report)?;
    let scale = report.scale;
    let ((rho_model, tau_model), model) = rayon::join(
        || model_albedo(prepared, &bsdf),
        || fitted_model(prepared, data, &bsdf),
    );
    // Two independent passes over the fitted samples, side by side.
    let (measured, peak) = rayon::join(
        || measured_sums(prepared, data, &model, scale),
        || peak_shape(prepared, data, &model),
    );
    let peak_offset_deg = peak.as_ref().map(|p| p.offset_deg);
    let gloss_width_deg = peak.map(|p| p.width_deg);
    // Data's reflectance: measured part ÷ scale, plus the model's rest.
    let complete = |part: Option<(f64, f64)>, model_total: f64| {
        part.map(|(data, model)| model_total + (data - model) / scale)
    };
    // A free scale's ρ would be the data ÷ a scale that moves with the
    // residual kind: its energy is given in the file's unit instead.
    if let crate::Conversion::Raw { unit, .. } = &prepared.conversion
        && prepared.conversion.is_free_scale()
    {
        let side = measured.front.map(|m| (false, m));
        let raw_energy = side
            .or(measured.back.map(|m| (true, m)))
            .map(|(back, (data, model))| crate::RawEnergy {
                unit: unit.clone(),
                back,
                data,
                model,
            });
        return Some(Adequacy {
            rho_data: None,
            rho_model,
            tau_data: None,
            tau_model,
            peak_offset_deg,
            gloss_width_deg,
            residual_check: None,
            raw_energy,
        });
    }
    Some(Adequacy {
        rho_data: complete(measured.front, rho_model),
        rho_model,
        tau_data: complete(measured.back, tau_model),
        tau_model,
        peak_offset_deg,
        gloss_width_deg,
        residual_check: None,
        raw_energy: None,
    })
}

/// The peak of data and model over the fitted directions: the angle
/// between their directions and their widths. `None` when the data have
/// no distinct peak (their brightest samples are less than twice their
/// median). `model` holds the model's values at the fitted samples
/// ([`fitted_model`]); `data` the fitter's view of them (their directions).
///
/// Patch averages (Klems data) are few and wide: the brightest three of
/// 145 patches jump from one patch to its neighbour on a small change of
/// value. There both centroids are taken over the same patches (the
/// brightest of the data's and of the model's), so that a model equal to
/// the data's averages has its peak exactly there.
fn peak_shape(
    prepared: &PreparedMeasurement,
    data: &IncidenceData,
    model: &[f64],
) -> Option<PeakShape> {
    let channels = prepared.channels();
    let mut dirs = Vec::with_capacity(model.len());
    let (mut data_values, mut model_values, mut omegas) = (Vec::new(), Vec::new(), Vec::new());
    for ((s, &f), (_, sample)) in data.samples.iter().zip(model).zip(prepared.fitted()) {
        let y = luminance(s.value, channels);
        if y.is_finite() {
            dirs.push(s.view);
            data_values.push(y);
            model_values.push(f);
            omegas.push(sample.solid_angle_sr.unwrap_or(0.0));
        }
    }
    let ((data_peak, contrast), (model_peak, _)) = match rayon::join(
        || bright_centroid(&dirs, &data_values),
        || bright_centroid(&dirs, &model_values),
    ) {
        (Some(d), Some(m)) => (d, m),
        _ => return None,
    };
    if contrast < 2.0 {
        return None;
    }
    let (data_peak, model_peak) = if prepared.patch_pairs.is_some() {
        let mut common = brightest_indices(&data_values);
        common.extend(brightest_indices(&model_values));
        let centroid = |values: &[f64]| -> DVec3 {
            common
                .iter()
                .map(|&i| dirs[i] * values[i].max(0.0))
                .sum::<DVec3>()
                .normalize_or_zero()
        };
        (centroid(&data_values), centroid(&model_values))
    } else {
        (data_peak, model_peak)
    };
    let offset_deg = data_peak
        .dot(model_peak)
        .clamp(-1.0, 1.0)
        .acos()
        .to_degrees();
    let width_deg = [
        half_max_width_deg(&data_values, &omegas),
        half_max_width_deg(&model_values, &omegas),
    ];
    Some(PeakShape {
        offset_deg,
        width_deg,
    })
}

/// Where a peak is and how wide, data against model.
struct PeakShape {
    /// Angle between the two peak directions, degrees.
    offset_deg: f64,
    /// [data, model] half-maximum widths ([`half_max_width_deg`]).
    width_deg: [f64; 2],
}

/// The indices of the brightest [`crate::align::PEAK_FRACTION`] of
/// `values` (at least three).
fn brightest_indices(values: &[f64]) -> Vec<usize> {
    let count = ((values.len() as f64 * crate::align::PEAK_FRACTION).ceil() as usize)
        .clamp(3.min(values.len()), values.len());
    crate::align::brightest(values, count.max(1))
}

/// A peak's width: the full apex angle of the cone whose solid angle is
/// that of the samples above half the peak's height over the median (the
/// peak: the mean of the brightest samples). The measure of gloss width
/// that needs no model: data and model are judged alike.
fn half_max_width_deg(values: &[f64], omegas: &[f64]) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    let top = brightest_indices(values);
    let peak = top.iter().map(|&i| values[i]).sum::<f64>() / top.len() as f64;
    let mut sorted = values.to_vec();
    let mid = sorted.len() / 2;
    let median = *sorted.select_nth_unstable_by(mid, f64::total_cmp).1;
    let half = median + 0.5 * (peak - median);
    let omega: f64 = values
        .iter()
        .zip(omegas)
        .filter(|(v, _)| **v >= half)
        .map(|(_, w)| w)
        .sum();
    brtf_model::cone_apex_deg(omega)
}

/// The residual kind of the second fit: log for absolute residuals,
/// absolute for relative and log ones.
pub(crate) fn other_residual(kind: crate::ResidualKind) -> crate::ResidualKind {
    match kind {
        crate::ResidualKind::Absolute => crate::ResidualKind::Log,
        _ => crate::ResidualKind::Absolute,
    }
}

/// The parameter of `main` that moved most in `other` (fitted with the
/// residual kind `residual`). Small values are compared on an absolute
/// floor of 0.02, so that a specularity of 0.001 against 0.003 does not
/// count as a 200% change.
pub(crate) fn compare(
    main: &FitReport,
    other: &FitReport,
    residual: crate::ResidualKind,
) -> Option<ResidualCheck> {
    main.params
        .iter()
        .zip(&other.params)
        .filter(|(a, _)| !a.fixed && a.name != "scale")
        .map(|(a, b)| {
            // The orientation is an angle modulo 180°: its change is the
            // turn between the two, as a fraction of the largest (90°).
            let change = if a.name == "orient" {
                let turn = (a.value - b.value).rem_euclid(180.0);
                turn.min(180.0 - turn) / 90.0
            } else {
                (a.value - b.value).abs() / a.value.abs().max(b.value.abs()).max(0.02)
            };
            ResidualCheck {
                residual,
                param: a.name.clone(),
                values: [a.value, b.value],
                relative_change: change,
            }
        })
        .max_by(|a, b| a.relative_change.total_cmp(&b.relative_change))
}

/// The warnings the diagnostics call for.
pub(crate) fn warnings(a: &Adequacy) -> Vec<crate::FitWarning> {
    let mut warnings = Vec::new();
    if let Some(ratio) = a.energy_ratio()
        && !(1.0 / (1.0 + ENERGY_TOLERANCE)..=1.0 + ENERGY_TOLERANCE).contains(&ratio)
    {
        let figure = a.energy().expect("a ratio has its figure");
        warnings.push(crate::FitWarning::EnergyMismatch {
            data: figure.data,
            model: figure.model,
            unit: figure.unit,
        });
    }
    if let Some(offset) = a.peak_offset_deg
        && offset > PEAK_TOLERANCE_DEG
    {
        warnings.push(crate::FitWarning::PeakOffset { degrees: offset });
    }
    if let Some(check) = &a.residual_check
        && check.relative_change > RESIDUAL_KIND_TOLERANCE
    {
        warnings.push(crate::FitWarning::ResidualKindSensitive {
            check: check.clone(),
        });
    }
    warnings
}
