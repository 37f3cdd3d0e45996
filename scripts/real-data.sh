#!/usr/bin/env bash
# Full-resolution runs of `voxlod lod` on every mesh of ../shared/data and on the CT head at
# both thresholds (6 levels from 256, the command's defaults): every level must be a closed
# manifold. With them, the moderate-resolution tests, among them the orientation check of the
# shared CT head, NIfTI (Colin27), MetaImage (lung CT) and NRRD (tooth): the centroid of each
# mesh, in LPS, against the world centroid of the thresholded voxels as nibabel's affine or
# SimpleITK places them (skipped, saying why, without the peers' Python). Takes a minute or
# two; CI runs the moderate-resolution tests only.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --release -p voxlod-cli --test real_data -- --include-ignored "$@"
