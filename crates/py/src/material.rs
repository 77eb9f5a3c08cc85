//! `brtf.Material`: a Radiance Ward-type material, one primitive or a lobe
//! sum (a constant `mixfunc` tree of them), and the options it is
//! evaluated with (as `brtf eval`'s `--variant`, `--fresnel-k`,
//! `--source-omega`, `--curved`).

use crate::errors;
use brtf_model::{Composite, CompositeBsdf, EvalOptions, MaterialKind, Shape, direction};
use glam::DVec3;
use numpy::{IntoPyArray, PyArray1, PyArrayMethods, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyTuple;

/// A Radiance material (`plastic`, `metal`, `trans`, `plastic2`,
/// `metal2`, `trans2`, or a lobe sum of one of the first four types)
/// with its evaluation options.
#[pyclass(module = "brtf", frozen)]
pub struct Material {
    pub(crate) composite: Composite,
    pub(crate) bsdf: CompositeBsdf,
    /// The material identifier from a `.rad` file (`None` when built here).
    #[pyo3(get)]
    name: Option<String>,
    /// The type (of every lobe): `plastic`, `metal`, `trans`, `plastic2`,
    /// `metal2` or `trans2`.
    #[pyo3(get)]
    kind: &'static str,
    /// The shape: `metal`, `metal ×2 lobes`, `plastic2 (orientation
    /// fitted)` (None for a mixture of no lobe-sum shape).
    #[pyo3(get)]
    shape: Option<String>,
    /// The number of primitives mixed (1: one primitive).
    #[pyo3(get)]
    lobes: usize,
    /// The formula set: `radiance`, `manual2004` or `ward1992`.
    #[pyo3(get)]
    variant: &'static str,
    /// The roughness-0 Fresnel constant.
    #[pyo3(get)]
    fresnel_k: f64,
    /// The source solid angle in sr (lobe widening as rtrace).
    #[pyo3(get)]
    source_omega: f64,
    /// Evaluated on a curved surface (rtrace's bend of the specular lobe).
    #[pyo3(get)]
    curved: bool,
    /// The arguments: a primitive's real arguments in Radiance order, a
    /// lobe sum's flat arguments (None for a mixture of no lobe-sum shape).
    #[pyo3(get)]
    args: Option<Vec<f64>>,
    /// The names of `args` (`red`, `green`, `blue`, `spec`, `rough`;
    /// `split1`, `rough1`, `rough2`, `orient`, ... for lobe sums).
    #[pyo3(get)]
    param_names: Option<Vec<String>>,
    /// The orientation vector of the `*2` types.
    #[pyo3(get)]
    orientation: [f64; 3],
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
pub(crate) fn word<T: std::str::FromStr<Err: std::fmt::Display>>(
    what: &str,
    value: &str,
) -> PyResult<T> {
    value
        .parse::<T>()
        .map_err(|e| errors::model(format!("{what}={value:?}: {e}")))
}

/// The evaluation options, checked (`fresnel_k` None: the classic constant).
fn eval_options(
    variant: &str,
    fresnel_k: Option<&Bound<'_, PyAny>>,
    source_omega: f64,
    curved: bool,
) -> PyResult<EvalOptions> {
    let options = EvalOptions {
        variant: word("variant", variant)?,
        fresnel_k: fresnel_k.map_or(Ok(brtf_model::FRESNEL_K_CLASSIC), parse_fresnel_k)?,
        source_omega,
        flat: !curved,
        source_jitter: 0.0,
    };
    options.validate().map_err(errors::option)?;
    Ok(options)
}

/// A number or `n` numbers.
fn numbers<const N: usize>(value: &Bound<'_, PyAny>, what: &str) -> PyResult<[f64; N]> {
    if let Ok(x) = value.extract::<f64>() {
        return Ok([x; N]);
    }
    let v: Vec<f64> = value
        .extract()
        .map_err(|_| errors::model(format!("{what}: expected a number or {N} numbers")))?;
    <[f64; N]>::try_from(v.as_slice())
        .map_err(|_| errors::model(format!("{what}: expected {N} numbers, found {}", v.len())))
}

/// The real arguments from `rgb`, `spec`, `roughness`, `trans`, `tspec`.
fn primitive_args(
    kind: MaterialKind,
    rgb: &Bound<'_, PyAny>,
    spec: f64,
    roughness: Option<&Bound<'_, PyAny>>,
    trans: Option<f64>,
    tspec: Option<f64>,
) -> PyResult<Vec<f64>> {
    let [r, g, b] = numbers::<3>(rgb, "rgb")?;
    let [u, v] = roughness.map_or(Ok([0.0; 2]), |x| numbers::<2>(x, "roughness"))?;
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
        args.extend([need(trans, "trans")?, need(tspec, "tspec")?]);
    } else if trans.is_some() || tspec.is_some() {
        return Err(errors::model(format!(
            "{kind} does not transmit: trans and tspec are for trans and trans2"
        )));
    }
    Ok(args)
}

impl Material {
    pub fn new(composite: Composite, options: &EvalOptions, name: Option<String>) -> Material {
        Material {
            bsdf: CompositeBsdf::new(&composite, options),
            kind: composite.kind().name(),
            shape: composite.shape().map(|s| s.label()),
            lobes: composite.components().len(),
            variant: options.variant.name(),
            fresnel_k: options.fresnel_k,
            source_omega: options.source_omega,
            curved: !options.flat,
            args: composite.args().map(<[f64]>::to_vec),
            param_names: composite.shape().map(|s| s.param_names()),
            orientation: composite.orientation().to_array(),
            composite,
            name,
        }
    }

    /// The material of `shape` with flat arguments `args`, each lobe's
    /// arguments checked as Radiance reads them.
    fn build(shape: Shape, args: &[f64], orientation: Option<[f64; 3]>) -> PyResult<Composite> {
        let kind = shape.kind;
        if shape.is_single() {
            brtf_model::check_args(kind, args)
                .map_err(|e| errors::model(format!("{kind}: {e}")))?;
        }
        let composite = Composite::new(shape, args, orientation.map(DVec3::from_array))
            .map_err(|e| errors::model(e.to_string()))?;
        for (k, (_, m)) in composite.components().iter().enumerate() {
            brtf_model::check_args(kind, m.args())
                .map_err(|e| errors::model(format!("{}: lobe {}: {e}", shape.label(), k + 1)))?;
        }
        Ok(composite)
    }

    /// `f` of every row into `out` (3 per row): the incidence `ti`, `pi`
    /// is one for every row when it has one element.
    fn eval_rows(&self, ti: &[f64], pi: &[f64], to: &[f64], po: &[f64], out: &mut [f64]) {
        match (self.bsdf.parts(), ti.len()) {
            ([(_, one)], 1) => one.eval_degrees_from(ti[0], pi[0], to, po, out),
            ([(_, one)], _) => one.eval_degrees(ti, pi, to, po, out),
            _ => {
                let fixed = direction(ti[0], pi[0]);
                for (k, rgb) in out.chunks_exact_mut(3).enumerate() {
                    let l = if ti.len() == 1 {
                        fixed
                    } else {
                        direction(ti[k], pi[k])
                    };
                    rgb.copy_from_slice(&self.bsdf.eval(l, direction(to[k], po[k])));
                }
            }
        }
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

/// Checks every incidence as `brtf eval` does.
fn check_incidences(ti: &[f64], pi: &[f64]) -> PyResult<()> {
    for (&t, &p) in ti.iter().zip(pi) {
        brtf_model::check_incidence(t, p).map_err(errors::option)?;
    }
    Ok(())
}

#[pymethods]
impl Material {
    #[new]
    #[pyo3(signature = (kind, rgb = None, spec = 0.0, roughness = None, trans = None, tspec = None,
        *, orientation = None, args = None, lobes = 1, oriented = false, variant = "radiance",
        fresnel_k = None, source_omega = 0.0, curved = false))]
    #[allow(clippy::too_many_arguments)]
    fn py_new(
        kind: &str,
        rgb: Option<&Bound<'_, PyAny>>,
        spec: f64,
        roughness: Option<&Bound<'_, PyAny>>,
        trans: Option<f64>,
        tspec: Option<f64>,
        orientation: Option<[f64; 3]>,
        args: Option<Vec<f64>>,
        lobes: usize,
        oriented: bool,
        variant: &str,
        fresnel_k: Option<&Bound<'_, PyAny>>,
        source_omega: f64,
        curved: bool,
    ) -> PyResult<Material> {
        let kind: MaterialKind = word("kind", kind)?;
        let shape = Shape::new(kind, lobes, oriented).map_err(errors::model)?;
        let options = eval_options(variant, fresnel_k, source_omega, curved)?;
        let args = match (args, rgb) {
            (Some(_), _)
                if rgb.is_some() || roughness.is_some() || trans.is_some() || tspec.is_some() =>
            {
                return Err(errors::model(
                    "give either args=[...] or rgb/spec/roughness/trans/tspec, not both",
                ));
            }
            (Some(args), _) => args,
            (None, _) if !shape.is_single() => {
                return Err(errors::model(format!(
                    "{}: give its arguments as args=[{}]",
                    shape.label(),
                    shape.param_names().join(", ")
                )));
            }
            (None, None) => return Err(errors::model(format!("{kind}: rgb= is needed"))),
            (None, Some(rgb)) => primitive_args(kind, rgb, spec, roughness, trans, tspec)?,
        };
        let composite = Material::build(shape, &args, orientation)?;
        Ok(Material::new(composite, &options, None))
    }

    /// Reads a material (a primitive, or a constant `mixfunc` tree of
    /// them) from Radiance `text`; `label` names it in messages.
    #[staticmethod]
    #[pyo3(signature = (text, label, name = None, variant = "radiance", fresnel_k = None,
        source_omega = 0.0, curved = false))]
    fn _from_text(
        text: &str,
        label: &str,
        name: Option<&str>,
        variant: &str,
        fresnel_k: Option<&Bound<'_, PyAny>>,
        source_omega: f64,
        curved: bool,
    ) -> PyResult<Material> {
        let options = eval_options(variant, fresnel_k, source_omega, curved)?;
        let primitives = brtf_radiance::parse_primitives(text, label).map_err(errors::rad)?;
        let (chosen, composite) =
            brtf_radiance::select_composite(&primitives, name, label).map_err(errors::rad)?;
        Ok(Material::new(composite, &options, Some(chosen)))
    }

    /// The primitives mixed, as `(weight, Material)`, weights summing to 1.
    #[getter]
    fn components(&self) -> Vec<(f64, Material)> {
        let options = self.bsdf.options();
        let parts = self.composite.components().iter();
        parts
            .map(|(w, m)| {
                (
                    *w,
                    Material::new(Composite::from_material(m), options, None),
                )
            })
            .collect()
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
        let size = np.call_method1("prod", (&incidence_shape,))?;
        // One incidence for every row, or one per row.
        let rows = if size.extract::<f64>()? == 1.0 {
            incidence_shape
        } else {
            shape.clone()
        };
        let (ti, pi) = (flat(&np, theta_in, &rows)?, flat(&np, phi_in, &rows)?);
        let (to, po) = (flat(&np, theta_out, &shape)?, flat(&np, phi_out, &shape)?);
        let (ti, pi, to, po) = (
            ti.as_slice()?,
            pi.as_slice()?,
            to.as_slice()?,
            po.as_slice()?,
        );
        check_incidences(ti, pi)?;
        for (&t, &p) in to.iter().zip(po) {
            brtf_model::check_outgoing(t, p).map_err(errors::option)?;
        }
        let mut out = vec![0.0; 3 * to.len()];
        if !to.is_empty() {
            py.detach(|| self.eval_rows(ti, pi, to, po, &mut out));
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
        check_incidences(&thetas, &vec![phi_in; thetas.len()])?;
        let results: Vec<brtf_model::Albedo> = py.detach(|| {
            let light = |t: f64| direction(t, phi_in);
            let albedo = |&t: &f64| brtf_model::composite_albedo(&self.bsdf, light(t), tolerance);
            thetas.iter().map(albedo).collect()
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

    /// The material as Radiance text: one primitive (`void metal NAME
    /// ...`), or a lobe sum's primitives `NAME.1` ... and the `mixfunc`
    /// tree named `NAME` last.
    #[pyo3(signature = (name = None))]
    fn to_rad(&self, name: Option<&str>) -> PyResult<String> {
        let name = name.or(self.name.as_deref()).unwrap_or("material");
        if brtf_radiance::identifier(name).as_deref() != Some(name) {
            return Err(errors::model(format!(
                "name {name:?}: not a Radiance identifier (letters, digits, _ - . only)"
            )));
        }
        let primitives = brtf_radiance::composite_primitives(&self.composite, name);
        Ok(primitives
            .iter()
            .map(brtf_radiance::format_primitive)
            .collect())
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
        let rows = if per_row { n } else { 1 };
        let (ti, pi) = (vec![theta_in; rows], vec![phi_in; rows]);
        let mut out = vec![0.0; 3 * n];
        py.detach(|| {
            let start = std::time::Instant::now();
            self.eval_rows(&ti, &pi, &theta_out[..n], &phi_out[..n], &mut out);
            std::hint::black_box(&out);
            start.elapsed().as_secs_f64()
        })
    }
}

/// Directional-hemispherical reflectance and transmittance, per channel
/// (last axis RGB): the diffuse and rough parts, and the mirror and
/// straight-through delta parts of roughness-0 surfaces.
#[pyclass(module = "brtf", frozen, get_all)]
pub(crate) struct Albedo {
    /// ρ_dh without the delta part.
    pub rho: Py<PyAny>,
    /// τ_dh without the delta part.
    pub tau: Py<PyAny>,
    /// Mirror delta reflectance.
    pub rho_spike: Py<PyAny>,
    /// Straight-through delta transmittance.
    pub tau_spike: Py<PyAny>,
}
