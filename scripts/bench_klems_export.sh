#!/usr/bin/env bash
# Klems export speed: brtf export --klems vs Radiance's bsdf2klems -f on
# the same BSDF (the .cal brtf writes with --klems-cal), both on the Klems
# Full basis at the same number of samples per entry, in one run. The
# material is a rough trans: brtf computes two components (rf, tf; the
# back blocks of a two-sided material are copies), bsdf2klems two (rf,
# tf). Wall and CPU (user + sys) seconds are printed: on a loaded machine
# the CPU times are the fairer comparison (brtf uses every core).
# Usage: scripts/bench_klems_export.sh [N]   (N: samples, default 1024)
set -euo pipefail
cd "$(dirname "$0")/.."
n="${1:-1024}"
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
/usr/bin/time -f "%e %U %S" -o "$work/brtf.time" \
    target/release/brtf export --klems --material "$work/m.rad" --klems-samples "$n" --klems-cal --out "$work" >/dev/null
read -r bw bu bs < "$work/brtf.time"
echo "brtf export --klems:        wall ${bw} s, cpu $(echo "$bu + $bs" | bc) s"
(cd "$work" && /usr/bin/time -f "%e %U %S" -o bsdf2klems.time \
    bsdf2klems -n "$n" -f shade-bsdf2klems.cal brtf_bsdf > ref.xml 2>/dev/null)
read -r rw ru rs < "$work/bsdf2klems.time"
echo "bsdf2klems -n $n -f:      wall ${rw} s, cpu $(echo "$ru + $rs" | bc) s"
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "ratio wall: $(echo "scale=1; $rw / $bw" | bc), ratio cpu: $(echo "scale=1; ($ru + $rs) / ($bu + $bs)" | bc)"
