#!/usr/bin/env bash
# Runs every benchmark (release build) and prints, after their own reports (medians with min–max and the ratio to
# each issue's anchor), the heavy jobs next to bounds measured on THIS machine by `bench_bounds` (memory bandwidth
# by STREAM's triad, the f64 FLOP rate of the widest FMA path), the SIMD path each job takes here, and the ratio.
# A bound is the job's work (fixed by the performance analysis) divided by this machine's rate:
#   skin LUT 0.95 GFLOP (15 ms at 63.5 GFLOP/s), hemoglobin rig 79 GFLOP (1.25 s at 63.5 GFLOP/s, its loads counted
#   as flops), CPU SMAA 44.9 MB moved (2.3 ms at 19.5 GB/s) — the rates of the AVX-512F AMD EPYC the performance analysis used.
#   scripts/bench.sh [BENCH ...]     (default: all; logs in bench-out/<bench>.txt)
#   scripts/bench_skin_frames.sh [W H N]   (`run skin` frames per shader, before vs after a change, one adapter)
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
echo "== bench_bounds (this machine)"
./target/release/examples/bench_bounds | tee "$OUT/bench_bounds.txt"
for b in "${BENCHES[@]}"; do
    echo "== $b"
    "./target/release/examples/$b" 2>/dev/null | tee "$OUT/$b.txt"
done

# Heavy jobs against the bounds of this machine: the bound, the figure parsed from the logs above, the ratio.
row() { # name, figure in ms (or empty), bound in ms, goal ratio, SIMD path
    if [ -z "$2" ]; then printf '%-44s %12s %10.2f ms %8s   goal <= %sx  [%s]\n' "$1" "(not run)" "$3" "" "$4" "$5"; return; fi
    awk -v n="$1" -v f="$2" -v b="$3" -v g="$4" -v p="$5" \
        'BEGIN { printf "%-44s %9.1f ms %10.2f ms %7.2fx   goal <= %sx %s  [%s]\n", n, f, b, f / b, g, (f / b <= g ? "met" : "NOT met"), p }'
}
gbps=$(sed -n 's/^bounds: memory \([0-9.]*\) GB\/s.*/\1/p' "$OUT/bench_bounds.txt")
gflops=$(sed -n 's/^bounds: .*, f64 \([0-9.]*\) GFLOP\/s.*/\1/p' "$OUT/bench_bounds.txt")
path() { sed -n "s/^simd: .*$1 \\([a-z0-9+]*\\).*/\\1/p" "$OUT/bench_bounds.txt"; }
bound() { awk -v w="$1" -v r="$2" 'BEGIN { printf "%.3f", w / r }'; } # work in MFLOP or MB / rate in GFLOP/s or GB/s = ms
skin=$(sed -n 's/^table (tabulated, default): wall \([0-9.]*\) s.*/\1/p' "$OUT/bench_skin.txt" 2>/dev/null | awk '{print $1 * 1000}')
rig=$(sed -n 's/.*wall median \([0-9.]*\) s of.*/\1/p' "$OUT/bench_facial.txt" 2>/dev/null | awk '{print $1 * 1000}')
smaa=$(sed -n 's/^CPU reference SMAA 1x 1920x1080, 2 threads: \([0-9.]*\) ms.*/\1/p' "$OUT/bench_runtime.txt" 2>/dev/null)
smaa_reused=$(sed -n 's/^CPU reference SMAA 1x 1920x1080, 2 threads, buffers reused: \([0-9.]*\) ms.*/\1/p' \
    "$OUT/bench_runtime.txt" 2>/dev/null)
echo "== heavy jobs vs this machine's bounds ($gbps GB/s, $gflops GFLOP/s; the analysis machine: 19.5 GB/s, 63.5 GFLOP/s)"
printf '%-44s %12s %13s %8s\n' "job" "median" "bound" "ratio"
row "skin LUT 256x256 at 1 nm (FLOP bound)" "$skin" "$(bound 952.5 "$gflops")" 2 "$(path skin-lut)"
row "hemoglobin rig 4096x4096, 9 maps, r = 32 (FP)" "$rig" "$(bound 79375 "$gflops")" 2 "$(path rig)"
row "CPU SMAA 1x 1080p (memory bound)" "$smaa" "$(bound 44.85 "$gbps")" 3 "no explicit SIMD path"
row "CPU SMAA 1x 1080p, reused buffers (memory)" "$smaa_reused" "$(bound 44.85 "$gbps")" 3 "no explicit SIMD path"

# The lane kernel per instruction-set path against MCML 1.2.2, CPU seconds on one core (MCML_BIN / MCML_BIN2 name
# MCML binaries; without them the script says MCML is absent and prints rtbake's figures only).
echo "== bench_mcml (scripts/bench_mcml.sh)"
bash scripts/bench_mcml.sh | tee "$OUT/bench_mcml.txt"
