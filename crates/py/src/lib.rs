//! `brtf._brtf`: the native module of the Python package `brtf`
//! (`python/brtf`). It only converts between Python/numpy and the brtf
//! crates: the logic is theirs. Angles are degrees, as on the command line.
// pyo3's macros expand to `unsafe` blocks; this crate writes none itself.
#![allow(unsafe_code)]

mod errors;
mod fit;
mod material;
mod measurement;

use pyo3::prelude::*;

/// Fits a Radiance model to measurement files, as `brtf fit` does: one
/// fit per incidence, one for all, and the θ_in table. `inputs`: a path,
/// a `Measurement` read from a file, or a list of these.
#[pyfunction(name = "fit")]
#[pyo3(signature = (inputs, model = "metal", *, gray = false, residual = "absolute", loss = "none",
    name = None, variant = "radiance", fresnel_k = None, source_omega = 0.0,
    orientation = None, lobes = 1, floor = None, colour = "xyz", weights = "solid_angle",
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
    use material::word;
    let fresnel_k = match fresnel_k {
        Some(k) => material::parse_fresnel_k(k)?,
        None => brtf_model::FRESNEL_K_CLASSIC,
    };
    if orientation.is_some_and(|o| o.iter().all(|c| *c == 0.0)) {
        return Err(errors::model(
            "orientation needs three numbers x, y, z, not all zero",
        ));
    }
    let settings = brtf_workflow::FitSettings {
        gray,
        variant: word("variant", variant)?,
        fresnel_k,
        source_omega,
        orientation,
        lobes,
        residual: word("residual", residual)?,
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
        mask_holder,
        beam_integral,
        rho: rho.map(|(rho, theta_in)| brtf_fit::KnownReflectance { rho, theta_in }),
        free_scale,
        interpolation: word("interpolation", interpolation)?,
        adequacy,
        sides: match side {
            Some(side) => word::<brtf_gonio::klems::Side>("side", &side)?.into(),
            None => brtf_gonio::klems::Sides::Both,
        },
        incidences: incidences
            .map(|f| {
                f.parse::<brtf_fit::klems::IncidenceFilter>()
                    .map_err(|e| errors::model(format!("incidences={f:?}: {e}")))
            })
            .transpose()?,
        patch_samples,
        ..brtf_workflow::FitSettings::new(word::<brtf_fit::ModelChoice>("model", model)?)
    };
    fit::run_fit(py, inputs, settings, name, jobs)
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
