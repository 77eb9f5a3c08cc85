"""Speed of the Python package against Rust (a benchmark script, not a test).

    cargo bench -p brtf-py --bench eval_degrees   # the Rust single-thread rate
    cargo build --release                         # the brtf binary
    .venv/bin/python python/bench.py [--runs 7]

1. `Material.eval` on 10⁶ directions (metal, one incidence, one thread) in
   evaluations per second, and the same with a θ_in per direction; the
   ratio to the Rust rate of the same loop (`crates/py/src/kernel.rs`),
   read from criterion's estimates in target/criterion when present.
2. `brtf.fit` on golden_paper.txt (grey metal) against `brtf fit
   --no-plots --no-export` (whole process), medians of --runs runs each.
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


def best_and_median(f, runs):
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return min(times), statistics.median(times)


def criterion_seconds(name):
    path = REPO / "target/criterion/eval_degrees" / name / "new/estimates.json"
    if not path.is_file():
        return None
    estimates = json.loads(path.read_text())
    return estimates["median"]["point_estimate"] * 1e-9, estimates["mean"]["point_estimate"] * 1e-9


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--runs", type=int, default=7)
    parser.add_argument("--cli", type=Path, default=REPO / "target/release/brtf")
    args = parser.parse_args()

    # The grid of benches/eval_degrees.rs.
    i = np.arange(N)
    theta = (i % 1000) * 0.089
    phi = (i // 1000) * 0.36
    material = brtf.Material("metal", rgb=(0.9, 0.8, 0.7), spec=0.9, roughness=0.05)
    print(f"Material.eval on {N} directions (metal), best / median of {args.runs}:")
    for label, bench, call in [
        ("one incidence", "metal_1e6_one_incidence", lambda: material.eval(30.0, 0.0, theta, phi)),
        ("theta_in per direction", "metal_1e6_per_row_incidence", lambda: material.eval(np.full(N, 30.0), 0.0, theta, phi)),
    ]:
        best, median = best_and_median(call, args.runs)
        line = f"  {label:24} {best * 1e3:7.1f} ms best, {median * 1e3:7.1f} ms median: {N / median / 1e6:5.1f} M/s"
        rust = criterion_seconds(bench)
        if rust:
            line += f"; Rust {rust[0] * 1e3:.1f} ms median ({N / rust[0] / 1e6:.1f} M/s): Python at {rust[0] / median:.0%} of Rust"
        print(line)

    if not GOLDEN.is_file():
        raise SystemExit(f"{GOLDEN} is missing")
    print(f"\nbrtf.fit on golden_paper.txt (metal, gray), median of {args.runs}:")
    py = [best_and_median(lambda: brtf.fit(GOLDEN, model="metal", gray=True), 1)[0] for _ in range(args.runs)]
    with tempfile.TemporaryDirectory() as tmp:
        def save():
            fit = brtf.fit(GOLDEN, model="metal", gray=True)
            fit.save(Path(tmp) / "py", export=False, plots=False)

        py_save = [best_and_median(save, 1)[0] for _ in range(args.runs)]
        cli = []
        for _ in range(args.runs):
            t0 = time.perf_counter()
            subprocess.run(
                [args.cli, "fit", GOLDEN, "--model", "metal", "--gray", "--no-plots", "--no-export",
                 "--out", Path(tmp) / "cli", "--force"],
                check=True, capture_output=True,
            )
            cli.append(time.perf_counter() - t0)
    m_py, m_save, m_cli = statistics.median(py), statistics.median(py_save), statistics.median(cli)
    print(f"  brtf.fit                                   {m_py * 1e3:6.0f} ms ({m_py / m_cli:.2f} × the CLI)")
    print(f"  brtf.fit + save(export=False, plots=False) {m_save * 1e3:6.0f} ms ({m_save / m_cli:.2f} × the CLI)")
    print(f"  brtf fit --no-plots --no-export (process)  {m_cli * 1e3:6.0f} ms")
    print(f"\nload average {os.getloadavg()[0]:.2f}, {os.cpu_count()} cores")


if __name__ == "__main__":
    main()
