//! # brtf-radiance: Radiance scene text
//!
//! Reads and writes Radiance primitives (`modifier type identifier`, then
//! the string, integer and real argument lists), and converts the six
//! Ward-type material primitives to and from [`brtf_model::Material`], and
//! constant `mixfunc` trees of them (lobe sums) to and from
//! [`brtf_model::Composite`].
//! Errors carry the file and line: `file:line: message`.
//!
//! [`export`] writes a fit's Radiance materials: the static primitive, the
//! θ_in-dependent function material with its `.cal` file, and a preview
//! scene (`docs/radiance.md`).

mod composite;
pub mod export;
mod name;
mod primitive;

pub use composite::{
    MAX_MIXTURE_PARTS, composite_from_primitives, composite_primitives, select_composite,
};
pub use name::default_fit_name;

pub use primitive::{
    Primitive, RadError, format_primitive, identifier, material_from_primitive, parse_primitives,
    primitive_from_material, select_material,
};
