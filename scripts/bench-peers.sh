#!/usr/bin/env bash
# Side-by-side benchmarks of voxlod and the peers (VTK, SciPy, Open3D, trimesh, scikit-image) on
# the same inputs and machine, for BENCHMARKS.md. Needs ../shared/peers set up
# (../shared/peers/setup.sh) and hyperfine. Inputs go to $VOXLOD_BENCH_DIR (default
# ~/.cache/voxlod-bench).
set -euo pipefail
cd "$(dirname "$0")/.."
P="${VOXLOD_PEERS:-$HOME/.cache/voxlod-peers}/bin/python"
KIT=../shared/peers/peers.py
D="${VOXLOD_BENCH_DIR:-$HOME/.cache/voxlod-bench}"
mkdir -p "$D"
cargo build --release -q
V=target/release/voxlod

[ -f "$D/sf512.nrrd" ] || "$P" "$KIT" gen-volume --field sphereflake --n 512 -o "$D/sf512.nrrd"
[ -f "$D/gy256.nrrd" ] || "$P" "$KIT" gen-volume --field gyroid --n 256 -o "$D/gy256.nrrd"
[ -f "$D/sf1M.ply" ] || "$P" "$KIT" gen-mesh --field sphereflake --n 392 -o "$D/sf1M.ply"

echo "== marching cubes (peers: VTK FlyingEdges3D, scikit-image)"
"$P" "$KIT" mc "$D/sf512.nrrd" --iso 0
"$P" "$KIT" mc "$D/gy256.nrrd" --iso 0
echo "== marching cubes (voxlod contour, geometry only, 5 runs: triangles, marching cubes alone, the whole contouring with its checks and topology)"
for f in sf512 gy256; do
  for _ in 1 2 3 4 5; do
    "$V" contour "$D/$f.nrrd" -o "$D/$f.ply" --iso 0 --no-normals --json |
      "$P" -c "import json,sys; r=json.load(sys.stdin); print('$f', r['triangles'], round(r['marching_cubes_seconds'], 4), round(r['contour_seconds'], 4))"
  done
done

echo "== Gaussian sigma = 1 voxel on 512^3 (peers: SciPy, VTK)"
"$P" "$KIT" gauss "$D/sf512.nrrd" --sigma 1
echo "== occupancy / filtered density of the ~1.4 M-triangle sphereflake mesh at 128^3 (peers: Open3D, trimesh)"
"$P" "$KIT" occupancy "$D/sf1M.ply" --res 128
echo "== voxlod criterion benches (Gaussian, density, marching cubes)"
cargo bench -q -p voxlod --bench sampling 2>&1 | grep -E "^(gaussian|density)/|time:"
cargo bench -q -p voxlod-contouring --bench marching_cubes 2>&1 | grep -E "^marching_cubes/|time:"

echo "== vertex clustering at 64 cells (peers: Open3D, meshoptimizer simplifySloppy, VTK quadric clustering)"
"$P" "$KIT" --repeats 9 cluster "$D/sf1M.ply" --cells 64
echo "== voxlod clustering, 2 threads then 1 (best and median of 15)"
cargo run --release -q -p voxlod-clustering --example cluster_timing -- "$D/sf1M.ply" 64 15
RAYON_NUM_THREADS=1 cargo run --release -q -p voxlod-clustering --example cluster_timing -- "$D/sf1M.ply" 64 15

if [ -f ../shared/data/meshes/stanford-bunny.obj ]; then
  echo "== voxlod lod on the bunny, 6 levels from 256"
  hyperfine --warmup 1 --runs 5 --prepare "rm -rf $D/bunny" "$V lod ../shared/data/meshes/stanford-bunny.obj -o $D/bunny"
fi
