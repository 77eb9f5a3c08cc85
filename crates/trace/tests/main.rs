//! brtf-trace integration tests, one module per part of the tracer.
//!
//! * `shader`: the diffuse/specular split agrees with brtf-model's `f`;
//!   table shaders follow the fit table.
//! * `sampling`: chi² tests that every lobe sampler draws from its pdf.
//! * `gonio`: the virtual gonio-photometer against direct brtf-model
//!   evaluation (3σ, point-like apertures) and against the quadrature
//!   cone average (finite apertures).
//! * `furnace`: white furnace: rendered radiance = ρ_dh·L.
//! * `image`: determinism, HDR/PNG output, sphere lights.
//! * `scene_spec`: the picture scene of `brtf render image` (validation,
//!   Radiance text) and the gonio-photometer's grid and apertures.

mod common;
mod furnace;
mod gonio;
mod image;
mod sampling;
mod scene_spec;
mod shader;
