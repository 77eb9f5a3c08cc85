//! brtf-model benchmarks: BSDF evaluations per second per type, gradient
//! cost, and ρ_dh time per incidence. Seeded inputs, one bench binary.

use brtf_model::{
    Bsdf, Directions, EvalOptions, Geometry, GeometryBatch, Gradient, Material, MaterialKind,
    PairTerms, RgbBatch, albedo, direction,
};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::DVec3;
use std::hint::black_box;

const PAIRS: usize = 4096;

/// Seeded uniform numbers in [0, 1) (xorshift64).
fn uniform_numbers(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed;
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Deterministic (light, view) pairs: light in the front hemisphere, views
/// on both sides, a quarter of them near the mirror direction.
fn direction_pairs() -> Vec<(DVec3, DVec3)> {
    let mut uniform = uniform_numbers(0x9E37_79B9_7F4A_7C15u64);
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

/// Pairs in a Klems-like incidence.
const PATCH_PAIRS: usize = 100_000;

/// A Klems incidence's (light, view) pairs: lights spread over a patch
/// around θ = 30°, a sixth of the views within 5° of the mirror direction,
/// a sixth within 5° of straight through, the rest spread over both
/// hemispheres.
fn klems_pairs() -> (Vec<DVec3>, Vec<DVec3>) {
    let mut state = 0x5851_F42D_4C95_7F2Du64;
    let mut uniform = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..PATCH_PAIRS)
        .map(|i| {
            let (ti, pi) = (25.0 + 10.0 * uniform(), 10.0 * uniform());
            let (dt, dp) = (10.0 * (uniform() - 0.5), 10.0 * (uniform() - 0.5));
            let v = match i % 6 {
                0 => direction(ti + dt, pi + 180.0 + dp),
                1 => direction(180.0 - ti + dt, pi + 180.0 + dp),
                2 | 3 => direction(90.0 * uniform(), 360.0 * uniform()),
                _ => direction(90.0 + 90.0 * uniform(), 360.0 * uniform()),
            };
            (direction(ti, pi), v)
        })
        .unzip()
}

/// What a fit to patch averages does on every iteration: the sums of `f`
/// and its gradient over runs of pairs, the geometry precomputed.
/// `scalar`: `eval_geometry_channels_with_gradient::<CH>` per pair, summed;
/// `batch`: `sum_geometry_with_gradient::<CH>` per run. Rates are pairs per
/// second. `{type}/*`: one channel (a grey fit), runs of 128 pairs;
/// `trans_rgb/*`: three channels; `trans_run32/*`: runs of 32 pairs (the
/// shortest a Klems sample has).
fn bench_patch_sum(c: &mut Criterion) {
    let (lights, views) = klems_pairs();
    let mut group = c.benchmark_group("patch_sum");
    group.throughput(Throughput::Elements(PATCH_PAIRS as u64));
    for kind in [
        MaterialKind::Metal,
        MaterialKind::Plastic,
        MaterialKind::Trans,
    ] {
        patch_sum_pair::<1>(&mut group, kind, kind.name(), 128, &lights, &views);
    }
    let trans = MaterialKind::Trans;
    patch_sum_pair::<3>(&mut group, trans, "trans_rgb", 128, &lights, &views);
    patch_sum_pair::<1>(&mut group, trans, "trans_run32", 32, &lights, &views);
    group.finish();
}

/// `patch_sum/{name}/scalar` and `patch_sum/{name}/batch`.
fn patch_sum_pair<const CH: usize>(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    kind: MaterialKind,
    name: &str,
    run: usize,
    lights: &[DVec3],
    views: &[DVec3],
) {
    let bsdf = Bsdf::new(&material(kind), &EvalOptions::default());
    let geometry: Vec<Geometry> = lights
        .iter()
        .zip(views)
        .map(|(&l, &v)| bsdf.geometry(l, v))
        .collect();
    let mut batch = GeometryBatch::new();
    bsdf.geometry_batch(lights, views, &mut batch);
    group.bench_function(format!("{name}/scalar"), |b| {
        let (mut grad, mut grad_sum) = (Gradient::default(), Gradient::default());
        b.iter(|| {
            let mut total = 0.0;
            for pairs in geometry.chunks(run) {
                let mut f_sum = [0.0; 3];
                grad_sum.d = [[0.0; 3]; 8];
                for g in pairs {
                    let f =
                        black_box(&bsdf).eval_geometry_channels_with_gradient::<CH>(g, &mut grad);
                    for ch in 0..CH {
                        f_sum[ch] += f[ch];
                        for (s, d) in grad_sum.d.iter_mut().zip(&grad.d) {
                            s[ch] += d[ch];
                        }
                    }
                }
                total += f_sum[0] + grad_sum.d[4][0];
            }
            total
        })
    });
    // Every pair's terms, in runs (what a fit to measured samples asks).
    group.bench_function(format!("{name}/each"), |b| {
        let mut terms = PairTerms::new();
        b.iter(|| {
            let mut total = 0.0;
            for start in (0..geometry.len()).step_by(run) {
                let range = start..(start + run).min(geometry.len());
                black_box(&bsdf).eval_geometry_each_with_gradient::<CH>(&batch, range, &mut terms);
                total += terms.value(0, 0) + terms.derivative(terms.len() - 1, 4, 0);
            }
            total
        })
    });
    group.bench_function(format!("{name}/batch"), |b| {
        let mut grad_sum = Gradient::default();
        b.iter(|| {
            let mut total = 0.0;
            for start in (0..geometry.len()).step_by(run) {
                let range = start..(start + run).min(geometry.len());
                total +=
                    black_box(&bsdf).sum_geometry_with_gradient::<CH>(&batch, range, &mut grad_sum)
                        [0];
                total += grad_sum.d[4][0];
            }
            total
        })
    });
}

/// Klems-like samples: 32 lights of an incident patch around θ = 30°
/// with 32 views of an outgoing patch, which is the mirror patch, the
/// straight-through patch, or one of a ring on either side.
fn klems_products() -> (Vec<DVec3>, Vec<Vec<DVec3>>) {
    let mut uniform = uniform_numbers(0x2545_F491_4F6C_DD1Du64);
    let mut patch = |theta: f64, phi: f64| -> Vec<DVec3> {
        (0..32)
            .map(|_| {
                direction(
                    theta + 10.0 * (uniform() - 0.5),
                    phi + 10.0 * (uniform() - 0.5),
                )
            })
            .collect()
    };
    let lights = patch(30.0, 0.0);
    let views = (0..96)
        .map(|s| match s % 6 {
            0 => patch(30.0, 180.0),
            1 => patch(150.0, 180.0),
            2 | 3 => patch(10.0 + 13.0 * (s % 7) as f64, 30.0 * s as f64),
            _ => patch(170.0 - 13.0 * (s % 7) as f64, 30.0 * s as f64),
        })
        .collect();
    (lights, views)
}

/// What a fit to patch averages that cannot keep the geometry does on
/// every pass: each sample's pairs' geometry into a scratch batch.
/// `{type}/scalar`: `Bsdf::geometry` per pair; `{type}/simd`:
/// `geometry_product`. Rates are pairs per second.
fn bench_patch_geometry(c: &mut Criterion) {
    let (lights, samples) = klems_products();
    let mut group = c.benchmark_group("patch_geometry");
    group.throughput(Throughput::Elements(
        (lights.len() * samples.iter().map(Vec::len).sum::<usize>()) as u64,
    ));
    for kind in [
        MaterialKind::Trans,
        MaterialKind::Plastic,
        MaterialKind::Trans2,
    ] {
        let bsdf = Bsdf::new(&material(kind), &EvalOptions::default());
        group.bench_function(format!("{}/scalar", kind.name()), |b| {
            let mut scratch = GeometryBatch::new();
            b.iter(|| {
                let mut total = 0;
                for views in &samples {
                    scratch.clear();
                    let bsdf = black_box(&bsdf);
                    let pairs = lights
                        .iter()
                        .flat_map(|&l| views.iter().map(move |&v| (l, v)));
                    scratch.extend(pairs.map(|(l, v)| bsdf.geometry(l, v)));
                    black_box(scratch.get(scratch.len() / 2));
                    total += scratch.len();
                }
                total
            })
        });
        group.bench_function(format!("{}/simd", kind.name()), |b| {
            let mut scratch = GeometryBatch::new();
            b.iter(|| {
                let mut total = 0;
                for views in &samples {
                    black_box(&bsdf).geometry_product(&lights, views, &mut scratch, 0);
                    black_box(scratch.get(scratch.len() / 2));
                    total += scratch.len();
                }
                total
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

criterion_group!(
    benches,
    bench_eval,
    bench_eval_batch,
    bench_patch_sum,
    bench_patch_geometry,
    bench_albedo
);
criterion_main!(benches);
