//! `brtf export DIR`: the Radiance materials of a fit folder (static,
//! θ_in-dependent with its `.cal`, and a preview scene), from `fit.json`;
//! with `--klems`, a Klems BSDF XML file instead, from a fit folder or
//! (`--material`) from a static material.

use super::output::{print, relist};
use anyhow::{Context, Result};
use brtf_fit::FitResult;
use brtf_io::{FolderUpdate, Producer};
use brtf_radiance::export::{ExportOptions, write_exports};
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct ExportArgs {
    /// The fit folder (holds fit.json, or front/fit.json and back/fit.json).
    #[arg(required_unless_present = "material")]
    pub dir: Option<PathBuf>,
    /// Static material from the parameters at this θ_in (degrees) instead of
    /// the all-incidence fit: the matching incidence's fit, or the θ_in table.
    #[arg(long, value_name = "THETA")]
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
    #[command(flatten)]
    pub klems: KlemsArgs,
}

/// `--klems` and its options.
#[derive(Args, Debug)]
pub struct KlemsArgs {
    /// Write `<name>.xml`, a Klems BSDF XML file, in this basis (full,
    /// half or quarter; default full) instead of the Radiance materials.
    #[arg(long, value_name = "BASIS", num_args = 0..=1, default_missing_value = "full",
          value_parser = ["full", "half", "quarter"])]
    pub klems: Option<String>,
    /// With --klems: the static material in this Radiance file instead of a
    /// fit folder (`--name` picks one of several).
    #[arg(long, value_name = "M.rad", requires = "klems")]
    pub material: Option<PathBuf>,
    /// With --klems --material: formula set (radiance, manual2004, ward1992).
    #[arg(long, default_value = "radiance", value_parser = super::material::parse_variant,
          requires = "material")]
    pub variant: brtf_model::Variant,
    /// With --klems --material: Fresnel constant (classic, pyradiance or a number).
    #[arg(long, default_value = "classic", value_parser = super::material::parse_fresnel_k,
          requires = "material")]
    pub fresnel_k: f64,
    /// Samples per Klems matrix entry: quasi-random points of the outgoing
    /// × incident patch (16× near the horizon, 4× above 75°).
    #[arg(long, value_name = "N", requires = "klems",
          default_value_t = brtf_gonio::klems::model_matrix::DEFAULT_SAMPLES)]
    pub klems_samples: usize,
    /// Add a Solar band: `visible` repeats the Visible values (said in the
    /// header as an assumption), or a Radiance file with a material of the
    /// solar properties.
    #[arg(long, value_name = "visible|S.rad", requires = "klems")]
    pub solar: Option<String>,
    /// Add CIE-X and CIE-Z bands (colour).
    #[arg(long, requires = "klems")]
    pub colour: bool,
    /// With --klems --material: also write `<name>-bsdf2klems.cal`, the
    /// material's BSDF (CIE Y) as the six-argument function
    /// `bsdf2klems -f` takes, for an independent Klems file from Radiance.
    #[arg(long, requires = "material")]
    pub klems_cal: bool,
    /// `Manufacturer` in the Klems file.
    #[arg(long, default_value = "brtf", requires = "klems")]
    pub manufacturer: String,
    /// `Thickness` in the Klems file, millimetres.
    #[arg(long, value_name = "MM", default_value_t = 1.0, requires = "klems")]
    pub thickness: f64,
    /// `DeviceType` in the Klems file (WINDOW: Other, Woven, Venetian, ...).
    #[arg(long, default_value = "Other", requires = "klems")]
    pub device_type: String,
}

pub fn run(args: ExportArgs) -> Result<()> {
    if args.klems.klems.is_some() {
        return run_klems(args);
    }
    let dir = args.dir.context("give the fit folder")?;
    if let Some(at) = args.at {
        anyhow::ensure!(
            (0.0..90.0).contains(&at),
            "--at {at}: out of range; allowed: 0 ≤ θ_in < 90 degrees"
        );
    }
    let fit_path = dir.join("fit.json");
    let result = FitResult::read(&fit_path)?;
    let out = args.out.unwrap_or_else(|| dir.clone());
    let options = ExportOptions {
        name: args.name,
        at: args.at,
        theta_dependent: !args.static_only,
        preview: !args.no_preview,
    };
    // Into a copy of the folder, swapped in at the end: replaces this
    // command's own files, keeps the rest.
    let update = FolderUpdate::amend(&out)?;
    let exported = write_exports(update.path(), &result, &options)
        .with_context(|| format!("exporting {}", fit_path.display()))?;
    relist(update.path(), &exported.files, Producer::Export)?;
    let mut lines = String::new();
    for file in &exported.files {
        let name = file.strip_prefix(update.path()).unwrap_or(file);
        lines += &format!("wrote {}\n", out.join(name).display());
    }
    update.commit()?;
    for note in &exported.notes {
        say!("note: {note}");
    }
    print(&lines)
}

/// `brtf export DIR --klems` or `brtf export --klems --material M.rad`.
fn run_klems(args: ExportArgs) -> Result<()> {
    use brtf_gonio::klems::KlemsBasis;
    use brtf_radiance::export::klems::{self, KlemsOptions, SolarBand};
    let k = &args.klems;
    anyhow::ensure!(
        args.at.is_none(),
        "--at cannot be used with --klems: each incident patch gets its own θ_in"
    );
    let basis_name = match k.klems.as_deref() {
        Some("half") => "LBNL/Klems Half",
        Some("quarter") => "LBNL/Klems Quarter",
        _ => "LBNL/Klems Full",
    };
    let basis = KlemsBasis::built_in(basis_name).context("a built-in basis")?;
    let load =
        |path: &std::path::Path, name: Option<&str>| -> Result<(String, brtf_model::Material)> {
            let shown = path.display().to_string();
            let text = std::fs::read_to_string(path)
                .with_context(|| format!("cannot read material file {shown}"))?;
            let primitives = brtf_radiance::parse_primitives(&text, &shown)?;
            Ok(brtf_radiance::select_material(&primitives, name, &shown)?)
        };
    let solar = match k.solar.as_deref() {
        None => SolarBand::None,
        Some("visible") => SolarBand::ReuseVisible,
        Some(file) => {
            let (_, material) = load(std::path::Path::new(file), None)
                .with_context(|| format!("--solar {file}"))?;
            SolarBand::Material {
                material,
                source: file.to_string(),
            }
        }
    };
    let mut options = KlemsOptions::new("");
    options.basis = basis;
    options.sampling.samples = k.klems_samples;
    options.solar = solar;
    options.colour = k.colour;
    options.manufacturer = k.manufacturer.clone();
    options.thickness_mm = k.thickness;
    options.device_type = k.device_type.clone();
    options.command_line = std::env::args().collect();

    if let Some(material_path) = &k.material {
        anyhow::ensure!(
            args.dir.is_none(),
            "give either a fit folder or --material, not both"
        );
        let (name, material) = load(material_path, args.name.as_deref())?;
        let bytes = std::fs::read(material_path)
            .with_context(|| format!("cannot read {}", material_path.display()))?;
        let eval = brtf_model::EvalOptions {
            variant: k.variant,
            fresnel_k: k.fresnel_k,
            ..brtf_model::EvalOptions::default()
        };
        eval.validate()?;
        options.name = name.clone();
        let export = klems::klems_from_material(
            &material,
            &eval,
            &material_path.display().to_string(),
            &brtf_io::sha256_hex(&bytes),
            &options,
        )?;
        let out = args
            .out
            .or_else(|| material_path.parent().map(|p| p.to_path_buf()))
            .unwrap_or_default();
        brtf_io::ensure_folder(&out)?;
        let path = out.join(format!("{name}.xml"));
        klems::write_klems(&path, &export)?;
        let mut lines = format!("wrote {}\n", path.display());
        if k.klems_cal {
            let cal = brtf_radiance::export::klems_cal::bsdf_function_cal(&material)
                .map_err(|e| anyhow::anyhow!("--klems-cal: {e}"))?;
            let cal_path = out.join(format!("{name}-bsdf2klems.cal"));
            brtf_io::write_atomic(&cal_path, cal.as_bytes())?;
            lines += &format!("wrote {}\n", cal_path.display());
        }
        for note in &export.notes {
            say!("note: {note}");
        }
        return print(&lines);
    }

    let dir = args.dir.context("give the fit folder or --material")?;
    // A two-sided Klems fit: front/ and back/ inside `dir`.
    let two_sided = dir.join("front").join("fit.json").is_file();
    let front = if two_sided {
        dir.join("front").join("fit.json")
    } else {
        dir.join("fit.json")
    };
    let result = FitResult::read(&front)?;
    let name = match &args.name {
        Some(n) => n.clone(),
        // (A side's own folder, `…/front`, is named by its fit.)
        None if two_sided => dir
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| result.name.clone()),
        None => result.name.clone(),
    };
    let stem = klems::klems_file_stem(&name);
    options.name = name;
    let export = klems::klems_from_fit_dir(&dir, &options)
        .with_context(|| format!("exporting {} as Klems XML", dir.display()))?;
    let out = args.out.unwrap_or_else(|| dir.clone());
    brtf_io::ensure_folder(&out)?;
    let path = out.join(format!("{stem}.xml"));
    if out.join("fit.json").is_file() {
        // A fit folder: listed in fit.json with the other exports.
        let update = FolderUpdate::amend(&out)?;
        let staged = update.path().join(format!("{stem}.xml"));
        klems::write_klems(&staged, &export)?;
        let listed = FitResult::read(&update.path().join("fit.json"))?;
        let mut fresh: Vec<PathBuf> = listed
            .outputs
            .iter()
            .filter(|o| o.by == Producer::Export && update.path().join(&o.path).is_file())
            .map(|o| update.path().join(&o.path))
            .filter(|p| *p != staged)
            .collect();
        fresh.push(staged);
        relist(update.path(), &fresh, Producer::Export)?;
        update.commit()?;
    } else {
        klems::write_klems(&path, &export)?;
    }
    for note in &export.notes {
        say!("note: {note}");
    }
    print(&format!("wrote {}\n", path.display()))
}
