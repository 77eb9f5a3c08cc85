#!/usr/bin/env python3
"""Whole-process time of two brtf binaries, side by side.

    python3 scripts/compare-binaries.py OLD_BRTF NEW_BRTF [ROUNDS]

Each round runs `brtf fit golden_paper.txt --model metal --gray`, lean
(`--no-plots --no-export`) and with every output, with each binary in
turn (the order alternates between rounds), so both see the same machine
conditions. Prints the median and minimum wall time and the median CPU
time (user + sys) of each, and the ratio of the medians new / old.
"""

import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

GOLDEN = os.path.join(os.path.dirname(__file__), "..", "..", "shared", "data", "rgl-epfl-pgII-raw", "golden_paper.txt")


def run(command):
    used = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall = time.perf_counter() - t0
    now = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, now.ru_utime - used.ru_utime + now.ru_stime - used.ru_stime


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    binaries = {"old": sys.argv[1], "new": sys.argv[2]}
    rounds = int(sys.argv[3]) if len(sys.argv) > 3 else 21
    if not os.path.isfile(GOLDEN):
        sys.exit(f"compare-binaries.py: {GOLDEN} is missing (the shared data folder)")
    times = {(b, kind): [] for b in binaries for kind in ("lean", "full")}
    with tempfile.TemporaryDirectory() as work:
        for r in range(rounds):
            order = list(binaries) if r % 2 == 0 else list(reversed(binaries))
            for kind in ("lean", "full"):
                for b in order:
                    command = [binaries[b], "fit", GOLDEN, "--model", "metal", "--gray", "--force"]
                    command += ["--out", f"{work}/{b}-{kind}"]
                    if kind == "lean":
                        command += ["--no-plots", "--no-export"]
                    times[(b, kind)].append(run(command))
    for kind in ("lean", "full"):
        med = {}
        for b in binaries:
            walls = [w for w, _ in times[(b, kind)]]
            cpus = [c for _, c in times[(b, kind)]]
            med[b] = statistics.median(walls)
            print(
                f"{kind:4} {b}: median {1e3 * med[b]:.1f} ms, min {1e3 * min(walls):.1f} ms, "
                f"CPU median {1e3 * statistics.median(cpus):.1f} ms ({binaries[b]})"
            )
        print(f"{kind:4} new / old: {med['new'] / med['old']:.3f} ({rounds} rounds)")


if __name__ == "__main__":
    main()
