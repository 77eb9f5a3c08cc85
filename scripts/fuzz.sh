#!/usr/bin/env bash
# The long fuzz run (docs/reliability.md): a million mutated inputs built
# from the real files in ../shared/data and the shipped data, fits and
# .rad files, through every parser. Prints cases, panics, hangs (cases over
# 1 s), peak memory (VmHWM) and time; exits non-zero on any panic, hang or
# anomaly. Inputs of findings go to target/fuzz-findings/.
#
#   scripts/fuzz.sh                      # 10^6 cases, seed 1, all parsers
#   CASES=20000 SEED=7 scripts/fuzz.sh   # shorter, another seed
#   scripts/fuzz.sh --target mpc,mountain
#   scripts/fuzz.sh --replay 123 --dump case.txt   # one case again
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet -p brtf-fuzz
exec target/release/brtf-fuzz --cases "${CASES:-1000000}" --seed "${SEED:-1}" "$@"
