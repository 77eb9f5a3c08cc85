//! Per-incidence parameters as a function of θ_in: a monotone cubic
//! (PCHIP, Fritsch–Carlson) or linear interpolation, clamped outside the
//! measured range.
//!
//! An anisotropic type fitted to rings of incidences at several azimuths
//! (a Klems basis) also keeps each ring's incidences over φ_in
//! ([`AzimuthRing`]). Its parameters at (θ_in, φ_in) are each ring's
//! values at φ_in (linear between the ring's azimuths, periodic), then
//! interpolated over θ_in by the table's method, as the φ-averaged rows
//! are.

use crate::report::FitReport;
use brtf_model::{Composite, Material, MaterialKind, ModelError, Shape, ShapeArg};
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// How parameters are interpolated between measured incidences.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum Interpolation {
    /// Piecewise cubic Hermite with Fritsch–Carlson slopes: no overshoot,
    /// monotone where the data are.
    #[default]
    Pchip,
    /// Piecewise linear.
    Linear,
}

brtf_model::option_words!(Interpolation { Pchip => "pchip", Linear => "linear" });

/// Why a table could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum TableError {
    /// Interpolation needs two incidences or more.
    #[error("θ_in interpolation needs at least two incidences, found {0}")]
    NeedTwoIncidences(usize),
    /// Two rows share a θ_in.
    #[error("two incidences share θ_in = {0}°; give one file per incidence")]
    DuplicateTheta(f64),
    /// The interpolated parameters are not a valid material.
    #[error("interpolated parameters are not a valid material: {0}")]
    Material(#[from] ModelError),
    /// The table holds a lobe sum where one primitive is asked for.
    #[error("the table holds a lobe sum, not one primitive")]
    LobeSum,
    /// A stored table is not one brtf could have made.
    #[error("invalid θ_in table: {0}")]
    Invalid(String),
}

/// Material parameters tabulated over θ_in.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParamTable {
    /// The material type.
    #[serde(with = "crate::serde_kind")]
    pub kind: MaterialKind,
    /// Specular lobes of the shape (see [`brtf_model::Shape`]).
    #[serde(default = "one_lobe")]
    pub lobes: usize,
    /// The shape's orientation is an argument (`orient`).
    #[serde(default)]
    pub oriented: bool,
    /// Orientation of the `*2` types.
    pub orientation: [f64; 3],
    /// Interpolation method.
    pub method: Interpolation,
    /// θ_in of each row, ascending, in degrees.
    pub theta_in: Vec<f64>,
    /// `args[row]`: the material's real arguments at that θ_in (averaged
    /// over the row's azimuths when it has several).
    pub args: Vec<Vec<f64>>,
    /// For an anisotropic type fitted to rings of azimuths: each row's
    /// incidences over φ_in, so the parameters follow (θ_in, φ_in).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub azimuth: Option<Vec<AzimuthRing>>,
}

fn one_lobe() -> usize {
    1
}

/// The azimuth of a table's rings ([`AzimuthRing::phi_in`]) for a light
/// at azimuth `phi_data` (degrees) in the data's frame: counted from u,
/// the orientation's azimuth in that frame, and negated when the data's
/// frame is mirrored (the back side of a Klems file keeps x and y and
/// flips z; its right-handed frame, the side seen as a front, has −y).
pub fn azimuth_from_u(orientation: [f64; 3], mirrored: bool, phi_data: f64) -> f64 {
    let phi = phi_data - orientation[1].atan2(orientation[0]).to_degrees();
    (if mirrored { -phi } else { phi }).rem_euclid(360.0)
}

/// The incidences of one θ_in row at their azimuths.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AzimuthRing {
    /// φ_in of each incidence in degrees, ascending in [0, 360): the
    /// light's azimuth from u (the orientation vector projected on the
    /// surface) towards v = n × u, with n the normal on the light's side.
    pub phi_in: Vec<f64>,
    /// `args[k]`: the material's real arguments at `phi_in[k]`.
    pub args: Vec<Vec<f64>>,
}

impl AzimuthRing {
    /// Argument `j` at azimuth `phi` (degrees): linear between the ring's
    /// azimuths, across 360° → 0° too; one azimuth holds everywhere.
    pub fn arg_at(&self, j: usize, phi: f64) -> f64 {
        let n = self.phi_in.len();
        if n == 1 {
            return self.args[0][j];
        }
        let phi = phi.rem_euclid(360.0);
        // Between the last azimuth at or below φ and the next one, a turn
        // later past the last; below the first, from the last a turn back.
        let (k, from, next, to) = match self.phi_in.iter().rposition(|&p| p <= phi) {
            Some(k) if k + 1 < n => (k, self.phi_in[k], k + 1, self.phi_in[k + 1]),
            Some(k) => (k, self.phi_in[k], 0, self.phi_in[0] + 360.0),
            None => (n - 1, self.phi_in[n - 1] - 360.0, 0, self.phi_in[0]),
        };
        let t = (phi - from) / (to - from);
        self.args[k][j] + t * (self.args[next][j] - self.args[k][j])
    }
}

/// A material at some θ_in, and whether θ_in was outside the table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TableLookup {
    /// The interpolated material.
    pub material: Material,
    /// θ_in was outside the measured range, so the end row was used.
    pub clamped: bool,
}

impl ParamTable {
    /// Builds the table from per-incidence reports (sorted by θ_in here).
    pub fn from_reports(
        shape: Shape,
        orientation: [f64; 3],
        reports: &[FitReport],
        method: Interpolation,
    ) -> Result<ParamTable, TableError> {
        if reports.len() < 2 {
            return Err(TableError::NeedTwoIncidences(reports.len()));
        }
        let mut rows: Vec<(f64, Vec<f64>)> = reports
            .iter()
            .map(|r| (r.theta_in, r.material_args.clone()))
            .collect();
        rows.sort_by(|a, b| a.0.total_cmp(&b.0));
        if let Some(w) = rows.windows(2).find(|w| (w[1].0 - w[0].0).abs() < 1e-9) {
            return Err(TableError::DuplicateTheta(w[0].0));
        }
        // A fitted orientation is an angle modulo 180°: each row's is taken
        // within 90° of the row before, so that interpolation turns the
        // short way.
        if let Some(o) = shape.index_of(ShapeArg::Orient) {
            for k in 1..rows.len() {
                let before = rows[k - 1].1[o];
                let angle = &mut rows[k].1[o];
                *angle -= 180.0 * ((*angle - before) / 180.0).round();
            }
        }
        Ok(ParamTable {
            kind: shape.kind,
            lobes: shape.lobes,
            oriented: shape.oriented,
            orientation,
            method,
            theta_in: rows.iter().map(|r| r.0).collect(),
            args: rows.into_iter().map(|r| r.1).collect(),
            azimuth: None,
        })
    }

    /// The table of incidences that share θ_in rings, as a Klems basis
    /// has (one incidence per azimuth patch): each θ_in's material
    /// arguments are averaged over its incidences (over φ_in), which suits
    /// isotropic materials; rows with one incidence are kept as they are.
    pub fn from_reports_phi_averaged(
        shape: Shape,
        orientation: [f64; 3],
        reports: &[FitReport],
        method: Interpolation,
    ) -> Result<ParamTable, TableError> {
        let mut rings: Vec<(f64, Vec<f64>, usize)> = Vec::new();
        let mut order: Vec<&FitReport> = reports.iter().collect();
        order.sort_by(|a, b| a.theta_in.total_cmp(&b.theta_in));
        for r in order {
            match rings.last_mut() {
                Some((theta, sum, count)) if (r.theta_in - *theta).abs() < 1e-9 => {
                    for (s, a) in sum.iter_mut().zip(&r.material_args) {
                        *s += a;
                    }
                    *count += 1;
                }
                _ => rings.push((r.theta_in, r.material_args.clone(), 1)),
            }
        }
        if rings.len() < 2 {
            return Err(TableError::NeedTwoIncidences(rings.len()));
        }
        Ok(ParamTable {
            kind: shape.kind,
            lobes: shape.lobes,
            oriented: shape.oriented,
            orientation,
            method,
            theta_in: rings.iter().map(|r| r.0).collect(),
            args: rings
                .into_iter()
                .map(|(_, sum, count)| sum.into_iter().map(|s| s / count as f64).collect())
                .collect(),
            azimuth: None,
        })
    }

    /// [`Self::from_reports_phi_averaged`], keeping each row's incidences
    /// over φ_in too, for an anisotropic type. Each report's φ_in becomes
    /// [`azimuth_from_u`]'s: counted from u, and negated for data described
    /// in a mirrored frame (`mirrored`: the back side of a Klems file).
    pub fn from_reports_over_azimuth(
        shape: Shape,
        orientation: [f64; 3],
        reports: &[FitReport],
        method: Interpolation,
        mirrored: bool,
    ) -> Result<ParamTable, TableError> {
        let mut table = Self::from_reports_phi_averaged(shape, orientation, reports, method)?;
        let mut rings: Vec<Vec<(f64, Vec<f64>)>> = vec![Vec::new(); table.theta_in.len()];
        for r in reports {
            let row = table
                .theta_in
                .iter()
                .position(|t| (r.theta_in - t).abs() < 1e-9)
                .expect("every report's θ_in is a row");
            let phi = azimuth_from_u(orientation, mirrored, r.phi_in);
            rings[row].push((phi, r.material_args.clone()));
        }
        let mut azimuth = Vec::with_capacity(rings.len());
        for (mut ring, theta) in rings.into_iter().zip(&table.theta_in) {
            ring.sort_by(|a, b| a.0.total_cmp(&b.0));
            if ring.windows(2).any(|w| w[1].0 - w[0].0 < 1e-9) {
                return Err(TableError::Invalid(format!(
                    "two incidences share θ_in = {theta}° and φ_in"
                )));
            }
            let (phi_in, args) = ring.into_iter().unzip();
            azimuth.push(AzimuthRing { phi_in, args });
        }
        table.azimuth = Some(azimuth);
        Ok(table)
    }

    /// The shape of the tabulated material.
    pub fn shape(&self) -> Shape {
        Shape {
            kind: self.kind,
            lobes: self.lobes,
            oriented: self.oriented,
        }
    }

    /// The material of flat arguments `args`.
    fn composite(&self, args: &[f64]) -> Result<Composite, TableError> {
        let shape =
            Shape::new(self.kind, self.lobes, self.oriented).map_err(TableError::Invalid)?;
        Ok(Composite::new(
            shape,
            args,
            Some(DVec3::from_array(self.orientation)),
        )?)
    }

    /// One primitive of a one-lobe table (an error for a lobe sum).
    fn primitive(&self, args: &[f64]) -> Result<Material, TableError> {
        let material = self.composite(args)?;
        material.single().copied().ok_or(TableError::LobeSum)
    }

    /// Measured θ_in range.
    pub fn range(&self) -> (f64, f64) {
        (
            self.theta_in[0],
            *self.theta_in.last().expect("two rows or more"),
        )
    }

    /// Checks what interpolation relies on, for a table read from a file:
    /// two rows or more, finite θ_in strictly ascending, one row of the
    /// type's arguments per θ_in, each a valid material.
    pub fn validate(&self) -> Result<(), TableError> {
        let invalid = |why: String| Err(TableError::Invalid(why));
        if self.theta_in.len() < 2 {
            return Err(TableError::NeedTwoIncidences(self.theta_in.len()));
        }
        if self.args.len() != self.theta_in.len() {
            return invalid(format!(
                "{} rows of arguments for {} θ_in values",
                self.args.len(),
                self.theta_in.len()
            ));
        }
        if let Some(t) = self.theta_in.iter().find(|t| !(0.0..=180.0).contains(*t)) {
            return invalid(format!(
                "θ_in {t:.6e} is not an incidence in [0, 180] degrees"
            ));
        }
        if let Some(w) = self.theta_in.windows(2).find(|w| w[1] <= w[0]) {
            return invalid(format!("θ_in is not ascending at {}° → {}°", w[0], w[1]));
        }
        let shape =
            Shape::new(self.kind, self.lobes, self.oriented).map_err(TableError::Invalid)?;
        let n = shape.n_args();
        for (row, t) in self.args.iter().zip(&self.theta_in) {
            if row.len() != n {
                return invalid(format!(
                    "the row at {t}° has {} arguments, a {shape} has {n}",
                    row.len()
                ));
            }
            self.composite(row)?;
        }
        if let Some(rings) = &self.azimuth {
            if rings.len() != self.theta_in.len() {
                return invalid(format!(
                    "{} azimuth rings for {} θ_in values",
                    rings.len(),
                    self.theta_in.len()
                ));
            }
            for (ring, t) in rings.iter().zip(&self.theta_in) {
                if ring.phi_in.is_empty() || ring.phi_in.len() != ring.args.len() {
                    return invalid(format!(
                        "the ring at {t}° has {} azimuths and {} rows of arguments",
                        ring.phi_in.len(),
                        ring.args.len()
                    ));
                }
                if ring.phi_in.iter().any(|p| !(0.0..360.0).contains(p))
                    || ring.phi_in.windows(2).any(|w| w[1] <= w[0])
                {
                    return invalid(format!(
                        "the ring at {t}°: φ_in is not ascending in [0, 360)"
                    ));
                }
                for row in &ring.args {
                    if row.len() != n {
                        return invalid(format!(
                            "the ring at {t}° has a row of {} arguments, a {shape} has {n}",
                            row.len()
                        ));
                    }
                    self.composite(row)?;
                }
            }
        }
        Ok(())
    }

    /// Interpolated real arguments at `theta_in` (clamped to the range),
    /// from the rows (averaged over φ_in where a row has several).
    pub fn args_at(&self, theta_in: f64) -> (Vec<f64>, bool) {
        self.interpolate(theta_in, |row, j| self.args[row][j])
    }

    /// True when the parameters follow φ_in too ([`Self::azimuth`]).
    pub fn depends_on_azimuth(&self) -> bool {
        self.azimuth.is_some()
    }

    /// Interpolated real arguments for a light at (`theta_in`, `phi_in`)
    /// (degrees; φ_in as in [`AzimuthRing::phi_in`]): each row's value at
    /// φ_in, interpolated over θ_in. Without azimuth rings, [`Self::args_at`].
    pub fn args_at_direction(&self, theta_in: f64, phi_in: f64) -> (Vec<f64>, bool) {
        match &self.azimuth {
            None => self.args_at(theta_in),
            Some(rings) => self.interpolate(theta_in, |row, j| rings[row].arg_at(j, phi_in)),
        }
    }

    /// The material for a light at (`theta_in`, `phi_in`) (one-lobe tables).
    pub fn at_direction(&self, theta_in: f64, phi_in: f64) -> Result<TableLookup, TableError> {
        let (args, clamped) = self.args_at_direction(theta_in, phi_in);
        let material = self.primitive(&args)?;
        Ok(TableLookup { material, clamped })
    }

    /// The material (any shape) for a light at (`theta_in`, `phi_in`), and
    /// whether θ_in was outside the table.
    pub fn composite_at_direction(
        &self,
        theta_in: f64,
        phi_in: f64,
    ) -> Result<(Composite, bool), TableError> {
        let (args, clamped) = self.args_at_direction(theta_in, phi_in);
        Ok((self.composite(&args)?, clamped))
    }

    /// The material (any shape) at `theta_in`, and whether θ_in was
    /// outside the table.
    pub fn composite_at(&self, theta_in: f64) -> Result<(Composite, bool), TableError> {
        let (args, clamped) = self.args_at(theta_in);
        Ok((self.composite(&args)?, clamped))
    }

    /// Each argument interpolated over θ_in through the rows' values
    /// `value(row, argument)`.
    fn interpolate(&self, theta_in: f64, value: impl Fn(usize, usize) -> f64) -> (Vec<f64>, bool) {
        let (lo, hi) = self.range();
        let clamped = theta_in < lo || theta_in > hi;
        let t = theta_in.clamp(lo, hi);
        let n_args = self.args[0].len();
        let args = (0..n_args)
            .map(|j| {
                let ys: Vec<f64> = (0..self.theta_in.len()).map(|row| value(row, j)).collect();
                match self.method {
                    Interpolation::Linear => linear(&self.theta_in, &ys, t),
                    Interpolation::Pchip => pchip(&self.theta_in, &ys, t),
                }
            })
            .collect();
        (args, clamped)
    }

    /// The material at `theta_in` (one-lobe tables).
    pub fn at(&self, theta_in: f64) -> Result<TableLookup, TableError> {
        let (args, clamped) = self.args_at(theta_in);
        let material = self.primitive(&args)?;
        Ok(TableLookup { material, clamped })
    }
}

fn segment(xs: &[f64], x: f64) -> usize {
    xs.windows(2)
        .position(|w| x <= w[1])
        .unwrap_or(xs.len() - 2)
}

fn linear(xs: &[f64], ys: &[f64], x: f64) -> f64 {
    let i = segment(xs, x);
    let t = (x - xs[i]) / (xs[i + 1] - xs[i]);
    ys[i] + t * (ys[i + 1] - ys[i])
}

/// Fritsch–Carlson slopes: harmonic mean of neighbouring secants where they
/// share a sign, zero at local extrema; one-sided three-point ends.
fn pchip_slopes(xs: &[f64], ys: &[f64]) -> Vec<f64> {
    let n = xs.len();
    let h: Vec<f64> = xs.windows(2).map(|w| w[1] - w[0]).collect();
    let delta: Vec<f64> = (0..n - 1).map(|i| (ys[i + 1] - ys[i]) / h[i]).collect();
    if n == 2 {
        return vec![delta[0]; 2];
    }
    let mut d = vec![0.0; n];
    for i in 1..n - 1 {
        if delta[i - 1] * delta[i] > 0.0 {
            let w1 = 2.0 * h[i] + h[i - 1];
            let w2 = h[i] + 2.0 * h[i - 1];
            d[i] = (w1 + w2) / (w1 / delta[i - 1] + w2 / delta[i]);
        }
    }
    let end = |h0: f64, h1: f64, d0: f64, d1: f64| {
        let s = ((2.0 * h0 + h1) * d0 - h0 * d1) / (h0 + h1);
        if s * d0 <= 0.0 {
            0.0
        } else if d0 * d1 <= 0.0 && s.abs() > 3.0 * d0.abs() {
            3.0 * d0
        } else {
            s
        }
    };
    d[0] = end(h[0], h[1], delta[0], delta[1]);
    d[n - 1] = end(h[n - 2], h[n - 3], delta[n - 2], delta[n - 3]);
    d
}

fn pchip(xs: &[f64], ys: &[f64], x: f64) -> f64 {
    let d = pchip_slopes(xs, ys);
    let i = segment(xs, x);
    let h = xs[i + 1] - xs[i];
    let t = (x - xs[i]) / h;
    let (t2, t3) = (t * t, t * t * t);
    let h00 = 2.0 * t3 - 3.0 * t2 + 1.0;
    let h10 = t3 - 2.0 * t2 + t;
    let h01 = -2.0 * t3 + 3.0 * t2;
    let h11 = t3 - t2;
    h00 * ys[i] + h10 * h * d[i] + h01 * ys[i + 1] + h11 * h * d[i + 1]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pchip_interpolates_nodes_and_keeps_monotone_data_monotone() {
        let xs = [0.0, 15.0, 30.0, 45.0, 60.0];
        let ys = [0.1, 0.1, 0.12, 0.3, 0.31];
        for (x, y) in xs.iter().zip(ys) {
            assert!((pchip(&xs, &ys, *x) - y).abs() < 1e-12);
        }
        let mut last = f64::NEG_INFINITY;
        for k in 0..=600 {
            let v = pchip(&xs, &ys, k as f64 * 0.1);
            assert!(
                v >= last - 1e-12 && (0.1 - 1e-12..=0.31 + 1e-12).contains(&v),
                "overshoot at {k}: {v}"
            );
            last = v;
        }
    }

    fn ring(phi_in: &[f64], values: &[f64]) -> AzimuthRing {
        AzimuthRing {
            phi_in: phi_in.to_vec(),
            args: values.iter().map(|v| vec![*v]).collect(),
        }
    }

    #[test]
    fn a_ring_is_linear_between_azimuths_and_wraps_around() {
        let r = ring(&[0.0, 90.0, 180.0, 270.0], &[1.0, 2.0, 3.0, 4.0]);
        for (phi, want) in [
            (0.0, 1.0),
            (45.0, 1.5),
            (270.0, 4.0),
            (315.0, 2.5),
            (360.0, 1.0),
            (-45.0, 2.5),
        ] {
            assert!(
                (r.arg_at(0, phi) - want).abs() < 1e-12,
                "{phi}: {}",
                r.arg_at(0, phi)
            );
        }
        // Azimuths that do not start at 0 wrap below the first one.
        let r = ring(&[22.5, 202.5], &[0.0, 1.0]);
        assert!((r.arg_at(0, 0.0) - 0.125).abs() < 1e-12);
        assert!((r.arg_at(0, 350.0) - (1.0 - 147.5 / 180.0)).abs() < 1e-12);
        assert_eq!(ring(&[180.0], &[7.0]).arg_at(0, 3.0), 7.0);
    }

    #[test]
    fn linear_is_exact_on_lines() {
        let xs = [0.0, 10.0, 40.0];
        let ys = [1.0, 2.0, 5.0];
        assert!((linear(&xs, &ys, 25.0) - 3.5).abs() < 1e-12);
    }
}
