//! brtf-model benchmarks: BSDF evaluations per second per type, gradient
//! cost, and ρ_dh time per incidence. Seeded inputs, one bench binary.

use brtf_model::{
    Bsdf, Directions, EvalOptions, Gradient, Material, MaterialKind, RgbBatch, albedo, direction,
};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::DVec3;
use std::hint::black_box;

const PAIRS: usize = 4096;

/// Deterministic (light, view) pairs: light in the front hemisphere, views
/// on both sides, a quarter of them near the mirror direction.
fn direction_pairs() -> Vec<(DVec3, DVec3)> {
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut uniform = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..PAIRS)
        .map(|i| {
            let (ti, pi) = (80.0 * uniform(), 360.0 * uniform());
            let v = if i % 4 == 0 {
                direction(
                    ti + 5.0 * (uniform() - 0.5),
                    pi + 180.0 + 10.0 * (uniform() - 0.5),
                )
            } else {
                direction(179.0 * uniform(), 360.0 * uniform())
            };
            (direction(ti, pi), v)
        })
        .collect()
}

fn material(kind: MaterialKind) -> Material {
    let args: &[f64] = match kind {
        MaterialKind::Plastic => &[0.5, 0.4, 0.3, 0.05, 0.1],
        MaterialKind::Metal => &[0.9, 0.8, 0.7, 0.9, 0.1],
        MaterialKind::Trans => &[0.8, 0.8, 0.8, 0.05, 0.1, 0.5, 0.5],
        MaterialKind::Plastic2 => &[0.5, 0.4, 0.3, 0.05, 0.05, 0.2],
        MaterialKind::Metal2 => &[0.9, 0.8, 0.7, 0.9, 0.05, 0.2],
        MaterialKind::Trans2 => &[0.8, 0.8, 0.8, 0.05, 0.05, 0.2, 0.5, 0.5],
    };
    Material::new(kind, args, Some(DVec3::new(1.0, 1.0, 0.0))).unwrap()
}

fn bench_eval(c: &mut Criterion) {
    let pairs = direction_pairs();
    let mut group = c.benchmark_group("eval");
    group.throughput(Throughput::Elements(PAIRS as u64));
    for kind in MaterialKind::ALL {
        let bsdf = Bsdf::new(&material(kind), &EvalOptions::default());
        group.bench_function(kind.name(), |b| {
            b.iter(|| {
                let mut sum = 0.0;
                for &(l, v) in &pairs {
                    sum += bsdf.eval(black_box(l), black_box(v))[1];
                }
                sum
            })
        });
    }
    let bsdf = Bsdf::new(&material(MaterialKind::Metal), &EvalOptions::default());
    group.bench_function("metal_with_gradient", |b| {
        let mut grad = Gradient::default();
        b.iter(|| {
            let mut sum = 0.0;
            for &(l, v) in &pairs {
                sum += bsdf.eval_with_gradient(black_box(l), black_box(v), &mut grad)[1];
                sum += grad.d[4][1];
            }
            sum
        })
    });
    group.finish();
}

/// The same 4096 pairs through [`Bsdf::eval_batch`] (structure of arrays,
/// vectorised kernel); the rate is pairs per second on one core.
fn bench_eval_batch(c: &mut Criterion) {
    let pairs = direction_pairs();
    let lights: Vec<DVec3> = pairs.iter().map(|p| p.0).collect();
    let views: Vec<DVec3> = pairs.iter().map(|p| p.1).collect();
    let (light, view) = (
        Directions::from_vectors(&lights),
        Directions::from_vectors(&views),
    );
    let mut out = RgbBatch::default();
    let mut group = c.benchmark_group("eval_batch");
    group.throughput(Throughput::Elements(PAIRS as u64));
    for kind in MaterialKind::ALL {
        let bsdf = Bsdf::new(&material(kind), &EvalOptions::default());
        group.bench_function(kind.name(), |b| {
            b.iter(|| {
                bsdf.eval_batch(black_box(&light), black_box(&view), &mut out);
                out.g[PAIRS / 2]
            })
        });
    }
    group.finish();
}

fn bench_albedo(c: &mut Criterion) {
    let mut group = c.benchmark_group("albedo");
    for (kind, theta) in [
        (MaterialKind::Metal, 45.0),
        (MaterialKind::Metal, 75.0),
        (MaterialKind::Plastic, 45.0),
        (MaterialKind::Trans, 45.0),
        (MaterialKind::Metal2, 45.0),
    ] {
        let bsdf = Bsdf::new(&material(kind), &EvalOptions::default());
        let l = direction(theta, 30.0);
        group.bench_function(format!("{}_{theta}deg", kind.name()), |b| {
            b.iter(|| albedo(black_box(&bsdf), black_box(l), 1e-5))
        });
    }
    group.finish();
}

criterion_group!(benches, bench_eval, bench_eval_batch, bench_albedo);
criterion_main!(benches);
