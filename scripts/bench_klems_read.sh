#!/usr/bin/env bash
# Klems XML read speed: brtf's reader (criterion, in memory, medians) and
# Radiance's own loader (pyradiance.bsdf.load_file, SDloadFile) on the
# same files, in one run. Radiance caches a loaded file for the life of
# the process, so each pyradiance figure is the first load in a fresh
# Python process (the file is in the page cache for both).
# Usage: scripts/bench_klems_read.sh [ROUNDS]   (pyradiance processes per file, default 15)
set -euo pipefail
cd "$(dirname "$0")/.."
rounds="${1:-15}"
data="../shared/data/lbnl-frads-klems-fabrics"
echo "date: $(date -u '+%Y-%m-%d %H:%M UTC'), load: $(cut -d' ' -f1-3 /proc/loadavg), cores: $(nproc)"
cargo bench -q -p brtf-gonio --bench gonio -- 'klems/read_' --warm-up-time 1 --measurement-time 5 2>/dev/null |
    awk '/^klems\/read_/ {name=$1} /time:/ && name != "" {
        # criterion prints [low median high]
        line=$0; sub(/^[^[]*\[/, "", line); split(line, t, " ");
        printf "brtf   %-28s median %s %s\n", substr(name, 12), t[3], t[4]; name="" }'
for file in klems_aniso_high.xml 2011-SA1.xml; do
    for _ in $(seq "$rounds"); do
        .venv/bin/python - "$data/$file" <<'PY'
import sys, time
import pyradiance.bsdf as bsdf
start = time.perf_counter()
bsdf.load_file(sys.argv[1])
print((time.perf_counter() - start) * 1e3)
PY
    done | sort -g | awk -v f="$file" '{v[NR]=$1} END {printf "pyradiance %-24s median %.2f ms (best %.2f, %d processes)\n", f, v[int((NR+1)/2)], v[1], NR}'
done
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
