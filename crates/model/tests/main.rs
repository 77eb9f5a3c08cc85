//! brtf-model integration tests: one binary, modules mirror the source.

mod albedo;
mod batch;
mod batch_geometry;
mod batch_gradient;
mod bsdf;
mod oracle;
