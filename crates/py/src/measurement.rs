//! `brtf.Measurement`, `brtf.read`.

use crate::errors;
use brtf_gonio::Measurement as Scan;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// One gonio-photometer scan: one incidence, N scattered samples.
#[pyclass(module = "brtf", frozen)]
pub struct Measurement {
    scan: Scan,
    /// θ_in in degrees (towards the light, from the front normal).
    #[pyo3(get)]
    theta_in: f64,
    /// φ_in in degrees, in [0, 360).
    #[pyo3(get)]
    phi_in: f64,
    /// What the values are: `BSDF`, `DSF` or `raw`.
    #[pyo3(get)]
    quantity: &'static str,
    /// The values' unit: `1/sr`, or the raw signal's (e.g. `uA`).
    #[pyo3(get)]
    unit: String,
    /// The raw signal's beam integral, when the file gives it.
    #[pyo3(get)]
    beam_integral: Option<f64>,
    /// `CIE-Y` (one channel) or `CIE-XYZ` (three).
    #[pyo3(get)]
    channels: &'static str,
    /// The file format, e.g. `pab-opto Mountain`.
    #[pyo3(get)]
    format: String,
    /// `#sample_name`, when the file has one.
    #[pyo3(get)]
    sample_name: Option<String>,
    /// The file read (None for Klems patches, which cannot be re-read as
    /// one measurement).
    #[pyo3(get)]
    path: Option<String>,
    /// A label for messages and `repr`.
    #[pyo3(get, name = "_origin")]
    origin: String,
    /// The header lines as the file has them.
    #[pyo3(get)]
    header_lines: Vec<String>,
    solid_angle: Vec<f64>,
}

impl Measurement {
    pub fn new(mut scan: Scan, path: Option<PathBuf>, origin: String) -> Measurement {
        let solid_angle = brtf_gonio::solid_angles(&scan).per_sample_sr;
        // The Python side sees the solid angles through `solid_angle`; the
        // samples keep the file's own (or none), as `brtf fit` reads them.
        scan.samples.shrink_to_fit();
        let beam_integral = match &scan.quantity {
            brtf_gonio::Quantity::Raw { beam_integral, .. } => *beam_integral,
            _ => None,
        };
        Measurement {
            theta_in: scan.incidence.theta_deg,
            phi_in: scan.incidence.phi_deg,
            quantity: scan.quantity.name(),
            unit: scan.quantity.unit().to_string(),
            beam_integral,
            channels: scan.channels.colorimetry_name(),
            format: scan.format.describe().to_string(),
            sample_name: scan.sample_name.clone(),
            path: path.map(|p| p.display().to_string()),
            origin,
            header_lines: scan.header.clone(),
            solid_angle,
            scan,
        }
    }
}

#[pymethods]
impl Measurement {
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
        let samples = self.scan.samples.iter();
        let flat: Vec<f64> = samples
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

    fn __len__(&self) -> usize {
        self.scan.samples.len()
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
