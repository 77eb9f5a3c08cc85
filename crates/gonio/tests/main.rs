//! Integration tests for brtf-gonio: one binary, one module per source
//! module (plus `common` helpers and `robustness` fuzzing).
//!
//! Real pgII scans are read from `../shared/data/rgl-epfl-pgII-raw/` beside
//! the repository; the tests fail (never skip) when they are missing.

mod common;

mod convert;
mod encoding;
mod integral;
mod klems;
mod measurement;
mod read;
mod read_paths;
mod robustness;
mod select;
mod solid_angle;
mod solid_angle_paths;
mod summary;
mod synth;
mod ttree;
mod voronoi_fast_path;
mod write;
