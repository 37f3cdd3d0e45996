#!/usr/bin/env bash
# The budget pipeline's figures for BENCHMARKS.md (issue 12): on the bunny, rocker arm and
# fandisk of ../shared/data at 1/8, 1/32 and 1/128 of the input's triangles, the two-sided
# Hausdorff distance of the budget pipeline beside the clustering methods and meshoptimizer's
# simplify and simplifySloppy (voxlod evaluate); the bunny's chain of four budgets timed; and
# every shared mesh's levels checked against their budgets (within 10 %).
# Usage: scripts/budget-bench.sh [VOXLOD_BINARY]   (default: a release build of this checkout)
set -euo pipefail
cd "$(dirname "$0")/.."
DATA="${VOXLOD_SHARED_DATA:-../shared/data}/meshes"
OUT="${VOXLOD_BENCH_DIR:-$HOME/.cache/voxlod-bench}/budget"
mkdir -p "$OUT"
if [ $# -ge 1 ]; then V="$1"; else cargo build --release -q; V=target/release/voxlod; fi

echo "== Hausdorff (% of the diagonal) at 1/8, 1/32, 1/128 of the input's triangles"
for m in stanford-bunny rocker-arm fandisk; do
  f=$(ls "$DATA/$m".* | head -1)
  n=$("$V" inspect "$f" --json | python3 -c "import json,sys; print(json.load(sys.stdin)['triangles'])")
  b="$((n / 8)),$((n / 32)),$((n / 128))"
  "$V" evaluate "$f" -o "$OUT/$m" --budgets "$b" --views 0 --json \
    --methods budget,rossignac-borrel,low-tan,meshopt-sloppy,meshopt-simplify |
    python3 -c "
import json, sys
r = json.load(sys.stdin)
for c in r['curves']:
    cells = ['%6d: %.3f%% (%d)' % (p['budget'], 100 * p['hausdorff_fraction'], p['triangles']) for p in c['points']]
    print('$m', c['method'].ljust(18), ' | '.join(cells), *c['misses'])"
done

echo "== the bunny's chain of four budgets (wall seconds)"
/usr/bin/time -f "%e s wall" "$V" lod "$DATA/stanford-bunny.obj" -o "$OUT/bunny-chain" \
  --triangles 20000,5000,1000,250 --json | python3 -c "
import json, sys
r = json.load(sys.stdin)
for l in r['levels']:
    print(l['budget'], l['triangles'], l['resolution'], l['stage'], 'H=%.5f' % l['hausdorff'], 'genus', l['genus'], 'loops', l['boundary_loops'])"

echo "== budget accuracy on every shared mesh (20000, 5000, 1000, 250)"
for f in "$DATA"/*; do
  "$V" lod "$f" -o "$OUT/acc" --triangles 20000,5000,1000,250 --json 2>/dev/null | python3 -c "
import json, sys
r = json.load(sys.stdin)
misses = [(l['budget'], l['triangles']) for l in r['levels'] if abs(l['triangles'] / l['budget'] - 1) > 0.1]
print('$(basename "$f")', [l['triangles'] for l in r['levels']], 'misses:', misses or 'none')" ||
    echo "$(basename "$f"): failed"
done
