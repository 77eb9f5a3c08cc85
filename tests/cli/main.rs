//! End-to-end tests of the `brtf` binary, one module per area:
//!
//! * `eval`, `albedo`, `info`: the contracts of those commands;
//!   `rtrace`: `brtf eval` against live Radiance (`oconv` + `rtrace`), and
//!   `lobes`: mixfunc lobe sums against it. Radiance is looked for in
//!   `$RADIANCE_BIN`, on `PATH`, then in the repo's `.venv` (pyradiance);
//!   without it the live tests warn and skip, except under `CI`.
//! * `fit`, `recovery`, `align`, `shadow`, `many`, `peer`, `speed`: `brtf
//!   synth` + `brtf fit` (known parameters back, scans turned back into
//!   their plane of incidence, the holder's shadow found and masked, real
//!   scans, sample folders, the scipy peer and the data of the speed
//!   comparison).
//! * `contract`, `reproduce`, `safety`, `hostile`: what every command reads from a
//!   fit folder, `fits/alu-ggx` rebuilt byte for byte, and no lost result
//!   or unchecked option.
//! * `export`, `klems_export`, `klems_fit`: Radiance and Klems exports, and
//!   Klems XML in.
//! * `render`, `lobe_render`, `plot`, `residuals`: the tracer, `brtf
//!   check`, the plots and `residuals.csv`.
//! * `layout`: the source tree's shape (no import circles, thin front ends).
//! * `common`: shared helpers.

mod albedo;
mod align;
mod browser;
mod common;
mod contract;
mod eval;
mod export;
mod fit;
mod hostile;
mod info;
mod klems_export;
mod klems_fit;
mod layout;
mod lobe_render;
mod lobes;
mod many;
mod peer;
mod plot;
mod recovery;
mod render;
mod reproduce;
mod residuals;
mod rtrace;
mod safety;
mod shadow;
mod speed;
mod ttree;
mod verdict;
mod view3d;
