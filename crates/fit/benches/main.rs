//! brtf-fit benchmark: one `metal` fit of a 120 000-point incidence (the
//! size of a real pgII scan), on one core, from the data-driven start with
//! the multi-start. The same data is written to
//! `target/fit-bench-metal.csv` for the scipy peer (`scripts/scipy_peer.py`).

use brtf_fit::{FitConfig, FitSample, IncidenceData, fit_incidence};
use brtf_model::{Bsdf, EvalOptions, Material, MaterialKind, direction};
use criterion::{Criterion, criterion_group, criterion_main};
use std::io::Write;

/// 120 000 directions: 200 θ rings × 600 azimuths over the front
/// hemisphere, BSDF of a rough metal at θ_in = 30° with 2 % noise.
pub fn bench_data() -> (Material, IncidenceData) {
    let truth = Material::new(MaterialKind::Metal, &[0.9, 0.9, 0.9, 0.85, 0.08], None).unwrap();
    let bsdf = Bsdf::new(&truth, &EvalOptions::default());
    let l = direction(30.0, 0.0);
    let mut state = 12345u64;
    let mut gauss = move || {
        let mut u = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        let (a, b) = (u(), u());
        (-2.0 * a.ln()).sqrt() * (2.0 * std::f64::consts::PI * b).cos()
    };
    let mut samples = Vec::with_capacity(120_000);
    for i in 0..200 {
        let theta = 85.0 * (i as f64 + 0.5) / 200.0;
        for j in 0..600 {
            let phi = 360.0 * j as f64 / 600.0;
            let v = direction(theta, phi);
            let f = bsdf.eval(l, v)[1] * (1.0 + 0.02 * gauss());
            let weight = theta.to_radians().sin();
            samples.push(FitSample {
                view: v,
                value: [f, 0.0, 0.0],
                weight,
            });
        }
    }
    let data = IncidenceData {
        source: "bench".into(),
        theta_in: 30.0,
        phi_in: 0.0,
        channels: 1,
        samples,
        gates: Vec::new(),
        weighting: "ring solid angle".into(),
    };
    (truth, data)
}

fn write_peer_data(data: &IncidenceData) {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target");
    let Ok(file) = std::fs::File::create(dir.join("fit-bench-metal.csv")) else {
        return;
    };
    let mut out = std::io::BufWriter::new(file);
    let _ = writeln!(out, "theta_in,phi_in,vx,vy,vz,value,weight");
    for s in &data.samples {
        let _ = writeln!(
            out,
            "{},{},{},{},{},{},{}",
            data.theta_in, data.phi_in, s.view.x, s.view.y, s.view.z, s.value[0], s.weight
        );
    }
}

fn bench_fit(c: &mut Criterion) {
    let (_, data) = bench_data();
    write_peer_data(&data);
    // The same residuals as the scipy peer: relative, with the auto floor.
    let mut config = FitConfig::new(MaterialKind::Metal);
    config.gray = true;
    config.residual = brtf_fit::ResidualKind::Relative;
    let report = fit_incidence(&data, &config).unwrap();
    eprintln!(
        "metal 120k: spec {:.5} rough {:.5} colour {:.5} cost {:.6e} evals {} ({:?})",
        report.value("spec").unwrap(),
        report.value("rough").unwrap(),
        report.value("red").unwrap(),
        report.cost,
        report.evaluations,
        report.termination
    );
    let mut group = c.benchmark_group("fit");
    group.sample_size(10);
    group.bench_function("metal_120k_multistart", |b| {
        b.iter(|| fit_incidence(&data, &config).unwrap())
    });
    let mut single = config.clone();
    single.multistart = false;
    group.bench_function("metal_120k_single_start", |b| {
        b.iter(|| fit_incidence(&data, &single).unwrap())
    });
    group.finish();
}

criterion_group!(benches, bench_fit);
criterion_main!(benches);
