#!/usr/bin/env bash
# Levels of textured assets by appearance, voxlod's against gltfpack's `-si`, for BENCHMARKS.md:
# Spot (its OBJ written once as .glb) and two generated multi-part textured scenes (one with
# vertex colours), at 50 %, 20 %, 5 % and 1 % of the triangles; PSNR and SSIM over the 14 views
# (voxlod_eval::appearance), triangles, looks and seconds of each level, in the same run
# (crates/voxlod-eval/examples/looks_bench.rs).
# Usage: scripts/looks-bench.sh [OUT_DIR]   (default ~/.cache/voxlod-bench/looks)
# GLTFPACK overrides the gltfpack binary (default: the npm one in ~/.cache/voxlod-peers).
set -euo pipefail
cd "$(dirname "$0")/.."
OUT="${1:-${VOXLOD_BENCH_DIR:-$HOME/.cache/voxlod-bench}/looks}"
GLTFPACK="${GLTFPACK:-$HOME/.cache/voxlod-peers/node_modules/.bin/gltfpack}"
SPOT="${VOXLOD_SHARED_DATA:-../shared/data}/assets/spot/spot.obj"
mkdir -p "$OUT"
cargo build --release -q -p voxlod-eval --example looks_bench
echo "machine: $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg)"
"$GLTFPACK" -v 2>&1 | head -1 || true
target/release/examples/looks_bench "$OUT" "$GLTFPACK" "$SPOT" | tee "$OUT/looks-bench.txt"
echo "JSON: $OUT/looks-bench.json"
