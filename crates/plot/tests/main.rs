//! Integration tests for brtf-plot: one binary, modules by topic.
//!
//! The plots of the repository's `data/alu-ggx` set are drawn once per test
//! binary, from the committed `fits/alu-ggx/fit.json` (its measurement
//! paths are relative to the repository root), into a temporary folder.

mod common;

mod charts;
mod lobes;
mod report;
mod view;
