//! brtf-fit benchmark: one `metal` fit of a 120 000-point incidence (the
//! size of a real pgII scan), from the data-driven start with the
//! multi-start. The same data is written to `target/fit-bench-metal.csv`.
//!
//! `vs_scipy` (last, or alone with `-- vs_scipy`) measures brtf against the
//! scipy peer (`scripts/scipy_peer.py --serve`) in one run: rounds that
//! alternate brtf fits (two threads and one) with scipy fits, so both see
//! the same machine; it reports the best time of each and the ratio. It
//! needs numpy and scipy in the repository's `.venv`
//! (`scripts/bench-fit.sh` installs them) and is skipped without.

use brtf_fit::{FitConfig, FitSample, IncidenceData, fit_incidence};
use brtf_model::{Bsdf, EvalOptions, Material, MaterialKind, direction};
use criterion::Criterion;
use std::io::{BufRead, BufReader, Write};
use std::process::{Command, Stdio};
use std::time::Instant;

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
        weighting: brtf_fit::Weighting::Caller,
        patch_pairs: None,
        cosine_weighted: false,
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

/// The relative-residual grey metal fit both sides run.
fn peer_config() -> FitConfig {
    // The same residuals as the scipy peer: relative, with the auto floor.
    let mut config = FitConfig::new(MaterialKind::Metal);
    config.gray = true;
    config.residual = brtf_fit::ResidualKind::Relative;
    config
}

fn bench_fit(c: &mut Criterion, data: &IncidenceData) {
    let config = peer_config();
    let report = fit_incidence(data, &config).unwrap();
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
    group.sample_size(20);
    group.bench_function("metal_120k_multistart", |b| {
        b.iter(|| fit_incidence(data, &config).unwrap())
    });
    let mut single = config.clone();
    single.multistart = false;
    group.bench_function("metal_120k_single_start", |b| {
        b.iter(|| fit_incidence(data, &single).unwrap())
    });
    group.finish();
}

/// The repository's virtual environment's Python, if it has scipy.
fn peer_python() -> Option<std::path::PathBuf> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let python = root.join(".venv/bin/python");
    let ok = Command::new(&python)
        .args(["-c", "import numpy, scipy"])
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    ok.then_some(python)
}

/// Alternating rounds of brtf and scipy fits on the same data.
fn vs_scipy(data: &IncidenceData) {
    let Some(python) = peer_python() else {
        eprintln!("vs_scipy: no numpy/scipy in .venv (run scripts/bench-fit.sh); skipped");
        return;
    };
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut peer = Command::new(python)
        .arg(root.join("scripts/scipy_peer.py"))
        .arg("--serve")
        .arg(root.join("target/fit-bench-metal.csv"))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("start the scipy peer");
    let mut to_peer = peer.stdin.take().unwrap();
    let mut from_peer = BufReader::new(peer.stdout.take().unwrap());
    let mut line = String::new();
    from_peer.read_line(&mut line).unwrap();
    assert_eq!(line.trim(), "ready", "scipy peer did not start");

    let config = peer_config();
    let one_thread = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let time_brtf = |runs: usize, pool: Option<&rayon::ThreadPool>| {
        let mut best = f64::INFINITY;
        let mut cost = 0.0;
        for _ in 0..runs {
            let t = Instant::now();
            let report = match pool {
                Some(pool) => pool.install(|| fit_incidence(data, &config)),
                None => fit_incidence(data, &config),
            }
            .unwrap();
            best = best.min(t.elapsed().as_secs_f64() * 1e3);
            cost = report.cost;
        }
        (best, cost)
    };
    const ROUNDS: usize = 7;
    let (mut brtf2, mut brtf1, mut scipy) = (Vec::new(), Vec::new(), Vec::new());
    let (mut brtf_cost, mut scipy_cost) = (0.0, 0.0);
    let mut scipy_params = String::new();
    for _ in 0..ROUNDS {
        let (t2, cost) = time_brtf(10, None);
        let (t1, _) = time_brtf(3, Some(&one_thread));
        writeln!(to_peer, "fit").unwrap();
        line.clear();
        from_peer.read_line(&mut line).unwrap();
        let fields: Vec<&str> = line.split_whitespace().collect();
        scipy.push(fields[0].parse::<f64>().unwrap());
        scipy_cost = fields[1].parse::<f64>().unwrap();
        scipy_params = fields[2..].join(" ");
        brtf2.push(t2);
        brtf1.push(t1);
        brtf_cost = cost;
    }
    // Judge both solutions by one cost function, the peer's.
    let report = fit_incidence(data, &config).unwrap();
    let brtf_params = [
        report.value("red").unwrap(),
        report.value("spec").unwrap(),
        report.value("rough").unwrap(),
    ];
    writeln!(
        to_peer,
        "cost {:e} {:e} {:e}",
        brtf_params[0], brtf_params[1], brtf_params[2]
    )
    .unwrap();
    line.clear();
    from_peer.read_line(&mut line).unwrap();
    let peer_cost_at_brtf: f64 = line.trim().parse().unwrap();
    let _ = writeln!(to_peer, "quit");
    let _ = peer.wait();
    let best = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
    let mut ratios: Vec<f64> = scipy.iter().zip(&brtf2).map(|(s, b)| s / b).collect();
    ratios.sort_by(f64::total_cmp);
    let summary = format!(
        "vs_scipy: {ROUNDS} alternating rounds on 120 000 points (best of 10 brtf fits, \
         3 on one thread, 1 scipy fit per round)\n  \
         brtf, 2 threads: best {:.1} ms (rounds: {})\n  \
         brtf, 1 thread:  best {:.1} ms (rounds: {})\n  \
         scipy:           best {:.1} ms (rounds: {})\n  \
         ratio of best times: {:.1}x (2 threads), {:.1}x (1 thread); median per-round ratio {:.1}x\n  \
         cost ½Σr²: brtf {:.12e} by brtf; by scipy's own function at brtf's parameters \
         {:.12e}, at its own {:.12e}: brtf's solution is {}\n  \
         brtf colour {:.8} spec {:.8} rough {:.8}; scipy {}",
        best(&brtf2),
        list(&brtf2),
        best(&brtf1),
        list(&brtf1),
        best(&scipy),
        list(&scipy),
        best(&scipy) / best(&brtf2),
        best(&scipy) / best(&brtf1),
        ratios[ROUNDS / 2],
        brtf_cost,
        peer_cost_at_brtf,
        scipy_cost,
        // Within the rounding of a 120 000-term sum counts as equal.
        if peer_cost_at_brtf <= scipy_cost * (1.0 + 1e-12) {
            "equal (to 1e-12) or lower".to_string()
        } else {
            format!(
                "higher by {:.1e} relative",
                peer_cost_at_brtf / scipy_cost - 1.0
            )
        },
        brtf_params[0],
        brtf_params[1],
        brtf_params[2],
        scipy_params,
    );
    println!("{summary}");
    let _ = std::fs::write(root.join("target/fit-vs-scipy.txt"), summary + "\n");
}

fn list(v: &[f64]) -> String {
    v.iter()
        .map(|t| format!("{t:.1}"))
        .collect::<Vec<_>>()
        .join(", ")
}

fn main() {
    let filter: Option<String> = std::env::args().skip(1).find(|a| !a.starts_with('-'));
    let wants = |name: &str| {
        filter
            .as_deref()
            .is_none_or(|f| name.contains(f) || f.contains(name))
    };
    let (_, data) = bench_data();
    write_peer_data(&data);
    let mut c = Criterion::default().configure_from_args();
    bench_fit(&mut c, &data);
    c.final_summary();
    if wants("vs_scipy") {
        vs_scipy(&data);
    }
}
