//! `--model auto`: fit a candidate set and keep the material that earns
//! its parameters.
//!
//! The candidates, in one family (plastic or metal, whichever one-lobe fit
//! has the lower cost): the type itself, its anisotropic type with the
//! orientation fitted, two lobes, and two anisotropic lobes. Each is judged
//! by its held-out E1 ([`crate::FitReport::e1`]): every incidence's
//! samples are dealt into [`FOLDS`] folds, each fold fitted again without
//! its samples and judged on them. The winner is the candidate with the
//! fewest parameters whose held-out E1 is within [`MARGIN_POINTS`] (or
//! [`MARGIN_RELATIVE`]) of the best: more parameters must earn their place.
//! A candidate whose lobes collapsed is not chosen: its simpler twin is.

use crate::config::{FitConfig, FitError};
use crate::data::IncidenceData;
use crate::diagnose;
use crate::fitter::{SharedGeometry, e1_parts, heldout_e1_parts, shared_geometry};
use crate::params::ParamMap;
use crate::recipe::PreparedMeasurement;
use crate::report::{FitReport, FitWarning};
use brtf_model::MaterialKind;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// Folds of the held-out E1.
pub const FOLDS: usize = 5;
/// A candidate with more parameters wins only if its held-out E1 beats a
/// simpler one's by more than this (absolute, as a fraction)...
pub const MARGIN_POINTS: f64 = 0.005;
/// ...and by more than this fraction of it.
pub const MARGIN_RELATIVE: f64 = 0.05;

/// One candidate of `--model auto` and how it did.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CandidateRecord {
    /// The candidate, as people read it (`plastic2 ×2 lobes (orientation fitted)`).
    pub model: String,
    /// Its type.
    #[serde(with = "crate::serde_kind")]
    pub kind: MaterialKind,
    /// Its lobes.
    pub lobes: usize,
    /// Its orientation is fitted.
    pub oriented: bool,
    /// Free parameters (per incidence).
    pub parameters: usize,
    /// E1 of the fits on every sample, pooled over the incidences.
    pub e1: f64,
    /// E1 of each fold's fit on the samples it did not see, pooled.
    pub e1_heldout: f64,
    /// The largest peak offset over the incidences, degrees.
    pub peak_offset_deg: Option<f64>,
    /// The fits' cost, summed over the incidences.
    pub cost: f64,
    /// Some lobe collapsed (see [`FitWarning::CollapsedLobe`]).
    pub collapsed: bool,
    /// Wall time of its fits and folds, milliseconds.
    pub elapsed_ms: f64,
    /// Its fitted material arguments and free scale per incidence, in
    /// [`crate::FitResult::incidences`] order (what the report's 3D view
    /// draws for it; empty in fits written before they were kept).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub fitted: Vec<(Vec<f64>, f64)>,
}

/// What `--model auto` tried and why it chose what it chose.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AutoChoice {
    /// Every candidate, after the other family's one-lobe fit when both
    /// families were tried (`first` is the first candidate's index).
    pub candidates: Vec<CandidateRecord>,
    /// Index of the first candidate in `candidates` (1 when the other
    /// family's one-lobe fit comes first, else 0).
    pub first: usize,
    /// Index of the winner in `candidates`.
    pub chosen: usize,
    /// Why, for people.
    pub reason: String,
}

/// The candidate configurations of family `kind` (plastic or metal):
/// `oriented` says whether the anisotropic ones fit their orientation.
fn candidate_configs(base: &FitConfig, kind: MaterialKind, oriented: bool) -> Vec<FitConfig> {
    let anisotropic = match kind {
        MaterialKind::Metal => MaterialKind::Metal2,
        _ => MaterialKind::Plastic2,
    };
    [(kind, 1), (anisotropic, 1), (kind, 2), (anisotropic, 2)]
        .into_iter()
        .map(|(kind, lobes)| FitConfig {
            kind,
            lobes,
            oriented: kind.is_anisotropic() && oriented,
            ..base.clone()
        })
        .collect()
}

/// A candidate's fits: every incidence, and its record.
struct Candidate {
    config: FitConfig,
    reports: Vec<FitReport>,
    record: CandidateRecord,
}

/// Fits `config` to every incidence (a lobe sum from the one-lobe fits
/// `base`) and judges it.
fn judge(
    config: FitConfig,
    prepared: &[&PreparedMeasurement],
    data: &[IncidenceData],
    base: Option<&[FitReport]>,
) -> Result<Candidate, FitError> {
    let started = Instant::now();
    let geometry: Vec<SharedGeometry> = shared_geometry(data, &config)?;
    let reports: Vec<FitReport> = data
        .par_iter()
        .zip(&geometry)
        .enumerate()
        .map(|(k, (d, g))| match base {
            Some(base) => crate::fitter::fit_incidence_from(d, &config, g, &base[k]),
            None => crate::fitter::fit_incidence_sharing(d, &config, g),
        })
        .collect::<Result<_, _>>()?;
    let pooled = |parts: Vec<Option<(f64, f64)>>| -> f64 {
        let (m, t) = parts
            .into_iter()
            .flatten()
            .fold((0.0, 0.0), |(m, t), (a, b)| (m + a, t + b));
        m / t
    };
    let (full, heldout): (Vec<_>, Vec<_>) = data
        .par_iter()
        .zip(&reports)
        .map(|(d, r)| {
            (
                e1_parts(d, &config, &r.material_args, r.scale, r.floor),
                heldout_e1_parts(d, &config, r, FOLDS),
            )
        })
        .unzip();
    let peak_offset_deg = prepared
        .par_iter()
        .zip(data)
        .zip(&reports)
        .filter_map(|((p, d), r)| diagnose::diagnose(p, d, r, &config)?.peak_offset_deg)
        .reduce_with(f64::max);
    let collapsed = reports.iter().any(|r| {
        r.warnings
            .iter()
            .any(|w| matches!(w, FitWarning::CollapsedLobe { .. }))
    });
    let record = CandidateRecord {
        model: config.shape().label(),
        kind: config.kind,
        lobes: config.lobes,
        oriented: config.oriented,
        parameters: ParamMap::new(
            config.shape(),
            config.gray || data[0].channels == 1,
            config.free_scale,
        )
        .len(),
        e1: pooled(full),
        e1_heldout: pooled(heldout),
        peak_offset_deg,
        cost: reports.iter().map(|r| r.cost).sum(),
        collapsed,
        elapsed_ms: started.elapsed().as_secs_f64() * 1e3,
        fitted: reports
            .iter()
            .map(|r| (r.material_args.clone(), r.scale))
            .collect(),
    };
    Ok(Candidate {
        config,
        reports,
        record,
    })
}

/// Runs the candidate set on `data` (prepared as `prepared`) and returns
/// the chosen configuration, the record of the choice and the winner's
/// fit of every incidence.
pub(crate) fn choose(
    base: &FitConfig,
    prepared: &[&PreparedMeasurement],
    data: &[IncidenceData],
) -> Result<(FitConfig, AutoChoice, Vec<FitReport>), FitError> {
    // The family: plastic or metal, by the one-lobe fits' cost. Under a
    // free scale the colour is held at 1, where metal is plastic: plastic.
    let one = |kind| FitConfig {
        kind,
        lobes: 1,
        oriented: false,
        ..base.clone()
    };
    let mut candidates = Vec::new();
    let family = if base.free_scale {
        judge(one(MaterialKind::Plastic), prepared, data, None)?
    } else {
        let (plastic, metal) = rayon::join(
            || judge(one(MaterialKind::Plastic), prepared, data, None),
            || judge(one(MaterialKind::Metal), prepared, data, None),
        );
        let (plastic, metal) = (plastic?, metal?);
        let metal_wins = metal.record.cost < plastic.record.cost * (1.0 - 1e-9);
        let (family, rival) = if metal_wins {
            (metal, plastic)
        } else {
            (plastic, metal)
        };
        candidates.push(rival);
        family
    };
    let first = candidates.len();
    let configs = candidate_configs(base, family.config.kind, base.oriented);
    candidates.push(family);
    for (i, config) in configs.into_iter().enumerate().skip(1) {
        // Two lobes start from the candidate of one lobe of their type.
        let base = (config.lobes > 1).then(|| candidates[first + i - 2].reports.as_slice());
        let judged = judge(config, prepared, data, base)?;
        candidates.push(judged);
    }
    let records: Vec<CandidateRecord> = candidates.iter().map(|c| c.record.clone()).collect();
    let chosen = pick(&records, first);
    let reason = explain(&records, chosen, first);
    let winner = candidates.swap_remove(chosen);
    Ok((
        winner.config,
        AutoChoice {
            candidates: records,
            first,
            chosen,
            reason,
        },
        winner.reports,
    ))
}

/// The winner among `records` from index `first` on (see the module
/// docs); the rival family's one-lobe fit before it, if any, is a
/// reference, not a candidate.
fn pick(records: &[CandidateRecord], first: usize) -> usize {
    let eligible: Vec<usize> = (first..records.len())
        .filter(|&i| !records[i].collapsed && records[i].e1_heldout.is_finite())
        .collect();
    let Some(best) = eligible
        .iter()
        .map(|&i| records[i].e1_heldout)
        .reduce(f64::min)
    else {
        return first;
    };
    let good_enough = best + (MARGIN_POINTS).max(MARGIN_RELATIVE * best);
    eligible
        .into_iter()
        .filter(|&i| records[i].e1_heldout <= good_enough)
        .min_by(|&a, &b| {
            records[a]
                .parameters
                .cmp(&records[b].parameters)
                .then(records[a].e1_heldout.total_cmp(&records[b].e1_heldout))
        })
        .unwrap_or(first)
}

/// Why `chosen` won, for people.
fn explain(records: &[CandidateRecord], chosen: usize, first: usize) -> String {
    let c = &records[chosen];
    let pct = |x: f64| format!("{:.1}%", 100.0 * x);
    let mut text = format!(
        "{}: held-out E1 {} with {} parameters",
        c.model,
        pct(c.e1_heldout),
        c.parameters
    );
    let mut simpler: Vec<&CandidateRecord> = records[first..]
        .iter()
        .filter(|r| r.parameters < c.parameters)
        .collect();
    simpler.sort_by(|a, b| a.e1_heldout.total_cmp(&b.e1_heldout));
    if let Some(s) = simpler.first() {
        text += &format!(
            "; the best simpler candidate, {}, holds out {}",
            s.model,
            pct(s.e1_heldout)
        );
    }
    let richer: Vec<String> = records[first..]
        .iter()
        .filter(|r| r.parameters > c.parameters)
        .map(|r| {
            if r.collapsed {
                format!("{} collapsed", r.model)
            } else {
                format!(
                    "{} gains {:+.1} points",
                    r.model,
                    100.0 * (c.e1_heldout - r.e1_heldout)
                )
            }
        })
        .collect();
    if !richer.is_empty() {
        text += &format!(
            "; richer candidates do not earn their parameters ({}; {:.1} points or {:.0}% needed)",
            richer.join(", "),
            100.0 * MARGIN_POINTS,
            100.0 * MARGIN_RELATIVE
        );
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(model: &str, parameters: usize, heldout: f64, collapsed: bool) -> CandidateRecord {
        CandidateRecord {
            model: model.into(),
            kind: MaterialKind::Plastic,
            lobes: 1,
            oriented: false,
            parameters,
            e1: heldout,
            e1_heldout: heldout,
            peak_offset_deg: None,
            cost: 0.0,
            fitted: Vec::new(),
            collapsed,
            elapsed_ms: 0.0,
        }
    }

    #[test]
    fn more_parameters_must_earn_their_place() {
        let records = vec![
            record("metal", 3, 0.30, false),
            record("plastic", 3, 0.26, false),
            record("plastic2", 5, 0.258, false),
            record("plastic ×2", 5, 0.128, false),
            record("plastic2 ×2", 8, 0.125, false),
        ];
        // 0.125 is best; 0.128 is within 0.5 points of it: the simpler wins.
        assert_eq!(pick(&records, 1), 3);
        let mut clear = records.clone();
        clear[4].e1_heldout = 0.06;
        assert_eq!(pick(&clear, 1), 4);
        // A collapsed candidate never wins.
        clear[4].collapsed = true;
        assert_eq!(pick(&clear, 1), 3);
        // The rival family's record (index 0) is not a candidate.
        let mut rival = records.clone();
        rival[0].e1_heldout = 0.01;
        assert_eq!(pick(&rival, 1), 3);
        let text = explain(&records, 3, 1);
        assert!(
            text.starts_with("plastic ×2: held-out E1 12.8% with 5 parameters"),
            "{text}"
        );
        assert!(text.contains("plastic2 ×2 gains +0.3 points"), "{text}");
    }
}
