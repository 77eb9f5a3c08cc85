//! brtf-plot benchmarks on the real 127 039-point pgII scan
//! `golden_paper.txt` (read from `../shared/data`, never copied into the
//! repository), fitted once with `metal --gray` as `brtf fit` does by
//! default:
//!
//! * `plots/write_plots_with_data`: everything `brtf fit` adds for its
//!   plots (the model beside every fitted sample, every SVG and PNG,
//!   `report.html`), on the data the fit fitted, into a temporary folder.
//!   The target is 40 ms.
//! * `plots/write_plots`: the same as `brtf plot` does it, with the file
//!   read again and rebuilt with the fit's recipe.
//! * `plots/load`: only the rebuild of the data (`brtf_plot::bench::load`,
//!   the model beside every sample; the nearest-sample grids are made on
//!   first use, by `write_plots` beside the charts that do not need them).
//! * `plots/coverage`: the nearest-sample grid of the front disk
//!   (`brtf_plot::bench::Coverage`), which the map and the reflectance
//!   chart share.
//! * `plots/map_png`, `plots/map_svg`: the residual map alone, on data
//!   loaded afresh each time (outside the timing; the grid of the front
//!   disk, made on first use, inside it).

use brtf_fit::{FitConfig, FitSetOptions, NoProgress, Recipe};
use brtf_gonio::Hemisphere;
use brtf_model::MaterialKind;
use brtf_plot::PlotOptions;
use brtf_plot::bench::{self, MapChart};
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

fn golden_path() -> PathBuf {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data/rgl-epfl-pgII-raw/golden_paper.txt");
    assert!(
        path.is_file(),
        "{} is missing: the benchmark needs the shared data folder beside the repository",
        path.display()
    );
    path
}

/// The fit of `brtf fit golden_paper.txt --model metal --gray` with its
/// fitted data (made once).
fn fitted() -> &'static brtf_fit::FittedSet {
    static FIT: OnceLock<brtf_fit::FittedSet> = OnceLock::new();
    FIT.get_or_init(|| {
        let kind = MaterialKind::Metal;
        let mut config = FitConfig::new(kind);
        config.gray = true;
        let options = FitSetOptions {
            name: "golden_paper".into(),
            config,
            recipe: Recipe::for_kind(kind),
            known_reflectance: None,
            interpolation: Default::default(),
            command_line: vec!["bench".into()],
            adequacy: true,
            klems: Default::default(),
            auto: false,
        };
        brtf_fit::fit_set_with_data(&[golden_path()], &options, &NoProgress).expect("the scan fits")
    })
}

fn plots(c: &mut Criterion) {
    let set = fitted();
    let result = &set.result;
    let options = PlotOptions::default();
    let out = tempfile::tempdir().unwrap();
    let mut group = c.benchmark_group("plots");
    group.sample_size(20);
    group.bench_function("write_plots_with_data", |b| {
        b.iter(|| {
            brtf_plot::write_plots_with_data(out.path(), black_box(result), &set.prepared, &options)
                .unwrap()
        })
    });
    group.bench_function("write_plots", |b| {
        b.iter(|| brtf_plot::write_plots(out.path(), black_box(result), &options).unwrap())
    });
    group.bench_function("load", |b| {
        b.iter(|| bench::load(result, 0, "t".into(), out.path(), &[]).unwrap())
    });
    let inc = bench::load(result, 0, "t".into(), out.path(), &[]).unwrap();
    let (ids, points): (Vec<u32>, Vec<(f64, f64)>) = inc
        .samples
        .iter()
        .enumerate()
        .filter(|(_, s)| s.hemisphere() == Hemisphere::Front)
        .map(|(k, s)| (k as u32, bench::project(s.dir, Hemisphere::Front)))
        .unzip();
    group.bench_function("coverage", |b| {
        b.iter(|| {
            bench::Coverage::new(
                black_box(&points),
                &ids,
                bench::COVERAGE_SIZE,
                bench::radius_of(bench::FILL_DEG),
            )
        })
    });
    group.bench_function("map_png", |b| {
        b.iter_batched(
            || bench::load(result, 0, "t".into(), out.path(), &[]).unwrap(),
            |inc| {
                let map = MapChart::new(&inc, "map".into(), 2.0, 0.1);
                bench::render_png(&map).unwrap()
            },
            criterion::BatchSize::LargeInput,
        )
    });
    group.bench_function("map_svg", |b| {
        b.iter_batched(
            || bench::load(result, 0, "t".into(), out.path(), &[]).unwrap(),
            |inc| {
                let map = MapChart::new(&inc, "map".into(), 2.0, 0.1);
                bench::render_svg(&map).unwrap()
            },
            criterion::BatchSize::LargeInput,
        )
    });
    group.finish();
}

criterion_group! {
    name = benches;
    // No report charts: criterion's own plotters output finds no font.
    config = Criterion::default().without_plots();
    targets = plots
}
criterion_main!(benches);
