//! brtf-fit's θ_in interpolation as explicit piecewise cubics.
//!
//! [`ParamTable::args_at`] is piecewise cubic between the measured
//! incidences (PCHIP Hermite segments, or straight lines). This module
//! recovers each segment's power-basis coefficients from the table itself,
//! by sampling the segment at four points, so the `.cal` file reproduces
//! brtf-fit's interpolation to rounding error without duplicating how its
//! slopes are chosen.

use brtf_fit::ParamTable;

/// One cubic segment: `a0 + s (a1 + s (a2 + s a3))` with `s = θ − start`
/// in degrees.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Segment {
    /// θ_in where the segment starts (degrees).
    pub start: f64,
    /// Power-basis coefficients in `s`.
    pub coef: [f64; 4],
}

impl Segment {
    /// The cubic at `theta` (degrees).
    pub(super) fn eval(&self, theta: f64) -> f64 {
        let s = theta - self.start;
        let [a0, a1, a2, a3] = self.coef;
        a0 + s * (a1 + s * (a2 + s * a3))
    }
}

/// Every parameter's segments: `segments[param][i]` covers
/// `[nodes[i], nodes[i + 1]]`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Pieces {
    /// The measured θ_in, ascending.
    pub nodes: Vec<f64>,
    /// `segments[param][segment]`.
    pub segments: Vec<Vec<Segment>>,
    /// The segments are brtf-fit's own interpolation, not a resampling.
    pub exact: bool,
}

/// Sampling step (degrees) when the table is not piecewise cubic.
pub(crate) const FALLBACK_STEP: f64 = 0.5;

impl Pieces {
    /// The segments of `table`: exact cubics when the table is piecewise
    /// cubic between its nodes (checked at three more points per segment),
    /// otherwise straight lines every [`FALLBACK_STEP`] degrees.
    pub(super) fn of(table: &ParamTable) -> Pieces {
        let exact = Pieces::cubic(table, &table.theta_in);
        if exact.reproduces(table) {
            exact
        } else {
            Pieces::dense(table)
        }
    }

    /// One cubic per interval of `nodes`, through four samples of the table.
    fn cubic(table: &ParamTable, nodes: &[f64]) -> Pieces {
        let n_params = table.args.first().map_or(0, Vec::len);
        let mut segments = vec![Vec::with_capacity(nodes.len().saturating_sub(1)); n_params];
        for w in nodes.windows(2) {
            let (x0, h) = (w[0], w[1] - w[0]);
            // Four equally spaced samples, the ends being the table's nodes.
            let samples: Vec<Vec<f64>> = (0..4)
                .map(|j| match j {
                    0 => table.args_at(x0).0,
                    3 => table.args_at(w[1]).0,
                    _ => table.args_at(x0 + h * j as f64 / 3.0).0,
                })
                .collect();
            for (p, segs) in segments.iter_mut().enumerate() {
                let y = [samples[0][p], samples[1][p], samples[2][p], samples[3][p]];
                segs.push(Segment {
                    start: x0,
                    coef: cubic_through(y, h),
                });
            }
        }
        Pieces {
            nodes: nodes.to_vec(),
            segments,
            exact: true,
        }
    }

    /// Straight lines between samples every [`FALLBACK_STEP`] degrees.
    fn dense(table: &ParamTable) -> Pieces {
        let (lo, hi) = table.range();
        let n = ((hi - lo) / FALLBACK_STEP).ceil().max(1.0) as usize;
        let nodes: Vec<f64> = (0..=n)
            .map(|i| {
                if i == n {
                    hi
                } else {
                    lo + FALLBACK_STEP * i as f64
                }
            })
            .collect();
        let values: Vec<Vec<f64>> = nodes.iter().map(|&t| table.args_at(t).0).collect();
        let n_params = values[0].len();
        let segments = (0..n_params)
            .map(|p| {
                nodes
                    .windows(2)
                    .zip(values.windows(2))
                    .map(|(x, y)| Segment {
                        start: x[0],
                        coef: [y[0][p], (y[1][p] - y[0][p]) / (x[1] - x[0]), 0.0, 0.0],
                    })
                    .collect()
            })
            .collect();
        Pieces {
            nodes,
            segments,
            exact: false,
        }
    }

    /// True when the segments match the table at interior points.
    fn reproduces(&self, table: &ParamTable) -> bool {
        self.nodes.windows(2).enumerate().all(|(i, w)| {
            [1.0 / 6.0, 0.5, 5.0 / 6.0].iter().all(|f| {
                let t = w[0] + f * (w[1] - w[0]);
                let (args, _) = table.args_at(t);
                args.iter().enumerate().all(|(p, want)| {
                    let got = self.segments[p][i].eval(t);
                    (got - want).abs() <= 1e-10 * want.abs().max(1e-3)
                })
            })
        })
    }

    /// Parameter `param` at `theta`, clamped to the table's range like
    /// [`ParamTable::args_at`].
    #[cfg(test)]
    pub(super) fn eval(&self, param: usize, theta: f64) -> f64 {
        let (lo, hi) = (self.nodes[0], self.nodes[self.nodes.len() - 1]);
        let t = theta.clamp(lo, hi);
        let segs = &self.segments[param];
        let i = self
            .nodes
            .windows(2)
            .position(|w| t <= w[1])
            .unwrap_or(segs.len() - 1);
        segs[i].eval(t)
    }
}

/// Power-basis coefficients (in `s`, `0 ≤ s ≤ h`) of the cubic through
/// `y[j]` at `s = j h / 3`. Coefficients that only carry rounding noise
/// (a straight or constant segment) are set to exactly 0.
fn cubic_through(y: [f64; 4], h: f64) -> [f64; 4] {
    // Newton forward differences in w = 3 s / h (unit steps).
    let d1 = y[1] - y[0];
    let d2 = y[2] - 2.0 * y[1] + y[0];
    let d3 = y[3] - 3.0 * y[2] + 3.0 * y[1] - y[0];
    let w = [
        y[0],
        d1 - d2 / 2.0 + d3 / 3.0,
        d2 / 2.0 - d3 / 2.0,
        d3 / 6.0,
    ];
    let scale = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let k = 3.0 / h;
    let mut coef = [w[0], w[1] * k, w[2] * k * k, w[3] * k * k * k];
    for j in 1..4 {
        if w[j].abs() <= 1e-13 * scale {
            coef[j] = 0.0;
        }
    }
    coef
}

#[cfg(test)]
mod tests {
    use super::*;
    use brtf_fit::Interpolation;
    use brtf_model::MaterialKind;

    fn table(method: Interpolation) -> ParamTable {
        ParamTable {
            azimuth: None,
            kind: MaterialKind::Plastic,
            lobes: 1,
            oriented: false,
            orientation: [1.0, 0.0, 0.0],
            method,
            theta_in: vec![0.0, 15.0, 30.0, 50.0, 70.0],
            args: vec![
                vec![0.5, 0.4, 0.3, 0.05, 0.1],
                vec![0.52, 0.4, 0.31, 0.05, 0.12],
                vec![0.55, 0.4, 0.29, 0.06, 0.15],
                vec![0.6, 0.4, 0.3, 0.08, 0.14],
                vec![0.61, 0.4, 0.35, 0.1, 0.2],
            ],
        }
    }

    #[test]
    fn segments_reproduce_the_table_everywhere() {
        for method in [Interpolation::Pchip, Interpolation::Linear] {
            let t = table(method);
            let pieces = Pieces::of(&t);
            for k in -20..=900 {
                let theta = k as f64 * 0.1;
                let (args, _) = t.args_at(theta);
                for (p, want) in args.iter().enumerate() {
                    let got = pieces.eval(p, theta);
                    assert!(
                        (got - want).abs() <= 1e-13,
                        "{method:?} param {p} at {theta}: {got} vs {want}"
                    );
                }
            }
        }
    }

    #[test]
    fn the_dense_fallback_is_close_and_the_check_accepts_exact_pieces() {
        let t = table(Interpolation::Pchip);
        assert!(Pieces::of(&t).exact);
        let dense = Pieces::dense(&t);
        assert!(!dense.exact);
        assert_eq!(dense.nodes.len(), 141);
        for k in 0..=700 {
            let theta = k as f64 * 0.1;
            for (p, want) in t.args_at(theta).0.iter().enumerate() {
                assert!((dense.eval(p, theta) - want).abs() < 5e-5, "{p} at {theta}");
            }
        }
    }

    #[test]
    fn constant_and_straight_segments_have_zero_higher_coefficients() {
        let pieces = Pieces::of(&table(Interpolation::Linear));
        for segs in &pieces.segments {
            for s in segs {
                assert_eq!((s.coef[2], s.coef[3]), (0.0, 0.0), "{s:?}");
            }
        }
        // Green is constant.
        let pchip = Pieces::of(&table(Interpolation::Pchip));
        for s in &pchip.segments[1] {
            assert_eq!(s.coef, [0.4, 0.0, 0.0, 0.0]);
        }
    }
}
