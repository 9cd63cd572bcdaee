#!/usr/bin/env bash
# `run skin` frames before and after, in one run on one adapter: builds examples/bench_skin_frames at BASE (default:
# the merge-base with main, the runtime before this branch) from a `git archive` copy and at HEAD, runs both binaries
# back to back and prints, per shader, frame 1 and the median of frames 2..N (the "cached" columns: the runtime's
# per-device caches on, as `run skin` runs) before and after and the speed-ups, and the queue submissions and host
# read-backs of a steady-state frame after (the before binary may predate the counters).
#   scripts/bench_skin_frames.sh [WIDTH HEIGHT FRAMES]        (default 1280 720 5; PROFILE=debug for a quick run)
#   BASE=<commit> scripts/bench_skin_frames.sh ...
# The adapter is the one wgpu picks (WGPU_ADAPTER_NAME / WGPU_BACKEND to choose); both binaries print it.
set -euo pipefail
cd "$(dirname "$0")/.."
W=${1:-1280} H=${2:-720} N=${3:-5}
PROFILE=${PROFILE:-release}
BASE=${BASE:-$(git merge-base HEAD main)}
flag=$([ "$PROFILE" = release ] && echo --release || true)
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
mkdir -p "$dir/src" && git archive "$BASE" | tar -x -C "$dir/src"
# One target directory for both builds: only rtbake itself is compiled twice (run no other cargo command on that
# target directory meanwhile: the before build replaces the library there until the after build).
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-$PWD/target}
# Same package in two places: cargo's freshness check compares mtimes, so touch the crate root before each build.
touch "$dir/src/src/lib.rs"
(cd "$dir/src" && cargo build $flag --example bench_skin_frames --quiet)
cp "$CARGO_TARGET_DIR/$PROFILE/examples/bench_skin_frames" "$dir/before"
touch src/lib.rs
cargo build $flag --example bench_skin_frames --quiet
cp "$CARGO_TARGET_DIR/$PROFILE/examples/bench_skin_frames" "$dir/after"
cmp -s "$dir/before" "$dir/after" && { echo "before and after binaries are identical: nothing to compare" >&2; exit 1; }
echo "before: $(git rev-parse --short "$BASE"), after: $(git rev-parse --short HEAD) ($(git status --porcelain | grep -q . && echo 'with uncommitted changes' || echo clean)), $PROFILE build, ${W}x${H}, $N frames"
"$dir/before" "$W" "$H" "$N" 2>/dev/null | tee "$dir/before.txt"
"$dir/after" "$W" "$H" "$N" 2>/dev/null | tee "$dir/after.txt"
echo "== per shader, wall ms (runtime caches on): before -> after"
printf '%-12s %12s %12s %8s %12s %12s %8s\n' shader "1st before" "1st after" ratio "2..N before" "2..N after" ratio
for s in none ss-jittered ss-full separable ts; do
    b=$(awk -v s="$s" '$1 == s { print $5, $6 }' "$dir/before.txt")
    a=$(awk -v s="$s" '$1 == s { print $5, $6 }' "$dir/after.txt")
    [ -n "$b" ] && [ -n "$a" ] || continue
    c=$(awk -v s="$s" '$1 == s && NF >= 10 { print $9, $10 }' "$dir/after.txt")
    echo "$s $b $a ${c:-- -}" | awk '{ printf "%-12s %12.1f %12.1f %7.2fx %12.1f %12.1f %7.2fx   after: %s submissions, %s read-backs per frame\n", $1, $2, $4, $2 / $4, $3, $5, $3 / $5, $6, $7 }'
done
