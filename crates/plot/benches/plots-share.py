#!/usr/bin/env python3
"""The plots' share of a whole `brtf fit` run: runs
`brtf fit golden_paper.txt --model metal --gray` with and without
`--no-plots`, interleaved, for every binary given, and prints the medians of
wall time and CPU time (user + sys of the child) and of their per-round
differences, and the difference of the minima (on a loaded machine the
medians drift with the other load; the fastest runs are the least
disturbed ones). A script, not a test.

    python3 crates/plot/benches/plots-share.py ROUNDS BIN [BIN ...]
"""
import os
import statistics
import sys
import tempfile
import time

DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)),
                    "../../../../shared/data/rgl-epfl-pgII-raw/golden_paper.txt")


def run(binary, args):
    """Wall and CPU milliseconds of one run, output thrown away."""
    start = time.perf_counter()
    pid = os.fork()
    if pid == 0:
        null = os.open(os.devnull, os.O_WRONLY)
        os.dup2(null, 1)
        os.dup2(null, 2)
        os.execv(binary, [binary] + args)
    _, status, usage = os.wait4(pid, 0)
    wall = time.perf_counter() - start
    if status != 0:
        sys.exit(f"{binary} {' '.join(args)} failed (status {status})")
    return wall * 1e3, (usage.ru_utime + usage.ru_stime) * 1e3


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    rounds, binaries = int(sys.argv[1]), sys.argv[2:]
    data = os.path.normpath(DATA)
    with tempfile.TemporaryDirectory(prefix="plots-share-") as out:
        times = measure(binaries, rounds, data, out)
    report(binaries, rounds, times)


def measure(binaries, rounds, data, out):
    """Wall and CPU times of every run, by (binary, lean)."""
    times = {}
    for _ in range(rounds):
        for b in binaries:
            for lean in (False, True):
                args = ["fit", data, "--model", "metal", "--gray", "--out",
                        os.path.join(out, "lean" if lean else "full"), "--force"]
                times.setdefault((b, lean), []).append(run(b, args + ["--no-plots"] * lean))
    return times


def report(binaries, rounds, times):
    """Prints the medians and minima of every binary."""
    med = statistics.median
    for b in binaries:
        full, lean = times[(b, False)], times[(b, True)]
        print(f"{b}: {rounds} rounds; with plots {med(w for w, _ in full):.1f} ms wall, "
              f"{med(c for _, c in full):.1f} ms CPU; --no-plots {med(w for w, _ in lean):.1f} ms wall, "
              f"{med(c for _, c in lean):.1f} ms CPU; plots' share (median of per-round differences) "
              f"{med(f[0] - l[0] for f, l in zip(full, lean)):.1f} ms wall, "
              f"{med(f[1] - l[1] for f, l in zip(full, lean)):.1f} ms CPU; "
              f"minima (for a loaded machine: each the least disturbed run) with plots "
              f"{min(w for w, _ in full):.1f} ms wall, {min(c for _, c in full):.1f} ms CPU, "
              f"--no-plots {min(w for w, _ in lean):.1f} ms wall, {min(c for _, c in lean):.1f} ms CPU, "
              f"difference {min(w for w, _ in full) - min(w for w, _ in lean):.1f} ms wall, "
              f"{min(c for _, c in full) - min(c for _, c in lean):.1f} ms CPU")


if __name__ == "__main__":
    main()
