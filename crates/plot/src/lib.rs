//! # brtf-plot: residual plots and the report of a brtf fit
//!
//! Reads a fit ([`brtf_fit::FitResult`], the fit folder's `fit.json`) and
//! the measurement files it names, rebuilds the data exactly as `brtf fit`
//! compared them (conversion to BSDF, free scale, selections; see
//! [`prepare`]), and draws, as SVG and PNG each, into `<fit folder>/plots/`:
//!
//! | file | what |
//! |---|---|
//! | `map-<tag>` | per incidence: model ÷ data over the hemisphere, equal-area disk, diverging colour bar; light, mirror, beam mask, θ cap and unfitted samples marked |
//! | `cut-<tag>` | per incidence: the plane of incidence, data and model on a log axis, masked ranges shaded |
//! | `params` | every fitted parameter over θ_in with ±1 standard error, the θ_in interpolation and the all-incidence fit |
//! | `rho` | ρ_dh (and τ_dh) over θ_in: data against model |
//! | `rms` | the error of every incidence's fit |
//! | `cuts` | every incidence's cut in one chart |
//!
//! A fit of one incidence has no `params`, `rho`, `rms` or `cuts`: each
//! would show that incidence alone. The report says so in their place.
//!
//! `<tag>` is `t<θ_in>` (e.g. `t30`, `t26.8421`), with `-p<φ_in>` when
//! φ_in ≠ 0 or θ_in repeats. Then it writes `<fit folder>/report.html`,
//! which shows all of them with the parameter table, the exported
//! material text and the provenance, and needs nothing but a browser.
//!
//! Text is drawn with the DejaVu Sans font embedded in the binary (plotters
//! with `ab_glyph`, no fontconfig), so plotting works on a bare machine.
//! Every file is written atomically (temporary file + rename).
//!
//! A measurement file that cannot be found or read does not stop the
//! plots: that incidence's map and cut are skipped and the report says
//! why ([`Written::warnings`]).
//!
//! ```no_run
//! let dir = std::path::Path::new("fits/alu-ggx");
//! let result = brtf_plot::read_fit(dir)?;
//! let written = brtf_plot::write_plots(dir, &result, &brtf_plot::PlotOptions::default())?;
//! for w in &written.warnings {
//!     eprintln!("warning: {w}");
//! }
//! # Ok::<(), brtf_plot::PlotError>(())
//! ```

mod charts;
mod colour;
mod disk;
mod error;
mod figure;
mod klems;
mod prepare;
mod report;
mod viewer;

pub use error::PlotError;
pub use klems::klems_sides_report;
/// HTML-escapes text (`&`, `<`, `>`, `"`, `'`).
pub use report::esc as escape;

/// The pieces the criterion benches time one by one; not brtf-plot's API.
#[doc(hidden)]
pub mod bench {
    pub use crate::charts::map::MapChart;
    pub use crate::disk::{COVERAGE_SIZE, Coverage, FILL_DEG, project, radius_of};
    pub use crate::figure::{render_png, render_svg};
    pub use crate::prepare::load;
}

use brtf_fit::{FitResult, PreparedMeasurement};
use charts::azimuth::AzimuthChart;
use charts::cut::{CutChart, CutsChart};
use charts::map::MapChart;
use charts::theta::{ParamsChart, RhoChart, RmsChart};
use figure::{Chart, render_files, write_atomic};
use prepare::{DataUnit, Incidence};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// Ratios offered for the ends of the map's colour bar.
const NICE_RATIOS: [f64; 10] = [1.05, 1.1, 1.2, 1.5, 2.0, 3.0, 5.0, 10.0, 30.0, 100.0];

/// How to plot.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PlotOptions {
    /// Extra folders in which to look for measurement files whose recorded
    /// path is relative (besides the current folder, the fit folder and
    /// its ancestors).
    pub search_dirs: Vec<PathBuf>,
    /// The model ÷ data ratio `k > 1` at the ends of the maps' colour bar;
    /// `None` picks the smallest of 1.05, 1.1, 1.2, 1.5, 2, 3, 5, 10, 30,
    /// 100 that holds 95% of the fitted samples of every incidence.
    pub ratio: Option<f64>,
    /// Largest angle (degrees) between a sample and the plane of incidence
    /// for the cuts; `None` picks the smallest of 0.25–3° that gives 60
    /// fitted samples.
    pub plane_tolerance_deg: Option<f64>,
    /// Draw each incidence's map and cut: `None` draws them except for
    /// patch-averaged data (a Klems side's 145 incidences would give 290
    /// charts, most of the run's time and memory; its report's 3D view
    /// shows every incidence).
    pub incidence_charts: Option<bool>,
}

/// What [`write_plots`] wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct Written {
    /// Every file written: the plots (SVG and PNG) and the report.
    pub files: Vec<PathBuf>,
    /// `<dir>/report.html`.
    pub report: PathBuf,
    /// Plots that were skipped or may mislead, and why (also in the report).
    pub warnings: Vec<String>,
}

/// Reads `<dir>/fit.json` (see [`FitResult::read`]).
pub fn read_fit(dir: &Path) -> Result<FitResult, PlotError> {
    Ok(FitResult::read(&dir.join("fit.json"))?)
}

/// The colour-bar ratio for the maps (see [`PlotOptions::ratio`]).
fn auto_ratio(incs: &[&Incidence]) -> f64 {
    let mut all: Vec<f64> = incs
        .iter()
        .flat_map(|i| {
            i.samples
                .iter()
                .filter(|s| s.used())
                .map(|s| i.log_ratio(s).abs())
        })
        .filter(|v| v.is_finite())
        .collect();
    if all.is_empty() {
        return 2.0;
    }
    let k = ((all.len() - 1) as f64 * 0.95) as usize;
    let q = *all.select_nth_unstable_by(k, f64::total_cmp).1;
    NICE_RATIOS
        .into_iter()
        .find(|r| r.ln() >= q)
        .unwrap_or(NICE_RATIOS[NICE_RATIOS.len() - 1])
}

/// Median of |model ÷ data − 1| over the fitted samples (via the log ratio).
fn median_deviation(inc: &Incidence) -> Option<f64> {
    let mut v: Vec<f64> = inc
        .samples
        .iter()
        .filter(|s| s.used())
        .map(|s| inc.log_ratio(s).abs())
        .collect();
    if v.is_empty() {
        return None;
    }
    let k = v.len() / 2;
    Some(v.select_nth_unstable_by(k, f64::total_cmp).1.exp() - 1.0)
}

/// One of the charts to draw.
enum Job<'a> {
    Map(MapChart<'a>),
    Cut(CutChart<'a>),
    Cuts(CutsChart<'a>),
    Params(ParamsChart<'a>),
    Azimuth(AzimuthChart<'a>),
    Rho(RhoChart<'a>),
    Rms(RmsChart<'a>),
}

impl Job<'_> {
    /// The chart reads the incidences' nearest-sample grids.
    fn needs_coverage(&self) -> bool {
        matches!(self, Job::Map(_) | Job::Rho(_))
    }

    /// Where the job goes in a pass, longest first (as measured on a
    /// 127k-point scan: a map ~7 ms, the parameter charts ~4, a cut ~3,
    /// the others less), so that no long chart starts last and runs alone.
    fn rank(&self) -> u8 {
        match self {
            Job::Map(_) => 0,
            Job::Params(_) | Job::Azimuth(_) => 1,
            Job::Cuts(_) => 2,
            Job::Cut(_) => 3,
            Job::Rho(_) => 4,
            Job::Rms(_) => 5,
        }
    }

    fn render(&self, dir: &Path) -> Result<Vec<(PathBuf, Vec<u8>)>, PlotError> {
        match self {
            Job::Map(c) => {
                // Made once: a no-op when the grids' pass made it already.
                c.prepare();
                render_files(c, dir)
            }
            Job::Cut(c) => render_files(c, dir),
            Job::Cuts(c) => render_files(c, dir),
            Job::Params(c) => render_files(c, dir),
            Job::Azimuth(c) => render_files(c, dir),
            Job::Rho(c) => render_files(c, dir),
            Job::Rms(c) => render_files(c, dir),
        }
    }
}

/// Threads that write files: most of a write is waiting for the disk to
/// sync, so several run at once and the syncs overlap.
const WRITERS: usize = 4;

/// Renders every job and writes its files, then `last` (the report) once
/// every job rendered; returns the paths in `jobs` order, then `last`'s.
/// The files are written by threads of their own, so that rendering never
/// waits for the disk (each write syncs). `grids`, if any, makes the
/// nearest-sample grids, at the same time as the charts that do not need
/// them; the maps and the reflectance chart render after it. Without it
/// (the grids are made) every chart renders in one pass.
fn render_and_write(
    jobs: &[Job],
    dir: &Path,
    last: (PathBuf, Vec<u8>),
    grids: Option<&(dyn Fn() + Sync)>,
) -> Result<Vec<PathBuf>, PlotError> {
    let (send, receive) = std::sync::mpsc::channel::<(PathBuf, Vec<u8>)>();
    let receive = std::sync::Mutex::new(receive);
    // After the first failure nothing more is written.
    let failed = std::sync::atomic::AtomicBool::new(false);
    std::thread::scope(|scope| {
        let writers: Vec<_> = (0..WRITERS)
            .map(|_| {
                scope.spawn(|| {
                    let mut outcome = Ok(());
                    loop {
                        let next = receive.lock().unwrap_or_else(|e| e.into_inner()).recv();
                        let Ok((path, bytes)) = next else {
                            return outcome;
                        };
                        if !failed.load(std::sync::atomic::Ordering::Relaxed) {
                            outcome = write_atomic(&path, &bytes);
                            if outcome.is_err() {
                                failed.store(true, std::sync::atomic::Ordering::Relaxed);
                            }
                        }
                    }
                })
            })
            .collect();
        let render = |job: &Job| -> Result<Vec<PathBuf>, PlotError> {
            let files = job.render(dir)?;
            let paths = files.iter().map(|(p, _)| p.clone()).collect();
            for file in files {
                // The writers only stop early on a failure, reported below.
                let _ = send.send(file);
            }
            Ok(paths)
        };
        // The charts `pass` selects, each with its place in `jobs`: one
        // task each, handed out longest first.
        let pass = |select: &(dyn Fn(&Job) -> bool + Sync)| -> Vec<(usize, Result<Vec<PathBuf>, PlotError>)> {
            let mut order: Vec<usize> = (0..jobs.len()).filter(|&k| select(&jobs[k])).collect();
            order.sort_by_key(|&k| jobs[k].rank());
            order
                .par_iter()
                .with_max_len(1)
                .map(|&k| (k, render(&jobs[k])))
                .collect()
        };
        // The maps' colours and numbers (they do not need the grids), made
        // before any chart renders: both renderings of a map read them.
        let prepare_maps = || {
            for job in jobs {
                if let Job::Map(map) = job {
                    map.prepare();
                }
            }
        };
        let mut done = match grids {
            // First the charts without grids, beside the grids, then the
            // rest.
            Some(grids) => {
                let (mut done, ()) = rayon::join(
                    || {
                        prepare_maps();
                        pass(&|job| !job.needs_coverage())
                    },
                    grids,
                );
                done.extend(pass(&|job| job.needs_coverage()));
                done
            }
            // Each map's colours are made by its own job.
            None => pass(&|_| true),
        };
        done.sort_by_key(|(k, _)| *k);
        let rendered: Result<Vec<Vec<PathBuf>>, PlotError> =
            done.into_iter().map(|(_, paths)| paths).collect();
        let last_path = last.0.clone();
        if rendered.is_ok() {
            let _ = send.send(last);
        }
        drop(send);
        let mut written = Ok(());
        for writer in writers {
            let outcome = writer
                .join()
                .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
            if written.is_ok() {
                written = outcome;
            }
        }
        let mut files: Vec<PathBuf> = rendered?.into_iter().flatten().collect();
        written?;
        files.push(last_path);
        Ok(files)
    })
}

/// Draws every plot of `result` into `<dir>/plots/` and writes
/// `<dir>/report.html` (see the crate docs). `dir` is the fit folder: the
/// report embeds the `.rad` files found there and links `fit.json` and
/// `params.csv`. Plots of an earlier run that this run did not draw again
/// (`map-*`, `cut-*`, the charts over θ_in) are removed.
pub fn write_plots(
    dir: &Path,
    result: &FitResult,
    options: &PlotOptions,
) -> Result<Written, PlotError> {
    plot(dir, result, &[], options)
}

/// [`write_plots`] on the data the fit fitted (`prepared[k]` for
/// `result.incidences[k]`, as [`brtf_fit::fit_set_with_data`] returns
/// them) instead of reading and preparing the measurement files again.
/// Incidences without an entry in `prepared` are read from their files.
pub fn write_plots_with_data(
    dir: &Path,
    result: &FitResult,
    prepared: &[PreparedMeasurement],
    options: &PlotOptions,
) -> Result<Written, PlotError> {
    plot(dir, result, prepared, options)
}

fn plot(
    dir: &Path,
    result: &FitResult,
    prepared: &[PreparedMeasurement],
    options: &PlotOptions,
) -> Result<Written, PlotError> {
    if result.incidences.is_empty() {
        return Err(PlotError::NoIncidences);
    }
    let plots = dir.join("plots");
    let tags = prepare::tags(&result.incidences);
    // The fitted data's nearest-sample grids need only the directions and
    // the selection: they are made while the incidences are built (the
    // model beside every sample). Nothing here is made on first use, so
    // no thread waits for another's lazy value inside the joins.
    // A Klems side's maps and cuts are drawn on request only.
    let incidence_charts = options
        .incidence_charts
        .unwrap_or(result.recipe.patch_average.is_none());
    let (loaded, grids): (Vec<Result<Incidence, String>>, Vec<_>) = rayon::join(
        || load_all(dir, result, prepared, options),
        || {
            // Without maps, only the hemispherical integrals read the
            // grids: each is made there and dropped.
            let wanted = if incidence_charts { prepared.len() } else { 0 };
            prepared
                .par_iter()
                .take(wanted)
                .take(result.incidences.len())
                .map(prepare::grids_of_prepared)
                .collect()
        },
    );
    for (inc, grids) in loaded.iter().zip(grids) {
        if let Ok(inc) = inc {
            inc.set_grids(grids);
        }
    }
    let mut warnings: Vec<String> = Vec::new();
    for l in &loaded {
        match l {
            Ok(inc) => warnings.extend(inc.warnings.iter().cloned()),
            Err(why) => warnings.push(why.clone()),
        }
    }
    let incs: Vec<&Incidence> = loaded.iter().filter_map(|l| l.as_ref().ok()).collect();
    let by_index: Vec<Option<&Incidence>> = loaded.iter().map(|l| l.as_ref().ok()).collect();
    // Two passes over every fitted sample, at the same time.
    let (ratio, medians) = rayon::join(
        || map_ratio(options, &incs),
        || -> Vec<Option<f64>> {
            by_index
                .par_iter()
                .map(|i| i.and_then(median_deviation))
                .collect()
        },
    );
    let unit = incs.first().map_or_else(
        || {
            if result.config.free_scale {
                DataUnit::RawPerCos("data unit".into())
            } else {
                DataUnit::Bsdf
            }
        },
        |i| i.unit.clone(),
    );
    let channels = incs.first().map_or(1, |i| i.channels);
    let name = &result.name;
    // The type, or the lobe sum's label (`metal ×2 lobes`).
    let model = result.config.shape().label();

    let mut jobs: Vec<Job> = Vec::new();
    for inc in incs.iter().filter(|_| incidence_charts) {
        let report = &result.incidences[inc.index];
        let label = charts::incidence_label(inc.theta_in, inc.phi_in);
        let mut map = MapChart::new(inc, String::new(), ratio, report.rms_rel);
        map.title = title(
            &map,
            name,
            format!(" ({model}), {label}: model ÷ data over the hemisphere"),
        );
        jobs.push(Job::Map(map));
        let mut cut = CutChart {
            inc,
            title: String::new(),
            tolerance: options.plane_tolerance_deg,
        };
        cut.title = title(
            &cut,
            name,
            format!(" ({model}), {label}: cut through the plane of incidence"),
        );
        jobs.push(Job::Cut(cut));
    }
    // With one incidence every chart over θ_in would hold one point, and
    // the chart of all cuts would repeat its cut: none is drawn, and the
    // report says why.
    let mut overview = Vec::new();
    if result.incidences.len() >= 2 {
        overview_charts(
            &mut jobs,
            &mut overview,
            Overview {
                result,
                incs: &incs,
                by_index: &by_index,
                unit,
                channels,
                medians,
                tolerance: options.plane_tolerance_deg,
            },
        );
    }
    let entries = result
        .incidences
        .iter()
        .zip(&loaded)
        .zip(&tags)
        .map(|((report, l), tag)| {
            let data = l.as_ref().map_err(String::as_str);
            let charts = match data {
                Ok(inc) if incidence_charts => {
                    let map = MapChart::new(inc, String::new(), ratio, report.rms_rel);
                    let cut = CutChart {
                        inc,
                        title: String::new(),
                        tolerance: None,
                    };
                    vec![
                        (map.name(), map.size(), "model ÷ data over the hemisphere"),
                        (cut.name(), cut.size(), "cut through the plane of incidence"),
                    ]
                }
                _ => Vec::new(),
            };
            report::IncidenceEntry {
                report,
                tag: tag.clone(),
                data,
                charts,
            }
        })
        .collect();
    let html = report::html(&report::ReportInput {
        dir,
        result,
        overview,
        incidences: entries,
        warnings: &warnings,
        ratio,
        view: viewer::html(result, &incs, ratio, "view3d-viewer"),
        no_incidence_charts: (!incidence_charts).then(|| {
            format!(
                "Each incidence's map and cut are not drawn for patch-averaged data ({} \
                 incidences): the 3D view above shows every incidence; `brtf plot {} \
                 --incidence-charts` draws them.",
                result.incidences.len(),
                dir.display()
            )
        }),
    });
    // The report is written with the plots' files, once they all rendered.
    let report_path = dir.join("report.html");
    // Every grid a chart asks for (a map without fitted samples draws an
    // empty front disk).
    let wanted = Incidence::drawn_hemispheres;
    let grids = || {
        incs.par_iter().for_each(|inc| {
            for hemisphere in wanted(inc) {
                inc.coverage(hemisphere);
            }
        })
    };
    let made = !incidence_charts
        || incs
            .iter()
            .all(|inc| wanted(inc).into_iter().all(|h| inc.has_grid(h)));
    let files = render_and_write(
        &jobs,
        &plots,
        (report_path.clone(), html.into_bytes()),
        (!made).then_some(&grids as &(dyn Fn() + Sync)),
    )?;
    remove_stale(&plots, &files);
    Ok(Written {
        files,
        report: report_path,
        warnings,
    })
}

/// The report's 3D view of the fit in `dir` as one self-contained HTML
/// block (styles, data and script inlined), for a notebook cell or a page
/// of one's own: the measurement files are read again as
/// [`write_plots`] reads them. Each call's block has an id of its own, so
/// several can share a page.
pub fn view_html(
    dir: &Path,
    result: &FitResult,
    options: &PlotOptions,
) -> Result<String, PlotError> {
    if result.incidences.is_empty() {
        return Err(PlotError::NoIncidences);
    }
    let loaded = load_all(dir, result, &[], options);
    let incs: Vec<&Incidence> = loaded.iter().filter_map(|l| l.as_ref().ok()).collect();
    if incs.is_empty() {
        let why = loaded.into_iter().find_map(Result::err).unwrap_or_default();
        return Err(PlotError::NoData(why));
    }
    let ratio = map_ratio(options, &incs);
    static VIEWS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let serial = VIEWS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.subsec_nanos());
    let id = format!("brtf-view-{}-{nanos:x}-{serial}", std::process::id());
    Ok(format!(
        "<style>{}</style>{}",
        viewer::STYLE,
        viewer::html(result, &incs, ratio, &id)
    ))
}

/// Every incidence of `result` with the model beside its samples: from
/// `prepared[k]` when given, else read from its file; or why not.
fn load_all(
    dir: &Path,
    result: &FitResult,
    prepared: &[PreparedMeasurement],
    options: &PlotOptions,
) -> Vec<Result<Incidence, String>> {
    let tags = prepare::tags(&result.incidences);
    (0..result.incidences.len())
        .into_par_iter()
        .map(|k| match prepared.get(k) {
            Some(data) => prepare::from_prepared(result, k, tags[k].clone(), data),
            None => prepare::load(result, k, tags[k].clone(), dir, &options.search_dirs),
        })
        .collect()
}

/// The maps' colour-bar ratio: `--ratio`, else [`auto_ratio`].
fn map_ratio(options: &PlotOptions, incs: &[&Incidence]) -> f64 {
    options
        .ratio
        .filter(|r| r.is_finite() && *r > 1.0)
        .unwrap_or_else(|| auto_ratio(incs))
}

/// `name` then `rest` as `chart`'s title, the name shortened to fit the
/// chart's width ([`charts::fit_title`]).
fn title(chart: &impl Chart, name: &str, rest: String) -> String {
    charts::fit_title(name, &rest, chart.size().0)
}

/// What the charts over θ_in (and the chart of all cuts) are drawn from.
struct Overview<'a, 'b> {
    result: &'a FitResult,
    /// The incidences with data.
    incs: &'b [&'a Incidence],
    /// Incidence k's data, if read.
    by_index: &'b [Option<&'a Incidence>],
    unit: DataUnit,
    channels: usize,
    /// Median |model ÷ data − 1| per incidence.
    medians: Vec<Option<f64>>,
    /// Forced plane tolerance of the cuts, degrees.
    tolerance: Option<f64>,
}

/// Adds the charts over θ_in (and φ_in), and the chart of all cuts, to
/// `jobs`, and their `(stem, size, caption)` to `overview`, in the
/// report's order.
fn overview_charts<'a>(
    jobs: &mut Vec<Job<'a>>,
    overview: &mut Vec<(String, (u32, u32), String)>,
    o: Overview<'a, '_>,
) {
    let result = o.result;
    let name = &result.name;
    let model = result.config.shape().label();
    let mut params = ParamsChart {
        result,
        unit: o.unit.clone(),
        title: String::new(),
    };
    params.title = title(
        &params,
        name,
        format!(" ({model}): fitted parameters over θ_in"),
    );
    let mut rho = RhoChart {
        result,
        incs: o.by_index.to_vec(),
        integrals: Default::default(),
        unit: o.unit,
        channels: o.channels,
        title: String::new(),
    };
    rho.title = title(
        &rho,
        name,
        format!(" ({model}): hemispherical reflectance, data against model"),
    );
    let mut rms = RmsChart {
        result,
        medians: o.medians,
        title: String::new(),
    };
    rms.title = title(
        &rms,
        name,
        format!(" ({model}): error of each incidence's fit"),
    );
    overview.extend([
        (
            params.name(),
            params.size(),
            "Fitted parameters over θ_in: dots with ±1 standard-error bars per incidence, the θ_in \
             interpolation the exported material uses, and the all-incidence fit (dashed)."
                .to_string(),
        ),
        (
            rho.name(),
            rho.size(),
            "Directional-hemispherical reflectance: the data summed over the fitted samples, the model \
             over the same samples, and the model over the whole hemisphere."
                .to_string(),
        ),
        (
            rms.name(),
            rms.size(),
            "Error per incidence: the fit's RMS relative error and the median |model ÷ data − 1|."
                .to_string(),
        ),
    ]);
    jobs.push(Job::Params(params));
    if AzimuthChart::applies(result) {
        let mut azimuth = AzimuthChart {
            result,
            title: String::new(),
        };
        azimuth.title = title(
            &azimuth,
            name,
            format!(" ({model}): fitted parameters over φ_in, one line per θ_in ring"),
        );
        overview.insert(
            1,
            (
                azimuth.name(),
                azimuth.size(),
                "The parameters follow φ_in too: each θ_in ring's incidences (dots) and the linear, \
                 periodic interpolation between them that the exports use (lines)."
                    .to_string(),
            ),
        );
        jobs.push(Job::Azimuth(azimuth));
    }
    jobs.push(Job::Rho(rho));
    jobs.push(Job::Rms(rms));
    if !o.incs.is_empty() {
        let mut cuts = CutsChart {
            incs: o.incs.to_vec(),
            title: String::new(),
            tolerance: o.tolerance,
        };
        cuts.title = title(
            &cuts,
            name,
            format!(" ({model}): in-plane cuts of every incidence (dots: data, lines: model)"),
        );
        overview.push((
            cuts.name(),
            cuts.size(),
            "Every incidence's cut through its plane of incidence: fitted data near the plane (dots) and the \
             fitted model (lines), one colour per incidence."
                .to_string(),
        ));
        jobs.push(Job::Cuts(cuts));
    }
}

/// The charts drawn once per fit (not per incidence), by file stem.
const OVERVIEW_STEMS: [&str; 5] = ["params", "params-phi", "rho", "rms", "cuts"];

/// Removes plots that this run did not write: `map-*` and `cut-*` of
/// incidences no longer in the fit, and the charts of the whole fit it
/// did not draw (a fit of one incidence, a table that does not follow φ_in).
fn remove_stale(plots: &Path, written: &[PathBuf]) {
    let Ok(entries) = std::fs::read_dir(plots) else {
        return;
    };
    for e in entries.filter_map(|e| e.ok()) {
        let path = e.path();
        let name = e.file_name().to_string_lossy().into_owned();
        let Some(stem) = name
            .strip_suffix(".svg")
            .or_else(|| name.strip_suffix(".png"))
        else {
            continue;
        };
        let ours =
            stem.starts_with("map-") || stem.starts_with("cut-") || OVERVIEW_STEMS.contains(&stem);
        if ours && !written.contains(&path) {
            let _ = std::fs::remove_file(&path);
        }
    }
}
