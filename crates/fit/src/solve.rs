//! One Levenberg-Marquardt run on the compressed problem, with the
//! tolerances of its stage (a start, the polish, the final fit).

use crate::config::FitConfig;
use crate::params::ParamMap;
use crate::problem::{Block, Compressed, Problem};
use glam::DVec3;
use levenberg_marquardt::{LevenbergMarquardt, TerminationReason};
use nalgebra::{DMatrix, DVector};

/// Tolerances of one Levenberg-Marquardt run.
#[derive(Clone, Copy)]
pub(crate) struct Stage {
    /// ftol and xtol.
    tolerance: f64,
    /// Largest cosine between the residuals and a Jacobian column at a
    /// stationary point.
    gtol: f64,
    /// Evaluation budget in units of (parameters + 1).
    patience: usize,
    /// Its passes compute what the report uses (the sandwich's middle
    /// term, `rms_rel`); only the final fit's solution is reported.
    report: bool,
    /// LM's Hessian gets the large-residual correction of
    /// [`crate::problem::Secant`].
    secant: bool,
}

impl Stage {
    /// A start on the subsample only has to find its basin, within a budget
    /// of 8 (n + 1) evaluations: a start that has not converged by then
    /// (typically one far too narrow, whose lobe misses the data) is
    /// compared at the cost it reached. The best start is polished and fitted
    /// to every sample afterwards.
    pub(crate) const START: Stage = Stage {
        tolerance: 1e-6,
        gtol: 1e-14,
        patience: 8,
        report: false,
        secant: false,
    };
    /// The starts of an all-incidence fit stop at a relative change of
    /// 1e-3: over many incidences they only have to find a basin, and
    /// 1e-6 cost a Klems side's all-incidence fit 2.6× the passes (186
    /// against 72 on the Mecho fabric, same minimum). Per-incidence fits
    /// keep [`Stage::START`]: from starts stopped at 1e-3, one Klems
    /// `trans2` incidence crawled along its roughness bound for 1 455
    /// evaluations.
    pub(crate) const START_ALL_INCIDENCES: Stage = Stage {
        tolerance: 1e-3,
        ..Stage::START
    };
    /// A fit from a point near its minimum (the held-out folds of
    /// `--model auto`, from the fit on every sample): a few passes to a
    /// relative change of 1e-6.
    pub(crate) const REFIT: Stage = Stage {
        tolerance: 1e-6,
        gtol: 1e-8,
        patience: 10,
        report: false,
        secant: false,
    };
    /// The fit on every sample, with the secant term in its Hessian
    /// (golden_paper: 6 passes from the polished start, 7 for the log
    /// fit); the gradient test stops it where ftol alone would spend a
    /// pass confirming a zero reduction.
    pub(crate) const FINAL: Stage = Stage {
        tolerance: 1e-12,
        gtol: 1e-6,
        patience: 200,
        report: true,
        secant: true,
    };
}

/// Where one Levenberg-Marquardt run ended.
pub(crate) struct Solved {
    pub u: DVector<f64>,
    /// ½‖r‖² at `u` (infinite when it could not be evaluated).
    pub cost: f64,
    pub termination: TerminationReason,
    pub evaluations: usize,
    /// The compressed problem at `u`.
    pub at_solution: Option<Compressed>,
}

/// What every run of one fit shares.
pub(crate) struct Solver<'a> {
    pub map: &'a ParamMap,
    pub config: &'a FitConfig,
    pub orientation: DVec3,
    pub channels: usize,
    pub floor: f64,
}

impl Solver<'_> {
    /// The problem on `blocks`.
    pub(crate) fn problem<'b>(&'b self, blocks: &'b [Block<'b>]) -> Problem<'b> {
        Problem::new(
            self.map,
            self.config,
            self.orientation,
            blocks,
            self.channels,
            self.floor,
        )
    }

    /// Runs Levenberg-Marquardt from `u0` on `blocks`.
    pub(crate) fn solve(&self, blocks: &[Block<'_>], u0: DVector<f64>, stage: Stage) -> Solved {
        self.solve_seeded(blocks, u0, stage, Vec::new()).0
    }

    /// The all-incidence fit on every sample, in rounds of
    /// [`ROUND_PATIENCE`]: when a round ends on its budget, [`extrapolate`]
    /// estimates the limit its accepted points are heading for; the next
    /// round starts there if that lowers the cost. Without a gain, or after
    /// [`MAX_JUMPS`], the fit finishes in one run with the rest of the
    /// budget, keeping LM's damping.
    ///
    /// Gauss-Newton converges only linearly where the model cannot fit the
    /// data (a large residual): on a Klems fabric's all-incidence fit each
    /// step covered ~30 % of the remaining distance, 24–36 passes over
    /// ten million patch pairs. A fit that converges within one round
    /// takes exactly the steps it took before.
    pub(crate) fn solve_final(&self, blocks: &[Block<'_>], u0: DVector<f64>) -> Solved {
        let stage = Stage::FINAL;
        let budget = stage.patience * (self.map.len() + 1);
        let round = Stage {
            patience: ROUND_PATIENCE,
            ..stage
        };
        let mut spent = 0;
        let mut start = u0;
        let mut seed = Vec::new();
        for _ in 0..MAX_JUMPS {
            let (mut solved, accepted) = self.solve_seeded(blocks, start, round, seed);
            spent += solved.evaluations;
            let out_of_round = matches!(solved.termination, TerminationReason::LostPatience);
            let Some(at_solution) = solved.at_solution.clone().filter(|_| out_of_round) else {
                solved.evaluations = spent;
                return solved;
            };
            // Where the round ended, or the extrapolated limit if lower.
            let mut next = (solved.u.clone(), at_solution);
            let mut jumped = false;
            if let Some(jump) = extrapolate(&accepted) {
                let mut problem = self.problem(blocks);
                problem.report = stage.report;
                if let Some(c) = problem.evaluated(&jump) {
                    spent += problem.evaluations.get();
                    if 0.5 * c.residuals.norm_squared() < solved.cost {
                        next = (jump, c);
                        jumped = true;
                    }
                }
            }
            start = next.0.clone();
            seed = vec![next];
            if !jumped || spent >= budget {
                break;
            }
        }
        let rest = Stage {
            patience: budget
                .saturating_sub(spent)
                .div_ceil(self.map.len() + 1)
                .max(1),
            ..stage
        };
        let (mut last, _) = self.solve_seeded(blocks, start, rest, seed);
        last.evaluations += spent;
        last
    }

    /// Runs Levenberg-Marquardt from `u0`, whose pass may be in `seed`;
    /// also returns the accepted points (each lowering the cost) in order.
    fn solve_seeded(
        &self,
        blocks: &[Block<'_>],
        u0: DVector<f64>,
        stage: Stage,
        seed: Vec<(DVector<f64>, Compressed)>,
    ) -> (Solved, Vec<DVector<f64>>) {
        let mut problem = self.problem(blocks);
        *problem.history.borrow_mut() = seed;
        problem.u = u0.clone();
        problem.report = stage.report;
        problem.secant = stage.secant.then(Default::default);
        let (problem, report) = LevenbergMarquardt::new()
            .with_ftol(stage.tolerance)
            .with_xtol(stage.tolerance)
            .with_gtol(stage.gtol)
            .with_patience(stage.patience)
            .minimize(problem);
        // After User/Numerical stops the problem holds the rejected trial
        // point; fall back to the start then.
        let failed = matches!(
            report.termination,
            TerminationReason::User(_) | TerminationReason::Numerical(_)
        );
        let u = if failed { u0 } else { problem.u.clone() };
        let at_solution = problem.evaluated(&u);
        let history = problem.history.take();
        let mut accepted = Vec::new();
        let mut lowest = f64::INFINITY;
        for (at, c) in &history {
            let cost = 0.5 * c.residuals.norm_squared();
            if cost < lowest {
                lowest = cost;
                accepted.push(at.clone());
            }
        }
        let solved = Solved {
            cost: at_solution
                .as_ref()
                .map_or(f64::INFINITY, |c| 0.5 * c.residuals.norm_squared()),
            u,
            termination: report.termination,
            evaluations: problem.evaluations.get(),
            at_solution,
        };
        (solved, accepted)
    }
}

/// Evaluation budget of one round of [`Solver::solve_final`], in units of
/// (parameters + 1): a fit from a polished start converges within it.
const ROUND_PATIENCE: usize = 1;
/// Most extrapolations per fit: each restart costs LM its damping, which
/// a fit crawling along a bound (a Klems `trans2` roughness) needs; two
/// took the Mecho fabric's all-incidence fit to its minimum.
const MAX_JUMPS: usize = 3;
/// Most steps the extrapolation looks back on.
const LOOK_BACK: usize = 6;

/// Reduced rank extrapolation over the last accepted points u₀ … u_p:
/// where Gauss-Newton converges linearly, u_{k+1} − u* ≈ M (u_k − u*),
/// and the combination Σ γᵢ uᵢ (Σ γᵢ = 1) whose steps Σ γᵢ (u_{i+1} − uᵢ)
/// cancel best is the limit, exactly so when M has at most p − 1
/// eigenvalues that matter.
fn extrapolate(accepted: &[DVector<f64>]) -> Option<DVector<f64>> {
    let points = &accepted[accepted.len().saturating_sub(LOOK_BACK + 1)..];
    let p = points.len().checked_sub(1).filter(|&p| p >= 2)?;
    let steps = DMatrix::from_fn(points[0].len(), p, |r, c| points[c + 1][r] - points[c][r]);
    let mut gram = steps.transpose() * &steps;
    // A tiny ridge keeps nearly parallel steps solvable.
    let ridge = 1e-12 * gram.trace().max(f64::MIN_POSITIVE);
    for k in 0..p {
        gram[(k, k)] += ridge;
    }
    let weights = gram.cholesky()?.solve(&DVector::from_element(p, 1.0));
    let total = weights.sum();
    if !(total.is_finite() && total != 0.0) {
        return None;
    }
    let limit = points[..p]
        .iter()
        .zip(weights.iter())
        .fold(DVector::zeros(points[0].len()), |acc, (u, w)| {
            acc + u * (w / total)
        });
    limit.iter().all(|v| v.is_finite()).then_some(limit)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A linear iteration u_{k+1} − u* = M (u_k − u*) with two modes
    /// (ratios 0.7 and 0.4) and a third at rest: three steps determine u*.
    fn linear_sequence(count: usize) -> (Vec<DVector<f64>>, DVector<f64>) {
        let limit = DVector::from_vec(vec![1.0, -2.0, 0.5]);
        let m = DMatrix::from_row_slice(3, 3, &[0.7, 0.1, 0.0, 0.0, 0.4, 0.0, 0.0, 0.0, 0.0]);
        let mut u = DVector::from_vec(vec![3.0, 1.0, 0.5]);
        let mut points = Vec::new();
        for _ in 0..count {
            points.push(u.clone());
            u = &limit + &m * (&u - &limit);
        }
        (points, limit)
    }

    #[test]
    fn extrapolation_finds_the_limit_of_a_linear_iteration() {
        let (points, limit) = linear_sequence(6);
        let jump = extrapolate(&points).expect("an extrapolation");
        assert!((&jump - &limit).norm() < 1e-9, "{jump} vs {limit}");
        // The last point is still far from it: the jump is worth taking.
        assert!((points.last().unwrap() - &limit).norm() > 1e-2);
    }

    #[test]
    fn extrapolation_needs_three_points() {
        let (points, _) = linear_sequence(2);
        assert!(extrapolate(&points).is_none());
    }
}
