//! `brtf.fit` and `brtf.Fit`: `brtf fit` from Python, on the same
//! library calls (`brtf_fit::fit_set`, `FitResult::write`,
//! `brtf_radiance::export::write_exports`, `brtf_plot::write_plots`).

use crate::errors::{self, Class};
use crate::material::{Material, word};
use crate::measurement::Measurement;
use brtf_fit::{FitReport, FitResult, NoProgress};
use brtf_gonio::klems::{BasisSize, Sides};
use brtf_radiance::export::klems::KlemsOptions;
use brtf_workflow::{FitInputs, FitJob, FitSettings, Outputs, WorkflowError};
use numpy::{IntoPyArray, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// One file path per input: a path, or a Measurement read from a file.
fn input_paths(inputs: &Bound<'_, PyAny>) -> PyResult<Vec<PathBuf>> {
    let one = |item: &Bound<'_, PyAny>| -> PyResult<PathBuf> {
        if let Ok(m) = item.cast::<Measurement>() {
            let m = m.get();
            return m.path.clone().ok_or_else(|| {
                errors::error(
                    Class::Fit,
                    format!(
                        "{}: brtf.fit fits measurement files; this Measurement has no file of its own (a Klems patch)",
                        m.origin
                    ),
                    None,
                    None,
                )
            });
        }
        item.extract::<PathBuf>().map_err(|_| {
            errors::model(format!(
                "fit: expected paths or brtf.Measurement objects, found {}",
                item.get_type()
                    .name()
                    .map(|n| n.to_string())
                    .unwrap_or_default()
            ))
        })
    };
    let is_single = inputs.is_instance_of::<pyo3::types::PyString>()
        || inputs.cast::<Measurement>().is_ok()
        || inputs
            .is_instance(&inputs.py().import("os")?.getattr("PathLike")?)
            .unwrap_or(false);
    if is_single {
        return Ok(vec![one(inputs)?]);
    }
    let mut paths = Vec::new();
    for item in inputs.try_iter()? {
        paths.push(one(&item?)?);
    }
    if paths.is_empty() {
        return Err(errors::error(
            Class::Fit,
            "no measurement files given".into(),
            None,
            None,
        ));
    }
    Ok(paths)
}

/// Runs the fit: reads every file and fits it, on `jobs` threads (all
/// cores by default) with the GIL released. A Klems BSDF XML file is fitted
/// one side at a time (`settings.sides` front or back).
pub(crate) fn run_fit(
    py: Python<'_>,
    inputs: &Bound<'_, PyAny>,
    settings: FitSettings,
    name: Option<String>,
    jobs: Option<usize>,
) -> PyResult<Fit> {
    let paths = input_paths(inputs)?;
    let inputs = FitInputs::classify(&paths).map_err(errors::workflow)?;
    let side = match (inputs.is_klems(), settings.sides) {
        (false, Sides::Both) => None,
        (false, _) => {
            return Err(errors::model(
                "side= chooses the side of a Klems BSDF XML file",
            ));
        }
        (true, Sides::Both) => {
            return Err(errors::model(
                "a Klems BSDF XML file is fitted one side at a time: side=\"front\" or \"back\"",
            ));
        }
        (true, sides) => sides.sides().first().copied(),
    };
    let command_line = vec!["brtf.fit (Python)".to_string()];
    let fitted = py.detach(|| -> Result<_, WorkflowError> {
        let job = FitJob::new(&inputs, &settings, name, command_line)?;
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(jobs.unwrap_or(0))
            .build()
            .map_err(|e| WorkflowError::Usage(format!("cannot start worker threads: {e}")))?;
        pool.install(|| job.fit(side, &NoProgress))
    });
    let result = fitted.map_err(errors::workflow)?.result;
    Ok(Fit { result, paths })
}

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
    /// The material's real arguments (Radiance order).
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
    /// Samples fitted.
    #[pyo3(get)]
    n_points: usize,
    /// Why the optimiser stopped.
    #[pyo3(get)]
    termination: String,
    /// Did the optimiser converge?
    #[pyo3(get)]
    converged: bool,
    /// The warnings, as text.
    #[pyo3(get)]
    warnings: Vec<String>,
    report: FitReport,
    material: Option<brtf_model::Material>,
    options: brtf_model::EvalOptions,
}

impl IncidenceFit {
    fn new(result: &FitResult, report: &FitReport) -> IncidenceFit {
        IncidenceFit {
            theta_in: report.theta_in,
            phi_in: report.phi_in,
            source: report.source.clone(),
            material_args: report.material_args.clone(),
            scale: report.scale,
            cost: report.cost,
            rms_rel: report.rms_rel,
            n_points: report.n_points,
            termination: report.termination.label().to_string(),
            converged: report.termination.converged(),
            warnings: report.warnings.iter().map(|w| w.to_string()).collect(),
            material: result.material_of(report),
            options: result.options(),
            report: report.clone(),
        }
    }

    /// `name → f(parameter)` over the fitted parameters.
    fn by_name<'py, T: IntoPyObject<'py>>(
        &self,
        py: Python<'py>,
        f: impl Fn(&brtf_fit::ParamEstimate) -> T,
    ) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for p in &self.report.params {
            d.set_item(&p.name, f(p))?;
        }
        Ok(d)
    }
}

/// serde → JSON text → Python objects (`json.loads`).
fn to_python<'py, T: serde::Serialize>(py: Python<'py>, value: &T) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value).map_err(|e| errors::model(e.to_string()))?;
    py.import("json")?.call_method1("loads", (text,))
}

#[pymethods]
impl IncidenceFit {
    /// The fitted parameters, name → value (physical units).
    #[getter]
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.by_name(py, |p| p.value)
    }

    /// Standard errors, name → value (None where not available).
    #[getter]
    fn stderr<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.by_name(py, |p| p.stderr)
    }

    /// Robust (sandwich) standard errors, name → value.
    #[getter]
    fn stderr_robust<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.by_name(py, |p| p.stderr_robust)
    }

    /// The fitted material, with the fit's evaluation options.
    #[getter]
    fn material(&self) -> Option<Material> {
        self.material
            .map(|m| Material::from_model(m, &self.options, None))
    }

    /// The adequacy diagnostics (energy, peak, residual-kind check) as a
    /// dict, as in `fit.json`; None when not computed.
    #[getter]
    fn adequacy<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.report.adequacy)
    }

    /// Everything, as this report's entry in `fit.json`.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.report)
    }

    fn __repr__(&self) -> String {
        let params: Vec<String> = self
            .report
            .params
            .iter()
            .map(|p| format!("{}={:.6}", p.name, p.value))
            .collect();
        format!(
            "IncidenceFit(theta_in={}, {}, cost={:.6e}, rms_rel={:.4}, {})",
            self.theta_in,
            params.join(", "),
            self.cost,
            self.rms_rel,
            self.termination
        )
    }
}

/// A fit set: what `brtf fit` writes as `fit.json`, and its outputs.
#[pyclass(module = "brtf", frozen)]
pub struct Fit {
    result: FitResult,
    /// The measurement files, as given.
    paths: Vec<PathBuf>,
}

#[pymethods]
impl Fit {
    /// Reads a fit folder's `fit.json` (written by `brtf fit` or `Fit.save`).
    #[staticmethod]
    fn load(py: Python<'_>, folder: PathBuf) -> PyResult<Fit> {
        let path = folder.join("fit.json");
        let result = py
            .detach(|| FitResult::read(&path))
            .map_err(|e| errors::read_fit(e, &path))?;
        let paths = result
            .provenance
            .inputs
            .iter()
            .map(|i| PathBuf::from(&i.path))
            .collect();
        Ok(Fit { result, paths })
    }

    /// The material name.
    #[getter]
    fn name(&self) -> String {
        self.result.name.clone()
    }

    /// The model fitted.
    #[getter]
    fn model(&self) -> &'static str {
        self.result.config.kind.name()
    }

    /// One report per incidence, by θ_in.
    #[getter]
    fn incidences(&self) -> Vec<IncidenceFit> {
        self.result
            .incidences
            .iter()
            .map(|r| IncidenceFit::new(&self.result, r))
            .collect()
    }

    /// The fit of all incidences at once.
    #[getter]
    fn global_fit(&self) -> Option<IncidenceFit> {
        self.result
            .global
            .as_ref()
            .map(|r| IncidenceFit::new(&self.result, r))
    }

    /// The static material (the all-incidence fit), as the exports use.
    #[getter]
    fn material(&self) -> Option<Material> {
        self.result.static_material().map(|m| {
            Material::from_model(m, &self.result.options(), Some(self.result.name.clone()))
        })
    }

    /// The warnings of the whole set, as text.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.result.warnings.iter().map(|w| w.to_string()).collect()
    }

    /// The parameters interpolated in θ_in (degrees, scalar or array):
    /// name → array of θ_in's shape. Outside the fitted range they are
    /// held at the end values.
    fn table<'py>(
        &self,
        py: Python<'py>,
        theta_in: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let table = self.result.table.as_ref().ok_or_else(|| {
            errors::error(
                Class::Fit,
                "this fit has no θ_in table (it needs two incidences or more)".into(),
                None,
                None,
            )
        })?;
        let np = py.import("numpy")?;
        let array = np.call_method1("asarray", (theta_in, "float64"))?;
        let shape: Vec<usize> = array.getattr("shape")?.extract()?;
        let flat: Vec<f64> = array.call_method0("ravel")?.extract()?;
        let rows: Vec<Vec<f64>> = flat.iter().map(|&t| table.args_at(t).0).collect();
        let d = PyDict::new(py);
        for (i, name) in table.kind.param_names().iter().enumerate() {
            let column: Vec<f64> = rows.iter().map(|r| r[i]).collect();
            d.set_item(*name, column.into_pyarray(py).reshape(shape.clone())?)?;
        }
        Ok(d)
    }

    /// The material at θ_in from the table (with the fit's options); with
    /// `phi_in` (degrees, the data's frame), at that azimuth for a table
    /// that follows φ_in (anisotropic types fitted to Klems XML).
    #[pyo3(signature = (theta_in, phi_in=None))]
    fn material_at(&self, theta_in: f64, phi_in: Option<f64>) -> PyResult<Material> {
        let table = self.result.table.as_ref().ok_or_else(|| {
            errors::error(Class::Fit, "this fit has no θ_in table".into(), None, None)
        })?;
        let material = match phi_in {
            Some(phi) => self
                .result
                .material_at_direction(theta_in, phi, None)
                .ok_or_else(|| errors::model(format!("no material at ({theta_in}°, {phi}°)")))?,
            None => {
                table
                    .at(theta_in)
                    .map_err(|e| errors::model(e.to_string()))?
                    .material
            }
        };
        Ok(Material::from_model(
            material,
            &self.result.options(),
            Some(self.result.name.clone()),
        ))
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

    fn __repr__(&self) -> String {
        let global = self.result.global.as_ref().map(|g| {
            g.params
                .iter()
                .map(|p| format!("{}={:.6}", p.name, p.value))
                .collect::<Vec<_>>()
                .join(", ")
        });
        format!(
            "Fit(name={:?}, model={:?}, incidences={}, global_fit=({}))",
            self.result.name,
            self.result.config.kind.name(),
            self.result.incidences.len(),
            global.unwrap_or_default()
        )
    }
}
