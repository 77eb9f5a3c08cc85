//! `brtf fit FILE... --model M`: a progress bar around
//! [`brtf_fit::fit_set`], and its outputs, written into a staging folder
//! and swapped in as a whole ([`brtf_io::FolderUpdate`]).

mod args;
mod many;

use crate::cmd::output::print;
use anyhow::{Context, Result, bail};
pub use args::FitArgs;
use brtf_fit::Progress;
use brtf_gonio::klems::Side;
use brtf_io::{FolderUpdate, Producer, describe_outputs};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};

/// The progress bar of the fits.
struct Bar(ProgressBar);

impl Progress for Bar {
    fn begin(&self, total: u64) {
        self.0.set_length(total);
        self.0.set_position(0);
    }
    fn advance(&self) {
        self.0.inc(1);
    }
    fn end(&self) {
        self.0.finish_and_clear();
    }
}

pub fn run(args: FitArgs) -> Result<()> {
    if let Some(values) = &args.en14501 {
        return en14501(values, args.name.as_deref());
    }
    let mut options = args.options(String::new())?;
    options.validate()?;
    // Folders as inputs: one sample each (`many`).
    if args.files.iter().any(|f| f.is_dir()) {
        return many::run(&args, options);
    }
    let klems = args.files.iter().any(|f| args::is_klems(f));
    options.name = match &args.name {
        Some(name) => name.clone(),
        None => default_name(&args.files, klems)?,
    };
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| Path::new("fits").join(&options.name));
    let update = FolderUpdate::fresh(&out)?;
    // A two-sided Klems fit is one folder per side.
    let sides: Vec<Option<Side>> = if klems {
        args.side.sides().into_iter().map(Some).collect()
    } else {
        vec![None]
    };
    let nested = sides.len() > 1;
    if nested {
        check_two_sided_replaceable(update.target(), &args)?;
    } else {
        brtf_io::check_replaceable(update.target(), &args.files, args.force)?;
    }
    let bar = Bar(ProgressBar::new(0).with_style(
        ProgressStyle::with_template("{spinner} fitting {msg}{pos}/{len} [{bar:30}] {elapsed}")
            .expect("valid template")
            .progress_chars("=> "),
    ));
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.jobs.unwrap_or(0))
        .build()?;
    let mut results = Vec::new();
    let mut printed = String::new();
    let mut notes = Vec::new();
    for side in &sides {
        let mut options = options.clone();
        options.klems.side = *side;
        if let Some(side) = side {
            bar.0.set_message(format!("{side} side "));
        }
        let brtf_fit::FittedSet {
            mut result,
            prepared,
        } = pool.install(|| brtf_fit::fit_set_with_data(&args.files, &options, &bar))?;
        let (folder, shown) = match side {
            Some(side) if nested => (update.path().join(side.name()), out.join(side.name())),
            _ => (update.path().to_path_buf(), out.clone()),
        };
        std::fs::create_dir_all(&folder)
            .with_context(|| format!("creating {}", folder.display()))?;
        let lines = write_fit_folder(&folder, &shown, &mut result, &prepared, &args, &mut notes)?;
        drop(prepared);
        printed += &format!("{}{lines}", brtf_fit::summary(&result, &shown));
        results.push(result);
    }
    if nested {
        let labels = Side::BOTH.map(|s| s.name().to_string());
        let report = brtf_plot::klems_sides_report(&results, &labels, update.path());
        brtf_io::write_atomic(&update.path().join("report.html"), report.as_bytes())
            .with_context(|| format!("writing {}", out.join("report.html").display()))?;
        printed += &format!("wrote {} (both sides)\n", out.join("report.html").display());
    }
    update.commit()?;
    for result in &results {
        for warning in &result.warnings {
            say!("brtf: warning: {warning}");
        }
    }
    for note in &notes {
        say!("{note}");
    }
    print(&printed)
}

/// Writes one fit's folder (`fit.json`, `params.csv`, exports, plots) into
/// `stage`, shown to the user as `shown`; returns the lines to print. The
/// plots draw the fitted data `prepared` (see [`brtf_fit::FittedSet`]).
fn write_fit_folder(
    stage: &Path,
    shown: &Path,
    result: &mut brtf_fit::FitResult,
    prepared: &[brtf_fit::PreparedMeasurement],
    args: &FitArgs,
    notes: &mut Vec<String>,
) -> Result<String> {
    let context = || format!("writing the fit into {}", shown.display());
    // fit.json is written once, last (below); the exports and plots take
    // the result itself.
    result.write_params_csv(stage).with_context(context)?;
    let mut outputs = describe_outputs(stage, &[stage.join("params.csv")], Producer::Fit)?;
    let mut lines = String::new();
    if !args.no_export {
        let options = brtf_radiance::export::ExportOptions::default();
        let exported = brtf_radiance::export::write_exports(stage, result, &options)
            .with_context(|| format!("exporting Radiance materials into {}", shown.display()))?;
        outputs.extend(describe_outputs(stage, &exported.files, Producer::Export)?);
        for file in &exported.files {
            let name = file.strip_prefix(stage).unwrap_or(file);
            lines += &format!("wrote {}\n", shown.join(name).display());
        }
        notes.extend(exported.notes.iter().map(|n| format!("note: {n}")));
    }
    if !args.no_plots {
        let mut plot_options = brtf_plot::PlotOptions::default();
        plot_options.search_dirs.push(shown.to_path_buf());
        let written = brtf_plot::write_plots_with_data(stage, result, prepared, &plot_options)
            .with_context(|| format!("plotting into {}", shown.display()))?;
        outputs.extend(describe_outputs(stage, &written.files, Producer::Plot)?);
        lines += &format!(
            "wrote {} plots and {}\n",
            written.files.len().saturating_sub(1),
            shown.join("report.html").display()
        );
        notes.extend(
            written
                .warnings
                .iter()
                .map(|w| format!("brtf: warning: {w}")),
        );
    }
    outputs.sort_by(|a, b| a.path.cmp(&b.path));
    result.outputs = outputs;
    // fit.json last: it lists every other file of the folder.
    result.write_fit_json(stage).with_context(context)?;
    Ok(lines)
}

/// A two-sided Klems fit folder may be replaced when each side's folder
/// may ([`brtf_io::check_replaceable`]) and nothing else is in it.
fn check_two_sided_replaceable(target: &Path, args: &FitArgs) -> Result<()> {
    let Ok(entries) = std::fs::read_dir(target) else {
        return Ok(());
    };
    if args.force {
        return brtf_io::check_replaceable(target, &args.files, true).map_err(Into::into);
    }
    for entry in entries.flatten() {
        let name = entry.file_name();
        let name = name.to_string_lossy();
        match name.as_ref() {
            "front" | "back" => {
                brtf_io::check_replaceable(&entry.path(), &args.files, false)?;
            }
            "report.html" => {}
            other => bail!(
                "cannot replace the output folder {}: it holds {other}, which a two-sided Klems fit does not write; --force replaces it",
                target.display()
            ),
        }
    }
    // Inputs inside the folder are refused whatever it holds.
    brtf_io::check_replaceable(target, &args.files, true)?;
    Ok(())
}

/// The material name: the files' `#sample_name` when they agree, else the
/// longest common start of their file names ([`brtf_radiance::default_fit_name`];
/// [`brtf_io::check_replaceable`] keeps `fit` from replacing the fit of
/// another sample).
fn default_name(files: &[PathBuf], klems: bool) -> Result<String> {
    let mut sample_names = Vec::new();
    for file in files {
        let name = if klems {
            brtf_gonio::klems::read_path(file)
                .with_context(|| format!("cannot read {}", file.display()))?
                .header
                .name
        } else {
            // The header alone: the fit reads and checks the whole file.
            brtf_gonio::read_sample_name_at(file)
                .with_context(|| format!("cannot read {}", file.display()))?
        };
        sample_names.push(name);
    }
    let stems: Vec<String> = files
        .iter()
        .map(|f| {
            f.file_stem()
                .unwrap_or_default()
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    Ok(brtf_radiance::default_fit_name(&sample_names, &stems))
}

/// `brtf fit --en14501 …`: the `trans` of datasheet values, with the
/// model's own normal-incidence values as a check.
fn en14501(values: &brtf_fit::en14501::En14501, name: Option<&str>) -> Result<()> {
    let args = values
        .trans_args()
        .map_err(|e| anyhow::anyhow!("--en14501: {e}"))?;
    let name = match name {
        Some(n) => brtf_radiance::identifier(n)
            .ok_or_else(|| anyhow::anyhow!("--name {n}: not usable as a Radiance identifier"))?,
        None => "en14501".to_string(),
    };
    let material = brtf_model::Material::new(brtf_model::MaterialKind::Trans, &args, None)?;
    let bsdf = brtf_model::Bsdf::new(&material, &brtf_model::EvalOptions::default());
    let a = brtf_model::albedo(&bsdf, glam::DVec3::Z, 1e-8);
    let command: Vec<String> = std::env::args().collect();
    let numbers: Vec<String> = args.iter().map(|v| format!("{v:.6}")).collect();
    print(&format!(
        "# brtf {}: {}\n\
         # trans from EN 14501 normal-incidence values tau_nh={} tau_nn={} rho_nh={} spec={}\n\
         # brtf-model at normal incidence: rho_nh={:.4} tau_nh={:.4} tau_nn={:.4}\n\
         void trans {name}\n0\n0\n7 {}\n",
        env!("CARGO_PKG_VERSION"),
        command.join(" "),
        values.tau_nh,
        values.tau_nn,
        values.rho_nh,
        values.spec,
        a.rho[1] + a.rho_spike[1],
        a.tau[1] + a.tau_spike[1],
        a.tau_spike[1],
        numbers.join(" ")
    ))
}
