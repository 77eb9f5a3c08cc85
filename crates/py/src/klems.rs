//! `brtf._brtf._Klems`: a Klems BSDF XML file's matrices, read or computed
//! from a material as `brtf export --klems --material` does. The class
//! `brtf.Klems` (`_python.py`) builds its numpy views on these methods.

use crate::errors;
use crate::fit::to_python;
use crate::material::{Material, word};
use crate::measurement::Measurement;
use brtf_gonio::klems::{BasisSize, KlemsBand, KlemsBsdf, KlemsDirection, WindowFields};
use brtf_radiance::export::klems::{KlemsOptions, SolarBand};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use std::path::PathBuf;

/// The matrices of one Klems file, and the text the writer makes of them.
#[pyclass(module = "brtf", frozen, name = "_Klems")]
pub struct KlemsData {
    bsdf: KlemsBsdf,
    /// The file as `brtf export --klems` wrote it (a computed one).
    text: Option<String>,
    /// What the export said, one line each.
    #[pyo3(get)]
    notes: Vec<String>,
}

/// The block of `band` and `direction` (the file's words), if present.
fn block<'a>(bsdf: &'a KlemsBsdf, band: &str, direction: &str) -> PyResult<Option<&'a [f64]>> {
    let direction = KlemsDirection::parse(direction)
        .ok_or_else(|| errors::model(format!("direction={direction:?}: expected Transmission Front, Transmission Back, Reflection Front or Reflection Back")))?;
    let matrix = bsdf.matrix(&KlemsBand::parse(band), direction);
    Ok(matrix.map(|m| m.values.as_slice()))
}

#[pymethods]
impl KlemsData {
    /// Reads a Klems BSDF XML file.
    #[staticmethod]
    fn read(py: Python<'_>, path: PathBuf) -> PyResult<KlemsData> {
        let bsdf = py.detach(|| brtf_gonio::klems::read_path(&path));
        let (bsdf, text, notes) = (bsdf.map_err(errors::read)?, None, Vec::new());
        Ok(KlemsData { bsdf, text, notes })
    }

    /// The file read (or the label of a computed one).
    #[getter]
    fn source(&self) -> &str {
        &self.bsdf.source
    }

    /// Every patch of the basis (centre, bounds, Ω, Λ), and its name.
    fn basis<'py>(&self, py: Python<'py>) -> PyResult<(String, Bound<'py, PyAny>)> {
        let basis = &self.bsdf.basis;
        Ok((basis.name.clone(), to_python(py, &basis.patches())?))
    }

    /// The `Material` header fields.
    fn header<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.bsdf.header)
    }

    /// What `brtf info --json` gives for the file.
    fn info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.bsdf.info())
    }

    /// The (band, direction) of every matrix, in file order.
    fn blocks(&self) -> Vec<(String, &'static str)> {
        let matrices = self.bsdf.matrices.iter();
        matrices
            .map(|m| (m.band.name().to_string(), m.direction.name()))
            .collect()
    }

    /// One matrix, N × N, `[o, i]` = BSDF (1/sr) from incident patch i to
    /// outgoing patch o; None when the file has no such block.
    fn matrix<'py>(
        &self,
        py: Python<'py>,
        band: &str,
        direction: &str,
    ) -> PyResult<Option<Bound<'py, PyArray2<f64>>>> {
        let n = self.bsdf.basis.len();
        let values = block(&self.bsdf, band, direction)?;
        let array = values.map(|v| v.to_vec().into_pyarray(py).reshape([n, n]));
        array.transpose()
    }

    /// The column totals Σ_o BSDF[o][i] Λ_o of one matrix (ρ_dh or τ_dh
    /// per incident patch).
    fn totals<'py>(
        &self,
        py: Python<'py>,
        band: &str,
        direction: &str,
    ) -> PyResult<Option<Bound<'py, PyArray1<f64>>>> {
        block(&self.bsdf, band, direction)?;
        let direction = KlemsDirection::parse(direction).expect("checked by block");
        let totals = self.bsdf.column_totals(&KlemsBand::parse(band), direction);
        Ok(totals.map(|t| t.into_pyarray(py)))
    }

    /// One Measurement per incident patch and side (`brtf fit`'s data),
    /// the front's first.
    fn measurements(&self, py: Python<'_>) -> Vec<Measurement> {
        let source = &self.bsdf.source;
        let measurement = |m: brtf_gonio::Measurement| {
            let (t, p) = (m.incidence.theta_deg, m.incidence.phi_deg);
            Measurement::new(m, None, format!("{source} (θ_in {t}°, φ_in {p}°)"))
        };
        let scans = py.detach(|| self.bsdf.to_measurements());
        scans.into_iter().map(measurement).collect()
    }

    /// The XML text `write` writes: a computed file as `brtf export
    /// --klems` wrote it, a read one as the same writer writes its matrices.
    fn xml(&self) -> PyResult<String> {
        if let Some(text) = &self.text {
            return Ok(text.clone());
        }
        let version = env!("CARGO_PKG_VERSION");
        let comment = vec![format!(
            "{} written again by brtf {version} (brtf.Klems.write).",
            self.bsdf.source
        )];
        self.bsdf.to_xml(comment).map_err(errors::model)
    }

    /// Writes `xml()` to `path` (a temporary file, then renamed).
    fn write(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let text = self.xml()?;
        let written = py.detach(|| brtf_io::write_atomic(&path, text.as_bytes()));
        written.map_err(|e| errors::workflow(e.into()))
    }
}

/// `Material.to_klems`: the file `brtf export --klems --material` writes,
/// computed from `material` named `name` (`solar`: `"visible"`, `"none"`,
/// a `.rad` path or a Material).
#[pyfunction(name = "_to_klems")]
#[pyo3(signature = (material, name, basis, samples, solar, colour, manufacturer, thickness,
    device_type, conductivity, emissivity, ir_transmittance, permeability))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn to_klems(
    py: Python<'_>,
    material: &Material,
    name: &str,
    basis: &str,
    samples: usize,
    solar: &Bound<'_, PyAny>,
    colour: bool,
    manufacturer: String,
    thickness: f64,
    device_type: String,
    conductivity: Option<f64>,
    emissivity: Option<[f64; 2]>,
    ir_transmittance: Option<f64>,
    permeability: Option<f64>,
) -> PyResult<KlemsData> {
    let mut options = KlemsOptions::new(name);
    options.basis = word::<BasisSize>("basis", basis)?.basis();
    options.sampling.samples = samples;
    options.solar = match solar.cast::<Material>() {
        Ok(m) => SolarBand::Material {
            material: m.get().composite.clone(),
            source: "the solar brtf.Material".into(),
        },
        Err(_) => brtf_workflow::solar_band(Some(&solar.extract::<String>()?))
            .map_err(errors::workflow)?,
    };
    (options.colour, options.manufacturer) = (colour, manufacturer);
    (options.thickness_mm, options.device_type) = (thickness, device_type);
    options.window = WindowFields {
        conductivity,
        emissivity,
        ir_transmittance,
        permeability,
    };
    options.command_line = vec!["brtf.Material.to_klems (Python)".into()];
    // As `brtf export --klems`: the formula set and Fresnel constant, a
    // point source.
    let own = material.bsdf.options();
    let (variant, fresnel_k) = (own.variant, own.fresnel_k);
    let eval = brtf_model::EvalOptions {
        variant,
        fresnel_k,
        ..Default::default()
    };
    let source = format!("brtf.Material {name}");
    let export = py.detach(|| {
        brtf_workflow::klems_of_composite(&material.composite, name, &eval, options, &source)
    });
    let export = export.map_err(errors::workflow)?;
    let bsdf = brtf_gonio::klems::read_str(&export.text, format!("{name}.xml"));
    let bsdf = bsdf.map_err(errors::read)?;
    let (text, notes) = (Some(export.text), export.notes);
    Ok(KlemsData { bsdf, text, notes })
}
