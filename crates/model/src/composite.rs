//! Lobe sums: materials made of Radiance primitives mixed with constant
//! coefficients, exactly as rtrace renders a `mixfunc` tree.
//!
//! A [`Shape`] says how a material is built: one Ward-type, `lobes`
//! specular lobes (1 to [`MAX_LOBES`], plastic and metal types only) over
//! one shared diffuse base, and whether the in-plane orientation of an
//! anisotropic type is one of its arguments. A [`Composite`] is a material
//! of a shape: its flat argument vector, in the order
//!
//! ```text
//! red green blue spec [split1 .. split(N-1)] (rough_k | rough_uk rough_vk)×N [trans tspec] [orient]
//! ```
//!
//! with one lobe named as the plain type names them (`rough`, `rough_u`,
//! `rough_v`), several numbered from 1.
//!
//! Lobe k is the primitive `type(red, green, blue, spec, rough_k…)`; the
//! lobes are mixed with weights from the splits by stick-breaking,
//! `w1 = s1`, `w2 = (1 − s1) s2`, …, `wN = Π (1 − s_j)`: the coefficients
//! of the nested `mixfunc` tree `mix(m1, mix(m2, … mN), s2), s1)`. rtrace
//! mixes linearly, so the material is `f = Σ w_k f_k`:
//! `C (1 − spec)/π + Σ w_k spec · lobe_k` for plastic (the lobe coloured
//! by C for metal): one diffuse base, lobe k carrying `w_k · spec`.
//!
//! `orient` is the angle ψ in degrees, in the surface plane from +x
//! towards +y, of the orientation vector `(cos ψ, sin ψ, 0)`.

use crate::bsdf::{Bsdf, Rgb};
use crate::kind::MaterialKind;
use crate::material::{Material, ModelError};
use crate::options::EvalOptions;
use glam::DVec3;

/// The most specular lobes of a lobe sum.
pub const MAX_LOBES: usize = 3;

/// Most flat arguments of any shape (three anisotropic lobes, oriented).
pub const MAX_SHAPE_ARGS: usize = 4 + (MAX_LOBES - 1) + 2 * MAX_LOBES + 1;

/// How a material is built from Radiance primitives.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Shape {
    /// The Radiance type of every lobe.
    pub kind: MaterialKind,
    /// Specular lobes over the shared diffuse base (1 to [`MAX_LOBES`]).
    pub lobes: usize,
    /// The in-plane orientation is an argument (`orient`, degrees).
    pub oriented: bool,
}

/// What one flat argument of a shape is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShapeArg {
    /// Colour channel 0, 1 or 2.
    Colour(usize),
    /// The specularity shared by every lobe.
    Spec,
    /// Stick-breaking split `j` (0-based) of the lobe weights.
    Split(usize),
    /// Roughness of lobe `k` along u (or the isotropic roughness).
    RoughU(usize),
    /// Roughness of lobe `k` along v.
    RoughV(usize),
    /// Transmissivity (trans types).
    Trans,
    /// Transmitted specular fraction (trans types).
    Tspec,
    /// The orientation angle ψ, degrees.
    Orient,
}

impl Shape {
    /// One primitive of `kind`, its orientation fixed.
    pub fn single(kind: MaterialKind) -> Shape {
        Shape {
            kind,
            lobes: 1,
            oriented: false,
        }
    }

    /// A shape, checked: lobe sums for plastic and metal types only, 1 to
    /// [`MAX_LOBES`] lobes, orientation only for anisotropic types.
    pub fn new(kind: MaterialKind, lobes: usize, oriented: bool) -> Result<Shape, String> {
        if !(1..=MAX_LOBES).contains(&lobes) {
            return Err(format!(
                "{lobes} lobes: a lobe sum has 1 to {MAX_LOBES} lobes"
            ));
        }
        if lobes > 1 && kind.is_transmitting() {
            return Err(format!(
                "{kind} has one lobe: lobe sums are for plastic, metal, plastic2 and metal2"
            ));
        }
        if oriented && !kind.is_anisotropic() {
            return Err(format!("{kind} is isotropic: it has no orientation to fit"));
        }
        Ok(Shape {
            kind,
            lobes,
            oriented,
        })
    }

    /// True for one primitive with a fixed orientation: the plain type.
    pub fn is_single(&self) -> bool {
        self.lobes == 1 && !self.oriented
    }

    /// Roughness arguments per lobe.
    fn rough_per_lobe(&self) -> usize {
        if self.kind.is_anisotropic() { 2 } else { 1 }
    }

    /// Every flat argument, in order.
    pub fn args(&self) -> Vec<ShapeArg> {
        let mut args: Vec<ShapeArg> = (0..3).map(ShapeArg::Colour).collect();
        args.push(ShapeArg::Spec);
        args.extend((0..self.lobes - 1).map(ShapeArg::Split));
        for k in 0..self.lobes {
            args.push(ShapeArg::RoughU(k));
            if self.kind.is_anisotropic() {
                args.push(ShapeArg::RoughV(k));
            }
        }
        if self.kind.is_transmitting() {
            args.extend([ShapeArg::Trans, ShapeArg::Tspec]);
        }
        if self.oriented {
            args.push(ShapeArg::Orient);
        }
        args
    }

    /// Number of flat arguments.
    pub fn n_args(&self) -> usize {
        4 + (self.lobes - 1)
            + self.lobes * self.rough_per_lobe()
            + if self.kind.is_transmitting() { 2 } else { 0 }
            + usize::from(self.oriented)
    }

    /// The flat arguments' names: the type's own for one lobe (`red`,
    /// `spec`, `rough`, …), lobe-numbered roughnesses and `split1`… for
    /// several, and `orient`.
    pub fn param_names(&self) -> Vec<String> {
        let numbered = self.lobes > 1;
        let lobe = |base: &str, k: usize| {
            if numbered {
                format!("{base}{}", k + 1)
            } else {
                base.to_string()
            }
        };
        self.args()
            .into_iter()
            .map(|a| match a {
                ShapeArg::Colour(c) => ["red", "green", "blue"][c].to_string(),
                ShapeArg::Spec => "spec".into(),
                ShapeArg::Split(j) => format!("split{}", j + 1),
                ShapeArg::RoughU(k) if self.kind.is_anisotropic() => lobe("rough_u", k),
                ShapeArg::RoughU(k) => lobe("rough", k),
                ShapeArg::RoughV(k) => lobe("rough_v", k),
                ShapeArg::Trans => "trans".into(),
                ShapeArg::Tspec => "tspec".into(),
                ShapeArg::Orient => "orient".into(),
            })
            .collect()
    }

    /// The index of flat argument `arg`.
    pub fn index_of(&self, arg: ShapeArg) -> Option<usize> {
        self.args().iter().position(|a| *a == arg)
    }

    /// A short label: `metal`, `metal ×2 lobes`, `plastic2 (orientation fitted)`.
    pub fn label(&self) -> String {
        let mut text = self.kind.name().to_string();
        if self.lobes > 1 {
            text += &format!(" ×{} lobes", self.lobes);
        }
        if self.oriented {
            text += " (orientation fitted)";
        }
        text
    }
}

impl std::fmt::Display for Shape {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.label())
    }
}

/// The stick-breaking weights of `splits` (each in [0, 1]): they sum to 1.
pub fn lobe_weights(splits: &[f64]) -> Vec<f64> {
    let mut rest = 1.0;
    let mut weights = Vec::with_capacity(splits.len() + 1);
    for &s in splits {
        weights.push(rest * s);
        rest *= 1.0 - s;
    }
    weights.push(rest);
    weights
}

/// The splits whose stick-breaking weights are `weights` (summing to 1):
/// the inverse of [`lobe_weights`].
pub fn lobe_splits(weights: &[f64]) -> Vec<f64> {
    let mut rest = 1.0;
    let mut splits = Vec::with_capacity(weights.len().saturating_sub(1));
    for &w in &weights[..weights.len().saturating_sub(1)] {
        let s = if rest > 0.0 {
            (w / rest).clamp(0.0, 1.0)
        } else {
            0.0
        };
        splits.push(s);
        rest *= 1.0 - s;
    }
    splits
}

/// The orientation vector of angle `degrees` in the surface plane.
pub fn orientation_of_angle(degrees: f64) -> DVec3 {
    let (s, c) = crate::sin_cos_degrees(degrees);
    DVec3::new(c, s, 0.0)
}

/// A material made of Radiance primitives mixed with constant weights: a
/// lobe sum of a [`Shape`], one primitive, or (read from a `.rad` file)
/// any constant `mixfunc` tree of Ward-type primitives.
#[derive(Debug, Clone, PartialEq)]
pub struct Composite {
    /// The shape and its flat arguments, when the material is one.
    shaped: Option<(Shape, Vec<f64>)>,
    /// The orientation vector of the anisotropic types (+x by default).
    orientation: DVec3,
    components: Vec<(f64, Material)>,
}

impl Composite {
    /// The material of `shape` with flat arguments `args`; `orientation`
    /// is the anisotropic types' vector when the shape does not fit it.
    pub fn new(
        shape: Shape,
        args: &[f64],
        orientation: Option<DVec3>,
    ) -> Result<Composite, ModelError> {
        let expected = shape.n_args();
        if args.len() != expected {
            return Err(ModelError::ArgCount {
                kind: shape.kind,
                expected,
                found: args.len(),
            });
        }
        if let Some(index) = args.iter().position(|a| !a.is_finite()) {
            return Err(ModelError::NonFinite { index });
        }
        let names = shape.args();
        let at = |a: ShapeArg| args[names.iter().position(|x| *x == a).expect("argument")];
        let splits: Vec<f64> = (0..shape.lobes - 1)
            .map(|j| at(ShapeArg::Split(j)))
            .collect();
        if splits.iter().any(|s| !(0.0..=1.0).contains(s)) {
            return Err(ModelError::BadSplit);
        }
        let orientation = if shape.oriented {
            orientation_of_angle(at(ShapeArg::Orient))
        } else {
            orientation.unwrap_or(DVec3::X)
        };
        let weights = lobe_weights(&splits);
        let mut components = Vec::with_capacity(shape.lobes);
        for (k, &w) in weights.iter().enumerate() {
            let mut primitive = vec![
                at(ShapeArg::Colour(0)),
                at(ShapeArg::Colour(1)),
                at(ShapeArg::Colour(2)),
                at(ShapeArg::Spec),
                at(ShapeArg::RoughU(k)),
            ];
            if shape.kind.is_anisotropic() {
                primitive.push(at(ShapeArg::RoughV(k)));
            }
            if shape.kind.is_transmitting() {
                primitive.extend([at(ShapeArg::Trans), at(ShapeArg::Tspec)]);
            }
            components.push((w, Material::new(shape.kind, &primitive, Some(orientation))?));
        }
        Ok(Composite {
            shaped: Some((shape, args.to_vec())),
            orientation,
            components,
        })
    }

    /// One primitive as a composite.
    pub fn from_material(material: &Material) -> Composite {
        Composite {
            shaped: Some((Shape::single(material.kind()), material.args().to_vec())),
            orientation: material.orientation(),
            components: vec![(1.0, *material)],
        }
    }

    /// Primitives mixed with `weights` (each in [0, 1], summing to 1), as a
    /// constant `mixfunc` tree gives them. Recognised as a lobe sum of a
    /// [`Shape`] when the primitives are of one plastic or metal type,
    /// share colour, specularity and orientation, and are ordered by
    /// roughness.
    pub fn mixture(parts: Vec<(f64, Material)>) -> Result<Composite, ModelError> {
        let sum: f64 = parts.iter().map(|(w, _)| w).sum();
        let valid = !parts.is_empty()
            && parts.iter().all(|(w, _)| (0.0..=1.0).contains(w))
            && (sum - 1.0).abs() <= 1e-9;
        if !valid {
            return Err(ModelError::BadSplit);
        }
        if let [(_, m)] = parts.as_slice() {
            return Ok(Composite::from_material(m));
        }
        let first = parts[0].1;
        let kind = first.kind();
        let shared = |m: &Material| {
            m.kind() == kind
                && m.args()[..4] == first.args()[..4]
                && m.orientation() == first.orientation()
        };
        let shaped = (parts.len() <= MAX_LOBES
            && !kind.is_transmitting()
            && parts.iter().all(|(_, m)| shared(m)))
        .then(|| {
            let shape = Shape {
                kind,
                lobes: parts.len(),
                oriented: false,
            };
            let weights: Vec<f64> = parts.iter().map(|(w, _)| *w).collect();
            let mut args = first.args()[..4].to_vec();
            args.extend(lobe_splits(&weights));
            for (_, m) in &parts {
                args.extend_from_slice(&m.args()[4..]);
            }
            (shape, args)
        });
        Ok(Composite {
            shaped,
            orientation: first.orientation(),
            components: parts,
        })
    }

    /// The lobes as `(weight, primitive)`, weights summing to 1, in
    /// argument order.
    pub fn components(&self) -> &[(f64, Material)] {
        &self.components
    }

    /// The one primitive of a one-lobe material.
    pub fn single(&self) -> Option<&Material> {
        match self.components.as_slice() {
            [(_, m)] => Some(m),
            _ => None,
        }
    }

    /// The shape, when the material is a lobe sum of one (or one primitive).
    pub fn shape(&self) -> Option<Shape> {
        self.shaped.as_ref().map(|(s, _)| *s)
    }

    /// The shape's flat arguments.
    pub fn args(&self) -> Option<&[f64]> {
        self.shaped.as_ref().map(|(_, a)| a.as_slice())
    }

    /// The material type of the first lobe (of every lobe, for a shape).
    pub fn kind(&self) -> MaterialKind {
        self.components[0].1.kind()
    }

    /// The orientation vector of the anisotropic types.
    pub fn orientation(&self) -> DVec3 {
        self.orientation
    }

    /// The same shape with other flat arguments (`None`: not a shape).
    pub fn with_args(&self, args: &[f64]) -> Option<Result<Composite, ModelError>> {
        let shape = self.shape()?;
        Some(Composite::new(shape, args, Some(self.orientation)))
    }
}

/// A [`Composite`] prepared for evaluation: `f = Σ w_k f_k`.
#[derive(Debug, Clone)]
pub struct CompositeBsdf {
    parts: Vec<(f64, Bsdf)>,
    options: EvalOptions,
}

impl CompositeBsdf {
    /// Prepares `material` for evaluation under `options`.
    pub fn new(material: &Composite, options: &EvalOptions) -> CompositeBsdf {
        CompositeBsdf {
            parts: material
                .components()
                .iter()
                .map(|(w, m)| (*w, Bsdf::new(m, options)))
                .collect(),
            options: *options,
        }
    }

    /// The lobes: `(weight, Bsdf)`.
    pub fn parts(&self) -> &[(f64, Bsdf)] {
        &self.parts
    }

    /// The options it was built with.
    pub fn options(&self) -> &EvalOptions {
        &self.options
    }

    /// The material type of the first lobe.
    pub fn kind(&self) -> MaterialKind {
        self.parts[0].1.kind()
    }

    /// True when some lobe has a transmitted part.
    pub fn is_transmitting(&self) -> bool {
        self.parts.iter().any(|(_, b)| b.kind().is_transmitting())
    }

    /// BSDF `f(l, v)` in 1/sr, without the cosine factor.
    pub fn eval(&self, l: DVec3, v: DVec3) -> Rgb {
        self.weighted(|b| b.eval(l, v))
    }

    /// The diffuse part of `f(l, v)` (see [`Bsdf::eval_diffuse`]).
    pub fn eval_diffuse(&self, l: DVec3, v: DVec3) -> Rgb {
        self.weighted(|b| b.eval_diffuse(l, v))
    }

    /// Mirror and straight-through delta coefficients (roughness-0 lobes).
    pub fn delta_coefficients(&self, light_cosine: f64) -> (Rgb, Rgb) {
        let mut mirror = [0.0; 3];
        let mut through = [0.0; 3];
        for (w, b) in &self.parts {
            let (m, t) = b.delta_coefficients(light_cosine);
            for c in 0..3 {
                mirror[c] += w * m[c];
                through[c] += w * t[c];
            }
        }
        (mirror, through)
    }

    /// [`Bsdf::eval_batch`] of the sum: `out` gets `Σ w_k f_k` of every
    /// pair (one lobe: that lobe's values as they are).
    pub fn eval_batch(
        &self,
        light: &crate::Directions,
        view: &crate::Directions,
        out: &mut crate::RgbBatch,
    ) {
        if let [(_, bsdf)] = self.parts.as_slice() {
            return bsdf.eval_batch(light, view, out);
        }
        let mut part = crate::RgbBatch::default();
        out.resize(light.len());
        for (w, bsdf) in &self.parts {
            bsdf.eval_batch(light, view, &mut part);
            out.add_scaled(*w, &part);
        }
    }

    fn weighted(&self, f: impl Fn(&Bsdf) -> Rgb) -> Rgb {
        let mut sum = [0.0; 3];
        for (w, b) in &self.parts {
            let v = f(b);
            for c in 0..3 {
                sum[c] += w * v[c];
            }
        }
        sum
    }
}

/// ρ_dh and τ_dh of a lobe sum: the weighted sum of its lobes' (the
/// integral is linear).
pub fn composite_albedo(bsdf: &CompositeBsdf, l: DVec3, tolerance: f64) -> crate::Albedo {
    let mut total: Option<crate::Albedo> = None;
    for (w, b) in bsdf.parts() {
        let a = crate::albedo(b, l, tolerance);
        let scaled = |x: Rgb| x.map(|v| v * w);
        total = Some(match total {
            None => crate::Albedo {
                rho: scaled(a.rho),
                tau: scaled(a.tau),
                rho_spike: scaled(a.rho_spike),
                tau_spike: scaled(a.tau_spike),
                ..a
            },
            Some(t) => {
                let add = |x: Rgb, y: Rgb| std::array::from_fn(|c| x[c] + w * y[c]);
                crate::Albedo {
                    rho: add(t.rho, a.rho),
                    tau: add(t.tau, a.tau),
                    rho_spike: add(t.rho_spike, a.rho_spike),
                    tau_spike: add(t.tau_spike, a.tau_spike),
                    error_estimate: t.error_estimate + w * a.error_estimate,
                    evaluations: t.evaluations + a.evaluations,
                }
            }
        });
    }
    total.expect("at least one lobe")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::direction;

    #[test]
    fn one_lobe_shapes_keep_the_type_s_arguments() {
        for kind in MaterialKind::ALL {
            let shape = Shape::single(kind);
            let names: Vec<&str> = kind.param_names().to_vec();
            assert_eq!(shape.param_names(), names, "{kind}");
            assert_eq!(shape.n_args(), kind.n_args());
        }
        let oriented = Shape::new(MaterialKind::Metal2, 1, true).unwrap();
        assert_eq!(oriented.param_names().last().unwrap(), "orient");
        let two = Shape::new(MaterialKind::Plastic2, 2, true).unwrap();
        assert_eq!(
            two.param_names(),
            [
                "red", "green", "blue", "spec", "split1", "rough_u1", "rough_v1", "rough_u2",
                "rough_v2", "orient"
            ]
        );
        assert_eq!(two.n_args(), 10);
        assert!(Shape::new(MaterialKind::Trans, 2, false).is_err());
        assert!(Shape::new(MaterialKind::Metal, 1, true).is_err());
        assert!(Shape::new(MaterialKind::Metal, 4, false).is_err());
    }

    #[test]
    fn weights_break_the_stick_and_back() {
        let w = lobe_weights(&[0.25, 0.5]);
        assert_eq!(w, vec![0.25, 0.375, 0.375]);
        let s = lobe_splits(&w);
        assert!((s[0] - 0.25).abs() < 1e-15 && (s[1] - 0.5).abs() < 1e-15);
        assert_eq!(lobe_weights(&[]), vec![1.0]);
    }

    #[test]
    fn a_lobe_sum_is_the_weighted_sum_of_its_primitives() {
        let shape = Shape::new(MaterialKind::Metal, 2, false).unwrap();
        // red green blue spec split1 rough1 rough2
        let m = Composite::new(shape, &[0.8, 0.7, 0.6, 0.5, 0.3, 0.05, 0.25], None).unwrap();
        let options = EvalOptions::default();
        let bsdf = CompositeBsdf::new(&m, &options);
        let a = Bsdf::new(
            &Material::new(MaterialKind::Metal, &[0.8, 0.7, 0.6, 0.5, 0.05], None).unwrap(),
            &options,
        );
        let b = Bsdf::new(
            &Material::new(MaterialKind::Metal, &[0.8, 0.7, 0.6, 0.5, 0.25], None).unwrap(),
            &options,
        );
        let l = direction(30.0, 0.0);
        for (t, p) in [(30.0, 180.0), (10.0, 90.0), (60.0, 170.0)] {
            let v = direction(t, p);
            let (fa, fb, f) = (a.eval(l, v), b.eval(l, v), bsdf.eval(l, v));
            for c in 0..3 {
                let expected = 0.3 * fa[c] + 0.7 * fb[c];
                assert!((f[c] - expected).abs() <= 1e-15 * expected.abs().max(1.0));
            }
        }
        // One diffuse base: C (1 − spec)/π however the specularity is split.
        let d = bsdf.eval_diffuse(l, direction(20.0, 40.0));
        assert!((d[0] - 0.8 * 0.5 / std::f64::consts::PI).abs() < 1e-15);
        // The same lobes as a mixture are recognised as the same shape.
        let parts = m.components().to_vec();
        let again = Composite::mixture(parts).unwrap();
        assert_eq!(again.shape(), Some(shape));
        let (x, y) = (again.args().unwrap(), m.args().unwrap());
        assert!(
            x.iter().zip(y).all(|(a, b)| (a - b).abs() < 1e-15),
            "{x:?} {y:?}"
        );
        // Weights that do not sum to 1 are refused.
        let bad = vec![(0.5, m.components()[0].1), (0.6, m.components()[1].1)];
        assert_eq!(Composite::mixture(bad), Err(ModelError::BadSplit));
    }

    #[test]
    fn the_orientation_angle_turns_the_tangent_frame() {
        let shape = Shape::new(MaterialKind::Plastic2, 1, true).unwrap();
        let m = Composite::new(shape, &[0.5, 0.5, 0.5, 0.05, 0.2, 0.05, 30.0], None).unwrap();
        let o = m.components()[0].1.orientation();
        assert!((o - DVec3::new(0.75f64.sqrt(), 0.5, 0.0)).length() < 1e-15);
        let fixed = Material::new(
            MaterialKind::Plastic2,
            &[0.5, 0.5, 0.5, 0.05, 0.2, 0.05],
            Some(o),
        )
        .unwrap();
        let options = EvalOptions::default();
        let (a, b) = (
            CompositeBsdf::new(&m, &options),
            Bsdf::new(&fixed, &options),
        );
        let (l, v) = (direction(40.0, 10.0), direction(35.0, 200.0));
        assert_eq!(a.eval(l, v), b.eval(l, v));
    }
}
