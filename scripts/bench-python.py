"""Speed of the Python package against Rust (a benchmark script, not a test).

    cargo build --release --bin brtf             # the brtf binary
    .venv/bin/python scripts/bench-python.py [--runs 11] [--criterion]

1. `Material.eval` on 10⁶ directions (metal, one thread), one incidence
   and a θ_in per direction, against the Rust rate of the same loop
   (`crates/py/src/kernel.rs`) on inputs already in Rust vectors, as the
   criterion bench `cargo bench -p brtf-py --bench eval_degrees` runs it.
   The machine is shared and its load changes by the second, so the two
   alternate call by call in this process (`Material._kernel_seconds`
   times the Rust loop alone); reported: medians, and the median of the
   per-pair ratios. With --criterion the criterion bench runs too.
2. `brtf.fit` on golden_paper.txt (grey metal) against `brtf fit
   --no-plots --no-export` (the whole process), runs interleaved.
"""

import argparse
import json
import os
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

import brtf

REPO = Path(__file__).resolve().parents[1]
GOLDEN = REPO.parent / "shared/data/rgl-epfl-pgII-raw/golden_paper.txt"
N = 1_000_000
BENCHES = {"one incidence": "metal_1e6_one_incidence", "theta_in per direction": "metal_1e6_per_row_incidence"}


def median_time(f, runs):
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def rust_medians():
    """Runs the criterion bench; its median time per 10⁶ evaluations (s)."""
    subprocess.run(
        ["cargo", "bench", "-q", "-p", "brtf-py", "--bench", "eval_degrees", "--",
         "--warm-up-time", "1", "--measurement-time", "4"],
        cwd=REPO, check=True, capture_output=True,
    )
    out = {}
    for label, name in BENCHES.items():
        path = REPO / "target/criterion/eval_degrees" / name / "new/estimates.json"
        out[label] = json.loads(path.read_text())["median"]["point_estimate"] * 1e-9
    return out


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--criterion", action="store_true")
    parser.add_argument("--runs", type=int, default=11)
    parser.add_argument("--cli", type=Path, default=REPO / "target/release/brtf")
    args = parser.parse_args()

    # The grid of benches/eval_degrees.rs.
    i = np.arange(N)
    theta = (i % 1000) * 0.089
    phi = (i // 1000) * 0.36
    theta_in = np.full(N, 30.0)
    material = brtf.Material("metal", rgb=(0.9, 0.8, 0.7), spec=0.9, roughness=0.05)
    calls = {
        "one incidence": lambda: material.eval(30.0, 0.0, theta, phi),
        "theta_in per direction": lambda: material.eval(theta_in, 0.0, theta, phi),
    }
    theta_list, phi_list = theta.tolist(), phi.tolist()
    print(f"Material.eval on {N} directions (metal), {args.runs} alternating pairs:")
    for label, call in calls.items():
        per_row = label != "one incidence"
        py, rust = [], []
        for _ in range(args.runs):
            t0 = time.perf_counter()
            call()
            py.append(time.perf_counter() - t0)
            rust.append(material._kernel_seconds(30.0, 0.0, theta_list, phi_list, per_row))
        ratio = statistics.median(r / p for r, p in zip(rust, py))
        mp, mr = statistics.median(py), statistics.median(rust)
        print(f"  {label:24} Python {mp * 1e3:6.1f} ms ({N / mp / 1e6:5.1f} M/s), "
              f"Rust loop {mr * 1e3:6.1f} ms ({N / mr / 1e6:5.1f} M/s): Python at {ratio:.0%} of Rust")
    if args.criterion:
        rust = rust_medians()
        for label in calls:
            print(f"  criterion {BENCHES[label]}: {rust[label] * 1e3:.1f} ms ({N / rust[label] / 1e6:.1f} M/s)")

    if not GOLDEN.is_file():
        raise SystemExit(f"{GOLDEN} is missing")
    print(f"\nbrtf.fit on golden_paper.txt (metal, gray), median of {args.runs}, interleaved:")
    py, py_save, cli = [], [], []
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(args.runs):
            t0 = time.perf_counter()
            fit = brtf.fit(GOLDEN, model="metal", gray=True)
            t1 = time.perf_counter()
            fit.save(Path(tmp) / "py", export=False, plots=False)
            t2 = time.perf_counter()
            subprocess.run(
                [args.cli, "fit", GOLDEN, "--model", "metal", "--gray", "--no-plots", "--no-export",
                 "--out", Path(tmp) / "cli", "--force"],
                check=True, capture_output=True,
            )
            t3 = time.perf_counter()
            py.append(t1 - t0)
            py_save.append(t2 - t0)
            cli.append(t3 - t2)
    m_py, m_save, m_cli = statistics.median(py), statistics.median(py_save), statistics.median(cli)
    print(f"  brtf.fit                                   {m_py * 1e3:6.0f} ms ({m_py / m_cli:.2f} × the CLI)")
    print(f"  brtf.fit + save(export=False, plots=False) {m_save * 1e3:6.0f} ms ({m_save / m_cli:.2f} × the CLI)")
    print(f"  brtf fit --no-plots --no-export (process)  {m_cli * 1e3:6.0f} ms")
    print(f"\nload average {os.getloadavg()[0]:.2f}, {os.cpu_count()} cores")


if __name__ == "__main__":
    main()
