//! # brtf-trace: a minimal ray tracer that checks fitted materials
//!
//! A fitted material is only as good as what a renderer makes of it. This
//! crate renders brtf-model materials the way Radiance's lighting equation
//! (equation (1) of "Behavior of Materials in RADIANCE") prescribes, in
//! two instruments:
//!
//! * the **virtual gonio-photometer** ([`VirtualGonio`]): a flat sample, a beam of
//!   finite solid angle at (θ_in, φ_in) and a detector with an aperture at
//!   every measured (θ_out, φ_out); it returns the rendered BSDF per
//!   sample as a [`brtf_gonio::Measurement`];
//! * **pictures** ([`render`]): the material on a sphere and a plane under a
//!   source, through a pinhole camera with Radiance's view parameters,
//!   written as Radiance HDR ([`hdr`]) and tone-mapped PNG; the picture
//!   scene of `brtf render image` is a [`SceneSpec`],
//!   which also writes itself as Radiance text for `rpict`.
//!
//! ## Equation (1), as traced here
//!
//! `R = Σ_i ∫_{Ω_i} f(q, v) L_i |q·n| dω + ∫ f_s(q, v) R(q) |q·n| dω + ∫ f_d(q, v) R(q) |q·n| dω`
//!
//! * the direct term samples each source uniformly over its solid angle
//!   `Ω_i` with the whole BSDF `f` (brtf-model, evaluated for a point
//!   source: the source's extent is integrated, not modelled by widening);
//! * the specular part `f_s = f − f_d` is integrated with rays
//!   importance-sampled from the Gaussian lobes ([`ReflectionLobe`],
//!   [`TransmissionLobe`]; a lobe sum's lobes as a [`Mixture`]);
//!   roughness-0 surfaces trace their mirror and straight-through rays;
//! * the diffuse part `f_d` optionally gets one bounce.
//!
//! A material is a [`brtf_model::Composite`]: one Radiance primitive, or
//! a lobe sum mixed with constant weights, rendered as rtrace renders a
//! constant `mixfunc` tree, every term the weighted sum of the lobes'.
//!
//! ## Conventions
//!
//! As in every brtf crate: `f(l, v)` in 1/sr **without** the cosine,
//! local frame z = normal, `l` and `v` pointing away from the surface,
//! two-sided materials (the surface turns towards the viewer), degrees at
//! interfaces and radians inside. Every random number comes from a
//! stream seeded by `(seed, pixel or direction index)`, so results are
//! deterministic and independent of the thread count.

mod camera;
mod check;
mod direct;
mod frame;
mod gonio;
pub mod hdr;
mod image;
mod integrator;
mod sampling;
mod scene;
mod scene_spec;
mod shader;

pub use camera::Camera;
pub use check::{
    ApertureOrigin, CheckError, CheckOptions, CheckReport, DEFAULT_DETECTOR_APERTURE_DEG,
    DEFAULT_SOURCE_APERTURE_DEG, check_fit,
};
pub use frame::Frame;
pub use gonio::{
    Aperture, GonioError, GonioSetup, GonioValue, VirtualGonio, aperture_solid_angle, cone_average,
    grid, measurement_from,
};
pub use image::{Rendered, auto_exposure, render, write_png};
pub use integrator::{ImageOptions, RayCounts, Settings, Tracer};
pub use sampling::{
    DirectionSampler, LobeMix, Mixture, ReflectionLobe, TransmissionLobe, cosine_hemisphere,
    cosine_hemisphere_pdf, one_minus_cos, uniform_cone, uniform_cone_pdf,
};
pub use scene::{Ray, Scene, Shape, Source};
pub use scene_spec::{
    BALL_CENTER, FLOOR_RADIUS, LightKind, LightSpec, MATERIAL_NAME, SceneKind, SceneSpec,
    SceneSpecError, ViewSpec,
};
pub use shader::{Lobes, Shader, ShaderError};
