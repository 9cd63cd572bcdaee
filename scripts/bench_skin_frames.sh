#!/usr/bin/env bash
# `run skin` frames per shader on one adapter, in one run: the shading recorded into one command encoder with one
# read-back (the runtime's path) against each pass submitted and read back on its own (the path before), frame 1 on
# a fresh device and the median of frames 2..N with the two paths alternating, the ratio and the submissions and
# read-backs of a frame (examples/bench_skin_frames.rs).
#   scripts/bench_skin_frames.sh [WIDTH HEIGHT FRAMES [no-bloom]]   (default 1280 720 7; PROFILE=debug for a quick build)
# The adapter is the one wgpu picks (WGPU_ADAPTER_NAME / WGPU_BACKEND to choose); the binary prints it.
set -euo pipefail
cd "$(dirname "$0")/.."
W=${1:-1280} H=${2:-720} N=${3:-7}
PROFILE=${PROFILE:-release}
flag=$([ "$PROFILE" = release ] && echo --release || echo --profile=dev)
cargo build $flag --example bench_skin_frames --quiet
echo "$(git rev-parse --short HEAD) ($(git status --porcelain | grep -q . && echo 'with uncommitted changes' || echo clean)), $PROFILE build, ${W}x${H}, $N frames"
"${CARGO_TARGET_DIR:-target}/$PROFILE/examples/bench_skin_frames" "$W" "$H" "$N" ${4:-} 2>/dev/null
