#!/usr/bin/env bash
# Scene proxies beside gltfpack, for BENCHMARKS.md: the generated scenes of voxlod-testkit
# (room, machine, tree, building, props) at 5 % and 1 % of their triangles and Spot at 20 %,
# 5 % and 1 %; voxlod's baked proxy level against gltfpack -si and -si -sa on the same .glb,
# each read back: PSNR and SSIM over the 14 views, draw calls, triangles, closedness, the
# normal measure and seconds, in the same run (crates/voxlod-eval/examples/proxy_bench.rs).
# Then the time target: scene_1m (about 1 M triangles) to three proxy levels with 2048²
# textures, its seconds and its peak memory (/usr/bin/time -v).
# Usage: scripts/proxy-bench.sh [OUT_DIR]   (default ~/.cache/voxlod-bench/proxy)
# GLTFPACK overrides the gltfpack binary (default: the npm one in ~/.cache/voxlod-peers);
# PROXY_BENCH_ONLY=scenes or =time runs one half; PROXY_BENCH_INPUTS=tree,spot only those inputs.
# PROXY_BENCH_TEXTURE=2048 bakes the proxies' textures at that side (default 1024).
set -euo pipefail
cd "$(dirname "$0")/.."
OUT="${1:-${VOXLOD_BENCH_DIR:-$HOME/.cache/voxlod-bench}/proxy}"
GLTFPACK="${GLTFPACK:-$HOME/.cache/voxlod-peers/node_modules/.bin/gltfpack}"
SPOT="${VOXLOD_SHARED_DATA:-../shared/data}/assets/spot/spot.obj"
ONLY="${PROXY_BENCH_ONLY:-all}"
mkdir -p "$OUT"
cargo build --release -q -p voxlod-eval --example proxy_bench
BENCH=target/release/examples/proxy_bench
echo "machine: $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg)"
if [ "$ONLY" != time ]; then
    "$GLTFPACK" -v 2>&1 | head -1 || true
    "$BENCH" "$OUT" "$GLTFPACK" "$SPOT" | tee "$OUT/proxy-bench.txt"
    echo "JSON: $OUT/proxy-bench.json"
fi
if [ "$ONLY" != scenes ]; then
    echo "machine: load average $(cut -d' ' -f1-3 /proc/loadavg)"
    /usr/bin/time -v "$BENCH" --time-1m "$OUT" 2> "$OUT/time-1m.txt" | tee "$OUT/proxy-bench-1m.txt"
    grep -E "Elapsed \(wall clock\)|Maximum resident set size" "$OUT/time-1m.txt"
    peak_kb=$(sed -n 's/.*Maximum resident set size (kbytes): //p' "$OUT/time-1m.txt")
    python3 - "$OUT/proxy-bench-1m.json" "$peak_kb" <<'PY'
import json, sys
path, peak = sys.argv[1], int(sys.argv[2])
report = json.load(open(path))
report["peak_rss_mib"] = round(peak / 1024, 1)
json.dump(report, open(path, "w"), indent=2)
print(f"peak memory {report['peak_rss_mib']} MiB; JSON: {path}")
PY
fi
