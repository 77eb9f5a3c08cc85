#!/usr/bin/env bash
# Klems export speed: brtf export --klems --material vs Radiance's
# bsdf2klems -f on the same BSDF (the .cal brtf writes with --klems-cal),
# both on the Klems Full basis at the same number of samples per entry
# (brtf's default, 4096), in one run. brtf writes four components (front
# and back; a Radiance material is two-sided), bsdf2klems two (rf, tf).
# Usage: scripts/bench_klems_export.sh [N]   (N: samples, default 4096)
set -euo pipefail
cd "$(dirname "$0")/.."
n="${1:-4096}"
bin="${RADIANCE_BIN:-$(.venv/bin/python -c 'import os,pyradiance;print(os.path.dirname(pyradiance.__file__))')/bin}"
export PATH="$bin:$PATH"
export RAYPATH="${RAYPATH:-.:$bin/../lib}"
cargo build --release -q
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cat > "$work/m.rad" <<'RAD'
void trans shade
0
0
7 0.6 0.5 0.4 0.03 0.15 0.3 0.2
RAD
echo "date: $(date -u '+%Y-%m-%d %H:%M UTC'), load: $(cut -d' ' -f1-3 /proc/loadavg), cores: $(nproc), n = $n"
start=$(date +%s.%N)
target/release/brtf export --klems --material "$work/m.rad" --klems-samples "$n" --klems-cal --out "$work" >/dev/null
brtf_s=$(echo "$(date +%s.%N) - $start" | bc)
echo "brtf export --klems (4 components): ${brtf_s} s"
start=$(date +%s.%N)
(cd "$work" && bsdf2klems -n "$n" -f shade-bsdf2klems.cal brtf_bsdf > ref.xml 2>/dev/null)
ref_s=$(echo "$(date +%s.%N) - $start" | bc)
echo "bsdf2klems -n $n -f (2 components): ${ref_s} s"
echo "ratio (bsdf2klems / brtf): $(echo "scale=1; $ref_s / $brtf_s" | bc)"
echo "per component: brtf $(echo "scale=3; $brtf_s / 4" | bc) s, bsdf2klems $(echo "scale=1; $ref_s / 2" | bc) s, ratio $(echo "scale=1; ($ref_s / 2) / ($brtf_s / 4)" | bc)"
