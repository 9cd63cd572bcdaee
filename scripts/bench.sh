#!/usr/bin/env bash
# Runs every benchmark (release build) and prints, after their own reports (medians with min–max and the ratio to
# each issue's anchor), the heavy jobs next to the machine bounds issue 17 measured on the project's 2-core machine
# (19.5 GB/s memory, 63.5 GFLOP/s f64 over both cores) and the ratio to the bound.
#   scripts/bench.sh [BENCH ...]     (default: all; logs in bench-out/<bench>.txt)
# Run it on an idle machine: the figures are wall-clock medians.
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=bench-out
mkdir -p "$OUT"
ALL=(bench_aa bench_layered bench_fitting bench_separable bench_skin bench_facial bench_runtime bench_transport bench_profiles bench_spectral_mc)
BENCHES=("${@:-${ALL[@]}}")
cargo build --release --examples --quiet
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), \
$(awk '/MemTotal/ {printf "%.1f GiB", $2 / 1048576}' /proc/meminfo), load $(cut -d' ' -f1 /proc/loadavg); \
rtbake $(git rev-parse --short HEAD 2>/dev/null || echo '?'), $(date -u +%Y-%m-%dT%H:%MZ)"
for b in "${BENCHES[@]}"; do
    echo "== $b"
    "./target/release/examples/$b" 2>/dev/null | tee "$OUT/$b.txt"
done

# Heavy jobs against their bounds (issue 17): the bound, the figure parsed from the logs above, the ratio.
row() { # name, figure in ms (or empty), bound in ms, goal ratio
    if [ -z "$2" ]; then printf '%-44s %12s %10s ms %8s   goal <= %sx\n' "$1" "(not run)" "$3" "" "$4"; return; fi
    awk -v n="$1" -v f="$2" -v b="$3" -v g="$4" \
        'BEGIN { printf "%-44s %9.1f ms %10s ms %7.2fx   goal <= %sx %s\n", n, f, b, f / b, g, (f / b <= g ? "met" : "NOT met") }'
}
skin=$(sed -n 's/^table (tabulated, default): wall \([0-9.]*\) s.*/\1/p' "$OUT/bench_skin.txt" 2>/dev/null | awk '{print $1 * 1000}')
rig=$(sed -n 's/.*wall median \([0-9.]*\) s of.*/\1/p' "$OUT/bench_facial.txt" 2>/dev/null | awk '{print $1 * 1000}')
smaa=$(sed -n 's/^CPU reference SMAA 1x 1920x1080, 2 threads: \([0-9.]*\) ms.*/\1/p' "$OUT/bench_runtime.txt" 2>/dev/null)
smaa_reused=$(sed -n 's/^CPU reference SMAA 1x 1920x1080, 2 threads, buffers reused: \([0-9.]*\) ms.*/\1/p' \
    "$OUT/bench_runtime.txt" 2>/dev/null)
echo "== heavy jobs vs the machine's bound (issue 17)"
printf '%-44s %12s %13s %8s\n' "job" "median" "bound" "ratio"
row "skin LUT 256x256 at 1 nm (SIMD bound)" "$skin" 15 2
row "hemoglobin rig 4096x4096, 9 maps, r = 32 (load+FP)" "$rig" 1250 2
row "CPU SMAA 1x 1080p (memory bound)" "$smaa" 2.3 3
row "CPU SMAA 1x 1080p, reused buffers (memory)" "$smaa_reused" 2.3 3
