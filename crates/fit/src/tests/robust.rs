//! Robust reweighting: the IRLS multipliers of Huber and Cauchy on
//! hand-made residuals, the robust σ they are measured in, the parsing of
//! `--loss`, and a fit that the reweighting keeps from following outliers.

use super::{material, synth};
use crate::config::{FitConfig, RobustLoss};
use crate::fitter::fit_incidence;
use crate::robust::multipliers;
use brtf_model::MaterialKind;
use nalgebra::DVector;

/// 1.4826 × the median |r| (the consistency factor of the MAD for a
/// normal distribution).
const MAD_TO_SIGMA: f64 = 1.4826;

/// Textbook Huber weight of a standardised residual z (the IRLS weight
/// ψ(z)/z): 1 inside the threshold, c/|z| outside.
fn huber_weight(z: f64, c: f64) -> f64 {
    if z.abs() <= c { 1.0 } else { c / z.abs() }
}

/// Textbook Cauchy weight: 1 / (1 + (z/c)²).
fn cauchy_weight(z: f64, c: f64) -> f64 {
    1.0 / (1.0 + (z / c).powi(2))
}

/// The multipliers are the square roots of the weights (they multiply the
/// residuals, so the squares weigh the squared residuals).
fn assert_weights(multipliers: &[f64], weights: &[f64]) {
    assert_eq!(multipliers.len(), weights.len());
    for (i, (m, w)) in multipliers.iter().zip(weights).enumerate() {
        assert!(
            (m * m - w).abs() < 1e-12,
            "sample {i}: multiplier² {} vs weight {w}",
            m * m
        );
    }
}

#[test]
fn huber_weighs_one_inside_the_threshold_and_c_over_z_outside() {
    // |r| sorted: 0.5, 1, 2, 3, 12: the median is 2.
    let r = [0.5, -1.0, 2.0, -3.0, 12.0];
    let sigma = MAD_TO_SIGMA * 2.0;
    for c in [1.345, 0.8, 5.0] {
        let (m, s) = multipliers(&DVector::from_row_slice(&r), 1, RobustLoss::Huber(c));
        assert!((s - sigma).abs() < 1e-12, "σ {s}");
        let want: Vec<f64> = r.iter().map(|x| huber_weight(x / sigma, c)).collect();
        assert_weights(&m, &want);
    }
    // With the default c = 1.345 (threshold 3.99): only 12 is beyond it.
    let (m, _) = multipliers(&DVector::from_row_slice(&r), 1, RobustLoss::Huber(1.345));
    assert_eq!(&m[..4], &[1.0; 4]);
    assert!((m[4] * m[4] - 1.345 * sigma / 12.0).abs() < 1e-12);
    // c = 0.8 (threshold 2.37): 3 and 12 are beyond it.
    let (m, _) = multipliers(&DVector::from_row_slice(&r), 1, RobustLoss::Huber(0.8));
    assert_eq!(&m[..3], &[1.0; 3]);
    assert!(m[3] < 1.0 && m[4] < m[3]);
}

#[test]
fn cauchy_weighs_one_over_one_plus_z_over_c_squared() {
    let r = [0.5, -1.0, 2.0, -3.0, 12.0];
    let sigma = MAD_TO_SIGMA * 2.0;
    for c in [2.385, 1.5] {
        let (m, s) = multipliers(&DVector::from_row_slice(&r), 1, RobustLoss::Cauchy(c));
        assert!((s - sigma).abs() < 1e-12);
        let want: Vec<f64> = r.iter().map(|x| cauchy_weight(x / sigma, c)).collect();
        assert_weights(&m, &want);
    }
    // At z = c the weight is exactly ½.
    let r = [1.0, 1.0, 1.0, 1.5 * MAD_TO_SIGMA];
    let (m, _) = multipliers(&DVector::from_row_slice(&r), 1, RobustLoss::Cauchy(1.5));
    assert!((m[3] * m[3] - 0.5).abs() < 1e-12, "{m:?}");
}

#[test]
fn the_largest_channel_of_a_sample_decides_and_sigma_uses_every_channel() {
    // Three samples of three channels. |r| sorted: 0.1 ×4, 0.2 ×2, 0.3,
    // 0.35, 6: the median of all nine is 0.2.
    let r = [0.1, -6.0, 0.2, 0.3, 0.1, 0.1, -0.2, 0.35, 0.1];
    let sigma = MAD_TO_SIGMA * 0.2;
    let (m, s) = multipliers(&DVector::from_row_slice(&r), 3, RobustLoss::Huber(1.345));
    assert!((s - sigma).abs() < 1e-12);
    let want = [6.0, 0.3, 0.35].map(|x| huber_weight(x / sigma, 1.345));
    assert_eq!(m.len(), 3);
    assert_weights(&m, &want);
    assert!(m[0] < 1.0 && m[1] == 1.0 && m[2] == 1.0);
}

#[test]
fn no_loss_weighs_every_sample_one_and_degenerate_residuals_stay_finite() {
    let r = DVector::from_row_slice(&[3.0, -1.0, 100.0]);
    let (m, s) = multipliers(&r, 1, RobustLoss::None);
    assert_eq!(m, vec![1.0; 3]);
    assert!((s - MAD_TO_SIGMA * 3.0).abs() < 1e-12);
    // All residuals zero (an exact fit): σ would be 0; every weight is 1
    // and nothing is NaN.
    let zeros = DVector::from_element(6, 0.0);
    for loss in [RobustLoss::Huber(1.345), RobustLoss::Cauchy(2.385)] {
        let (m, s) = multipliers(&zeros, 2, loss);
        assert!(s > 0.0 && s.is_finite(), "σ {s}");
        assert_eq!(m, vec![1.0; 3], "{loss:?}");
    }
    // No residuals: no multipliers, σ 1.
    let (m, s) = multipliers(&DVector::zeros(0), 1, RobustLoss::Huber(1.0));
    assert!(m.is_empty());
    assert_eq!(s, 1.0);
}

#[test]
fn losses_parse_with_their_default_and_given_scales() {
    let parse = |s: &str| s.parse::<RobustLoss>();
    assert_eq!(parse("none"), Ok(RobustLoss::None));
    assert_eq!(parse("huber"), Ok(RobustLoss::Huber(1.345)));
    assert_eq!(parse("huber:2"), Ok(RobustLoss::Huber(2.0)));
    assert_eq!(parse("cauchy"), Ok(RobustLoss::Cauchy(2.385)));
    assert_eq!(parse("cauchy:1.5"), Ok(RobustLoss::Cauchy(1.5)));
    assert_eq!(RobustLoss::default(), RobustLoss::None);
    for bad in [
        "",
        "Huber",
        "tukey",
        "none:1",
        "huber:",
        "huber:x",
        "cauchy:1:2",
        "huber 2",
    ] {
        assert!(parse(bad).is_err(), "`{bad}` parsed as {:?}", parse(bad));
    }
    assert!(parse("huber:x").unwrap_err().contains("bad loss scale `x`"));
    assert!(parse("tukey").unwrap_err().contains("`tukey`"));
}

#[test]
fn reweighting_keeps_a_fit_from_following_outliers() {
    // A grey metal with 1 % noise; every 37th sample reads 5× too high
    // (84 of 3 096). Plain least squares follows them; Huber and Cauchy
    // down-weigh them and recover the generating parameters.
    let truth = [0.7, 0.7, 0.7, 0.8, 0.1];
    let mut data = synth(&material(MaterialKind::Metal, &truth), 30.0, 1, 0.01, 11);
    for s in data.samples.iter_mut().step_by(37) {
        s.value[0] *= 5.0;
    }
    let fit = |loss: RobustLoss| {
        let mut config = FitConfig::new(MaterialKind::Metal);
        config.loss = loss;
        config.multistart = false;
        fit_incidence(&data, &config).expect("a fit")
    };
    let error = |args: &[f64]| {
        args.iter()
            .zip(&truth)
            .map(|(a, t)| (a / t - 1.0).abs())
            .fold(0.0, f64::max)
    };
    let plain = fit(RobustLoss::None);
    assert!(plain.robust.is_none());
    let plain_error = error(&plain.material_args);
    for loss in [RobustLoss::Huber(1.345), RobustLoss::Cauchy(2.385)] {
        let report = fit(loss);
        let record = report.robust.expect("a robust record");
        assert!(record.settled && record.rounds >= 1, "{loss:?}: {record:?}");
        assert!(record.sigma.is_finite() && record.sigma > 0.0);
        let robust_error = error(&report.material_args);
        assert!(
            robust_error < 0.02 && robust_error < 0.25 * plain_error,
            "{loss:?}: {:?} (off by {robust_error}) vs plain {:?} (off by {plain_error})",
            report.material_args,
            plain.material_args
        );
    }
}
