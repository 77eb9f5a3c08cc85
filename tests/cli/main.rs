//! End-to-end tests of the `brtf` binary.
//!
//! * `eval`, `albedo`: the CLI contract of `brtf eval` and `brtf albedo`
//!   (columns, stdin handling, material selection, error messages, a few
//!   exact values).
//! * `rtrace`: live comparison against real Radiance (`oconv` + `rtrace`).
//!   It looks for Radiance in `$RADIANCE_BIN`, on `PATH`, then in the repo's
//!   `.venv` (pyradiance). Without Radiance it warns and skips, except under
//!   `CI`, where it fails.

mod albedo;
mod common;
mod contract;
mod eval;
mod export;
mod fit;
mod info;
mod klems_export;
mod klems_fit;
mod lobe_render;
mod lobes;
mod many;
mod peer;
mod plot;
mod recovery;
mod render;
mod reproduce;
mod rtrace;
mod safety;
mod speed;
