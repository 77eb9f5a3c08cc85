//! `brtf.fit` and `brtf.Fit`: `brtf fit` from Python, on the same
//! brtf-workflow calls as the command line (`FitJob`, `save_fit`,
//! `export_into`).

use crate::errors;
use crate::material::{Material, word};
use brtf_fit::{FitReport, FitResult};
use brtf_gonio::klems::BasisSize;
use brtf_radiance::export::klems::KlemsOptions;
use brtf_workflow::{Outputs, WorkflowError};
use numpy::{IntoPyArray, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// One fit report (an incidence, or all of them at once).
#[pyclass(module = "brtf", frozen)]
pub struct IncidenceFit {
    /// θ_in in degrees (the mean incidence for the all-incidence fit).
    #[pyo3(get)]
    theta_in: f64,
    /// φ_in in degrees.
    #[pyo3(get)]
    phi_in: f64,
    /// The file (or `all incidences`).
    #[pyo3(get)]
    source: String,
    /// The material's real arguments (the flat arguments of a lobe sum).
    #[pyo3(get)]
    material_args: Vec<f64>,
    /// The free scale (1 for absolute data).
    #[pyo3(get)]
    scale: f64,
    /// ½ Σ (weighted residual)² at the optimum.
    #[pyo3(get)]
    cost: f64,
    /// RMS relative residual.
    #[pyo3(get)]
    rms_rel: f64,
    /// E1: Σ ω |model − data| ÷ Σ ω |data| over the fitted samples, the
    /// share of the measured light the material puts in the wrong place.
    #[pyo3(get)]
    e1: Option<f64>,
    /// Samples fitted.
    #[pyo3(get)]
    n_points: usize,
    /// Why the optimiser stopped.
    #[pyo3(get)]
    termination: &'static str,
    /// Did the optimiser converge?
    #[pyo3(get)]
    converged: bool,
    /// The warnings, as text.
    #[pyo3(get)]
    warnings: Vec<String>,
    /// The fitted material (any shape), with the fit's evaluation options.
    #[pyo3(get)]
    material: Option<Py<Material>>,
    report: FitReport,
}

impl IncidenceFit {
    fn new(py: Python<'_>, result: &FitResult, r: &FitReport) -> PyResult<IncidenceFit> {
        let material = result.composite_of(r).map(|m| {
            let material = Material::new(m, &result.options(), None);
            Py::new(py, material)
        });
        Ok(IncidenceFit {
            theta_in: r.theta_in,
            phi_in: r.phi_in,
            source: r.source.clone(),
            material_args: r.material_args.clone(),
            scale: r.scale,
            cost: r.cost,
            rms_rel: r.rms_rel,
            e1: r.e1,
            n_points: r.n_points,
            termination: r.termination.label(),
            converged: r.termination.converged(),
            warnings: r.warnings.iter().map(|w| w.to_string()).collect(),
            material: material.transpose()?,
            report: r.clone(),
        })
    }
}

/// serde → JSON text → Python objects (`json.loads`).
pub(crate) fn to_python<'py, T: serde::Serialize>(
    py: Python<'py>,
    value: &T,
) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value).map_err(|e| errors::model(e.to_string()))?;
    py.import("json")?.call_method1("loads", (text,))
}

#[pymethods]
impl IncidenceFit {
    /// Everything, as this report's entry in `fit.json`.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.report)
    }
}

/// A fit set: what `brtf fit` writes as `fit.json`, and its outputs.
#[pyclass(module = "brtf", frozen)]
pub struct Fit {
    result: FitResult,
    /// The measurement files, as given.
    paths: Vec<PathBuf>,
    /// The folder `Fit.load` read (where relative input paths start).
    folder: Option<PathBuf>,
}

impl Fit {
    pub(crate) fn new(result: FitResult, paths: Vec<PathBuf>) -> Fit {
        let folder = None;
        Fit {
            result,
            paths,
            folder,
        }
    }

    /// The θ_in table, or the error of a fit without one.
    fn table_of(&self) -> PyResult<&brtf_fit::ParamTable> {
        let message = "this fit has no θ_in table (it needs two incidences or more)";
        let error = || errors::error("FitError", message, None, None);
        self.result.table.as_ref().ok_or_else(error)
    }

    /// A material of this fit, with its options and name.
    fn material_of(&self, composite: brtf_model::Composite) -> Material {
        let name = Some(self.result.name.clone());
        Material::new(composite, &self.result.options(), name)
    }
}

#[pymethods]
impl Fit {
    /// Reads a fit folder's `fit.json` (written by `brtf fit` or `Fit.save`).
    #[staticmethod]
    fn load(py: Python<'_>, folder: PathBuf) -> PyResult<Fit> {
        let path = folder.join("fit.json");
        let result = py.detach(|| FitResult::read(&path));
        let result = result.map_err(errors::read_fit)?;
        let inputs = result.provenance.inputs.iter();
        let paths = inputs.map(|i| PathBuf::from(&i.path)).collect();
        let folder = Some(folder);
        Ok(Fit {
            result,
            paths,
            folder,
        })
    }

    /// The report's 3D view of the data against the model, which a
    /// notebook shows; a line saying why when the files cannot be read.
    fn _repr_html_(&self, py: Python<'_>) -> String {
        let dir = self.folder.clone().unwrap_or_else(|| PathBuf::from("."));
        let options = brtf_plot::PlotOptions::default();
        let view = py.detach(|| brtf_plot::view_html(&dir, &self.result, &options));
        view.unwrap_or_else(|e| {
            format!(
                "<p>brtf: no 3D view: {}</p>",
                brtf_plot::escape(&e.to_string())
            )
        })
    }

    /// The material name.
    #[getter]
    fn name(&self) -> &str {
        &self.result.name
    }

    /// The model fitted (the type of every lobe).
    #[getter]
    fn model(&self) -> &'static str {
        self.result.config.kind.name()
    }

    /// One report per incidence, by θ_in.
    #[getter]
    fn incidences(&self, py: Python<'_>) -> PyResult<Vec<IncidenceFit>> {
        let reports = self.result.incidences.iter();
        reports
            .map(|r| IncidenceFit::new(py, &self.result, r))
            .collect()
    }

    /// The fit of all incidences at once.
    #[getter]
    fn global_fit(&self, py: Python<'_>) -> PyResult<Option<IncidenceFit>> {
        let global = self.result.global.as_ref();
        global
            .map(|r| IncidenceFit::new(py, &self.result, r))
            .transpose()
    }

    /// The static material (the all-incidence fit), as the exports use.
    #[getter]
    fn material(&self) -> Option<Material> {
        let composite = self.result.static_composite()?;
        Some(self.material_of(composite))
    }

    /// The warnings of the whole set, as text.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.result.warnings.iter().map(|w| w.to_string()).collect()
    }

    /// What `model="auto"` tried and chose, as `fit.json`'s `auto`
    /// (None for a fit of one model).
    #[getter]
    fn auto<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.result.auto)
    }

    /// The parameters interpolated in θ_in (degrees, scalar or array):
    /// name → array of θ_in's shape. Outside the fitted range they are
    /// held at the end values.
    fn table<'py>(
        &self,
        py: Python<'py>,
        theta_in: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let table = self.table_of()?;
        let array = py
            .import("numpy")?
            .call_method1("asarray", (theta_in, "float64"))?;
        let shape: Vec<usize> = array.getattr("shape")?.extract()?;
        let flat: Vec<f64> = array.call_method0("ravel")?.extract()?;
        let rows: Vec<Vec<f64>> = flat.iter().map(|&t| table.args_at(t).0).collect();
        let d = PyDict::new(py);
        for (i, name) in table.shape().param_names().iter().enumerate() {
            let column: Vec<f64> = rows.iter().map(|r| r[i]).collect();
            d.set_item(name, column.into_pyarray(py).reshape(shape.clone())?)?;
        }
        Ok(d)
    }

    /// The material at θ_in from the table (with the fit's options); with
    /// `phi_in` (degrees, the data's frame), at that azimuth for a table
    /// that follows φ_in (anisotropic types fitted to Klems XML).
    #[pyo3(signature = (theta_in, phi_in=None))]
    fn material_at(&self, theta_in: f64, phi_in: Option<f64>) -> PyResult<Material> {
        let table = self.table_of()?;
        let composite = match phi_in {
            Some(phi) => self
                .result
                .composite_at_direction(theta_in, phi, None)
                .ok_or_else(|| errors::model(format!("no material at ({theta_in}°, {phi}°)")))?,
            None => {
                let at = table.composite_at(theta_in);
                at.map_err(|e| errors::model(e.to_string()))?.0
            }
        };
        Ok(self.material_of(composite))
    }

    /// `fit.json` as a dict.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py.import("json")?
            .call_method1("loads", (self.result.to_json(),))
    }

    /// Writes the folder `brtf fit` writes (`params.csv`, `fit.json`, the
    /// Radiance exports, the plots and `report.html`), replacing `folder`
    /// as a whole. `force` as `brtf fit --force`.
    #[pyo3(signature = (folder, *, export = true, plots = true, force = false))]
    fn save(
        &self,
        py: Python<'_>,
        folder: PathBuf,
        export: bool,
        plots: bool,
        force: bool,
    ) -> PyResult<Vec<String>> {
        let outputs = Outputs { export, plots };
        let saved = py.detach(|| {
            brtf_workflow::save_fit(&self.result, &[], &self.paths, &folder, outputs, force)
        });
        let (files, _) = saved.map_err(errors::workflow)?;
        Ok(files.iter().map(|f| f.display().to_string()).collect())
    }

    /// Writes the Radiance materials into `folder` (created if missing;
    /// other files kept), as `brtf export`: `at` (θ_in) picks the static
    /// material's parameters. `klems="full"` (or `"half"`, `"quarter"`)
    /// also writes `<name>.xml`, a Klems BSDF XML file, as `brtf export
    /// DIR --klems`; it is made from the folder's `fit.json`, so this fit's
    /// `fit.json` and `params.csv` are written there first when the folder
    /// has none. Returns the files written.
    #[pyo3(signature = (folder, *, at = None, name = None, static_only = false, preview = true,
        klems = None, klems_colour = false))]
    #[allow(clippy::too_many_arguments)]
    fn export(
        &self,
        py: Python<'_>,
        folder: PathBuf,
        at: Option<f64>,
        name: Option<String>,
        static_only: bool,
        preview: bool,
        klems: Option<String>,
        klems_colour: bool,
    ) -> PyResult<Vec<String>> {
        let klems_options = match klems.as_deref() {
            None => None,
            Some(basis) => {
                let mut options = KlemsOptions::new("");
                options.basis = word::<BasisSize>("klems", basis)?.basis();
                options.colour = klems_colour;
                options.command_line = vec!["brtf.Fit.export (Python)".into()];
                Some(options)
            }
        };
        let options = brtf_radiance::export::ExportOptions {
            name: name.clone(),
            at,
            theta_dependent: !static_only,
            preview,
            colour: None,
        };
        let written = py.detach(|| -> Result<Vec<PathBuf>, WorkflowError> {
            let mut files = match klems_options {
                Some(_) => brtf_workflow::ensure_fit_json(&folder, &self.result)?,
                None => Vec::new(),
            };
            files.extend(brtf_workflow::export_into(&folder, &self.result, &options)?.files);
            if let Some(klems_options) = klems_options {
                // As `brtf export DIR --klems`: from the folder's fit.json.
                let name = name.as_deref().unwrap_or(&self.result.name);
                let (stem, export) =
                    brtf_workflow::klems_of_fit_folder(&folder, Some(name), klems_options)?;
                files.push(brtf_workflow::write_klems_into(&folder, &stem, &export)?);
            }
            Ok(files)
        });
        let files = written.map_err(errors::workflow)?;
        Ok(files.iter().map(|f| f.display().to_string()).collect())
    }
}
