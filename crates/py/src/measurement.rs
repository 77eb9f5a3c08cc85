//! `brtf.Measurement`, `brtf.read`, `brtf.read_klems`.

use crate::errors;
use crate::material::word;
use brtf_gonio::Measurement as Scan;
use brtf_gonio::klems::Sides;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// One gonio-photometer scan: one incidence, N scattered samples.
#[pyclass(module = "brtf", frozen)]
pub struct Measurement {
    pub(crate) scan: Scan,
    /// The file it was read from (`None` for Klems patches, which cannot
    /// be re-read as one measurement).
    pub(crate) path: Option<PathBuf>,
    /// A label for messages and `repr`.
    pub(crate) origin: String,
    pub(crate) solid_angle: Vec<f64>,
}

impl Measurement {
    pub fn new(mut scan: Scan, path: Option<PathBuf>, origin: String) -> Measurement {
        let solid_angle = brtf_gonio::solid_angles(&scan).per_sample_sr;
        // The Python side sees the solid angles through `solid_angle`; the
        // samples keep the file's own (or none), as `brtf fit` reads them.
        scan.samples.shrink_to_fit();
        Measurement {
            scan,
            path,
            origin,
            solid_angle,
        }
    }
}

#[pymethods]
impl Measurement {
    /// θ_in in degrees (towards the light, from the front normal).
    #[getter]
    fn theta_in(&self) -> f64 {
        self.scan.incidence.theta_deg
    }

    /// φ_in in degrees, in [0, 360).
    #[getter]
    fn phi_in(&self) -> f64 {
        self.scan.incidence.phi_deg
    }

    /// θ_out of every sample, degrees (> 90: back side).
    #[getter]
    fn theta<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let v: Vec<f64> = self.scan.samples.iter().map(|s| s.theta_deg).collect();
        v.into_pyarray(py)
    }

    /// φ_out of every sample, degrees, in [0, 360).
    #[getter]
    fn phi<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let v: Vec<f64> = self.scan.samples.iter().map(|s| s.phi_deg).collect();
        v.into_pyarray(py)
    }

    /// The values, N × channels (1: CIE-Y; 3: CIE X, Y, Z); NaN = not available.
    #[getter]
    fn value<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let channels = self.scan.channels.count();
        let flat: Vec<f64> = self
            .scan
            .samples
            .iter()
            .flat_map(|s| s.values[..channels].iter().copied())
            .collect();
        let array = Array2::from_shape_vec((self.scan.samples.len(), channels), flat)
            .map_err(|e| errors::model(e.to_string()))?;
        Ok(array.into_pyarray(py))
    }

    /// The solid angle (sr) each sample stands for: the file's Voronoi
    /// cells when it has them, else computed from the directions.
    #[getter]
    fn solid_angle<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.solid_angle.clone().into_pyarray(py)
    }

    /// What the values are: `BSDF`, `DSF` or `raw`.
    #[getter]
    fn quantity(&self) -> &'static str {
        self.scan.quantity.name()
    }

    /// The values' unit: `1/sr`, or the raw signal's (e.g. `uA`).
    #[getter]
    fn unit(&self) -> String {
        self.scan.quantity.unit().to_string()
    }

    /// The raw signal's beam integral, when the file gives it.
    #[getter]
    fn beam_integral(&self) -> Option<f64> {
        match &self.scan.quantity {
            brtf_gonio::Quantity::Raw { beam_integral, .. } => *beam_integral,
            _ => None,
        }
    }

    /// `CIE-Y` (one channel) or `CIE-XYZ` (three).
    #[getter]
    fn channels(&self) -> &'static str {
        self.scan.channels.colorimetry_name()
    }

    /// The file format, e.g. `pab-opto Mountain`.
    #[getter]
    fn format(&self) -> String {
        self.scan.format.describe().to_string()
    }

    /// `#sample_name`, when the file has one.
    #[getter]
    fn sample_name(&self) -> Option<String> {
        self.scan.sample_name.clone()
    }

    /// The file read (None for Klems patches).
    #[getter]
    fn path(&self) -> Option<String> {
        self.path.as_ref().map(|p| p.display().to_string())
    }

    /// The header as a dict: `#key value` lines give `key → value`
    /// (quotes and tabs trimmed), `.mpc` `#label:` lines followed by a
    /// value line give `label → value`. A key seen twice keeps its last value.
    #[getter]
    fn header<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let dict = PyDict::new(py);
        for (key, value) in self.scan.header_pairs() {
            dict.set_item(key, value)?;
        }
        Ok(dict)
    }

    /// The header lines as the file has them.
    #[getter]
    fn header_lines(&self) -> Vec<String> {
        self.scan.header.clone()
    }

    fn __len__(&self) -> usize {
        self.scan.samples.len()
    }

    fn __repr__(&self) -> String {
        format!(
            "Measurement({:?}, theta_in={}, phi_in={}, samples={}, quantity={:?}, channels={:?})",
            self.origin,
            self.scan.incidence.theta_deg,
            self.scan.incidence.phi_deg,
            self.scan.samples.len(),
            self.scan.quantity.name(),
            self.scan.channels.colorimetry_name()
        )
    }
}

/// Reads one measurement file (`.mpc` or pab-opto Mountain).
#[pyfunction]
pub(crate) fn read(py: Python<'_>, path: PathBuf) -> PyResult<Measurement> {
    let scan = py
        .detach(|| brtf_gonio::read_path(&path))
        .map_err(errors::read)?;
    let origin = path.display().to_string();
    Ok(py.detach(|| Measurement::new(scan, Some(path), origin)))
}

/// Reads a Klems BSDF XML file: one Measurement per incident patch and side.
#[pyfunction]
#[pyo3(signature = (path, side = "both"))]
pub(crate) fn read_klems(py: Python<'_>, path: PathBuf, side: &str) -> PyResult<Vec<Measurement>> {
    let sides: Sides = word("side", side)?;
    let bsdf = py
        .detach(|| brtf_gonio::klems::read_path(&path))
        .map_err(errors::read)?;
    let origin = path.display().to_string();
    let scans = py.detach(|| bsdf.to_measurements());
    Ok(scans
        .into_iter()
        // Light from the front has θ_in ≤ 90°, from the back θ_in > 90°.
        .filter(|m| match sides {
            Sides::Both => true,
            Sides::Front => m.incidence.theta_deg <= 90.0,
            Sides::Back => m.incidence.theta_deg > 90.0,
        })
        .map(|m| {
            let label = format!(
                "{origin} (θ_in {}°, φ_in {}°)",
                m.incidence.theta_deg, m.incidence.phi_deg
            );
            Measurement::new(m, None, label)
        })
        .collect())
}
