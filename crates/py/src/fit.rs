//! `brtf.fit` and `brtf.Fit`: `brtf fit` from Python, on the same
//! library calls (`brtf_fit::fit_set`, `FitResult::write`,
//! `brtf_radiance::export::write_exports`, `brtf_plot::write_plots`).

use crate::errors::{self, Class};
use crate::material::{Material, parse_kind, parse_variant};
use crate::measurement::Measurement;
use brtf_fit::{
    ColourConversion, FitConfig, FitReport, FitResult, FitSetOptions, Interpolation, NoProgress,
    Recipe, ResidualKind, RobustLoss, ScaleRule, SelectionOptions, WeightRule,
};
use brtf_gonio::Hemisphere;
use brtf_gonio::klems::KlemsBasis;
use brtf_io::{FolderUpdate, Producer, describe_outputs};
use brtf_radiance::export::klems::{self, KlemsOptions};
use numpy::{IntoPyArray, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::{Path, PathBuf};

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

/// True when `path` starts like XML (a Klems BSDF file).
fn is_klems(path: &Path) -> bool {
    use std::io::Read;
    let mut head = Vec::with_capacity(4096);
    let opened = std::fs::File::open(path).and_then(|f| f.take(4096).read_to_end(&mut head));
    opened.is_ok() && brtf_gonio::is_xml(&head)
}

/// The keyword arguments of `brtf.fit`, as `brtf fit`'s options.
pub struct FitKwargs {
    pub model: String,
    pub gray: bool,
    pub residual: String,
    pub loss: String,
    pub name: Option<String>,
    pub variant: String,
    pub fresnel_k: f64,
    pub source_omega: f64,
    pub orientation: [f64; 3],
    pub floor: Option<f64>,
    pub colour: String,
    pub weights: String,
    pub multistart: bool,
    pub theta_cap: f64,
    pub beam_mask: f64,
    pub hemisphere: Option<String>,
    pub min_value: Option<f64>,
    pub mask_holder: bool,
    pub beam_integral: Option<f64>,
    pub rho: Option<(f64, f64)>,
    pub free_scale: bool,
    pub interpolation: String,
    pub adequacy: bool,
    /// Klems XML: the side fitted (`front` or `back`), the incidences kept
    /// (`theta<=60`, …) and the view directions per outgoing patch.
    pub side: Option<String>,
    pub incidences: Option<String>,
    pub patch_samples: usize,
}

/// A choice among fixed words, or a `brtf.ModelError` listing them.
fn choose<T: Copy>(what: &str, value: &str, choices: &[(&str, T)]) -> PyResult<T> {
    choices
        .iter()
        .find(|(k, _)| *k == value)
        .map(|(_, v)| *v)
        .ok_or_else(|| {
            let names: Vec<&str> = choices.iter().map(|(k, _)| *k).collect();
            errors::model(format!(
                "{what}={value:?}: expected one of {}",
                names.join(", ")
            ))
        })
}

impl FitKwargs {
    /// The library options, mapped exactly as `brtf fit` maps its
    /// arguments; `klems` for Klems BSDF XML inputs (one side).
    fn options(&self, name: String, klems: bool) -> PyResult<FitSetOptions> {
        let kind = parse_kind(&self.model)?;
        if self.orientation.iter().all(|c| *c == 0.0) {
            return Err(errors::model(
                "orientation needs three numbers x, y, z, not all zero",
            ));
        }
        let hemisphere = match self.hemisphere.as_deref() {
            Some(h) => choose(
                "hemisphere",
                h,
                &[
                    ("front", Some(Hemisphere::Front)),
                    ("back", Some(Hemisphere::Back)),
                    ("both", None),
                ],
            )?,
            None => SelectionOptions::default_hemisphere(kind),
        };
        let selections = SelectionOptions {
            hemisphere,
            theta_cap: self.theta_cap,
            beam_mask: self.beam_mask,
            min_value: self.min_value,
            mask_holder: self.mask_holder,
        }
        .gates(klems);
        let mut config = FitConfig::new(kind);
        config.options.variant = parse_variant(&self.variant)?;
        config.options.fresnel_k = self.fresnel_k;
        config.options.source_omega = self.source_omega;
        config.orientation = self.orientation;
        config.gray = self.gray;
        config.free_scale = self.free_scale;
        config.residual = choose(
            "residual",
            &self.residual,
            &[
                ("absolute", ResidualKind::Absolute),
                ("relative", ResidualKind::Relative),
                ("log", ResidualKind::Log),
            ],
        )?;
        config.floor = self.floor;
        config.loss = self
            .loss
            .parse::<RobustLoss>()
            .map_err(|e| errors::model(format!("loss={:?}: {e}", self.loss)))?;
        config.multistart = self.multistart;
        let options = FitSetOptions {
            name,
            config,
            recipe: Recipe {
                scale: match self.beam_integral {
                    Some(value) => ScaleRule::BeamIntegral { value },
                    None => ScaleRule::FromFiles,
                },
                colour: choose(
                    "colour",
                    &self.colour,
                    &[
                        ("xyz", ColourConversion::XyzToRadianceRgb),
                        ("as_recorded", ColourConversion::AsRecorded),
                    ],
                )?,
                selections,
                weights: choose(
                    "weights",
                    &self.weights,
                    &[
                        ("solid_angle", WeightRule::SolidAngle),
                        ("uniform", WeightRule::Uniform),
                    ],
                )?,
                ..Recipe::for_kind(kind)
            },
            known_reflectance: self.rho,
            interpolation: choose(
                "interpolation",
                &self.interpolation,
                &[
                    ("pchip", Interpolation::Pchip),
                    ("linear", Interpolation::Linear),
                ],
            )?,
            command_line: vec!["brtf.fit (Python)".into()],
            adequacy: self.adequacy,
            klems: brtf_fit::KlemsOptions {
                side: match (klems, self.side.as_deref()) {
                    (false, None) => None,
                    (false, Some(_)) => {
                        return Err(errors::model(
                            "side= chooses the side of a Klems BSDF XML file",
                        ));
                    }
                    (true, None) => {
                        return Err(errors::model(
                            "a Klems BSDF XML file is fitted one side at a time: side=\"front\" or \"back\"",
                        ));
                    }
                    (true, Some(side)) => Some(choose(
                        "side",
                        side,
                        &[
                            ("front", brtf_gonio::klems::Side::Front),
                            ("back", brtf_gonio::klems::Side::Back),
                        ],
                    )?),
                },
                incidences: match (klems, self.incidences.as_deref()) {
                    (_, None) => None,
                    (false, Some(_)) => {
                        return Err(errors::model(
                            "incidences= selects the incident patches of Klems BSDF XML files",
                        ));
                    }
                    (true, Some(filter)) => Some(
                        filter
                            .parse::<brtf_fit::klems::IncidenceFilter>()
                            .map_err(|e| errors::model(format!("incidences={filter:?}: {e}")))?,
                    ),
                },
            },
        };
        if !(1..=4096).contains(&self.patch_samples) {
            return Err(errors::model("patch_samples must be between 1 and 4096"));
        }
        let options = if klems {
            options.for_klems(self.patch_samples)
        } else {
            options
        };
        options
            .validate()
            .map_err(|e| errors::model(e.to_string()))?;
        Ok(options)
    }
}

/// Runs the fit set: reads every file, fits, on `jobs` threads (all cores
/// by default) with the GIL released.
pub fn run_fit(
    py: Python<'_>,
    inputs: &Bound<'_, PyAny>,
    kwargs: FitKwargs,
    jobs: Option<usize>,
) -> PyResult<Fit> {
    let paths = input_paths(inputs)?;
    let klems = paths.iter().filter(|p| is_klems(p)).count();
    if klems > 0 && klems < paths.len() {
        return Err(errors::error(
            Class::Fit,
            "Klems BSDF XML files are fitted on their own, not with gonio-photometer files".into(),
            None,
            None,
        ));
    }
    let klems = klems > 0;
    let name = match &kwargs.name {
        Some(name) => name.clone(),
        None => {
            let mut sample_names = Vec::new();
            for path in &paths {
                let name = if klems {
                    py.detach(|| brtf_gonio::klems::read_path(path))
                        .map_err(|e| {
                            errors::error(
                                Class::Format,
                                e.to_string(),
                                Some(path.display().to_string()),
                                None,
                            )
                        })?
                        .header
                        .name
                } else {
                    py.detach(|| brtf_gonio::read_path(path))
                        .map_err(errors::read)?
                        .sample_name
                };
                sample_names.push(name);
            }
            let stems: Vec<String> = paths
                .iter()
                .map(|f| {
                    f.file_stem()
                        .unwrap_or_default()
                        .to_string_lossy()
                        .into_owned()
                })
                .collect();
            brtf_radiance::default_fit_name(&sample_names, &stems)
        }
    };
    let options = kwargs.options(name, klems)?;
    let result = py.detach(|| -> Result<_, String> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(jobs.unwrap_or(0))
            .build()
            .map_err(|e| format!("cannot start worker threads: {e}"))?;
        Ok(pool.install(|| brtf_fit::fit_set(&paths, &options, &NoProgress)))
    });
    let result = result.map_err(|e| errors::error(Class::Fit, e, None, None))?;
    let result = result.map_err(errors::fit_set)?;
    Ok(Fit { result, paths })
}

/// One fit report (an incidence, or all of them at once).
#[pyclass(module = "brtf", frozen)]
pub struct IncidenceFit {
    report: FitReport,
    material: Option<brtf_model::Material>,
    options: brtf_model::EvalOptions,
}

impl IncidenceFit {
    fn new(result: &FitResult, report: &FitReport) -> IncidenceFit {
        IncidenceFit {
            material: result.material_of(report),
            options: result.options(),
            report: report.clone(),
        }
    }
}

/// serde → JSON text → Python objects (`json.loads`).
fn to_python<'py, T: serde::Serialize>(py: Python<'py>, value: &T) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value).map_err(|e| errors::model(e.to_string()))?;
    py.import("json")?.call_method1("loads", (text,))
}

#[pymethods]
impl IncidenceFit {
    /// θ_in in degrees (the mean incidence for the all-incidence fit).
    #[getter]
    fn theta_in(&self) -> f64 {
        self.report.theta_in
    }

    #[getter]
    fn phi_in(&self) -> f64 {
        self.report.phi_in
    }

    /// The file (or `all incidences`).
    #[getter]
    fn source(&self) -> String {
        self.report.source.clone()
    }

    /// The fitted parameters, name → value (physical units).
    #[getter]
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for p in &self.report.params {
            d.set_item(&p.name, p.value)?;
        }
        Ok(d)
    }

    /// Standard errors, name → value (None where not available).
    #[getter]
    fn stderr<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for p in &self.report.params {
            d.set_item(&p.name, p.stderr)?;
        }
        Ok(d)
    }

    /// Robust (sandwich) standard errors, name → value.
    #[getter]
    fn stderr_robust<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for p in &self.report.params {
            d.set_item(&p.name, p.stderr_robust)?;
        }
        Ok(d)
    }

    /// The material's real arguments (Radiance order).
    #[getter]
    fn material_args(&self) -> Vec<f64> {
        self.report.material_args.clone()
    }

    /// The fitted material, with the fit's evaluation options.
    #[getter]
    fn material(&self) -> Option<Material> {
        self.material
            .map(|m| Material::from_model(m, &self.options, None))
    }

    /// The free scale (1 for absolute data).
    #[getter]
    fn scale(&self) -> f64 {
        self.report.scale
    }

    /// ½ Σ (weighted residual)² at the optimum.
    #[getter]
    fn cost(&self) -> f64 {
        self.report.cost
    }

    /// RMS relative residual.
    #[getter]
    fn rms_rel(&self) -> f64 {
        self.report.rms_rel
    }

    /// Samples fitted.
    #[getter]
    fn n_points(&self) -> usize {
        self.report.n_points
    }

    /// Why the optimiser stopped.
    #[getter]
    fn termination(&self) -> String {
        self.report.termination.label().to_string()
    }

    /// Did the optimiser converge?
    #[getter]
    fn converged(&self) -> bool {
        self.report.termination.converged()
    }

    /// The warnings, as text.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.report.warnings.iter().map(|w| w.to_string()).collect()
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
            self.report.theta_in,
            params.join(", "),
            self.report.cost,
            self.report.rms_rel,
            self.report.termination.label()
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
        let written =
            py.detach(|| save_folder(&self.result, &self.paths, &folder, export, plots, force));
        written.map_err(|(class, message)| {
            errors::error(class, message, Some(folder.display().to_string()), None)
        })
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
        if let Some(at) = at
            && !(0.0..90.0).contains(&at)
        {
            return Err(errors::model(format!(
                "at={at}: out of range; allowed: 0 ≤ θ_in < 90 degrees"
            )));
        }
        let klems_options = match klems.as_deref() {
            None => None,
            Some(basis) => {
                let basis_name = choose(
                    "klems",
                    basis,
                    &[
                        ("full", "LBNL/Klems Full"),
                        ("half", "LBNL/Klems Half"),
                        ("quarter", "LBNL/Klems Quarter"),
                    ],
                )?;
                let mut options = KlemsOptions::new(name.as_deref().unwrap_or(&self.result.name));
                options.basis = KlemsBasis::built_in(basis_name)
                    .ok_or_else(|| errors::model(format!("no built-in basis {basis_name}")))?;
                options.colour = klems_colour;
                options.command_line = vec!["brtf.Fit.export (Python)".into()];
                Some(options)
            }
        };
        let options = brtf_radiance::export::ExportOptions {
            name,
            at,
            theta_dependent: !static_only,
            preview,
        };
        let written = py.detach(|| -> Result<Vec<PathBuf>, String> {
            let update = FolderUpdate::amend(&folder).map_err(|e| e.to_string())?;
            let stage = update.path().to_path_buf();
            let mut files = Vec::new();
            if klems_options.is_some() && !stage.join("fit.json").is_file() {
                self.result.write(&stage).map_err(|e| e.to_string())?;
                files.push(stage.join("params.csv"));
                files.push(stage.join("fit.json"));
            }
            let exported = brtf_radiance::export::write_exports(&stage, &self.result, &options)
                .map_err(|e| e.to_string())?;
            relist(&stage, &exported.files).map_err(|e| e.to_string())?;
            files.extend(exported.files);
            update.commit().map_err(|e| e.to_string())?;
            if let Some(klems_options) = &klems_options {
                // As `brtf export DIR --klems`: from the folder's fit.json.
                let export = klems::klems_from_fit_dir(&folder, klems_options)
                    .map_err(|e| format!("exporting {} as Klems XML: {e}", folder.display()))?;
                let update = FolderUpdate::amend(&folder).map_err(|e| e.to_string())?;
                let staged = update.path().join(format!(
                    "{}.xml",
                    brtf_radiance::export::klems::klems_file_stem(&klems_options.name)
                ));
                klems::write_klems(&staged, &export).map_err(|e| e.to_string())?;
                let listed =
                    FitResult::read(&update.path().join("fit.json")).map_err(|e| e.to_string())?;
                let mut fresh: Vec<PathBuf> = listed
                    .outputs
                    .iter()
                    .filter(|o| o.by == Producer::Export && update.path().join(&o.path).is_file())
                    .map(|o| update.path().join(&o.path))
                    .filter(|p| *p != staged)
                    .collect();
                fresh.push(staged.clone());
                relist(update.path(), &fresh).map_err(|e| e.to_string())?;
                files.push(staged);
                update.commit().map_err(|e| e.to_string())?;
            }
            Ok(files
                .iter()
                .map(|f| folder.join(f.file_name().unwrap_or_default()))
                .collect())
        });
        let files = written.map_err(errors::export)?;
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

/// `brtf fit`'s folder: the result, the exports, the plots, then
/// `fit.json` listing them, written into a staging folder swapped in whole.
fn save_folder(
    result: &FitResult,
    inputs: &[PathBuf],
    out: &Path,
    export: bool,
    plots: bool,
    force: bool,
) -> Result<Vec<String>, (Class, String)> {
    let io = |e: brtf_io::IoError| (Class::File, e.to_string());
    let update = FolderUpdate::fresh(out).map_err(io)?;
    brtf_io::check_replaceable(update.target(), inputs, force).map_err(io)?;
    let stage = update.path();
    let mut result = result.clone();
    // fit.json is written once, last (below).
    result.write_params_csv(stage).map_err(io)?;
    let mut outputs =
        describe_outputs(stage, &[stage.join("params.csv")], Producer::Fit).map_err(io)?;
    if export {
        let options = brtf_radiance::export::ExportOptions::default();
        let exported = brtf_radiance::export::write_exports(stage, &result, &options)
            .map_err(|e| (Class::Export, format!("exporting Radiance materials: {e}")))?;
        outputs.extend(describe_outputs(stage, &exported.files, Producer::Export).map_err(io)?);
    }
    if plots {
        let mut plot_options = brtf_plot::PlotOptions::default();
        plot_options.search_dirs.push(out.to_path_buf());
        let written = brtf_plot::write_plots(stage, &result, &plot_options)
            .map_err(|e| (Class::Export, format!("plotting: {e}")))?;
        outputs.extend(describe_outputs(stage, &written.files, Producer::Plot).map_err(io)?);
    }
    outputs.sort_by(|a, b| a.path.cmp(&b.path));
    result.outputs = outputs;
    // fit.json last: it lists every other file of the folder.
    result.write_fit_json(stage).map_err(io)?;
    let mut files: Vec<String> = result
        .outputs
        .iter()
        .map(|o| out.join(&o.path).display().to_string())
        .collect();
    files.push(out.join("fit.json").display().to_string());
    update.commit().map_err(io)?;
    Ok(files)
}

/// When the folder holds a `fit.json`, lists the fresh exports in it in
/// place of the old ones (as `brtf export` does).
fn relist(stage: &Path, fresh: &[PathBuf]) -> Result<(), Box<dyn std::error::Error>> {
    let path = stage.join("fit.json");
    if !path.exists() {
        return Ok(());
    }
    let mut fit = FitResult::read(&path)?;
    let fresh = describe_outputs(stage, fresh, Producer::Export)?;
    fit.outputs = brtf_io::replace_outputs(stage, &fit.outputs, fresh, Producer::Export)?;
    Ok(brtf_io::write_atomic(&path, fit.to_json().as_bytes())?)
}
