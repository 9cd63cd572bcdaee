#!/usr/bin/env bash
# Runs the GPU pass benchmarks from a directory of release example binaries and prints everything: the adapter,
# the copy bandwidth, per pass the GPU time (timestamp queries where the adapter has them), the bytes it moves,
# its bytes-moved bound and time/bound, and the SMAA modes.
#
#   scripts/gpu_bench.sh BIN_DIR [WIDTHxHEIGHT]      # default 1920x1080
#
# On a GPU machine, from the repository root (the exact command; release build of the examples, then the run):
#   cargo build --release --example bench_runtime --example bench_smaa_modes --example bench_skin_frames \
#     --example bench_frame_passes && scripts/gpu_bench.sh target/release/examples 1920x1080 2>&1 | tee gpu_bench.log
#
# SMAA 1x and MLAA are measured in both shapes in one run: bench_runtime times the fragment passes (before) and the
# compute passes (after, the default) side by side, each pass beside its bytes-moved bound, and prints the speed-up;
# bench_smaa_modes runs once per shape (RTBAKE_AA_PASSES=fragment, then compute). The per-shape byte identity is
# a test: `cargo test --test it runtime_smaa::compute_and_fragment` (run it on the GPU too).
# The SSS passes likewise: bench_runtime times separable, sum of Gaussians and SS Jittered as fragment passes (before)
# and compute passes (after) side by side, each pass beside its bound (RTBAKE_SSS_PASSES=fragment|compute picks the
# shape elsewhere). Their GPU-vs-CPU tests: `cargo test --test it -- runtime_gaussian_sss runtime_importance_sss`.
#
# BIN_DIR holds release builds of the examples (`cargo build --release --example bench_runtime --example
# bench_smaa_modes` puts them in target/release/examples). The same command runs binaries built from an older tree
# (e.g. main): bench_runtime there ignores the size argument and prints both 1280x720 and 1920x1080 without the
# bounds, and both print their own medians. Tables are read from $RTBAKE_BAKED_DIR, else ./baked when it exists
# (run from the repository root: the binaries' built-in path is the tree they were compiled in, which a copy of the
# tree on another machine does not have).
set -euo pipefail
bin=${1:?usage: scripts/gpu_bench.sh BIN_DIR [WIDTHxHEIGHT]}
size=${2:-1920x1080}
if [[ ! $size =~ ^[0-9]+x[0-9]+$ ]]; then
  echo "gpu_bench.sh: size must be WIDTHxHEIGHT, e.g. 1920x1080, got '$size'" >&2
  exit 2
fi
for b in bench_runtime bench_smaa_modes; do
  [[ -x $bin/$b ]] || { echo "gpu_bench.sh: $bin/$b is missing (build it with --release --example $b)" >&2; exit 2; }
done
if [[ -z ${RTBAKE_BAKED_DIR:-} && -d baked ]]; then
  export RTBAKE_BAKED_DIR=$PWD/baked
fi
echo "== gpu_bench $(date -u +%FT%TZ) bin=$bin size=$size"
command -v nvidia-smi >/dev/null && nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.mem --format=csv || true
echo "== bench_runtime $size gpu-only"
"$bin/bench_runtime" "$size" gpu-only
for shape in fragment compute; do
  echo "== bench_smaa_modes RTBAKE_AA_PASSES=$shape"
  RTBAKE_AA_PASSES=$shape "$bin/bench_smaa_modes"
done
if [[ -x $bin/bench_skin_frames ]]; then
  # run skin's whole frame per shader, the runtime's caches off (as before them) and on; absent from older trees.
  echo "== bench_skin_frames ${size/x/ } 5"
  "$bin/bench_skin_frames" ${size/x/ } 5 2>/dev/null
fi
if [[ -x $bin/bench_frame_passes ]]; then
  # every pass of run skin's frame per shader, GPU ms beside its bytes-moved bound; absent from older trees.
  echo "== bench_frame_passes ${size/x/ } 7"
  "$bin/bench_frame_passes" ${size/x/ } 7 2>/dev/null
fi
