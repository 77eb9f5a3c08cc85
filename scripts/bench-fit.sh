#!/usr/bin/env bash
# brtf's fitter against the scipy peer, measured in one run on the same
# 120 000-point data (written by the criterion bench), with the same model
# and residuals. Prints both times and the ratio.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! .venv/bin/python -c "import scipy" 2>/dev/null; then
    python3 -m venv .venv
    .venv/bin/pip install --quiet --disable-pip-version-check numpy scipy
fi
cargo bench -p brtf-fit --bench fit -- --warm-up-time 2 --measurement-time 10 fit/metal_120k_multistart
.venv/bin/python scripts/scipy_peer.py target/fit-bench-metal.csv 7 \
    target/criterion/fit/metal_120k_multistart/new/estimates.json
