//! The Rust single-thread rate that `python/bench.py` compares
//! `Material.eval` with: the very loop the binding calls
//! (`Bsdf::eval_degrees_from` and `Bsdf::eval_degrees`), on 10⁶ directions
//! in degrees, metal material.

use brtf_model::{Bsdf, EvalOptions, Material, MaterialKind};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;

const N: usize = 1_000_000;

/// 10⁶ outgoing directions on a regular grid over the front hemisphere.
fn directions() -> (Vec<f64>, Vec<f64>) {
    let (mut theta, mut phi) = (Vec::with_capacity(N), Vec::with_capacity(N));
    for i in 0..N {
        theta.push((i % 1000) as f64 * 0.089);
        phi.push((i / 1000) as f64 * 0.36);
    }
    (theta, phi)
}

fn bench(c: &mut Criterion) {
    let material =
        Material::new(MaterialKind::Metal, &[0.9, 0.8, 0.7, 0.9, 0.05], None).expect("valid metal");
    let bsdf = Bsdf::new(&material, &EvalOptions::default());
    let (theta, phi) = directions();
    let theta_in = vec![30.0; N];
    let phi_in = vec![0.0; N];
    let mut out = vec![0.0; 3 * N];
    let mut group = c.benchmark_group("eval_degrees");
    group.throughput(Throughput::Elements(N as u64));
    group.sample_size(20);
    group.bench_function("metal_1e6_one_incidence", |b| {
        b.iter(|| {
            bsdf.eval_degrees_from(30.0, 0.0, &theta, &phi, &mut out);
            black_box(&out);
        })
    });
    group.bench_function("metal_1e6_per_row_incidence", |b| {
        b.iter(|| {
            bsdf.eval_degrees(&theta_in, &phi_in, &theta, &phi, &mut out);
            black_box(&out);
        })
    });
    group.finish();
}

criterion_group! {
    name = benches;
    // No plots: criterion's plotting panics on a machine without fonts.
    config = Criterion::default().without_plots();
    targets = bench
}
criterion_main!(benches);
