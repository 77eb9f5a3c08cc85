//! Robust losses by iteratively reweighted least squares: each round
//! weighs every sample by the loss's weight of its residual (in robust
//! standard deviations) and refits.

use crate::config::RobustLoss;
use nalgebra::DVector;

/// The IRLS multiplier (the square root of the weight) of each sample,
/// from the residuals `r` (`channels` per sample, in sample order): the
/// sample's largest channel residual decides. Also returns σ, the robust
/// standard deviation the loss's threshold is measured in.
pub(crate) fn multipliers(r: &DVector<f64>, channels: usize, loss: RobustLoss) -> (Vec<f64>, f64) {
    let sigma = robust_sigma(r);
    let multipliers = r
        .as_slice()
        .chunks(channels)
        .map(|sample| {
            let z = sample.iter().map(|x| x.abs()).fold(0.0, f64::max) / sigma;
            let w = match loss {
                RobustLoss::Huber(c) => {
                    if z <= c {
                        1.0
                    } else {
                        c / z
                    }
                }
                RobustLoss::Cauchy(c) => 1.0 / (1.0 + (z / c) * (z / c)),
                RobustLoss::None => 1.0,
            };
            w.sqrt()
        })
        .collect();
    (multipliers, sigma)
}

/// 1.4826 × the median absolute residual, a robust standard deviation.
fn robust_sigma(r: &DVector<f64>) -> f64 {
    let mut a: Vec<f64> = r.iter().map(|x| x.abs()).collect();
    if a.is_empty() {
        return 1.0;
    }
    let mid = a.len() / 2;
    a.select_nth_unstable_by(mid, f64::total_cmp);
    (1.4826 * a[mid]).max(1e-300)
}
