#!/usr/bin/env bash
# brtf's fitter against the scipy peer, measured in one run on the same
# 120 000-point data: the criterion benches of one fit, then `vs_scipy`,
# which alternates brtf fits (two threads and one) with scipy fits
# (scripts/scipy_peer.py --serve) and prints the best times, the ratio and
# both solutions' costs by scipy's own cost function. The summary is also
# written to target/fit-vs-scipy.txt.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! .venv/bin/python -c "import numpy, scipy" 2>/dev/null; then
    [ -x .venv/bin/python ] || python3 -m venv .venv
    .venv/bin/pip install --quiet --disable-pip-version-check numpy scipy
fi
cargo bench -p brtf-fit --bench fit -- "$@"
