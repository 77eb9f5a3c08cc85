//! One Levenberg-Marquardt run on the compressed problem, with the
//! tolerances of its stage (a start, the polish, the final fit).

use crate::config::FitConfig;
use crate::params::ParamMap;
use crate::problem::{Block, Compressed, Problem};
use glam::DVec3;
use levenberg_marquardt::{LevenbergMarquardt, TerminationReason};
use nalgebra::DVector;

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
    };
    /// The fit on every sample. From the polished start it takes three
    /// steps; the gradient test stops it after the third, where ftol alone
    /// would spend a fourth pass confirming a zero reduction.
    pub(crate) const FINAL: Stage = Stage {
        tolerance: 1e-12,
        gtol: 1e-6,
        patience: 200,
        report: true,
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
        let mut problem = self.problem(blocks);
        problem.u = u0.clone();
        problem.report = stage.report;
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
        Solved {
            cost: at_solution
                .as_ref()
                .map_or(f64::INFINITY, |c| 0.5 * c.residuals.norm_squared()),
            u,
            termination: report.termination,
            evaluations: problem.evaluations.get(),
            at_solution,
        }
    }
}
