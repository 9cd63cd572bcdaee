#!/usr/bin/env bash
# Regenerates every committed asset in baked/ from the embedded defaults, then verifies the result.
# This is the one command that produced the repository's baked/ directory.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo run --locked -- bake --out baked "$@"
cargo run --locked -- verify --dir baked
