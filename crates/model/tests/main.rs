//! brtf-model integration tests: one binary, modules mirror the source.

mod albedo;
mod bsdf;
mod oracle;
