//! `brtf._brtf`: the native module of the Python package `brtf`
//! (`python/brtf`). It only converts between Python/numpy and the brtf
//! crates: the logic is theirs. Angles are degrees, as on the command line.
// pyo3's macros expand to `unsafe` blocks; this crate writes none itself.
#![allow(unsafe_code)]

mod errors;
mod fit;
mod kernel;
mod material;
mod measurement;

use pyo3::prelude::*;

/// Fits a Radiance model to measurement files, as `brtf fit` does: one
/// fit per incidence, one for all, and the θ_in table. `inputs`: a path,
/// a `Measurement` read from a file, or a list of these.
#[pyfunction(name = "fit")]
#[pyo3(signature = (inputs, model = "metal", *, gray = false, residual = "absolute", loss = "none",
    name = None, variant = "radiance", fresnel_k = None, source_omega = 0.0,
    orientation = [1.0, 0.0, 0.0], floor = None, colour = "xyz", weights = "solid_angle",
    multistart = true, theta_cap = brtf_gonio::DEFAULT_THETA_CAP_DEG, beam_mask = 3.0,
    hemisphere = None, min_value = None, mask_holder = false, beam_integral = None, rho = None,
    free_scale = false, interpolation = "pchip", adequacy = true, side = None, incidences = None,
    patch_samples = 32, jobs = None))]
#[allow(clippy::too_many_arguments)]
fn fit_set(
    py: Python<'_>,
    inputs: &Bound<'_, PyAny>,
    model: &str,
    gray: bool,
    residual: &str,
    loss: &str,
    name: Option<String>,
    variant: &str,
    fresnel_k: Option<&Bound<'_, PyAny>>,
    source_omega: f64,
    orientation: [f64; 3],
    floor: Option<f64>,
    colour: &str,
    weights: &str,
    multistart: bool,
    theta_cap: f64,
    beam_mask: f64,
    hemisphere: Option<String>,
    min_value: Option<f64>,
    mask_holder: bool,
    beam_integral: Option<f64>,
    rho: Option<(f64, f64)>,
    free_scale: bool,
    interpolation: &str,
    adequacy: bool,
    side: Option<String>,
    incidences: Option<String>,
    patch_samples: usize,
    jobs: Option<usize>,
) -> PyResult<fit::Fit> {
    let fresnel_k = match fresnel_k {
        Some(k) => material::parse_fresnel_k(k)?,
        None => brtf_model::FRESNEL_K_CLASSIC,
    };
    let kwargs = fit::FitKwargs {
        model: model.to_string(),
        gray,
        residual: residual.to_string(),
        loss: loss.to_string(),
        name,
        variant: variant.to_string(),
        fresnel_k,
        source_omega,
        orientation,
        floor,
        colour: colour.to_string(),
        weights: weights.to_string(),
        multistart,
        theta_cap,
        beam_mask,
        hemisphere,
        min_value,
        mask_holder,
        beam_integral,
        rho,
        free_scale,
        interpolation: interpolation.to_string(),
        adequacy,
        side,
        incidences,
        patch_samples,
    };
    fit::run_fit(py, inputs, kwargs, jobs)
}

#[pymodule]
fn _brtf(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<measurement::Measurement>()?;
    m.add_class::<material::Material>()?;
    m.add_class::<material::Albedo>()?;
    m.add_class::<fit::Fit>()?;
    m.add_class::<fit::IncidenceFit>()?;
    m.add_function(wrap_pyfunction!(measurement::read, m)?)?;
    m.add_function(wrap_pyfunction!(measurement::read_klems, m)?)?;
    m.add_function(wrap_pyfunction!(fit_set, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
