//! `brtf.Material`: a Radiance Ward-type material and the options it is
//! evaluated with (as `brtf eval`'s `--variant`, `--fresnel-k`,
//! `--source-omega`, `--curved`).

use crate::errors;
use brtf_model::{
    Bsdf, EvalOptions, FRESNEL_K_CLASSIC, Material as Model, MaterialKind, Variant, WordError,
};
use glam::DVec3;
use numpy::{IntoPyArray, PyArray1, PyArrayMethods, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

/// A Radiance material (`plastic`, `metal`, `trans`, `plastic2`,
/// `metal2`, `trans2`) with its evaluation options.
#[pyclass(module = "brtf", frozen)]
pub struct Material {
    pub(crate) model: Model,
    pub(crate) bsdf: Bsdf,
    /// The material identifier from a `.rad` file (`None` when built here).
    pub(crate) name: Option<String>,
}

/// `fresnel_k`: `"classic"`, `"pyradiance"` or a number.
pub(crate) fn parse_fresnel_k(value: &Bound<'_, PyAny>) -> PyResult<f64> {
    if let Ok(text) = value.extract::<String>() {
        return brtf_model::parse_fresnel_k(&text)
            .map_err(|e| errors::model(format!("fresnel_k={text:?}: {e}")));
    }
    value
        .extract::<f64>()
        .map_err(|_| errors::model("fresnel_k: expected \"classic\", \"pyradiance\" or a number"))
}

/// The keyword argument `what=value` read as one of a library enum's words
/// (a `brtf.ModelError` listing them otherwise).
pub(crate) fn word<T: std::str::FromStr<Err = WordError>>(what: &str, value: &str) -> PyResult<T> {
    value
        .parse::<T>()
        .map_err(|e| errors::model(format!("{what}={value:?}: {e}")))
}

/// The evaluation options, checked.
pub(crate) fn eval_options(
    variant: &str,
    fresnel_k: &Bound<'_, PyAny>,
    source_omega: f64,
    curved: bool,
) -> PyResult<EvalOptions> {
    let options = EvalOptions {
        variant: word("variant", variant)?,
        fresnel_k: parse_fresnel_k(fresnel_k)?,
        source_omega,
        flat: !curved,
        source_jitter: 0.0,
    };
    options
        .validate()
        .map_err(|e| errors::model(e.to_string()))?;
    Ok(options)
}

/// A number or three numbers.
fn rgb_of(value: &Bound<'_, PyAny>) -> PyResult<[f64; 3]> {
    if let Ok(x) = value.extract::<f64>() {
        return Ok([x; 3]);
    }
    let v: Vec<f64> = value
        .extract()
        .map_err(|_| errors::model("rgb: expected a number or three numbers"))?;
    <[f64; 3]>::try_from(v.as_slice())
        .map_err(|_| errors::model(format!("rgb: expected three numbers, found {}", v.len())))
}

/// A float or `(u, v)`.
fn roughness_of(value: &Bound<'_, PyAny>) -> PyResult<[f64; 2]> {
    if let Ok(x) = value.extract::<f64>() {
        return Ok([x; 2]);
    }
    let v: Vec<f64> = value
        .extract()
        .map_err(|_| errors::model("roughness: expected a number or (u, v)"))?;
    <[f64; 2]>::try_from(v.as_slice()).map_err(|_| {
        errors::model(format!(
            "roughness: expected (u, v), found {} numbers",
            v.len()
        ))
    })
}

impl Material {
    pub fn from_model(model: Model, options: &EvalOptions, name: Option<String>) -> Material {
        Material {
            bsdf: Bsdf::new(&model, options),
            model,
            name,
        }
    }

    fn build(kind: MaterialKind, args: &[f64], orientation: Option<[f64; 3]>) -> PyResult<Model> {
        brtf_model::check_args(kind, args).map_err(|e| errors::model(format!("{kind}: {e}")))?;
        Model::new(kind, args, orientation.map(DVec3::from_array))
            .map_err(|e| errors::model(e.to_string()))
    }
}

/// An array argument as a flat float64 array, broadcast to `shape`.
fn flat<'py>(
    np: &Bound<'py, PyModule>,
    value: &Bound<'py, PyAny>,
    shape: &Bound<'py, PyAny>,
) -> PyResult<PyReadonlyArray1<'py, f64>> {
    let a = np.call_method1("asarray", (value, "float64"))?;
    let b = np.call_method1("broadcast_to", (a, shape))?;
    let c = np.call_method1("ascontiguousarray", (b.call_method0("ravel")?,))?;
    let array = c.cast_into::<PyArray1<f64>>().map_err(PyErr::from)?;
    Ok(array.readonly())
}

#[pymethods]
impl Material {
    #[new]
    #[pyo3(signature = (kind, rgb = None, spec = 0.0, roughness = None, trans = None, tspec = None,
        *, orientation = None, args = None, variant = "radiance", fresnel_k = None,
        source_omega = 0.0, curved = false))]
    #[allow(clippy::too_many_arguments)]
    fn py_new(
        py: Python<'_>,
        kind: &str,
        rgb: Option<&Bound<'_, PyAny>>,
        spec: f64,
        roughness: Option<&Bound<'_, PyAny>>,
        trans: Option<f64>,
        tspec: Option<f64>,
        orientation: Option<[f64; 3]>,
        args: Option<Vec<f64>>,
        variant: &str,
        fresnel_k: Option<&Bound<'_, PyAny>>,
        source_omega: f64,
        curved: bool,
    ) -> PyResult<Material> {
        let kind: MaterialKind = word("kind", kind)?;
        let classic = "classic".into_pyobject(py)?.into_any();
        let options = eval_options(variant, fresnel_k.unwrap_or(&classic), source_omega, curved)?;
        let args = match args {
            Some(args) => {
                if rgb.is_some() || roughness.is_some() || trans.is_some() || tspec.is_some() {
                    return Err(errors::model(
                        "give either args=[...] or rgb/spec/roughness/trans/tspec, not both",
                    ));
                }
                args
            }
            None => {
                let rgb = rgb.ok_or_else(|| errors::model(format!("{kind}: rgb= is needed")))?;
                let [r, g, b] = rgb_of(rgb)?;
                let [u, v] = match roughness {
                    Some(x) => roughness_of(x)?,
                    None => [0.0; 2],
                };
                if !kind.is_anisotropic() && u != v {
                    return Err(errors::model(format!(
                        "{kind} is isotropic: roughness takes one number"
                    )));
                }
                let mut args = vec![r, g, b, spec, u];
                if kind.is_anisotropic() {
                    args.push(v);
                }
                if kind.is_transmitting() {
                    let need = |x: Option<f64>, what: &str| {
                        x.ok_or_else(|| errors::model(format!("{kind}: {what}= is needed")))
                    };
                    args.push(need(trans, "trans")?);
                    args.push(need(tspec, "tspec")?);
                } else if trans.is_some() || tspec.is_some() {
                    return Err(errors::model(format!(
                        "{kind} does not transmit: trans and tspec are for trans and trans2"
                    )));
                }
                args
            }
        };
        let model = Material::build(kind, &args, orientation)?;
        Ok(Material::from_model(model, &options, None))
    }

    /// Reads a material from Radiance text, or from a `.rad` file when
    /// `text_or_path` is a path (a `pathlib.Path`, or a one-line string
    /// naming an existing file). `name` picks one of several materials.
    #[staticmethod]
    #[pyo3(signature = (text_or_path, name = None, *, variant = "radiance", fresnel_k = None,
        source_omega = 0.0, curved = false))]
    fn from_rad(
        py: Python<'_>,
        text_or_path: &Bound<'_, PyAny>,
        name: Option<&str>,
        variant: &str,
        fresnel_k: Option<&Bound<'_, PyAny>>,
        source_omega: f64,
        curved: bool,
    ) -> PyResult<Material> {
        let classic = "classic".into_pyobject(py)?.into_any();
        let options = eval_options(variant, fresnel_k.unwrap_or(&classic), source_omega, curved)?;
        let os = py.import("os")?;
        let is_path_object = text_or_path.is_instance(&os.getattr("PathLike")?)?;
        let (text, label) = match text_or_path.extract::<String>() {
            Ok(text)
                if !is_path_object
                    && (text.contains('\n') || !std::path::Path::new(&text).is_file()) =>
            {
                if !text.contains('\n') && text.trim_end().ends_with(".rad") {
                    return Err(errors::error(
                        errors::Class::MissingFile,
                        format!("{text}: no such file"),
                        Some(text.clone()),
                        None,
                    ));
                }
                (text, "<text>".to_string())
            }
            _ => {
                let path: std::path::PathBuf = text_or_path.extract()?;
                let label = path.display().to_string();
                let text = std::fs::read_to_string(&path).map_err(|e| {
                    errors::error(
                        errors::io_class(&e),
                        format!("{label}: cannot read: {e}"),
                        Some(label.clone()),
                        None,
                    )
                })?;
                (text, label)
            }
        };
        let primitives = brtf_radiance::parse_primitives(&text, &label).map_err(errors::rad)?;
        let (chosen, model) =
            brtf_radiance::select_material(&primitives, name, &label).map_err(errors::rad)?;
        Ok(Material::from_model(model, &options, Some(chosen)))
    }

    /// The type: `plastic`, `metal`, `trans`, `plastic2`, `metal2` or `trans2`.
    #[getter]
    fn kind(&self) -> &'static str {
        self.model.kind().name()
    }

    /// The real arguments in Radiance order.
    #[getter]
    fn args(&self) -> Vec<f64> {
        self.model.args().to_vec()
    }

    /// The names of the real arguments (`red`, `green`, `blue`, `spec`, `rough`, ...).
    #[getter]
    fn param_names(&self) -> Vec<&'static str> {
        self.model.kind().param_names().to_vec()
    }

    /// The arguments as a dict, name → value.
    #[getter]
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, v) in self
            .model
            .kind()
            .param_names()
            .iter()
            .zip(self.model.args())
        {
            d.set_item(*k, *v)?;
        }
        Ok(d)
    }

    /// The orientation vector of the `*2` types.
    #[getter]
    fn orientation(&self) -> [f64; 3] {
        self.model.orientation().to_array()
    }

    /// The identifier read from a `.rad` file, if any.
    #[getter]
    fn name(&self) -> Option<String> {
        self.name.clone()
    }

    /// The formula set: `radiance`, `manual2004` or `ward1992`.
    #[getter]
    fn variant(&self) -> &'static str {
        self.bsdf.options().variant.name()
    }

    /// The roughness-0 Fresnel constant.
    #[getter]
    fn fresnel_k(&self) -> f64 {
        self.bsdf.options().fresnel_k
    }

    /// The source solid angle in sr (lobe widening as rtrace).
    #[getter]
    fn source_omega(&self) -> f64 {
        self.bsdf.options().source_omega
    }

    /// The BSDF in 1/sr (no cosine), RGB, for light from (θ_in, φ_in)
    /// seen from (θ_out, φ_out), in degrees. Arguments broadcast like
    /// numpy; the result has their broadcast shape plus a last axis of 3.
    fn eval<'py>(
        &self,
        py: Python<'py>,
        theta_in: &Bound<'py, PyAny>,
        phi_in: &Bound<'py, PyAny>,
        theta_out: &Bound<'py, PyAny>,
        phi_out: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let np = py.import("numpy")?;
        let shapes = [theta_in, phi_in, theta_out, phi_out]
            .iter()
            .map(|a| np.call_method1("shape", (*a,)))
            .collect::<PyResult<Vec<_>>>()?;
        let shape = np.call_method1("broadcast_shapes", PyTuple::new(py, &shapes)?)?;
        let incidence_shape = np.call_method1("broadcast_shapes", (&shapes[0], &shapes[1]))?;
        let one_incidence = incidence_shape.len()? == 0
            || np
                .call_method1("prod", (&incidence_shape,))?
                .extract::<usize>()?
                == 1;
        let to = flat(&np, theta_out, &shape)?;
        let po = flat(&np, phi_out, &shape)?;
        let (to, po) = (to.as_slice()?, po.as_slice()?);
        let mut out = vec![0.0; 3 * to.len()];
        if one_incidence {
            let ti = flat(&np, theta_in, &incidence_shape)?;
            let pi = flat(&np, phi_in, &incidence_shape)?;
            let (ti, pi) = (ti.as_slice()?[0], pi.as_slice()?[0]);
            brtf_model::check_incidence(ti, pi).map_err(|e| errors::model(e.to_string()))?;
            py.detach(|| self.bsdf.eval_degrees_from(ti, pi, to, po, &mut out));
        } else {
            let ti = flat(&np, theta_in, &shape)?;
            let pi = flat(&np, phi_in, &shape)?;
            let (ti, pi) = (ti.as_slice()?, pi.as_slice()?);
            for (&t, &p) in ti.iter().zip(pi) {
                brtf_model::check_incidence(t, p).map_err(|e| errors::model(e.to_string()))?;
            }
            py.detach(|| self.bsdf.eval_degrees(ti, pi, to, po, &mut out));
        }
        let mut full_shape: Vec<usize> = shape.extract()?;
        full_shape.push(3);
        Ok(out.into_pyarray(py).reshape(full_shape)?.into_any())
    }

    /// ρ_dh and τ_dh (per channel) for light from θ_in (degrees, scalar or
    /// array) at azimuth φ_in, as `brtf albedo`.
    #[pyo3(signature = (theta_in, phi_in = 0.0, tolerance = 1e-5))]
    fn albedo(
        &self,
        py: Python<'_>,
        theta_in: &Bound<'_, PyAny>,
        phi_in: f64,
        tolerance: f64,
    ) -> PyResult<Albedo> {
        if !(tolerance > 0.0 && tolerance < 1.0) {
            return Err(errors::model(format!(
                "tolerance={tolerance}: out of range; allowed: 0 < tolerance < 1"
            )));
        }
        let np = py.import("numpy")?;
        let shape = np.call_method1("shape", (theta_in,))?;
        let thetas = flat(&np, theta_in, &shape)?;
        let thetas = thetas.as_slice()?.to_vec();
        for &t in &thetas {
            brtf_model::check_incidence(t, phi_in).map_err(|e| errors::model(e.to_string()))?;
        }
        let results: Vec<brtf_model::Albedo> = py.detach(|| {
            thetas
                .iter()
                .map(|&t| {
                    brtf_model::albedo(&self.bsdf, brtf_model::direction(t, phi_in), tolerance)
                })
                .collect()
        });
        let mut full_shape: Vec<usize> = shape.extract()?;
        full_shape.push(3);
        let array = |f: &dyn Fn(&brtf_model::Albedo) -> [f64; 3]| -> PyResult<Py<PyAny>> {
            let v: Vec<f64> = results.iter().flat_map(f).collect();
            Ok(v.into_pyarray(py)
                .reshape(full_shape.clone())?
                .into_any()
                .unbind())
        };
        Ok(Albedo {
            rho: array(&|a| a.rho)?,
            tau: array(&|a| a.tau)?,
            rho_spike: array(&|a| a.rho_spike)?,
            tau_spike: array(&|a| a.tau_spike)?,
        })
    }

    /// The material as a Radiance primitive (`void metal NAME ...`).
    #[pyo3(signature = (name = None))]
    fn to_rad(&self, name: Option<&str>) -> PyResult<String> {
        let name = name.or(self.name.as_deref()).unwrap_or("material");
        if brtf_radiance::identifier(name).as_deref() != Some(name) {
            return Err(errors::model(format!(
                "name {name:?}: not a Radiance identifier (letters, digits, _ - . only)"
            )));
        }
        let primitive = brtf_radiance::primitive_from_material(&self.model, name);
        Ok(brtf_radiance::format_primitive(&primitive))
    }

    /// For `scripts/bench-python.py` only: seconds the Rust loop behind
    /// `eval` takes on these directions, with inputs and output already
    /// in Rust vectors (as the criterion bench), so that Python and Rust
    /// can be timed alternately in one process under the same load.
    #[pyo3(signature = (theta_in, phi_in, theta_out, phi_out, per_row = false))]
    fn _kernel_seconds(
        &self,
        py: Python<'_>,
        theta_in: f64,
        phi_in: f64,
        theta_out: Vec<f64>,
        phi_out: Vec<f64>,
        per_row: bool,
    ) -> f64 {
        let n = theta_out.len().min(phi_out.len());
        let (ti, pi) = (vec![theta_in; n], vec![phi_in; n]);
        let mut out = vec![0.0; 3 * n];
        py.detach(|| {
            let start = std::time::Instant::now();
            if per_row {
                self.bsdf
                    .eval_degrees(&ti, &pi, &theta_out, &phi_out, &mut out);
            } else {
                self.bsdf
                    .eval_degrees_from(theta_in, phi_in, &theta_out, &phi_out, &mut out);
            }
            std::hint::black_box(&out);
            start.elapsed().as_secs_f64()
        })
    }

    fn __repr__(&self) -> String {
        let args: Vec<String> = self.model.args().iter().map(|a| a.to_string()).collect();
        let mut text = format!(
            "Material({:?}, args=[{}]",
            self.model.kind().name(),
            args.join(", ")
        );
        if self.model.kind().is_anisotropic() {
            let o = self.model.orientation();
            text += &format!(", orientation=({}, {}, {})", o.x, o.y, o.z);
        }
        let options = self.bsdf.options();
        if options.variant != Variant::Radiance {
            text += &format!(", variant={:?}", options.variant.name());
        }
        if options.fresnel_k != FRESNEL_K_CLASSIC {
            text += &format!(", fresnel_k={}", options.fresnel_k);
        }
        if options.source_omega != 0.0 {
            text += &format!(", source_omega={}", options.source_omega);
        }
        if !options.flat {
            text += ", curved=True";
        }
        text + ")"
    }
}

/// Directional-hemispherical reflectance and transmittance, per channel
/// (last axis RGB): the diffuse and rough parts, and the mirror and
/// straight-through delta parts of roughness-0 surfaces.
#[pyclass(module = "brtf", frozen, get_all)]
pub struct Albedo {
    /// ρ_dh without the delta part.
    pub rho: Py<PyAny>,
    /// τ_dh without the delta part.
    pub tau: Py<PyAny>,
    /// Mirror delta reflectance.
    pub rho_spike: Py<PyAny>,
    /// Straight-through delta transmittance.
    pub tau_spike: Py<PyAny>,
}

#[pymethods]
impl Albedo {
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!(
            "Albedo(rho={}, tau={})",
            self.rho.bind(py).repr()?,
            self.tau.bind(py).repr()?
        ))
    }
}
