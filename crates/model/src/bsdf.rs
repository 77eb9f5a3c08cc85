//! The BSDF itself: `f(l, v)` in 1/sr (no cosine) and its analytic
//! gradient with respect to every real argument.
//!
//! [`Bsdf`] is a material prepared for evaluation: the per-material work
//! (tangent frame, lobe widening, Fresnel switch) is done once in
//! [`Bsdf::new`], so `eval` only does the per-direction work.
//!
//! Directions are unit vectors in the local frame (z = front normal),
//! both pointing away from the surface: `l` towards the light, `v`
//! towards the viewer. `v.z < 0` is the back side; like rtrace, the
//! surface is turned towards the viewer, so every material is two-sided.

#![allow(clippy::needless_range_loop)] // channel loops index several arrays at once

use crate::kind::{ArgLayout, MaterialKind, Variant};
use crate::material::{FTINY, MAX_ARGS, Material};
use crate::options::EvalOptions;
use glam::DVec3;
use std::f64::consts::PI;

/// RGB BSDF value in 1/sr.
pub type Rgb = [f64; 3];

/// Rtrace's Fresnel switch: only surfaces with at least this specularity
/// get the roughness-0 Fresnel estimate (FRESTHRESH).
const FRESNEL_THRESHOLD: f64 = 0.017999;

/// rtrace clamps the view cosine to at least this (`pdot >= .001`).
const MIN_VIEW_COSINE: f64 = 0.001;

/// ∂f/∂a for every real argument a: `d[arg][channel]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gradient {
    /// `d[j][c]` = ∂f_c / ∂(argument j).
    pub d: [Rgb; MAX_ARGS],
}

impl Default for Gradient {
    fn default() -> Self {
        Gradient {
            d: [[0.0; 3]; MAX_ARGS],
        }
    }
}

/// A material prepared for evaluation with fixed options.
#[derive(Debug, Clone, Copy)]
pub struct Bsdf {
    material: Material,
    options: EvalOptions,
    layout: ArgLayout,
    color: Rgb,
    spec: f64,
    trans: f64,
    tspec: f64,
    /// Squared roughness along û and v̂ (equal for isotropic types).
    alpha2_u: f64,
    alpha2_v: f64,
    /// ∂(alpha2_u)/∂a_u, ∂(alpha2_u)/∂a_v, ∂(alpha2_v)/∂a_u, ∂(alpha2_v)/∂a_v.
    dalpha2: [[f64; 2]; 2],
    /// 1/(α² + widening) of the reflected lobe along û and v̂.
    reflect_inv_width: (f64, f64),
    /// Added to α² for the transmitted lobe (`ω/π`).
    transmit_widening: f64,
    /// Roughness 0: no specular lobe in the direct term.
    pure: bool,
    /// The roughness-0 Fresnel estimate applies (radiance variant).
    fresnel: bool,
    anisotropic: bool,
    metal: bool,
    /// `trans` or `trans2`: light from behind can reach the viewer.
    transmitting: bool,
    frame_u: DVec3,
    frame_v: DVec3,
}

/// The split of [`Bsdf::view_split`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewSplit {
    /// Specularity after the view-side Fresnel estimate.
    pub spec: f64,
    /// Transmitted fraction `a_t (1 − spec)`.
    pub transmitted: f64,
    /// Diffuse reflection fraction `1 − transmitted − spec`.
    pub diffuse: f64,
}

/// What the view direction alone fixes: the effective specularity and the
/// split into diffuse reflection, diffuse and specular transmission.
#[derive(Debug, Clone, Copy)]
struct ViewCoefficients {
    /// Specularity after the view-side Fresnel estimate.
    spec: f64,
    /// ∂spec/∂a4.
    dspec: f64,
    /// Transmitted fraction `a_t (1 - spec)`.
    transmitted: f64,
    /// Diffuse reflection fraction `1 - T - spec`.
    diffuse: f64,
}

/// What `f(l, v)` takes from the two directions alone: everything that
/// does not depend on the material's arguments. Made by
/// [`Bsdf::geometry`] and valid for every [`Bsdf`] of the same type,
/// orientation and options, so a fitter can compute it once per sample
/// and evaluate many parameter sets with [`Bsdf::eval_geometry`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Geometry {
    /// cos θ of the light once the surface faces the viewer: > 0 reflection,
    /// < 0 transmission.
    pub(crate) light_cosine: f64,
    /// cos θ of the viewer, clamped as rtrace does.
    pub(crate) view_cosine: f64,
    /// The lobe's normalisation (reflection) or geometry factor (transmission).
    pub(crate) lobe_factor: f64,
    /// Exponent numerators along û and v̂ (isotropic types use `x_u` only).
    pub(crate) x_u: f64,
    pub(crate) x_v: f64,
    /// Anisotropic transmission: `sqrt(|cos θ_l| / cos θ_v)` for rtrace's cut-off.
    pub(crate) cutoff_factor: f64,
}

impl Bsdf {
    /// Prepares `material` for evaluation under `options`.
    pub fn new(material: &Material, options: &EvalOptions) -> Bsdf {
        let kind = material.kind();
        let layout = kind.layout();
        let args = material.args();
        let variant = options.variant;
        let omega = options.source_omega.max(0.0);
        let reflect_widening = match variant {
            Variant::Radiance if options.flat => (1.0 - options.source_jitter) * omega / (4.0 * PI),
            Variant::Radiance => 0.0,
            Variant::Manual2004 => omega / (4.0 * PI),
            Variant::Ward1992 if options.flat => omega / (4.0 * PI),
            Variant::Ward1992 => 0.0,
        };
        let alpha_u = args[layout.rough_u];
        let mut alpha2_u = alpha_u * alpha_u;
        let mut alpha2_v = alpha2_u;
        let mut dalpha2 = [[2.0 * alpha_u, 0.0], [2.0 * alpha_u, 0.0]];
        let (mut frame_u, mut frame_v) = (DVec3::X, DVec3::Y);
        if let Some(iv) = layout.rough_v {
            let alpha_v = args[iv];
            alpha2_v = alpha_v * alpha_v;
            dalpha2 = [[2.0 * alpha_u, 0.0], [0.0, 2.0 * alpha_v]];
            let orient = material.orientation();
            let cross = DVec3::Z.cross(orient);
            if cross.length_squared() > 0.0 {
                frame_v = cross.normalize();
                frame_u = frame_v.cross(DVec3::Z);
            } else {
                // rtrace: orientation along the normal gives an arbitrary
                // tangent frame and the mean squared roughness on both axes.
                let mean = 0.5 * (alpha2_u + alpha2_v);
                alpha2_u = mean;
                alpha2_v = mean;
                dalpha2 = [[alpha_u, alpha_v], [alpha_u, alpha_v]];
            }
        }
        let anisotropic = kind.is_anisotropic();
        let pure = !anisotropic && alpha2_u <= FTINY;
        let spec = args[3];
        Bsdf {
            material: *material,
            options: *options,
            layout,
            color: material.color(),
            spec,
            trans: layout.trans.map_or(0.0, |i| args[i]),
            tspec: layout.tspec.map_or(0.0, |i| args[i]),
            alpha2_u,
            alpha2_v,
            dalpha2,
            reflect_inv_width: (
                1.0 / (alpha2_u + reflect_widening),
                1.0 / (alpha2_v + reflect_widening),
            ),
            transmit_widening: omega / PI,
            pure,
            fresnel: variant == Variant::Radiance && pure && spec >= FRESNEL_THRESHOLD,
            anisotropic,
            metal: kind.is_metal(),
            transmitting: kind.is_transmitting(),
            frame_u,
            frame_v,
        }
    }

    /// The material this was built from.
    pub fn material(&self) -> &Material {
        &self.material
    }

    /// The options this was built with.
    pub fn options(&self) -> &EvalOptions {
        &self.options
    }

    /// The material type.
    pub fn kind(&self) -> MaterialKind {
        self.material.kind()
    }

    /// True for roughness-0 isotropic surfaces, whose specular part is a
    /// delta (mirror / straight-through) and not in the direct term.
    pub fn is_pure(&self) -> bool {
        self.pure
    }

    /// The tangent frame (û, v̂) of the anisotropic types.
    pub fn tangent_frame(&self) -> (DVec3, DVec3) {
        (self.frame_u, self.frame_v)
    }

    /// The specularity argument (before any Fresnel estimate).
    pub(crate) fn spec_arg(&self) -> f64 {
        self.spec
    }

    /// The transmissivity argument (0 for the opaque types).
    pub(crate) fn trans_arg(&self) -> f64 {
        self.trans
    }

    /// The transmitted-specular fraction (0 for the opaque types).
    pub(crate) fn tspec_arg(&self) -> f64 {
        self.tspec
    }

    /// The roughness-0 Fresnel estimate applies.
    pub(crate) fn has_fresnel(&self) -> bool {
        self.fresnel
    }

    /// 1/(α² + widening) of the reflected lobe along û and v̂.
    pub(crate) fn reflect_inv_width(&self) -> (f64, f64) {
        self.reflect_inv_width
    }

    /// ∂(α²_u, α²_v)/∂(a_u, a_v): `[[∂α²_u/∂a_u, ∂α²_u/∂a_v], [∂α²_v/∂a_u, ∂α²_v/∂a_v]]`.
    pub(crate) fn width_derivatives(&self) -> [[f64; 2]; 2] {
        self.dalpha2
    }

    /// α² + ω/π of the transmitted lobe along û and v̂.
    pub(crate) fn transmit_width(&self) -> (f64, f64) {
        (
            self.alpha2_u + self.transmit_widening,
            self.alpha2_v + self.transmit_widening,
        )
    }

    /// Rtrace's Fresnel estimate `exp(-5.85 c) - K`.
    pub fn fresnel_estimate(&self, cosine: f64) -> f64 {
        (-5.85 * cosine).exp() - self.options.fresnel_k
    }

    /// BSDF `f(l, v)` in 1/sr, without the cosine factor.
    #[inline]
    pub fn eval(&self, l: DVec3, v: DVec3) -> Rgb {
        let mut unused = Gradient::default();
        self.eval_impl::<false, 3, true>(&self.geometry(l, v), &mut unused)
    }

    /// BSDF and its gradient with respect to every real argument.
    /// Entries beyond the type's argument count are left at 0.
    #[inline]
    pub fn eval_with_gradient(&self, l: DVec3, v: DVec3, grad: &mut Gradient) -> Rgb {
        *grad = Gradient::default();
        self.eval_impl::<true, 3, true>(&self.geometry(l, v), grad)
    }

    /// The diffuse part of `f(l, v)`: `C R_d/π` in front (`C T_d/π`
    /// behind), with the Fresnel and variant details of [`Bsdf::eval`]; the
    /// rest of `f` is the specular lobes. A renderer that traces the
    /// specular rays and the diffuse ambient separately needs the split.
    #[inline]
    pub fn eval_diffuse(&self, l: DVec3, v: DVec3) -> Rgb {
        let mut unused = Gradient::default();
        self.eval_impl::<false, 3, false>(&self.geometry(l, v), &mut unused)
    }

    /// How light leaving towards a view at cosine `view_cosine` divides
    /// between the specular, transmitted and diffuse-reflected parts (the
    /// cosine is clamped as rtrace does).
    pub fn view_split(&self, view_cosine: f64) -> ViewSplit {
        let v = self.view_coefficients(view_cosine.max(MIN_VIEW_COSINE));
        ViewSplit {
            spec: v.spec,
            transmitted: v.transmitted,
            diffuse: v.diffuse,
        }
    }

    /// The argument-free part of `f(l, v)`; see [`Geometry`].
    #[inline(always)]
    pub fn geometry(&self, l: DVec3, v: DVec3) -> Geometry {
        // Turn the surface towards the viewer.
        let (l, v) = if v.z < 0.0 {
            (DVec3::new(l.x, l.y, -l.z), DVec3::new(v.x, v.y, -v.z))
        } else {
            (l, v)
        };
        let mut g = Geometry {
            light_cosine: l.z,
            view_cosine: v.z.max(MIN_VIEW_COSINE),
            ..Geometry::default()
        };
        if g.light_cosine > FTINY {
            self.reflection_geometry(l, v, &mut g);
        } else if g.light_cosine < -FTINY && self.transmitting {
            // Opaque types return 0 here whatever their arguments.
            self.transmission_geometry(l, v, &mut g);
        }
        g
    }

    /// `f` for directions prepared by [`Bsdf::geometry`] (of this or any
    /// `Bsdf` with the same type, orientation and options).
    #[inline]
    pub fn eval_geometry(&self, g: &Geometry) -> Rgb {
        let mut unused = Gradient::default();
        self.eval_impl::<false, 3, true>(g, &mut unused)
    }

    /// `f` and its gradient for directions prepared by [`Bsdf::geometry`].
    #[inline]
    pub fn eval_geometry_with_gradient(&self, g: &Geometry, grad: &mut Gradient) -> Rgb {
        *grad = Gradient::default();
        self.eval_impl::<true, 3, true>(g, grad)
    }

    /// Like [`Bsdf::eval_geometry_with_gradient`] for the first `CH`
    /// channels only: the other channels' values are returned as 0 and
    /// their entries in `grad` are not touched. A grey or single-channel
    /// fit needs channel 0 alone, at a fraction of the work.
    #[inline(always)]
    pub fn eval_geometry_channels_with_gradient<const CH: usize>(
        &self,
        g: &Geometry,
        grad: &mut Gradient,
    ) -> Rgb {
        for d in &mut grad.d {
            d[..CH].fill(0.0);
        }
        self.eval_impl::<true, CH, true>(g, grad)
    }

    fn view_coefficients(&self, view_cosine: f64) -> ViewCoefficients {
        let (spec, dspec) = if self.fresnel {
            let f = self.fresnel_estimate(view_cosine);
            (self.spec + f * (1.0 - self.spec), 1.0 - f)
        } else if self.options.variant == Variant::Ward1992 && !self.metal {
            let e = (-6.0 * view_cosine).exp();
            (self.spec + e * (1.0 - self.spec), 1.0 - e)
        } else {
            (self.spec, 1.0)
        };
        let transmitted = self.trans * (1.0 - spec);
        ViewCoefficients {
            spec,
            dspec,
            transmitted,
            diffuse: 1.0 - transmitted - spec,
        }
    }

    /// The specular mirror and straight-through delta coefficients of a
    /// roughness-0 surface for light at cosine `light_cosine` (> 0),
    /// as RGB reflectance and transmittance: `(mirror, through)`.
    /// Zero for rough surfaces.
    pub fn delta_coefficients(&self, light_cosine: f64) -> (Rgb, Rgb) {
        if !self.pure {
            return ([0.0; 3], [0.0; 3]);
        }
        // The mirror and through rays leave at the light's own cosine.
        let view = self.view_coefficients(light_cosine.max(MIN_VIEW_COSINE));
        let mut mirror = [view.spec; 3];
        if self.metal {
            let f = if self.fresnel {
                self.fresnel_estimate(light_cosine.max(MIN_VIEW_COSINE))
            } else {
                0.0
            };
            for (c, m) in mirror.iter_mut().enumerate() {
                *m = if f > FTINY {
                    f + self.color[c] * self.spec * (1.0 - f)
                } else {
                    self.color[c] * self.spec
                };
            }
        }
        let ts = view.transmitted * self.tspec;
        let through = self.color.map(|c| c * ts);
        (mirror, through)
    }

    #[inline(always)]
    fn eval_impl<const GRAD: bool, const CH: usize, const SPECULAR: bool>(
        &self,
        g: &Geometry,
        grad: &mut Gradient,
    ) -> Rgb {
        let view_cosine = g.view_cosine;
        let light_cosine = g.light_cosine;
        let view = self.view_coefficients(view_cosine);
        let t = view.transmitted;
        let wrong_side = if light_cosine < 0.0 {
            t <= FTINY
        } else {
            t >= 1.0 - FTINY
        };
        let mut f = [0.0; 3];
        if wrong_side {
            return f;
        }
        let ts = t * self.tspec;
        let td = t - ts;
        let rd = view.diffuse;
        let light_fresnel = if self.fresnel && (rd > FTINY || td > FTINY) {
            1.0 - self.fresnel_estimate(light_cosine.abs())
        } else {
            1.0
        };
        let lay = self.layout;
        let c = self.color;
        if light_cosine > FTINY {
            self.add_reflection::<GRAD, CH, SPECULAR>(g, &view, light_fresnel, &mut f, grad);
        } else if light_cosine < -FTINY {
            // Diffuse transmission C·Td/π.
            // (td > 0 only for the transmitting types, which have both indices.)
            if let (true, Some(it), Some(is)) = (td > FTINY, lay.trans, lay.tspec) {
                let k = td * light_fresnel / PI;
                for ch in 0..CH {
                    f[ch] += c[ch] * k;
                }
                if GRAD {
                    let g = light_fresnel / PI;
                    for ch in 0..CH {
                        grad.d[ch][ch] += k;
                        grad.d[3][ch] +=
                            c[ch] * g * (-self.trans * (1.0 - self.tspec) * view.dspec);
                        grad.d[it][ch] += c[ch] * g * (1.0 - view.spec) * (1.0 - self.tspec);
                        grad.d[is][ch] += c[ch] * g * (-self.trans * (1.0 - view.spec));
                    }
                }
            }
            if SPECULAR && !self.pure && ts > FTINY {
                self.add_transmission::<GRAD, CH>(g, &view, ts, &mut f, grad);
            }
        }
        f
    }

    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn add_reflection<const GRAD: bool, const CH: usize, const SPECULAR: bool>(
        &self,
        g: &Geometry,
        view: &ViewCoefficients,
        light_fresnel: f64,
        f: &mut Rgb,
        grad: &mut Gradient,
    ) {
        let c = self.color;
        let lay = self.layout;
        let ward_metal = self.metal && self.options.variant == Variant::Ward1992;
        // Ward 1992 metal: the Fresnel estimate acts on each channel's
        // coloured specularity, and diffuse is C (1 - that).
        let ward_e = if ward_metal {
            (-6.0 * g.view_cosine).exp()
        } else {
            0.0
        };
        // Diffuse reflection C·Rd/π.
        if ward_metal {
            for ch in 0..CH {
                let s = c[ch] * self.spec + (1.0 - c[ch] * self.spec) * ward_e;
                f[ch] += c[ch] * (1.0 - s) / PI;
                if GRAD {
                    grad.d[ch][ch] += ((1.0 - s) - c[ch] * self.spec * (1.0 - ward_e)) / PI;
                    grad.d[3][ch] += -c[ch] * c[ch] * (1.0 - ward_e) / PI;
                }
            }
        } else if view.diffuse > FTINY {
            let k = view.diffuse * light_fresnel / PI;
            for ch in 0..CH {
                f[ch] += c[ch] * k;
            }
            if GRAD {
                let g = light_fresnel / PI;
                for ch in 0..CH {
                    grad.d[ch][ch] += k;
                    grad.d[3][ch] += c[ch] * g * (-(1.0 - self.trans) * view.dspec);
                    if let Some(it) = lay.trans {
                        grad.d[it][ch] += c[ch] * g * (-(1.0 - view.spec));
                    }
                }
            }
        }
        let spec_on = if ward_metal {
            self.spec > FTINY
        } else {
            view.spec > FTINY
        };
        if !SPECULAR || self.pure || !spec_on {
            return;
        }
        let lobe = self.reflection_lobe(g);
        if !lobe.passes_cutoff {
            return;
        }
        for ch in 0..CH {
            let (s, ds_dc, ds_drs) = if ward_metal {
                (
                    c[ch] * self.spec + (1.0 - c[ch] * self.spec) * ward_e,
                    self.spec * (1.0 - ward_e),
                    c[ch] * (1.0 - ward_e),
                )
            } else if self.metal {
                (c[ch] * self.spec, self.spec, c[ch])
            } else {
                (view.spec, 0.0, view.dspec)
            };
            f[ch] += s * lobe.value;
            if GRAD {
                grad.d[ch][ch] += ds_dc * lobe.value;
                grad.d[3][ch] += ds_drs * lobe.value;
                self.add_roughness_gradient(grad, ch, s, lobe.d_width_u, lobe.d_width_v);
            }
        }
    }

    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn add_transmission<const GRAD: bool, const CH: usize>(
        &self,
        g: &Geometry,
        view: &ViewCoefficients,
        ts: f64,
        f: &mut Rgb,
        grad: &mut Gradient,
    ) {
        let lobe = self.transmission_lobe(g);
        if !lobe.passes_cutoff {
            return;
        }
        let c = self.color;
        for ch in 0..CH {
            f[ch] += c[ch] * ts * lobe.value;
        }
        if let (true, Some(it), Some(is)) = (GRAD, self.layout.trans, self.layout.tspec) {
            for ch in 0..CH {
                grad.d[ch][ch] += ts * lobe.value;
                grad.d[3][ch] += c[ch] * (-self.trans * self.tspec * view.dspec) * lobe.value;
                grad.d[it][ch] += c[ch] * self.tspec * (1.0 - view.spec) * lobe.value;
                grad.d[is][ch] += c[ch] * self.trans * (1.0 - view.spec) * lobe.value;
                self.add_roughness_gradient(grad, ch, c[ch] * ts, lobe.d_width_u, lobe.d_width_v);
            }
        }
    }

    /// Chain rule from the lobe widths (α² + widening) to the roughness arguments.
    #[inline(always)]
    fn add_roughness_gradient(&self, grad: &mut Gradient, ch: usize, coef: f64, du: f64, dv: f64) {
        let iu = self.layout.rough_u;
        grad.d[iu][ch] += coef * (du * self.dalpha2[0][0] + dv * self.dalpha2[1][0]);
        if let Some(iv) = self.layout.rough_v {
            grad.d[iv][ch] += coef * (du * self.dalpha2[0][1] + dv * self.dalpha2[1][1]);
        }
    }

    /// The reflected lobe's direction factors: normalisation and exponent
    /// numerators (`ci`, `co`: light and view cosines).
    #[inline(always)]
    fn reflection_geometry(&self, l: DVec3, v: DVec3, g: &mut Geometry) {
        let (ci, co) = (g.light_cosine, g.view_cosine);
        let h = l + v;
        let hn = h.z;
        let hh = h.dot(h);
        let inv_hn2 = 1.0 / (hn * hn);
        let variant = self.options.variant;
        g.lobe_factor = match variant {
            Variant::Radiance => hh * inv_hn2 * inv_hn2 * (1.0 / PI),
            Variant::Manual2004 => 1.0 / (4.0 * PI * ci * co),
            Variant::Ward1992 => 1.0 / (4.0 * PI * (ci * co).sqrt()),
        };
        if !self.anisotropic {
            g.x_u = match variant {
                Variant::Ward1992 => 2.0 - 2.0 * hn / hh.sqrt(),
                // tan²θ_h
                _ => hh * inv_hn2 - 1.0,
            };
            return;
        }
        let hu = h.dot(self.frame_u);
        let hv = h.dot(self.frame_v);
        let scale = match variant {
            // Seed 000: exponent -2[(ĥ·x)²/αx + (ĥ·y)²/αy]/(1 + ĥ·n), ĥ unit.
            Variant::Ward1992 => 2.0 / (hh * (1.0 + hn / hh.sqrt())),
            _ => inv_hn2,
        };
        g.x_u = hu * hu * scale;
        g.x_v = hv * hv * scale;
    }

    /// The transmitted lobe's direction factors.
    #[inline(always)]
    fn transmission_geometry(&self, l: DVec3, v: DVec3, g: &mut Geometry) {
        let (ci, co) = (-g.light_cosine, g.view_cosine);
        g.lobe_factor = match self.options.variant {
            Variant::Manual2004 => 1.0 / (ci * co),
            _ => 1.0 / (ci * co).sqrt(),
        };
        if !self.anisotropic {
            // 2 - 2 t·l with t = -v.
            g.x_u = 2.0 + 2.0 * v.dot(l);
            return;
        }
        let c = l + v;
        let cc = c.dot(c);
        let s2 = if cc > FTINY * FTINY {
            1.0 - c.z * c.z / cc
        } else {
            cc
        };
        if s2 > FTINY * FTINY {
            let cu = c.dot(self.frame_u);
            let cv = c.dot(self.frame_v);
            g.x_u = cu * cu / s2;
            g.x_v = cv * cv / s2;
        }
        g.cutoff_factor = (ci / co).sqrt();
    }

    /// The reflected lobe (specularity not included) and its derivatives
    /// with respect to the squared widths along û and v̂.
    #[inline(always)]
    fn reflection_lobe(&self, g: &Geometry) -> Lobe {
        let cutoff = self.options.variant == Variant::Radiance;
        if !self.anisotropic {
            let inv_w = self.reflect_inv_width.0;
            let x = g.x_u;
            let value = g.lobe_factor * (-x * inv_w).exp() * inv_w;
            return Lobe {
                value,
                d_width_u: value * (x * inv_w - 1.0) * inv_w,
                d_width_v: 0.0,
                passes_cutoff: !cutoff || value > FTINY,
            };
        }
        let (inv_wu, inv_wv) = self.reflect_inv_width;
        let (xu, xv) = (g.x_u, g.x_v);
        let value = g.lobe_factor * (-(xu * inv_wu + xv * inv_wv)).exp() * (inv_wu * inv_wv).sqrt();
        Lobe {
            value,
            d_width_u: value * (xu * inv_wu - 0.5) * inv_wu,
            d_width_v: value * (xv * inv_wv - 0.5) * inv_wv,
            passes_cutoff: !cutoff || value > FTINY,
        }
    }

    /// The transmitted lobe (C·Ts not included).
    #[inline(always)]
    fn transmission_lobe(&self, g: &Geometry) -> Lobe {
        let bu = self.alpha2_u + self.transmit_widening;
        let bv = self.alpha2_v + self.transmit_widening;
        let radiance = self.options.variant == Variant::Radiance;
        if !self.anisotropic {
            let x = g.x_u;
            let lobe = (-x / bu).exp() / (PI * bu);
            let value = lobe * g.lobe_factor;
            return Lobe {
                value,
                d_width_u: value * (x / bu - 1.0) / bu,
                d_width_v: 0.0,
                passes_cutoff: !radiance || lobe > FTINY,
            };
        }
        let (xu, xv) = (g.x_u, g.x_v);
        let e = (-(xu / bu + xv / bv)).exp();
        let root = (bu * bv).sqrt();
        let value = e * g.lobe_factor / (PI * root);
        // rtrace applies its cut-off after multiplying by sqrt(|ci|/co).
        let cutoff_value = e * g.cutoff_factor / (PI * root);
        Lobe {
            value,
            d_width_u: value * (xu / bu - 0.5) / bu,
            d_width_v: value * (xv / bv - 0.5) / bv,
            passes_cutoff: !radiance || cutoff_value > FTINY,
        }
    }
}

/// A specular lobe's value and its derivatives with respect to the squared
/// lobe widths.
#[derive(Debug, Clone, Copy)]
struct Lobe {
    value: f64,
    d_width_u: f64,
    d_width_v: f64,
    passes_cutoff: bool,
}

impl Bsdf {
    /// `out[3 i .. 3 i + 3]` = the BSDF (1/sr, RGB) for light from
    /// (`theta_in[i]`, `phi_in[i]`) seen from (`theta_out[i]`,
    /// `phi_out[i]`), all in degrees, as `brtf eval` computes it. All
    /// slices have the same length; `out` is three times as long.
    pub fn eval_degrees(
        &self,
        theta_in: &[f64],
        phi_in: &[f64],
        theta_out: &[f64],
        phi_out: &[f64],
        out: &mut [f64],
    ) {
        let rows = theta_in
            .iter()
            .zip(phi_in)
            .zip(theta_out.iter().zip(phi_out));
        for (((ti, pi), (to, po)), rgb) in rows.zip(out.chunks_exact_mut(3)) {
            let (l, v) = (crate::direction(*ti, *pi), crate::direction(*to, *po));
            rgb.copy_from_slice(&self.eval(l, v));
        }
    }

    /// [`Bsdf::eval_degrees`] for one incidence and many outgoing
    /// directions: the light direction is computed once.
    pub fn eval_degrees_from(
        &self,
        theta_in: f64,
        phi_in: f64,
        theta_out: &[f64],
        phi_out: &[f64],
        out: &mut [f64],
    ) {
        let l = crate::direction(theta_in, phi_in);
        for ((to, po), rgb) in theta_out.iter().zip(phi_out).zip(out.chunks_exact_mut(3)) {
            rgb.copy_from_slice(&self.eval(l, crate::direction(*to, *po)));
        }
    }
}
