#!/usr/bin/env bash
# The one test command (README.md): installs what the tests need, checks
# formatting and lints, then runs every test, including the live
# comparisons against real Radiance (rtrace from the PyPI package pyradiance).
set -euo pipefail
cd "$(dirname "$0")/.."

# Real Radiance 6.0a binaries, in a project-local virtual environment.
if ! .venv/bin/python -c "import pyradiance" 2>/dev/null; then
    echo "== installing pyradiance 1.3.1 (real Radiance binaries) into .venv"
    python3 -m venv .venv
    .venv/bin/pip install --quiet --disable-pip-version-check pyradiance==1.3.1
fi
# numpy and scipy for the scipy peer (tests/cli/peer.rs).
if ! .venv/bin/python -c "import numpy, scipy" 2>/dev/null; then
    echo "== installing numpy and scipy (the scipy peer) into .venv"
    .venv/bin/pip install --quiet --disable-pip-version-check numpy scipy
fi
# pyWinCalc, LBNL WINDOW's calculation engine, reads the Klems exports
# (tests/cli/klems_export.rs).
if ! .venv/bin/python -c "import pywincalc" 2>/dev/null; then
    echo "== installing pywincalc 3.3.1 (WINDOW's engine) into .venv"
    .venv/bin/pip install --quiet --disable-pip-version-check pywincalc==3.3.1
fi
pkg=$(.venv/bin/python -c "import os, pyradiance; print(os.path.dirname(pyradiance.__file__))")
export RADIANCE_BIN="$pkg/bin"
export RAYPATH=".:$pkg/lib"
echo "== Radiance: $("$RADIANCE_BIN/rtrace" -version 2>&1 | head -n 1)"

# Headless Chromium for the report test (Debian packages; CI runs as root).
if ! command -v chromium >/dev/null || ! command -v chromedriver >/dev/null; then
    echo "== installing chromium and chromium-driver (Debian) for the report test"
    sudo_cmd=""
    [ "$(id -u)" -eq 0 ] || sudo_cmd="sudo"
    $sudo_cmd apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq chromium chromium-driver >/dev/null
fi

echo "== cargo fmt --check"
cargo fmt --all -- --check
echo "== cargo clippy"
cargo clippy --workspace --all-targets --quiet -- -D warnings
echo "== cargo test"
mkdir -p target
# No test may change an input: every tracked file and every file of
# ../shared/data is hashed now and checked after the last test.
{
    git ls-files -z 2>/dev/null | xargs -0 -r sha256sum
    find ../shared/data -type f -print0 2>/dev/null | sort -z | xargs -0 -r sha256sum
} > target/inputs.sha256
set +e
cargo test --workspace 2>&1 | tee target/test-output.log
status=${PIPESTATUS[0]}
set -e
# One closing line for the whole run (cargo's last line is a doc-test
# binary's, often "0 passed").
awk '/^test result:/ { for (i = 1; i <= NF; i++) { if ($(i+1) ~ /^passed/) p += $i; if ($(i+1) ~ /^failed/) f += $i } }
     END { printf "tests: %d passed, %d failed\n", p, f }' target/test-output.log

# --- Python package (python/, crates/py; docs/python.md) -------------------
# Builds the `brtf` wheel (maturin, release build of crates/py) into .venv,
# then runs its pytest suite, which compares it with the brtf binary that
# `cargo test` just built, and the worked example of docs/python.md.
# A failure here fails the script.
if ! .venv/bin/python -c "import maturin, pytest, matplotlib" 2>/dev/null; then
    echo "== installing maturin, pytest and matplotlib into .venv"
    .venv/bin/pip install --quiet --disable-pip-version-check "maturin>=1.9,<2" pytest matplotlib
fi
echo "== pip install ./python (maturin, release build)"
python_status=0
PATH="$PWD/.venv/bin:$PATH" .venv/bin/pip install --quiet --disable-pip-version-check \
    --no-build-isolation --force-reinstall --no-deps ./python || python_status=$?
if [ "$python_status" -eq 0 ]; then
    echo "== pytest python/tests"
    BRTF_BIN="${CARGO_TARGET_DIR:-$PWD/target}/debug/brtf" .venv/bin/python -m pytest -q -p no:cacheprovider python/tests \
        || python_status=$?
    echo "== docs/python.md example"
    .venv/bin/python python/examples/golden_paper.py --out target/python-example >/dev/null \
        || python_status=$?
fi
[ "$status" -ne 0 ] || status=$python_status
echo "== inputs unchanged (SHA-256 of $(wc -l < target/inputs.sha256) files)"
if ! sha256sum --quiet --check target/inputs.sha256; then
    echo "a test changed the inputs above"
    status=1
fi
exit "$status"
