#!/usr/bin/env bash
# The budget portfolio's figures for BENCHMARKS.md: on every shared mesh and every generated
# case (voxlod-testkit's corpus), at 1/8, 1/32 and 1/128 of the input's triangles and at 1000 and
# 300 where below 1/8, the two-sided Hausdorff and mean distance of `voxlod lod --triangles`'s
# levels beside meshoptimizer's simplify and simplifySloppy on the same input, in the same run
# (one independent measure, 50 000 samples a side), and the chain's time against simplify's for
# the same counts; then the CT head's bone surface and the 1.4 M-triangle sphereflake.
# Usage: scripts/budget-bench.sh [OUT_DIR]   (default ~/.cache/voxlod-bench/budget)
set -euo pipefail
cd "$(dirname "$0")/.."
OUT="${1:-${VOXLOD_BENCH_DIR:-$HOME/.cache/voxlod-bench}/budget}"
mkdir -p "$OUT"
cargo build --release -q -p voxlod-budget --example portfolio
cargo build --release -q
P=target/release/examples/portfolio
"$P" --shared --corpus --json "$OUT/shared-and-corpus.json" | tee "$OUT/shared-and-corpus.txt"
CT="${VOXLOD_SHARED_DATA:-../shared/data}/volumes/CThead_256x256x113_uint16be.raw"
if [ -f "$CT" ]; then
  target/release/voxlod contour "$CT" --dims 256,256,113 --dtype u16 --endian big \
    --spacing 1,1,2 --iso 1500 --close -o "$OUT/ctbone.ply"
  "$P" "$OUT/ctbone.ply" --sphereflake 392 --json "$OUT/ct-and-flake.json" | tee "$OUT/ct-and-flake.txt"
else
  echo "skipped the CT bone surface: $CT is absent"
  "$P" --sphereflake 392 --json "$OUT/flake.json" | tee "$OUT/flake.txt"
fi
