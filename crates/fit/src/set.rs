//! A fit set: measurement files → [`Recipe`] → per-incidence and
//! all-incidence fits → θ_in table → [`FitResult`]. This is `brtf fit`
//! without the command line.

use crate::config::{FitConfig, FitError};
use crate::data::IncidenceData;
use crate::diagnose;
use crate::fitter::{SharedGeometry, fit_global_sharing, fit_incidence_sharing, shared_geometry};
use crate::recipe::{PreparedMeasurement, Recipe, RecipeError, ScaleRule};
use crate::report::FitReport;
use crate::result::{FIT_JSON_SCHEMA, FitResult, InputFile, Provenance, SetWarning};
use crate::table::{Interpolation, ParamTable};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// Reports the progress of a long run (the CLI draws a bar).
pub trait Progress: Sync {
    /// `total` steps are about to run.
    fn begin(&self, _total: u64) {}
    /// One step finished.
    fn advance(&self) {}
    /// All steps finished.
    fn end(&self) {}
    /// What is being worked on now (`front side`, `12 samples`).
    fn label(&self, _text: &str) {}
    /// True when the caller wants the run to stop (Ctrl-C in Python): the
    /// incidences not yet begun are not fitted, and the run fails with
    /// [`FitError::Interrupted`].
    fn cancelled(&self) -> bool {
        false
    }
}

/// Reports nothing.
pub struct NoProgress;

impl Progress for NoProgress {}

/// What a fit set needs besides the files.
#[derive(Debug, Clone)]
pub struct FitSetOptions {
    /// Material name of the exports.
    pub name: String,
    /// The fit settings. `free_scale` forces a free scale; raw files
    /// without a beam integral get one anyway.
    pub config: FitConfig,
    /// How the files become data (`scale`: [`ScaleRule::FromFiles`] or
    /// [`ScaleRule::BeamIntegral`]).
    pub recipe: Recipe,
    /// A known reflectance `(ρ_dh, θ_in)` that makes raw data absolute.
    pub known_reflectance: Option<(f64, f64)>,
    /// θ_in interpolation of the table.
    pub interpolation: Interpolation,
    /// The command line, for the provenance.
    pub command_line: Vec<String>,
    /// Judge each incidence's fit (energy, peak, a second fit with another
    /// residual kind; see [`crate::Adequacy`]).
    pub adequacy: bool,
    /// What to take from Klems BSDF XML inputs.
    pub klems: KlemsOptions,
    /// `--model auto`: fit the candidate set and keep the winner
    /// ([`crate::AutoChoice`]); `config`'s type is then ignored.
    pub auto: bool,
}

impl FitSetOptions {
    /// The options for Klems BSDF XML inputs: the model averaged over each
    /// sample's patch pairs, `outgoing_samples` view directions per patch
    /// (`docs/klems.md`), and the lowest roughness Klems data can tell
    /// ([`crate::klems::MIN_KLEMS_ROUGHNESS`]). The selections are the
    /// caller's, made with `SelectionOptions::gates(true)`. `brtf fit` and
    /// the Python package both use it.
    pub fn for_klems(mut self, outgoing_samples: usize) -> FitSetOptions {
        self.recipe.patch_average = Some(crate::PatchAveraging {
            outgoing_samples,
            ..Default::default()
        });
        self.config.min_roughness = crate::klems::MIN_KLEMS_ROUGHNESS;
        // Patch averages have no peak to align (and a Klems basis no turn).
        self.recipe.azimuth = crate::AzimuthRule::file_frame();
        self
    }
}

/// What a fit set takes from Klems BSDF XML files.
#[derive(Debug, Clone, Default)]
pub struct KlemsOptions {
    /// The side whose incident patches are fitted (each side is its own
    /// fit: measured fabrics are not reciprocal).
    pub side: Option<brtf_gonio::klems::Side>,
    /// Which incident patches (by θ_in); all when `None`.
    pub incidences: Option<crate::klems::IncidenceFilter>,
    /// Tensor trees: the θ_in fitted (degrees, at φ_in = 0), each moved
    /// to the centre of the tree's finest input cell;
    /// [`crate::ttree::DEFAULT_THETAS`] when `None`.
    pub theta_in_grid: Option<Vec<f64>>,
}

/// Why a fit set could not be made.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FitSetError {
    /// No input files.
    #[error("no measurement files given")]
    NoInputs,
    /// A file could not be read.
    #[error("cannot read {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// A file could not be parsed.
    #[error(transparent)]
    Read(#[from] brtf_gonio::ReadError),
    /// A file could not be converted.
    #[error(transparent)]
    Recipe(#[from] RecipeError),
    /// A fit failed.
    #[error(transparent)]
    Fit(#[from] FitError),
    /// Some files are absolute and some need a free scale.
    #[error("the files mix absolute and raw-signal data; give --beam-integral or --free-scale")]
    MixedScale,
    /// `--rho` on data that are already absolute.
    #[error("--rho is for raw-signal data fitted with a free scale; these data are absolute")]
    KnownReflectanceOnAbsoluteData,
    /// The fitted model reflects nothing at the `--rho` incidence.
    #[error("--rho: the fitted model has no reflectance at {0}°")]
    NoReflectance(f64),
    /// `--theta-in-grid` given for a Klems matrix file, whose incidences
    /// are its incident patches.
    #[error(
        "{}: --theta-in-grid sets the incidences of tensor trees; a Klems matrix file's are its incident patches (select them with --incidences)",
        .0.display()
    )]
    ThetaGridOnKlemsMatrix(PathBuf),
    /// `--energy exact` on data of unknown scale.
    #[error(
        "--energy exact holds the model to the data's energy, which raw-signal data fitted with a free scale do not have; give --beam-integral, or fit without --energy exact"
    )]
    EnergyOfRawSignal,
    /// `--energy exact` without the samples' solid angles.
    #[error(
        "{0}: --energy exact integrates the data over their solid angles, which uniform weights (--weights uniform) leave out"
    )]
    EnergyWithoutSolidAngles(String),
    /// The selection left no incidence to fit.
    #[error(
        "no incidence to fit: the Klems file has no data for this side, or --incidences excludes every patch"
    )]
    NoIncidences,
}

/// One input file, read and prepared.
struct Input {
    file: InputFile,
    prepared: PreparedMeasurement,
}

/// A fit set and the data it fitted.
#[derive(Debug, Clone)]
pub struct FittedSet {
    /// The fit.
    pub result: FitResult,
    /// The fitted data of each incidence, as [`prepare_input`] would make
    /// them again from the file (`prepared[k]` belongs to
    /// `result.incidences[k]`), so that plots need not read the files again.
    pub prepared: Vec<PreparedMeasurement>,
}

/// Reads, prepares and fits every file; see the module docs.
pub fn fit_set(
    paths: &[PathBuf],
    options: &FitSetOptions,
    progress: &dyn Progress,
) -> Result<FitResult, FitSetError> {
    fit_set_with_data(paths, options, progress).map(|set| set.result)
}

/// [`fit_set`], keeping the fitted data.
pub fn fit_set_with_data(
    paths: &[PathBuf],
    options: &FitSetOptions,
    progress: &dyn Progress,
) -> Result<FittedSet, FitSetError> {
    if paths.is_empty() {
        return Err(FitSetError::NoInputs);
    }
    let mut recipe = options.recipe.clone();
    let per_path: Vec<Vec<Input>> = paths
        .par_iter()
        .map(|p| read_input(p, &recipe, &options.klems))
        .collect::<Result<_, _>>()?;
    let mut inputs: Vec<Input> = per_path.into_iter().flatten().collect();
    if inputs.is_empty() {
        return Err(FitSetError::NoIncidences);
    }
    inputs.sort_by(|a, b| a.file.theta_in.total_cmp(&b.file.theta_in));

    let mut config = options.config.clone();
    let free = inputs
        .iter()
        .filter(|i| i.prepared.conversion.is_free_scale());
    let free_count = free.count();
    if free_count > 0 && free_count < inputs.len() && !config.free_scale {
        return Err(FitSetError::MixedScale);
    }
    config.free_scale |= free_count > 0;
    if config.energy == crate::EnergyRule::Exact {
        if config.free_scale {
            return Err(FitSetError::EnergyOfRawSignal);
        }
        if let Some(i) = inputs
            .iter()
            .find(|i| i.prepared.weighting == crate::Weighting::Uniform)
        {
            return Err(FitSetError::EnergyWithoutSolidAngles(i.file.path.clone()));
        }
    }

    let mut warnings = Vec::new();
    // The adequacy diagnostics' second fit (another residual kind) needs
    // only the data: unless `--rho` changes the data after the main fits,
    // it runs beside them.
    let other_early = options.adequacy && options.known_reflectance.is_none();
    let steps = fit_all_steps(inputs.len()) + if other_early { inputs.len() } else { 0 };
    progress.begin(steps as u64);
    // The energy and peak diagnostics follow the main fits there, while
    // the second fits may still run.
    // What the fitter reads of each input, made once for both fits.
    let mut data = incidence_data(&inputs);
    // `--model auto`: the candidates' fits decide the configuration.
    let auto = if options.auto {
        if recipe.patch_average.is_some() {
            return Err(FitSetError::Fit(FitError::Failed {
                origin: "--model auto".into(),
                reason: "the candidates' lobe sums need gonio-photometer scans, not Klems \
                         patch averages"
                    .into(),
            }));
        }
        let prepared: Vec<&PreparedMeasurement> = inputs.iter().map(|i| &i.prepared).collect();
        let (chosen, record, reports) = crate::auto::choose(&config, &prepared, &data)?;
        config = chosen;
        Some((record, reports))
    } else {
        None
    };
    let (auto, chosen_reports) = match auto {
        Some((record, reports)) => (Some(record), Some(reports)),
        None => (None, None),
    };
    // So is the geometry, which a rescale of the values leaves as it is.
    let geometry = shared_geometry(&data, &config)?;
    let (main, early) = rayon::join(
        || {
            let (reports, global) = match chosen_reports {
                // The winner's fits are made: the all-incidence fit remains.
                Some(reports) => {
                    for _ in 0..reports.len() {
                        progress.advance();
                    }
                    let global = global_fit(&data, &geometry, &config, &reports)?;
                    progress.advance();
                    (reports, global)
                }
                None => fit_all(&data, &geometry, &config, progress)?,
            };
            let adequacy = other_early.then(|| diagnose_all(&inputs, &data, &reports, &config));
            Ok::<_, FitSetError>((reports, global, adequacy))
        },
        || other_early.then(|| other_fits(&data, &geometry, &config, progress)),
    );
    progress.end();
    let (mut reports, mut global, early_adequacy) = main?;

    // A known reflectance turns a free-scale fit absolute: the data's own
    // ρ_dh at that incidence (measured directions from the data, the rest
    // from the free-scale fit) fixes the instrument's scale K; the data are
    // divided by K and fitted again without a free scale.
    if let Some((rho, theta)) = options.known_reflectance {
        if free_count == 0 {
            return Err(FitSetError::KnownReflectanceOnAbsoluteData);
        }
        let nearest = (0..reports.len())
            .min_by(|&a, &b| {
                (reports[a].theta_in - theta)
                    .abs()
                    .total_cmp(&(reports[b].theta_in - theta).abs())
            })
            .expect("at least one incidence");
        if (reports[nearest].theta_in - theta).abs() > 5.0 {
            warnings.push(SetWarning::RhoFarFromIncidence {
                requested: theta,
                used: reports[nearest].theta_in,
            });
        }
        warnings.extend(rho_from_header(&inputs[nearest].prepared, rho));
        let k = instrument_scale(
            &config,
            &inputs[nearest].prepared,
            &data[nearest],
            &reports[nearest],
            rho,
        )?;
        for input in &mut inputs {
            input.prepared.rescale_known_reflectance(k, rho, theta);
            input.file.conversion = input.prepared.conversion.clone();
        }
        recipe.scale = ScaleRule::KnownReflectance {
            rho,
            theta_in: theta,
            k,
        };
        config.free_scale = false;
        progress.begin(fit_all_steps(inputs.len()) as u64);
        data = incidence_data(&inputs);
        let refit = fit_all(&data, &geometry, &config, progress);
        progress.end();
        (reports, global) = refit?;
    }

    if options.adequacy {
        let others = match early {
            Some(others) => others,
            None => {
                progress.begin(inputs.len() as u64);
                let others = other_fits(&data, &geometry, &config, progress);
                progress.end();
                others
            }
        };
        let adequacy =
            early_adequacy.unwrap_or_else(|| diagnose_all(&inputs, &data, &reports, &config));
        assess(&mut reports, &config, adequacy, others);
    }

    // Klems incidences come in θ rings of azimuth patches: the table
    // averages each ring over φ_in, and an anisotropic type's also keeps
    // each ring over φ_in.
    let (kind, orientation, method) = (config.shape(), config.orientation, options.interpolation);
    let built = if recipe.patch_average.is_none() {
        ParamTable::from_reports(kind, orientation, &reports, method)
    } else if kind.kind.is_anisotropic() {
        // The back side's frame is mirrored.
        let mirrored = inputs.iter().any(|i| i.file.is_klems_back_side());
        ParamTable::from_reports_over_azimuth(kind, orientation, &reports, method, mirrored)
    } else {
        ParamTable::from_reports_phi_averaged(kind, orientation, &reports, method)
    };
    let table = match built {
        Ok(t) => Some(t),
        Err(e) => {
            warnings.push(SetWarning::NoTable {
                reason: e.to_string(),
            });
            None
        }
    };
    let (files, prepared) = inputs.into_iter().map(|i| (i.file, i.prepared)).unzip();
    let result = FitResult {
        schema: FIT_JSON_SCHEMA,
        name: options.name.clone(),
        provenance: Provenance {
            brtf_version: env!("CARGO_PKG_VERSION").into(),
            command_line: options.command_line.clone(),
            created: brtf_io::utc_now_rfc3339(),
            inputs: files,
        },
        recipe,
        config,
        incidences: reports,
        global: Some(global),
        table,
        interpolation: options.interpolation,
        warnings,
        auto,
        outputs: Vec::new(),
    };
    Ok(FittedSet { result, prepared })
}

/// Reads one file and applies the recipe: one input, or for a Klems file
/// one per incident patch of the chosen side.
fn read_input(
    path: &Path,
    recipe: &Recipe,
    klems: &KlemsOptions,
) -> Result<Vec<Input>, FitSetError> {
    let bytes = brtf_io::read_input(path).map_err(|source| FitSetError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    // The file's digest is computed while it is read.
    let klems_xml = brtf_gonio::detect_format(&bytes, path) == brtf_gonio::SourceFormat::KlemsXml;
    let (sha256, measurement) = rayon::join(
        || brtf_io::sha256_hex(&bytes),
        || (!klems_xml).then(|| brtf_gonio::read_bytes(&bytes, path)),
    );
    let source = path.display().to_string();
    let input = |prepared: PreparedMeasurement, samples, at| {
        let incidence = prepared.measurement.incidence;
        Input {
            file: InputFile {
                path: source.clone(),
                sha256: sha256.clone(),
                theta_in: incidence.theta_deg,
                phi_in: incidence.phi_deg,
                conversion: prepared.conversion.clone(),
                samples,
                klems: at,
                phi_turn_deg: prepared.phi_turn_deg,
                peak_arc_deg: prepared.peak_arc_deg,
                shadows: prepared.shadows.clone(),
                channels: prepared.channels(),
            },
            prepared,
        }
    };
    let Some(measurement) = measurement else {
        let side = klems.side.unwrap_or(brtf_gonio::klems::Side::Front);
        let bsdf = match brtf_gonio::klems::read_any_bytes(&bytes, path)? {
            brtf_gonio::klems::BsdfXml::Klems(_) if klems.theta_in_grid.is_some() => {
                return Err(FitSetError::ThetaGridOnKlemsMatrix(path.to_path_buf()));
            }
            brtf_gonio::klems::BsdfXml::Klems(bsdf) => bsdf,
            brtf_gonio::klems::BsdfXml::TensorTree(tree) => {
                let thetas = klems
                    .theta_in_grid
                    .clone()
                    .unwrap_or_else(|| crate::ttree::DEFAULT_THETAS.to_vec());
                let mut inputs: Vec<Input> = Vec::new();
                for (patch, &theta) in thetas.iter().enumerate() {
                    if klems.incidences.as_ref().is_some_and(|f| !f.keeps(theta)) {
                        continue;
                    }
                    let at = crate::klems::KlemsPatchRef { side, patch };
                    let label = format!("{source} [{side} patch {patch}]");
                    let Some(mut prepared) =
                        crate::ttree::prepare_incidence(recipe, &tree, side, theta, 0.0, &label)?
                    else {
                        continue;
                    };
                    // Two θ_in in one input cell are one incidence.
                    let snapped = prepared.measurement.incidence.theta_deg;
                    if inputs
                        .iter()
                        .any(|i| (i.file.theta_in - snapped).abs() < 1e-9)
                    {
                        continue;
                    }
                    prepared.source = label;
                    let samples = prepared.measurement.len();
                    inputs.push(input(prepared, samples, Some(at)));
                }
                return Ok(inputs);
            }
        };
        let mut inputs = Vec::new();
        let directions = recipe
            .patch_average
            .map(|rule| crate::klems::PatchDirections::new(&bsdf.basis, &rule));
        for patch in 0..bsdf.basis.len() {
            let at = crate::klems::KlemsPatchRef { side, patch };
            let theta = bsdf.basis.patch(patch).map_or(f64::NAN, |p| p.theta_deg);
            if klems.incidences.as_ref().is_some_and(|f| !f.keeps(theta)) {
                continue;
            }
            let label = format!("{source} [{side} patch {patch}]");
            let Some(mut prepared) = crate::klems::prepare_patch_sharing(
                recipe,
                &bsdf,
                at,
                &label,
                directions.as_ref(),
            )?
            else {
                continue;
            };
            prepared.source = label;
            let samples = prepared.measurement.len();
            inputs.push(input(prepared, samples, Some(at)));
        }
        return Ok(inputs);
    };
    let measurement = measurement?;
    let samples = measurement.len();
    let prepared = recipe.prepare(measurement, &source)?;
    Ok(vec![input(prepared, samples, None)])
}

/// Rebuilds the fitted data of one input file of a fit, from the file's
/// bytes and the fit's recipe, exactly as the fit made it: what plots and
/// checks use.
pub fn prepare_input(
    recipe: &Recipe,
    input: &InputFile,
    bytes: &[u8],
    path: &Path,
) -> Result<PreparedMeasurement, FitSetError> {
    match input.klems {
        Some(_) => prepare_inputs_of_xml(recipe, &[input], bytes, path)?
            .pop()
            .ok_or(FitSetError::NoIncidences),
        None => {
            let measurement = brtf_gonio::read_bytes(bytes, path)?;
            Ok(recipe.prepare(measurement, &input.path)?)
        }
    }
}

/// [`prepare_input`] of several incidences of one BSDF XML file, read
/// once (a Klems side has 145: parsing the file for each took most of the
/// side-by-side report's time), in parallel and in order.
pub fn prepare_inputs_of_xml(
    recipe: &Recipe,
    inputs: &[&InputFile],
    bytes: &[u8],
    path: &Path,
) -> Result<Vec<PreparedMeasurement>, FitSetError> {
    let xml = brtf_gonio::klems::read_any_bytes(bytes, path)?;
    let directions = match (&xml, recipe.patch_average) {
        (brtf_gonio::klems::BsdfXml::Klems(bsdf), Some(rule)) => {
            Some(crate::klems::PatchDirections::new(&bsdf.basis, &rule))
        }
        _ => None,
    };
    inputs
        .par_iter()
        .map(|input| {
            let label = input.label();
            let at = input.klems.ok_or(FitSetError::NoIncidences)?;
            let prepared = match &xml {
                brtf_gonio::klems::BsdfXml::Klems(bsdf) => crate::klems::prepare_patch_sharing(
                    recipe,
                    bsdf,
                    at,
                    &label,
                    directions.as_ref(),
                )?,
                brtf_gonio::klems::BsdfXml::TensorTree(tree) => crate::ttree::prepare_incidence(
                    recipe,
                    tree,
                    at.side,
                    input.theta_in,
                    input.phi_in,
                    &label,
                )?,
            };
            let mut prepared = prepared.ok_or(FitSetError::NoIncidences)?;
            prepared.source = label;
            Ok(prepared)
        })
        .collect()
}

/// A warning when `rho` equals, to its printed digits, a number of one of
/// the header's integrals (`#integrated_value`, `#front_integral`, …):
/// detector integrals a user may take for a reflectance.
fn rho_from_header(prepared: &PreparedMeasurement, rho: f64) -> Option<SetWarning> {
    let unit = match &prepared.conversion {
        crate::Conversion::Raw { unit, .. } => unit.clone(),
        _ => return None,
    };
    // Of the numbers it matches, the one written with the most digits.
    let pairs = prepared.measurement.header_pairs();
    let (key, value, _) = pairs
        .iter()
        .filter(|(key, _)| key.contains("integral") || key.contains("integrated"))
        .flat_map(|(key, value)| value.split_whitespace().map(move |word| (key, word)))
        .filter_map(|(key, word)| {
            let number = word.parse::<f64>().ok()?;
            let decimals = word.split_once('.').map_or(0, |(_, d)| d.len()) as i32;
            let close = (number - rho).abs() < 0.5 * 10f64.powi(-decimals) * (1.0 + 1e-9);
            close.then_some((key, word, decimals))
        })
        .max_by_key(|m| m.2)?;
    Some(SetWarning::RhoFromHeader {
        rho,
        key: key.clone(),
        value: value.to_string(),
        unit,
    })
}

/// K such that the data ÷ K have the reflectance `rho` at their incidence:
/// the data's own raw-unit ρ_dh (measured directions from the data, the
/// unmeasured rest from the free-scale fit `report`) ÷ `rho`.
fn instrument_scale(
    config: &FitConfig,
    prepared: &PreparedMeasurement,
    data: &IncidenceData,
    report: &FitReport,
    rho: f64,
) -> Result<f64, FitSetError> {
    let bsdf = diagnose::fitted_bsdf(config, report).ok_or_else(|| {
        FitSetError::Fit(FitError::Failed {
            origin: report.source.clone(),
            reason: "the fitted arguments are not a valid material".into(),
        })
    })?;
    let (rho_model, _) = diagnose::model_albedo(prepared, &bsdf);
    let measured = diagnose::measured_integrals(prepared, data, &bsdf, report.scale);
    let (data, model) = measured.front.unwrap_or((0.0, 0.0));
    let k = (data + report.scale * rho_model - model) / rho;
    if k.is_finite() && k > 0.0 {
        Ok(k)
    } else {
        Err(FitSetError::NoReflectance(report.theta_in))
    }
}

/// Every incidence fitted again with the other residual kind (see
/// [`diagnose::other_residual`]) and no robust loss: the adequacy
/// diagnostics' second fit. `None` where that fit fails.
fn other_fits(
    data: &[IncidenceData],
    geometry: &[SharedGeometry],
    config: &FitConfig,
    progress: &dyn Progress,
) -> Vec<Option<FitReport>> {
    let mut other_config = config.clone();
    other_config.residual = diagnose::other_residual(config.residual);
    other_config.loss = crate::RobustLoss::None;
    data.par_iter()
        .zip(geometry)
        .map(|(d, g)| {
            let r = (!progress.cancelled())
                .then(|| fit_incidence_sharing(d, &other_config, g).ok())
                .flatten();
            progress.advance();
            r
        })
        .collect()
}

/// The energy and peak diagnostics of every incidence's fit (see
/// [`diagnose::diagnose`]), in parallel.
fn diagnose_all(
    inputs: &[Input],
    data: &[IncidenceData],
    reports: &[FitReport],
    config: &FitConfig,
) -> Vec<Option<crate::adequacy::Adequacy>> {
    inputs
        .par_iter()
        .zip(data)
        .zip(reports)
        .map(|((input, data), report)| diagnose::diagnose(&input.prepared, data, report, config))
        .collect()
}

/// Completes the adequacy diagnostics of every incidence (`adequacy`,
/// from [`diagnose_all`]) with the fits made with the other residual kind
/// (`others`, from [`other_fits`] on the same data), and adds their
/// warnings.
fn assess(
    reports: &mut [FitReport],
    config: &FitConfig,
    adequacy: Vec<Option<crate::adequacy::Adequacy>>,
    others: Vec<Option<FitReport>>,
) {
    let other = diagnose::other_residual(config.residual);
    for ((report, adequacy), other_fit) in reports.iter_mut().zip(adequacy).zip(others) {
        let Some(mut adequacy) = adequacy else {
            continue;
        };
        adequacy.residual_check = other_fit.and_then(|o| diagnose::compare(report, &o, other));
        report.warnings.extend(diagnose::warnings(&adequacy));
        report.adequacy = Some(adequacy);
    }
}

/// The fitter's view of every input (see
/// [`PreparedMeasurement::incidence_data`]), in parallel.
fn incidence_data(inputs: &[Input]) -> Vec<IncidenceData> {
    inputs
        .par_iter()
        .map(|i| i.prepared.incidence_data())
        .collect()
}

/// The progress steps of [`fit_all`] on `incidences` incidences.
fn fit_all_steps(incidences: usize) -> usize {
    incidences + 1
}

/// Fits every incidence and all of them at once, in parallel. The caller
/// begins and ends the progress ([`fit_all_steps`] steps).
fn fit_all(
    data: &[IncidenceData],
    geometry: &[SharedGeometry],
    config: &FitConfig,
    progress: &dyn Progress,
) -> Result<(Vec<FitReport>, FitReport), FitSetError> {
    let (reports, global) = rayon::join(
        || {
            data.par_iter()
                .enumerate()
                .map(|(i, d)| {
                    if progress.cancelled() {
                        return Err(FitError::Interrupted);
                    }
                    let r = fit_incidence_sharing(d, config, &geometry[i]);
                    // A fit stopped inside its solve ended anywhere.
                    if progress.cancelled() || config.stop.is_raised() {
                        return Err(FitError::Interrupted);
                    }
                    progress.advance();
                    r
                })
                .collect::<Vec<_>>()
        },
        || {
            // With one incidence the all-incidence fit is that fit.
            if data.len() < 2 {
                return None;
            }
            // Once begun it runs to its end (on a thread of its own when
            // there are two).
            if progress.cancelled() {
                return Some(Err(FitError::Interrupted));
            }
            let r = fit_global_sharing(data, config, geometry);
            if progress.cancelled() || config.stop.is_raised() {
                return Some(Err(FitError::Interrupted));
            }
            progress.advance();
            Some(r)
        },
    );
    let reports = reports.into_iter().collect::<Result<Vec<_>, _>>()?;
    let global = match global {
        Some(g) => g?,
        None => FitReport {
            source: "all incidences".into(),
            ..reports[0].clone()
        },
    };
    Ok((reports, global))
}

/// The all-incidence fit beside per-incidence `reports` made already
/// (with one incidence, that incidence's fit).
fn global_fit(
    data: &[IncidenceData],
    geometry: &[SharedGeometry],
    config: &FitConfig,
    reports: &[FitReport],
) -> Result<FitReport, FitSetError> {
    if data.len() < 2 {
        return Ok(FitReport {
            source: "all incidences".into(),
            ..reports[0].clone()
        });
    }
    Ok(fit_global_sharing(data, config, geometry)?)
}
