#!/usr/bin/env bash
# brtf's fitter against the scipy peer, measured side by side in one run.
#
# 1. Whole process: `brtf fit golden_paper.txt --model metal
#    --gray`, once with `--no-plots --no-export` and once with every output,
#    against scripts/scipy_peer.py's least_squares fit alone on the same
#    122 278 samples brtf fits (written by the CLI test `speed` to
#    target/golden-peer.csv). Each round runs the lean brtf, the full brtf
#    and one scipy fit (the scipy process stays up, --serve), so all three
#    see the same machine conditions; it prints the medians over the rounds
#    (ROUNDS, default 7) and the ratios scipy / brtf, and for the brtf runs
#    also the CPU time (user + sys of the process), which other load on
#    the machine changes far less than the wall time. The summary also
#    goes to target/bench-whole-process.txt.
#    Each round also runs a two-lobe plastic (lean) and `--model auto`
#    with every output.
# 2. Unless --whole-only is given: the criterion benches of one fit on
#    120 000 synthetic points, then `vs_scipy`, which alternates brtf fits
#    (two threads and one) with scipy fits and prints the best times, the
#    ratio and both solutions' costs by scipy's own cost function (summary
#    in target/fit-vs-scipy.txt). Other arguments go to criterion.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! .venv/bin/python -c "import numpy, scipy" 2>/dev/null; then
    [ -x .venv/bin/python ] || python3 -m venv .venv
    .venv/bin/pip install --quiet --disable-pip-version-check numpy scipy
fi
whole_only=false
if [ "${1:-}" = "--whole-only" ]; then
    whole_only=true
    shift
fi

golden=../shared/data/rgl-epfl-pgII-raw/golden_paper.txt
[ -f "$golden" ] || { echo "bench-fit.sh: $golden is missing (the shared data folder)" >&2; exit 1; }
cargo build --release --quiet
BRTF_PEER_CSV="$PWD/target/golden-peer.csv" cargo test --quiet --test cli speed:: >/dev/null

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
ROUNDS="${ROUNDS:-7}" .venv/bin/python - "$golden" "$work" <<'EOF' | tee target/bench-whole-process.txt
import os, resource, statistics, subprocess, sys, time

golden, work = sys.argv[1], sys.argv[2]
rounds = int(os.environ["ROUNDS"])
brtf = "target/release/brtf"
common = [brtf, "fit", golden, "--model", "metal", "--gray", "--force"]
lean = common + ["--no-plots", "--no-export", "--out", f"{work}/lean"]
full = common + ["--out", f"{work}/full"]
# The lobe sums of --model auto, in the same rounds: a two-lobe plastic
# lean, and auto with every output.
two_lobes = [brtf, "fit", golden, "--model", "plastic", "--lobes", "2", "--force",
             "--no-plots", "--no-export", "--out", f"{work}/two"]
auto = [brtf, "fit", golden, "--model", "auto", "--force", "--out", f"{work}/auto"]
peer = subprocess.Popen([sys.executable, "scripts/scipy_peer.py", "--serve", "target/golden-peer.csv"],
                        stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
assert peer.stdout.readline().strip() == "ready"


cpu = {"lean": [], "full": [], "two": [], "auto": []}
PAUSE = 0.5  # seconds


def run(key, command):
    used = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall = time.perf_counter() - t0
    now = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu[key].append(now.ru_utime - used.ru_utime + now.ru_stime - used.ru_stime)
    return wall


times = {"lean": [], "full": [], "two": [], "auto": [], "scipy": []}
for _ in range(rounds):
    times["lean"].append(run("lean", lean))
    times["full"].append(run("full", full))
    times["two"].append(run("two", two_lobes))
    times["auto"].append(run("auto", auto))
    peer.stdin.write("fit\n")
    peer.stdin.flush()
    times["scipy"].append(float(peer.stdout.readline().split()[0]) / 1e3)
    # BLAS worker threads keep spinning for a while after the scipy fit;
    # without a pause they take a core from the next brtf run.
    time.sleep(PAUSE)
peer.stdin.close()
peer.wait()

med = {k: statistics.median(v) for k, v in times.items()}
load = os.getloadavg()[0]
print(f"whole process on golden_paper.txt (127 039 rows), {rounds} rounds, "
      f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, load {load:.2f}, {os.cpu_count()} cores")
for key, label in [("lean", "brtf fit --no-plots --no-export"), ("full", "brtf fit (all outputs)"),
                   ("two", "--lobes 2, --no-plots --no-export"), ("auto", "--model auto (all outputs)"),
                   ("scipy", "scipy least_squares alone")]:
    v = sorted(times[key])
    line = f"  {label:34s} median {1e3 * med[key]:8.1f} ms  (min {1e3 * v[0]:.1f}, max {1e3 * v[-1]:.1f})"
    if key in cpu:
        line += f"; CPU median {1e3 * statistics.median(cpu[key]):.1f} ms"
    print(line)
print(f"  ratio scipy / brtf lean: {med['scipy'] / med['lean']:.1f}x;"
      f" scipy / brtf with all outputs: {med['scipy'] / med['full']:.1f}x")
EOF

if ! $whole_only; then
    cargo bench -p brtf-fit --bench fit -- "$@"
fi
