//! End-to-end benchmark of the `brtf` binary: `brtf fit` on the five
//! shipped `data/alu-ggx` scans (read, solid angles, gates, five fits plus
//! the all-incidence fit on 2 threads, outputs), as a user runs it.

use criterion::{Criterion, criterion_group, criterion_main};
use std::process::Command;

fn bench_fit_cli(c: &mut Criterion) {
    let root = env!("CARGO_MANIFEST_DIR");
    let files: Vec<String> = ["0", "15", "30", "45", "60"]
        .iter()
        .map(|t| format!("{root}/data/alu-ggx/alu-ggx:+{t}+0.mpc"))
        .collect();
    let out = std::env::temp_dir().join("brtf-bench-fit");
    let mut group = c.benchmark_group("cli");
    group.sample_size(10);
    group.bench_function("fit_alu_ggx_5_incidences", |b| {
        b.iter(|| {
            let status = Command::new(env!("CARGO_BIN_EXE_brtf"))
                .arg("fit")
                .args(&files)
                .args(["--model", "metal", "--no-export", "--no-plots", "--out"])
                .arg(&out)
                .stdout(std::process::Stdio::null())
                .status()
                .expect("run brtf");
            assert!(status.success());
        })
    });
    group.finish();
}

criterion_group!(benches, bench_fit_cli);
criterion_main!(benches);
