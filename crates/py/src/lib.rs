//! `brtf._brtf`, the native module of the Python package `brtf`: it converts between
//! Python/numpy and the brtf crates (angles in degrees); `python/brtf/_python.py` adds
//! the plain-Python parts (`brtf.fit`'s inputs, `Material.from_rad`'s file, every `repr`).
// pyo3's macros expand to `unsafe` blocks; this crate writes none itself.
#![allow(unsafe_code)]

mod errors;
mod fit;
mod klems;
mod material;
mod measurement;

use brtf_gonio::klems::{Side, Sides};
use brtf_workflow::{FitInputs, FitJob, WorkflowError};
use pyo3::prelude::*;

/// Fits a Radiance model to the measurement files `paths`, as `brtf fit`
/// does: one fit per incidence, one for all, and the θ_in table (`brtf.fit`
/// turns its `inputs` into the paths). A Klems BSDF XML file is fitted per
/// side: `side="both"` gives the sides the file holds, each its own fit.
#[pyfunction(name = "fit")]
#[pyo3(signature = (paths, model = "metal", *, gray = false, residual = "absolute", loss = "none", energy = "free",
    name = None, variant = "radiance", fresnel_k = None, source_omega = 0.0,
    orientation = None, lobes = 1, floor = None, colour = "xyz", weights = "solid_angle",
    multistart = true, theta_cap = brtf_gonio::DEFAULT_THETA_CAP_DEG, beam_mask = 3.0,
    hemisphere = None, min_value = None, mask_holder = None, phi_offset = None, beam_integral = None,
    rho = None,
    free_scale = false, interpolation = "pchip", adequacy = true, side = None, incidences = None,
    patch_samples = 32, jobs = None))]
#[allow(clippy::too_many_arguments)]
fn fit_set(
    py: Python<'_>,
    paths: Vec<std::path::PathBuf>,
    model: &str,
    gray: bool,
    residual: &str,
    loss: &str,
    energy: &str,
    name: Option<String>,
    variant: &str,
    fresnel_k: Option<&Bound<'_, PyAny>>,
    source_omega: f64,
    orientation: Option<[f64; 3]>,
    lobes: usize,
    floor: Option<f64>,
    colour: &str,
    weights: &str,
    multistart: bool,
    theta_cap: f64,
    beam_mask: f64,
    hemisphere: Option<String>,
    min_value: Option<f64>,
    mask_holder: Option<String>,
    phi_offset: Option<String>,
    beam_integral: Option<f64>,
    rho: Option<(f64, f64)>,
    free_scale: bool,
    interpolation: &str,
    adequacy: bool,
    side: Option<String>,
    incidences: Option<String>,
    patch_samples: usize,
    jobs: Option<usize>,
) -> PyResult<Vec<(Option<&'static str>, fit::Fit)>> {
    use material::word;
    let fresnel_k =
        fresnel_k.map_or(Ok(brtf_model::FRESNEL_K_CLASSIC), material::parse_fresnel_k)?;
    let sides = side.map(|s| word::<Sides>("side", &s)).transpose()?;
    let settings = brtf_workflow::FitSettings {
        gray,
        variant: word("variant", variant)?,
        fresnel_k,
        source_omega,
        orientation,
        lobes,
        residual: word("residual", residual)?,
        energy: word("energy", energy)?,
        floor,
        loss: loss
            .parse::<brtf_fit::RobustLoss>()
            .map_err(|e| errors::model(format!("loss={loss:?}: {e}")))?,
        colour: word("colour", colour)?,
        weights: word("weights", weights)?,
        multistart,
        theta_cap,
        beam_mask,
        hemisphere: hemisphere.map(|h| word("hemisphere", &h)).transpose()?,
        min_value,
        mask_holder: mask_holder.map(|v| word("mask_holder", &v)).transpose()?,
        phi_offset: phi_offset.map(|v| word("phi_offset", &v)).transpose()?,
        beam_integral,
        rho: rho.map(|(rho, theta_in)| brtf_fit::KnownReflectance { rho, theta_in }),
        free_scale,
        interpolation: word("interpolation", interpolation)?,
        adequacy,
        sides: sides.unwrap_or_default(),
        incidences: incidences
            .map(|f| {
                f.parse::<brtf_fit::klems::IncidenceFilter>()
                    .map_err(|e| errors::model(format!("incidences={f:?}: {e}")))
            })
            .transpose()?,
        patch_samples,
        stop: brtf_fit::StopFlag::new(),
        ..brtf_workflow::FitSettings::new(word::<brtf_fit::ModelChoice>("model", model)?)
    };
    let inputs = FitInputs::classify(&paths).map_err(errors::workflow)?;
    if inputs.is_klems() != sides.is_some() {
        return Err(errors::model(match sides {
            Some(_) => "side= chooses the side of a Klems BSDF XML file",
            None => "a Klems file is fitted per side: side=\"front\", \"back\" or \"both\"",
        }));
    }
    // Read and fitted on `jobs` threads, the GIL released; this thread
    // watches for Ctrl-C meanwhile and stops the fit within one pass of
    // the solve under way.
    let command_line = vec!["brtf.fit (Python)".to_string()];
    let cancel = Cancel(settings.stop.clone());
    let fitted = std::thread::scope(|scope| {
        let worker = scope.spawn(|| -> Result<_, WorkflowError> {
            let job = FitJob::new(&inputs, &settings, name, command_line)?;
            let (sides, _) = job.sides(settings.sides)?;
            let fit = |side: Option<Side>| Ok((side.map(Side::name), job.fit(side, &cancel)?));
            brtf_workflow::with_jobs(jobs, || sides.into_iter().map(fit).collect())?
        });
        while !worker.is_finished() {
            py.detach(|| std::thread::sleep(std::time::Duration::from_millis(20)));
            if let Err(interrupt) = py.check_signals() {
                cancel.0.raise();
                let _ = py.detach(|| worker.join());
                return Err(interrupt);
            }
        }
        py.detach(|| worker.join())
            .map_err(|_| pyo3::exceptions::PyRuntimeError::new_err("the fit thread panicked"))
    })?;
    let fitted: Vec<(Option<&str>, brtf_fit::FittedSet)> = fitted.map_err(errors::workflow)?;
    let fit =
        |(side, set): (_, brtf_fit::FittedSet)| (side, fit::Fit::new(set.result, paths.clone()));
    Ok(fitted.into_iter().map(fit).collect())
}

/// The `trans` of EN 14501 datasheet values at normal incidence, as the
/// Radiance text `brtf fit --en14501` prints.
#[pyfunction]
fn en14501(
    tau_nh: f64,
    tau_nn: f64,
    rho_nh: f64,
    spec: f64,
    name: Option<&str>,
) -> PyResult<String> {
    // Through the command line's parser, which checks each value's range.
    let text = format!("tau_nh={tau_nh},tau_nn={tau_nn},rho_nh={rho_nh},spec={spec}");
    let values: brtf_fit::en14501::En14501 = text.parse().map_err(errors::model)?;
    values.trans_args().map_err(errors::model)?;
    let command_line = ["brtf.en14501 (Python)".to_string()];
    let rad = brtf_workflow::en14501_material(&values, name, &command_line);
    rad.map_err(errors::workflow)
}

/// A fit's progress that only carries the stop request of Ctrl-C (the
/// same flag stops the solve under way).
struct Cancel(brtf_fit::StopFlag);

impl brtf_fit::Progress for Cancel {
    fn cancelled(&self) -> bool {
        self.0.is_raised()
    }
}

#[pymodule]
fn _brtf(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<measurement::Measurement>()?;
    m.add_class::<material::Material>()?;
    m.add_class::<material::Albedo>()?;
    m.add_class::<fit::Fit>()?;
    m.add_class::<fit::IncidenceFit>()?;
    m.add_function(wrap_pyfunction!(measurement::read, m)?)?;
    m.add_class::<klems::KlemsData>()?;
    m.add_function(wrap_pyfunction!(klems::to_klems, m)?)?;
    m.add_function(wrap_pyfunction!(en14501, m)?)?;
    m.add_function(wrap_pyfunction!(fit_set, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("_FRESNEL_K_CLASSIC", brtf_model::FRESNEL_K_CLASSIC)?;
    Ok(())
}
