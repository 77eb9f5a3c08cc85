//! brtf-model integration tests: one binary, modules mirror the source.

mod albedo;
mod batch;
mod bsdf;
mod oracle;
