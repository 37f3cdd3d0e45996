#!/usr/bin/env bash
# The long version of the readers' mutation sweep (crates/voxlod-io/tests/mutation_sweep.rs),
# for a night: every seed file of every format mutated ITERATIONS times, for each of ROUNDS
# random seeds, in release mode. A failure stops the run and prints the mutations and where
# the failing file was kept (target/.../tmp/mutation-sweep-failures/). The seeds are the
# test's: files of every format, and Zarr stores (folders: a format-3 and a format-2 array and
# an OME-Zarr 0.4 group, each with its zarr.json, .zarray or .zattrs, or one chunk, mutated).
#
#   scripts/mutation-sweep.sh                 # 20 rounds x 5000 mutations per seed file
#   ITERATIONS=20000 ROUNDS=100 scripts/mutation-sweep.sh
#   FIRST_SEED=7 ROUNDS=1 scripts/mutation-sweep.sh   # one round again, to reproduce it
#
# The seeds are those of mutation_sweep.rs: every format, DICOM among them (a CT slice, c.dcm,
# and a segmentation, s.seg.dcm, read as a label map); OBJ, PLY and OFF are read with their looks
# too (read_asset), and a textured OBJ with its MTL is mutated on either file.
# The CI run (cargo test) uses 400 mutations per seed file and a fixed seed.
set -euo pipefail
cd "$(dirname "$0")/.."
iterations=${ITERATIONS:-5000}
rounds=${ROUNDS:-20}
first=${FIRST_SEED:-1}
cargo test --release -p voxlod-io --test mutation_sweep --no-run
for ((seed = first; seed < first + rounds; seed++)); do
  echo "== round seed $seed, $iterations mutations per seed file"
  VOXLOD_SWEEP_ITERATIONS=$iterations VOXLOD_SWEEP_SEED=$seed \
    cargo test --release -p voxlod-io --test mutation_sweep -- --nocapture 2>&1 |
    grep -E "mutation sweep|panicked|mutations:|kept at|test result"
done
