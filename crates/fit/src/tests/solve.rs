//! The solver's terminations and what the report makes of them: exact
//! synthetic data converge to the generating parameters; a run out of
//! budget loses patience; a vanished lobe ends at a bound and says so;
//! standard errors are positive, finite and proportional to the noise.

use super::{material, synth};
use crate::config::FitConfig;
use crate::fitter::fit_incidence;
use crate::params::ParamMap;
use crate::prepare;
use crate::report::{FitWarning, Termination};
use crate::solve::{Solver, Stage};
use brtf_model::MaterialKind;
use glam::DVec3;
use levenberg_marquardt::TerminationReason;
use nalgebra::DVector;

fn not_converged(warnings: &[FitWarning]) -> bool {
    warnings
        .iter()
        .any(|w| matches!(w, FitWarning::NotConverged { .. }))
}

#[test]
fn an_exact_fit_converges_to_the_generating_parameters() {
    let truth = [0.45, 0.3, 0.2, 0.06, 0.09];
    let data = synth(&material(MaterialKind::Plastic, &truth), 40.0, 3, 0.0, 1);
    let report = fit_incidence(&data, &FitConfig::new(MaterialKind::Plastic)).unwrap();
    assert!(report.termination.converged(), "{:?}", report.termination);
    assert!(!not_converged(&report.warnings), "{:?}", report.warnings);
    assert_eq!(report.n_points, data.samples.len());
    for (got, want) in report.material_args.iter().zip(truth) {
        assert!(
            (got - want).abs() < 1e-7,
            "fitted {:?} vs {truth:?}",
            report.material_args
        );
    }
    // The model goes through every sample.
    assert!(report.rms_rel < 1e-7, "rms_rel {}", report.rms_rel);
    for p in &report.params {
        assert!(!p.at_bound && !p.fixed, "{p:?}");
        let se = p.stderr.expect("an identifiable parameter has an error");
        assert!(se.is_finite() && se >= 0.0, "{p:?}");
    }
    // (The residuals are rounding noise, so the sandwich's ratio to the
    // plain errors, and its warning, mean nothing here.)
    assert!(
        !report.warnings.iter().any(|w| matches!(
            w,
            FitWarning::AtBound { .. } | FitWarning::DegenerateLobe | FitWarning::FreeScaleColour
        )),
        "{:?}",
        report.warnings
    );
    assert_eq!(report.scale, 1.0);
}

#[test]
fn a_free_scale_fit_reports_scale_times_colour_and_warns() {
    // Raw data of unknown scale: 40 × a grey metal of colour 0.6.
    let truth = [0.6, 0.6, 0.6, 0.7, 0.12];
    let mut data = synth(&material(MaterialKind::Metal, &truth), 20.0, 1, 0.0, 2);
    for s in &mut data.samples {
        s.value[0] *= 40.0;
    }
    let mut config = FitConfig::new(MaterialKind::Metal);
    config.free_scale = true;
    let report = fit_incidence(&data, &config).unwrap();
    assert!(report.termination.converged(), "{:?}", report.termination);
    // The colour is fixed at 1; the scale carries 40 × 0.6.
    assert_eq!(&report.material_args[..3], &[1.0; 3]);
    assert!(
        (report.scale - 24.0).abs() < 1e-6 * 24.0,
        "{}",
        report.scale
    );
    assert!((report.value("spec").unwrap() - 0.7).abs() < 1e-7);
    assert!((report.value("rough").unwrap() - 0.12).abs() < 1e-7);
    let scale = report.params.last().unwrap();
    assert_eq!(scale.name, "scale");
    assert!(!scale.fixed && !scale.at_bound);
    for p in &report.params[..3] {
        assert!(p.fixed && p.stderr.is_none(), "{p:?}");
        assert_eq!(p.missing_error_reason(), Some("fixed"));
    }
    assert!(report.warnings.contains(&FitWarning::FreeScaleColour));
}

#[test]
fn standard_errors_are_positive_cover_the_truth_and_scale_with_the_noise() {
    // Multiplicative noise fitted with relative residuals: homoscedastic,
    // so s²(JᵀJ)⁻¹ applies. The same normal deviates at twice the
    // amplitude: near the minimum the fit is linear in the noise, so every
    // error (and every deviation from the truth) doubles.
    let truth = [0.5, 0.4, 0.3, 0.08, 0.1];
    let m = material(MaterialKind::Plastic, &truth);
    let mut config = FitConfig::new(MaterialKind::Plastic);
    config.residual = crate::problem::ResidualKind::Relative;
    let fits: Vec<_> = [0.01, 0.02]
        .iter()
        .map(|&noise| fit_incidence(&synth(&m, 30.0, 3, noise, 5), &config).unwrap())
        .collect();
    for report in &fits {
        assert!(report.termination.converged(), "{:?}", report.termination);
        for (p, want) in report.params.iter().zip(truth) {
            let se = p.stderr.expect("a standard error");
            let robust = p.stderr_robust.expect("a sandwich error");
            assert!(se > 0.0 && se.is_finite() && robust > 0.0 && robust.is_finite());
            assert!(
                (p.value - want).abs() < 4.0 * se,
                "{}: {} ± {se} vs {want}",
                p.name,
                p.value
            );
        }
    }
    for (small, large) in fits[0].params.iter().zip(&fits[1].params) {
        let ratio = large.stderr.unwrap() / small.stderr.unwrap();
        assert!((1.9..2.1).contains(&ratio), "{}: ratio {ratio}", small.name);
    }
    // The rms relative residual is the noise's amplitude.
    for (report, noise) in fits.iter().zip([0.01, 0.02]) {
        assert!(
            (report.rms_rel / noise - 1.0).abs() < 0.1,
            "rms_rel {} for noise {noise}",
            report.rms_rel
        );
    }
}

#[test]
fn a_vanished_lobe_ends_at_the_spec_bound_with_its_flags_and_warnings() {
    // Lambertian data (spec 0): the specularity goes to its lower bound,
    // where it has no standard error, and the roughness means nothing.
    let truth = [0.5, 0.5, 0.5, 0.0, 0.1];
    let data = synth(&material(MaterialKind::Plastic, &truth), 30.0, 1, 0.0, 3);
    let report = fit_incidence(&data, &FitConfig::new(MaterialKind::Plastic)).unwrap();
    let spec = report.params.iter().find(|p| p.name == "spec").unwrap();
    assert!(spec.at_bound, "{spec:?}");
    assert!(spec.value < 1e-4, "{spec:?}");
    assert_eq!(spec.stderr, None);
    assert_eq!(spec.stderr_robust, None);
    assert_eq!(spec.missing_error_reason(), Some("at bound"));
    assert!(report.warnings.iter().any(
        |w| matches!(w, FitWarning::AtBound { param, value } if param == "spec" && *value == spec.value)
    ), "{:?}", report.warnings);
    assert!(report.warnings.contains(&FitWarning::DegenerateLobe));
    // The diffuse colour is still recovered.
    for c in &report.material_args[..3] {
        assert!((c - 0.5).abs() < 1e-6, "{:?}", report.material_args);
    }
}

#[test]
fn a_run_out_of_budget_loses_patience_where_the_final_stage_converges() {
    // A grey metal with a narrow lobe, started far away (a wide lobe of
    // almost nothing): a start's budget, 8 (n + 1) evaluations, is not
    // enough to get there; the final stage's 200 (n + 1) is.
    let kind = MaterialKind::Metal;
    let truth = [0.8, 0.8, 0.8, 0.9, 0.03];
    let data = synth(&material(kind, &truth), 30.0, 1, 0.0, 4);
    let config = FitConfig::new(kind);
    let map = ParamMap::new(brtf_model::Shape::single(kind), true, false);
    assert_eq!(
        map.slots
            .iter()
            .map(|s| s.name.as_str())
            .collect::<Vec<_>>(),
        ["gray", "spec", "rough"]
    );
    let floor = 1e-6;
    let mut block = prepare::scan(&data, 1, &config).unwrap().block;
    block.set_factors(config.residual, floor);
    let blocks = [block];
    let solver = Solver {
        map: &map,
        config: &config,
        orientation: DVec3::X,
        channels: 1,
        floor,
    };
    let start = [0.01, 0.01, 0.3];
    let u0 = DVector::from_iterator(3, (0..3).map(|i| map.to_unconstrained(i, start[i])));
    let start_cost = solver.problem(&blocks).cost(&u0).unwrap();

    let short = solver.solve(&blocks, u0.clone(), Stage::START);
    let termination = Termination::from_lm(&short.termination);
    assert_eq!(
        termination,
        Termination::LostPatience,
        "{:?}",
        short.termination
    );
    assert!(!termination.converged());
    assert_eq!(termination.label(), "lost_patience");
    assert!(
        short.evaluations <= 8 * (map.len() + 1) + 2,
        "{}",
        short.evaluations
    );
    // It stopped early, but LM only accepts steps that lower the cost.
    assert!(short.cost < start_cost, "{} vs {start_cost}", short.cost);

    let full = solver.solve(&blocks, u0, Stage::FINAL);
    assert!(
        Termination::from_lm(&full.termination).converged(),
        "{:?}",
        full.termination
    );
    assert!(
        full.cost < 1e-6 * short.cost,
        "{} vs {}",
        full.cost,
        short.cost
    );
    for (i, want) in [0.8, 0.9, 0.03].into_iter().enumerate() {
        let got = map.to_physical(i, full.u[i]).0;
        assert!(
            (got - want).abs() < 1e-6,
            "{}: {got} vs {want}",
            map.slots[i].name
        );
    }
}

#[test]
fn terminations_map_from_the_optimiser_and_say_whether_they_converged() {
    let cases = [
        (
            TerminationReason::Converged {
                ftol: true,
                xtol: false,
            },
            Termination::Converged {
                ftol: true,
                xtol: false,
            },
            true,
            "converged",
        ),
        (
            TerminationReason::Orthogonal,
            Termination::Orthogonal,
            true,
            "converged (gradient)",
        ),
        (
            TerminationReason::ResidualsZero,
            Termination::ResidualsZero,
            true,
            "residuals_zero",
        ),
        (
            TerminationReason::LostPatience,
            Termination::LostPatience,
            false,
            "lost_patience",
        ),
        (
            TerminationReason::Numerical("jacobian"),
            Termination::Numerical("jacobian".into()),
            false,
            "numerical",
        ),
    ];
    for (lm, ours, converged, label) in cases {
        let t = Termination::from_lm(&lm);
        assert_eq!(t, ours);
        assert_eq!(t.converged(), converged, "{t:?}");
        assert_eq!(t.label(), label);
        assert_eq!(t.to_string(), label);
    }
    let user = Termination::from_lm(&TerminationReason::User("no residuals"));
    assert!(matches!(&user, Termination::Other(s) if s.contains("no residuals")));
    assert!(!user.converged());
}

/// A report never says both "converged" and "not converged": the fitter's
/// `NotConverged` warning follows `termination.converged()` (what `brtf
/// radiance export` and the Python package check), also for
/// `NoImprovementPossible`, which LM's own `was_successful()` counts as a
/// failure.
#[test]
fn the_converged_test_agrees_with_the_not_converged_warning() {
    for (lm, converged) in [
        (TerminationReason::NoImprovementPossible("ftol"), true),
        (TerminationReason::NoImprovementPossible("xtol"), true),
        (
            TerminationReason::Converged {
                ftol: true,
                xtol: true,
            },
            true,
        ),
        (TerminationReason::Orthogonal, true),
        (TerminationReason::LostPatience, false),
        (TerminationReason::Numerical("jacobian"), false),
    ] {
        let termination = Termination::from_lm(&lm);
        assert_eq!(termination.converged(), converged, "{lm:?}");
        let warning = FitWarning::not_converged(&termination);
        assert_eq!(warning.is_none(), converged, "{lm:?}");
        if let Some(FitWarning::NotConverged { termination: t }) = warning {
            assert_eq!(t, termination);
        }
    }
}

#[test]
fn a_raised_stop_flag_ends_the_solve_at_its_next_pass() {
    let truth = [0.45, 0.3, 0.2, 0.06, 0.09];
    let data = synth(&material(MaterialKind::Plastic, &truth), 40.0, 3, 0.0, 1);
    let mut config = FitConfig::new(MaterialKind::Plastic);
    config.stop = crate::StopFlag::new();
    let clone = config.clone();
    assert!(fit_incidence(&data, &config).is_ok());
    // Raised on a clone (as Python's Ctrl-C raises the caller's copy):
    // no pass runs, so the fit has no solution.
    clone.stop.raise();
    assert!(config.stop.is_raised());
    let stopped = fit_incidence(&data, &config);
    assert!(stopped.is_err(), "{stopped:?}");
    // The flag is no part of what decides a fit.
    assert_eq!(config, FitConfig::new(MaterialKind::Plastic));
}
