//! brtf-gonio benchmarks: parse throughput, solid angles and the summary on
//! the real 4 MB pgII scan `golden_paper.txt`, and reading the two real
//! Klems Full files (all read from `../shared/data`, never copied into the
//! repository).

use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::time::Duration;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};

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

fn parse(c: &mut Criterion) {
    let path = golden_path();
    let bytes = std::fs::read(&path).unwrap();
    let mut group = c.benchmark_group("parse");
    group.throughput(Throughput::Bytes(bytes.len() as u64));
    group.bench_function("golden_paper_mountain", |b| {
        b.iter(|| brtf_gonio::read_bytes(black_box(&bytes), &path).unwrap())
    });
    group.bench_function("golden_paper_from_path", |b| {
        b.iter(|| brtf_gonio::read_path(black_box(&path)).unwrap())
    });
    // Lone-CR line ends (classic Mac): every row takes the general rules.
    let lone_cr: Vec<u8> = bytes.iter().copied().filter(|&b| b != b'\n').collect();
    group.bench_function("golden_paper_mountain_lone_cr", |b| {
        b.iter(|| brtf_gonio::read_bytes(black_box(&lone_cr), &path).unwrap())
    });
    group.finish();
}

fn write(c: &mut Criterion) {
    let m = brtf_gonio::read_path(&golden_path()).unwrap();
    let mut group = c.benchmark_group("write");
    group.sample_size(20);
    group.bench_function("golden_paper_mountain_string", |b| {
        b.iter(|| brtf_gonio::to_mountain_string(black_box(&m)))
    });
    group.finish();
}

fn geometry(c: &mut Criterion) {
    let m = brtf_gonio::read_path(&golden_path()).unwrap();
    let mut group = c.benchmark_group("geometry");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(8));
    group.bench_function("solid_angles_golden_paper_127k", |b| {
        b.iter(|| brtf_gonio::compute_solid_angles(black_box(&m.samples)))
    });
    // The cells alone on golden_paper's projected directions: brtf's own
    // triangulation against the delaunator-based reference it replaced.
    let projected: Vec<[f64; 2]> = m
        .samples
        .iter()
        .map(|s| brtf_gonio::project(s.theta_deg, s.phi_deg, s.hemisphere()))
        .collect();
    group.bench_function("disk_voronoi_golden_paper_127k", |b| {
        b.iter(|| brtf_gonio::disk_voronoi_areas(black_box(&projected)))
    });
    group.bench_function("disk_voronoi_golden_paper_127k_reference", |b| {
        b.iter(|| brtf_gonio::reference_disk_voronoi_areas(black_box(&projected)))
    });
    // A ring layout of the same size (212 rings x 600 azimuths to 85°):
    // the ring path.
    let rings: Vec<brtf_gonio::Sample> = (0..212)
        .flat_map(|i| {
            let theta = 85.0 * (i as f64 + 0.5) / 212.0;
            (0..600).map(move |j| brtf_gonio::Sample::luminance(theta, 0.6 * j as f64, 1.0))
        })
        .collect();
    group.bench_function("solid_angles_rings_127k", |b| {
        b.iter(|| brtf_gonio::compute_solid_angles(black_box(&rings)))
    });
    group.bench_function("solid_angles_rings_127k_voronoi", |b| {
        b.iter(|| brtf_gonio::voronoi_solid_angles(black_box(&rings)))
    });
    group.bench_function("summary_golden_paper_127k", |b| {
        b.iter(|| black_box(&m).summary())
    });
    let weights = brtf_gonio::solid_angles(&m);
    group.bench_function("summary_with_known_weights", |b| {
        b.iter(|| black_box(&m).summary_with(&weights))
    });
    group.finish();
}

/// Reading the real Klems Full files (bytes already in memory: XML parse,
/// basis, 145 x 145 matrices). pyradiance's own loader is not a peer here:
/// a loop of `pyradiance.bsdf.load_file` in one Python process did not
/// finish (and `pyradiance.bsdf.free` aborts with a double free), so it
/// cannot be timed properly.
fn klems(c: &mut Criterion) {
    let folder =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/lbnl-frads-klems-fabrics");
    let mut group = c.benchmark_group("klems");
    for name in ["klems_aniso_high.xml", "2011-SA1.xml"] {
        let path = folder.join(name);
        assert!(
            path.is_file(),
            "{} is missing: the benchmark needs the shared data folder beside the repository",
            path.display()
        );
        let bytes = std::fs::read(&path).unwrap();
        group.throughput(Throughput::Bytes(bytes.len() as u64));
        group.bench_function(format!("read_{name}"), |b| {
            b.iter(|| brtf_gonio::klems::read_bytes(black_box(&bytes), &path).unwrap())
        });
    }
    group.finish();
    let mecho = brtf_gonio::klems::read_path(&folder.join("klems_aniso_high.xml")).unwrap();
    let mut group = c.benchmark_group("klems_convert");
    group.bench_function("to_measurements_klems_aniso_high", |b| {
        b.iter(|| black_box(&mecho).to_measurements())
    });
    group.finish();
}

criterion_group!(benches, parse, write, geometry, klems);
criterion_main!(benches);
