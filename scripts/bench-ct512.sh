#!/usr/bin/env bash
# Issue 14, the CT target: a 512×512×361 int16 CT thresholded, six levels from 256, against VTK
# FlyingEdges3D's full-resolution contour of the same data (target: within 4× of it).
#
# Generates the CT once (the shared CT head, 256×256×113 u16 at 1×1×2 mm, resampled trilinearly
# to 512×512×361 over the same box, stored as little-endian int16 in a raw-encoded NRRD; a
# synthetic head of skin and skull when ../shared/data is absent) under
# $CARGO_TARGET_DIR/bench-ct512 (never committed), then runs under /usr/bin/time:
#   dense          voxlod lod CT.nrrd --threshold T            (the scan read whole; default chain)
#   dense-plain    ... --no-monotone --no-clean                (plain marching cubes)
#   blockwise      ... --blockwise                             (read blockwise, same levels)
#   blockwise-plain ... --blockwise --no-monotone --no-clean
#   vtk            VTK FlyingEdges3D at full resolution, 2 threads (peers' reader, one contour;
#                  the median of 3 contour calls is printed beside the process's figures)
# and prints wall, CPU (user + sys), peak RSS and triangles of each, the load average, and
# whether each blockwise run's levels have the dense run's triangle counts.
# Then the shared CT head at full resolution (the issue's under-1-s target), when present.
# Usage: scripts/bench-ct512.sh [T] (500: the skin; 1500: the skull).
# Needs the peers' Python (~/.cache/voxlod-peers, ../shared/peers/setup.sh) or $PYTHON with
# numpy, scipy and vtk.
set -euo pipefail
threshold=${1:-500}
root=$(cd "$(dirname "$0")/.." && pwd)
python=${PYTHON:-$HOME/.cache/voxlod-peers/bin/python}
peers=${VOXLOD_PEERS_DIR:-$root/../shared/peers}
target=${CARGO_TARGET_DIR:-$root/target}
voxlod=${VOXLOD:-$target/release/voxlod}
dir=$target/bench-ct512
mkdir -p "$dir"
if ! "$python" -c 'import numpy, scipy, vtk' 2>/dev/null; then
    echo "skipped: $python has no numpy, scipy and vtk (../shared/peers/setup.sh)" >&2
    exit 0
fi
[ -x "$voxlod" ] || (cd "$root" && cargo build --release -p voxlod-cli)
ct=$dir/ct-512x512x361-int16.nrrd
if [ ! -f "$ct" ]; then
    "$python" - "$ct" "$root/../shared/data/volumes/CThead_256x256x113_uint16be.raw" <<'PY'
import os, sys
import numpy as np
from scipy import ndimage
out, head = sys.argv[1], sys.argv[2]
shape = (361, 512, 512)  # z, y, x
if os.path.exists(head):
    ct = np.fromfile(head, dtype=">u2").reshape(113, 256, 256).astype(np.float32)
    extent = (112 * 2.0, 255.0, 255.0)
    # Corners aligned (grid_mode=False): the zoom factors only fix the output shape.
    big = ndimage.zoom(ct, [n / m for n, m in zip(shape, ct.shape)], order=1,
                       grid_mode=False)
    assert big.shape == shape, big.shape
    what = "the CT head resampled"
else:
    extent = (224.0, 255.0, 255.0)
    z, y, x = np.ogrid[-1:1:361j, -1:1:512j, -1:1:512j]
    r = np.sqrt((x / 0.8) ** 2 + (y / 0.9) ** 2 + (z / 0.95) ** 2)
    big = np.where(r < 0.95, 1050.0, 20.0) + np.where((r > 0.85) & (r < 0.9), 900.0, 0.0)
    big = ndimage.gaussian_filter(big.astype(np.float32), 1.5)
    what = "a synthetic head"
spacing = [e / (n - 1) for e, n in zip(extent, shape)]  # z, y, x
data = np.rint(big).astype("<i2")
with open(out + ".part", "wb") as fh:
    fh.write((f"NRRD0004\ntype: short\ndimension: 3\nsizes: 512 512 361\n"
              f"spacings: {spacing[2]} {spacing[1]} {spacing[0]}\nendian: little\n"
              f"encoding: raw\n\n").encode())
    fh.write(data.tobytes())
os.replace(out + ".part", out)
print(f"generated {out}: {what}, values {data.min()}..{data.max()}", file=sys.stderr)
PY
fi
echo "machine: $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg); CT $ct, threshold $threshold"
triangles() {
    "$python" -c "import json,sys; print(' '.join(str(l['triangles']) for l in json.load(open(sys.argv[1]))['levels']))" "$1"
}
figures() {  # wall, CPU and peak RSS from a /usr/bin/time -v log
    awk -F': ' '/Elapsed/ {w=$2} /User time/ {u=$2} /System time/ {s=$2}
        /Maximum resident/ {m=$2} END {printf "wall %s, cpu %.2f s, peak RSS %.0f MiB", w, u + s, m / 1024}' "$1"
}
run() {
    local name=$1; shift
    local out=$dir/out-$name
    /usr/bin/time -v "$voxlod" lod "$ct" --threshold "$threshold" -o "$out" --json "$@" \
        > "$out.json" 2> "$out.time"
    echo "$name: $(figures "$out.time"); triangles per level $(triangles "$out.json")"
}
run dense
run dense-plain --no-monotone --no-clean
run blockwise --blockwise
run blockwise-plain --blockwise --no-monotone --no-clean
for pair in "dense blockwise" "dense-plain blockwise-plain"; do
    set -- $pair
    if [ "$(triangles "$dir/out-$1.json")" = "$(triangles "$dir/out-$2.json")" ]; then
        echo "$2: the same triangle counts as $1"
    else
        echo "$2: triangle counts DIFFER from $1"
    fi
done
/usr/bin/time -v "$python" - "$peers" "$ct" "$threshold" > "$dir/vtk.out" 2> "$dir/vtk.time" <<'PY'
import sys, time
sys.path.insert(0, sys.argv[1])
import numpy as np
import vtk
from peers import read_nrrd, vtk_image
arr, _, _ = read_nrrd(sys.argv[2])
img = vtk_image(np.ascontiguousarray(arr, dtype=np.float32))
vtk.vtkSMPTools.Initialize(2)
times = []
for _ in range(3):
    t = time.perf_counter()
    fe = vtk.vtkFlyingEdges3D()
    fe.SetInputData(img)
    fe.SetValue(0, float(sys.argv[3]))
    fe.ComputeNormalsOff()
    fe.Update()
    times.append(time.perf_counter() - t)
print(f"{sorted(times)[1]:.3f} s per contour (median of 3), "
      f"{fe.GetOutput().GetNumberOfCells()} triangles")
PY
echo "vtk FlyingEdges3D (2 threads, full resolution): $(cat "$dir/vtk.out"); process (read, 3 contours): $(figures "$dir/vtk.time")"
# The second target: the shared CT head itself at full resolution (one level), under 1 s.
head=$root/../shared/data/volumes/CThead_256x256x113_uint16be.raw
if [ -f "$head" ]; then
    for flags in "" "--no-monotone --no-clean"; do
        out=$dir/out-cthead
        # shellcheck disable=SC2086
        /usr/bin/time -v "$voxlod" lod "$head" --dims 256,256,113 --dtype u16 --endian big \
            --spacing 1,1,2 --threshold "$threshold" --resolution 256 --levels 1 -o "$out" \
            --json $flags > "$out.json" 2> "$out.time"
        echo "CT head 256x256x113 at resolution 256 ${flags:-(default chain)}: $(figures "$out.time"); triangles $(triangles "$out.json")"
    done
fi
