//! # brtf-workflow: the fit folder as one thing
//!
//! Both front ends, the `brtf` command line and the Python package, run
//! their fits through this crate, so that a fit folder is made, read and
//! added to in one way:
//!
//! * [`FitSettings`]: every fit option, typed; [`FitSettings::options`]
//!   turns them into the fitter's [`brtf_fit::FitSetOptions`].
//! * [`FitInputs`] sorts the inputs (measurement files, Klems XML, sample
//!   folders); [`FitJob`] is one sample's fit with its default name.
//! * [`fit_to_folder`] fits into a staged folder (lock, `params.csv`,
//!   exports, plots, report, `fit.json` with its manifest) and swaps it in;
//!   [`fit_samples`] does it for many sample folders; [`save_fit`] saves a
//!   fit made earlier.
//! * [`export_into`], [`write_klems_into`] and [`plot_folder`] add to a fit
//!   folder and keep its manifest true; [`read_fit`] reads one back.
//!
//! A new output file is added here once and both front ends have it.

mod amend;
mod directions;
mod en14501;
mod error;
mod folder;
mod info;
mod inputs;
mod jobs;
mod material;
mod render;
mod residuals;
mod run;
mod settings;

pub use amend::{
    Amended, check_folder, ensure_fit_json, export_into, export_klems_of_material,
    klems_of_composite, klems_of_fit_folder, plot_folder, read_fit, write_klems_into,
};
pub use directions::{ThetaGrid, parse_direction_line, parse_numbers};
pub use en14501::en14501_material;
pub use error::WorkflowError;
pub use folder::{FolderWritten, Outputs, save_fit, write_fit_folder};
pub use info::describe_files;
pub use inputs::{FitInputs, default_name, is_klems, sample_files};
pub use jobs::with_jobs;
pub use material::{read_material_file, solar_band};
pub use render::{
    GonioRequest, GonioRun, ImageRequest, ImageRun, MaterialSource, RenderMaterial,
    load_render_material, render_gonio, render_image, with_extension, write_synth_set,
};
pub use run::{FitJob, FolderRequest, FolderRun, SampleOutcome, fit_samples, fit_to_folder};
pub use settings::{FitSettings, MAX_PATCH_SAMPLES};
