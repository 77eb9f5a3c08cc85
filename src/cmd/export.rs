//! `brtf export DIR`: a fit folder's Radiance materials (static, θ_in-
//! dependent with its `.cal`, a preview scene) from `fit.json`; `--klems`:
//! a Klems BSDF XML file, of a fit folder or (`--material`) a material.

use super::material::FormulaArgs;
use super::output::print;
use super::shared::words;
use anyhow::{Context, Result};
use brtf_gonio::klems::BasisSize;
use brtf_radiance::export::ExportOptions;
use brtf_radiance::export::klems::KlemsOptions;
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub(crate) struct ExportArgs {
    /// The fit folder (holds fit.json, or front/fit.json and back/fit.json).
    #[arg(required_unless_present = "material")]
    pub dir: Option<PathBuf>,
    /// Static material from the parameters at this θ_in (degrees) instead of
    /// the all-incidence fit: the matching incidence's fit, or the θ_in table.
    #[arg(long, value_name = "THETA", conflicts_with = "klems")]
    pub at: Option<f64>,
    /// Material identifier and file stem (default: the fit's name).
    #[arg(long, value_name = "NAME")]
    pub name: Option<String>,
    /// Write into this folder instead of DIR (created if missing).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Only the static material: no θ_in-dependent material, no .cal.
    #[arg(long)]
    pub static_only: bool,
    /// No preview scene.
    #[arg(long)]
    pub no_preview: bool,
    /// A colour measured elsewhere: its chromaticity at the fitted luminance.
    #[arg(long, value_name = "R,G,B", value_parser = brtf_model::parse_rgb, conflicts_with = "klems")]
    pub colour: Option<[f64; 3]>,
    #[command(flatten)]
    pub klems: KlemsArgs,
}

/// `--klems` and its options.
#[derive(Args, Debug)]
pub(crate) struct KlemsArgs {
    /// Write `<name>.xml`, a Klems BSDF XML file, in this basis (default
    /// full) instead of the Radiance materials.
    #[arg(long, value_name = "BASIS", num_args = 0..=1, default_missing_value = "full",
          value_parser = words::<BasisSize>())]
    pub klems: Option<BasisSize>,
    /// With --klems: the static material in this Radiance file instead of a
    /// fit folder (`--name` picks one of several).
    #[arg(long, value_name = "M.rad", requires = "klems", conflicts_with = "dir")]
    pub material: Option<PathBuf>,
    #[command(flatten)]
    pub formula: FormulaArgs,
    /// Samples per Klems matrix entry: quasi-random points of the outgoing
    /// × incident patch (16× near the horizon, 4× above 75°).
    #[arg(long, value_name = "N", requires = "klems",
          default_value_t = brtf_gonio::klems::DEFAULT_SAMPLES)]
    pub klems_samples: usize,
    /// The Solar band: `visible` (default) repeats Visible, saying so; `none`;
    /// or a Radiance file with a material of the solar properties.
    #[arg(long, value_name = "visible|none|S.rad", requires = "klems")]
    pub solar: Option<String>,
    /// Add CIE-X and CIE-Z bands (colour).
    #[arg(long, requires = "klems")]
    pub xyz_bands: bool,
    /// With --material: also write `<name>-bsdf2klems.cal`, its BSDF (CIE Y)
    /// for `bsdf2klems -f`: an independent Klems file from Radiance.
    #[arg(long, requires = "material")]
    pub klems_cal: bool,
    /// `Manufacturer` in the Klems file.
    #[arg(long, default_value = "brtf", requires = "klems")]
    pub manufacturer: String,
    /// `Thickness` in the Klems file, millimetres.
    #[arg(long, value_name = "MM", default_value_t = 1.0, requires = "klems")]
    pub thickness: f64,
    /// `PermeabilityFactor` in the Klems file: the open fraction, 0 to 1.
    #[arg(long, value_name = "F", requires = "klems")]
    pub permeability: Option<f64>,
    /// `EmissivityFront`, `EmissivityBack` (WINDOW's sides) in the Klems file.
    #[arg(long, value_name = "FRONT,BACK", requires = "klems", value_parser = brtf_workflow::parse_numbers::<2>)]
    pub emissivity: Option<[f64; 2]>,
    /// `TIR` in the Klems file: the infrared transmittance, 0 to 1.
    #[arg(long, value_name = "T", requires = "klems")]
    pub ir_transmittance: Option<f64>,
    /// `ThermalConductivity` in the Klems file, W/(m·K).
    #[arg(long, value_name = "K", requires = "klems")]
    pub conductivity: Option<f64>,
    /// `DeviceType` in the Klems file (WINDOW: Other, Woven, Venetian, ...).
    #[arg(long, default_value = "Other", requires = "klems")]
    pub device_type: String,
}

pub(crate) fn run(args: ExportArgs) -> Result<()> {
    if let Some(basis) = args.klems.klems {
        return run_klems(&args, basis);
    }
    let dir = args.dir.as_ref().context("give the fit folder")?;
    let options = ExportOptions {
        name: args.name.clone(),
        at: args.at,
        theta_dependent: !args.static_only,
        preview: !args.no_preview,
        colour: args.colour,
    };
    options.validate()?;
    let result = brtf_workflow::read_fit(dir)?;
    let out = args.out.as_ref().unwrap_or(dir);
    print_written(&brtf_workflow::export_into(out, &result, &options)?)
}

/// `brtf export DIR --klems` or `brtf export --klems --material M.rad`.
fn run_klems(args: &ExportArgs, basis: BasisSize) -> Result<()> {
    let k = &args.klems;
    let mut options = KlemsOptions::new("");
    options.basis = basis.basis();
    options.sampling.samples = k.klems_samples;
    options.solar = brtf_workflow::solar_band(k.solar.as_deref())?;
    options.colour = k.xyz_bands;
    options.manufacturer = k.manufacturer.clone();
    options.thickness_mm = k.thickness;
    options.device_type = k.device_type.clone();
    options.window = brtf_gonio::klems::WindowFields {
        conductivity: k.conductivity,
        emissivity: k.emissivity,
        ir_transmittance: k.ir_transmittance,
        permeability: k.permeability,
    };
    options.command_line = super::fit::command_line();
    let Some(material_path) = &k.material else {
        let dir = args
            .dir
            .as_ref()
            .context("give the fit folder or --material")?;
        let (stem, export) =
            brtf_workflow::klems_of_fit_folder(dir, args.name.as_deref(), options)?;
        let out = args.out.as_ref().unwrap_or(dir);
        let files = vec![brtf_workflow::write_klems_into(out, &stem, &export)?];
        let notes = export.notes;
        return print_written(&brtf_workflow::Amended { files, notes });
    };
    let written = brtf_workflow::export_klems_of_material(
        material_path,
        args.name.as_deref(),
        &k.formula.options(),
        options,
        args.out.as_deref(),
        k.klems_cal,
    )?;
    print_written(&written)
}

/// Prints the notes, then a `wrote …` line per file.
fn print_written(written: &brtf_workflow::Amended) -> Result<()> {
    for note in &written.notes {
        say!("note: {note}");
    }
    let lines: String = written
        .files
        .iter()
        .map(|f| format!("wrote {}\n", f.display()))
        .collect();
    print(&lines)
}
