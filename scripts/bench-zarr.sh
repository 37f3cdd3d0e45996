#!/usr/bin/env bash
# Issue 14, item 3: peak memory of the bricked threshold route on a chunked Zarr scan.
#
# Generates an N³ u8 gyroid (period N/2 samples, chunks of 128³, zarr-python's default zstd)
# as a Zarr v3 array and the same samples as a raw file under ~/.cache/voxlod-zarr-bench,
# then runs `voxlod lod --threshold 128 --resolution N --levels 1` on the Zarr (bricked route)
# and, when N <= 512, on the raw file (dense route) under /usr/bin/time -v, and prints wall
# time, peak resident memory and the triangle counts. Usage: scripts/bench-zarr.sh [N] (1024).
# Needs a Python with numpy and zarr >= 3 ($PYTHON, else ~/.cache/voxlod-peers/bin/python).
set -euo pipefail
n=${1:-1024}
root=$(cd "$(dirname "$0")/.." && pwd)
python=${PYTHON:-$HOME/.cache/voxlod-peers/bin/python}
voxlod=${VOXLOD:-${CARGO_TARGET_DIR:-$root/target}/release/voxlod}
dir=$HOME/.cache/voxlod-zarr-bench
mkdir -p "$dir"
if ! "$python" -c 'import numpy, zarr' 2>/dev/null; then
    echo "skipped: $python has no numpy and zarr (pip install numpy 'zarr>=3')" >&2
    exit 0
fi
[ -x "$voxlod" ] || (cd "$root" && cargo build --release -p voxlod-cli)
base=$dir/gyroid-$n
if [ ! -d "$base.zarr" ]; then
    "$python" - "$n" "$base" <<'PY'
import sys, numpy as np, zarr
n, base = int(sys.argv[1]), sys.argv[2]
k = 2 * np.pi / (n / 2)
x = np.arange(n) * k
z = zarr.create_array(base + ".zarr", shape=(n, n, n), chunks=(128, 128, 128), dtype="u1",
                      dimension_names=["z", "y", "x"], overwrite=True)
with open(base + ".raw", "wb") as raw:
    for z0 in range(0, n, 128):
        zs = x[z0:z0 + 128]
        g = (np.sin(x)[None, None, :] * np.cos(x)[None, :, None]
             + np.sin(x)[None, :, None] * np.cos(zs)[:, None, None]
             + np.sin(zs)[:, None, None] * np.cos(x)[None, None, :])
        slab = np.clip(128 + 80 * g, 0, 255).astype(np.uint8)
        z[z0:z0 + len(zs)] = slab
        raw.write(slab.tobytes())
PY
fi
echo "machine: $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg)"
run() {
    local name=$1; shift
    local out=$dir/out-$name
    /usr/bin/time -v "$voxlod" lod "$@" --threshold 128 --resolution "$n" --levels 1 -o "$out" \
        --json > "$out.json" 2> "$out.time"
    local peak wall tris
    peak=$(awk -F': ' '/Maximum resident/ {printf "%.0f MiB", $2 / 1024}' "$out.time")
    wall=$(awk -F': ' '/Elapsed/ {print $2}' "$out.time")
    tris=$("$python" -c "import json,sys; print(json.load(open(sys.argv[1]))['levels'][0]['triangles'])" "$out.json")
    echo "$name: ${n}^3 u8, wall $wall, peak RSS $peak, $tris triangles"
}
run zarr "$base.zarr"
if [ "$n" -le 512 ]; then
    run raw "$base.raw" --dims "$n,$n,$n" --dtype u8
fi
