#!/usr/bin/env bash
# Full-resolution runs of `voxlod lod` on every mesh of ../shared/data, on the CT head at both
# thresholds and on the other scans (6 levels, the command's defaults): every level must be a
# closed manifold, and the genus must never rise from a level to the next (each chain's
# resolutions and genus sequence are printed), and the same meshes by budget (--triangles
# 20000,5000,1000,250: each level within 10 %, the genus never rising). With them, the
# moderate-resolution tests, among them the orientation check of the shared CT head, NIfTI
# (Colin27), MetaImage (lung CT) and NRRD (tooth): the centroid of each mesh, in LPS, against
# the world centroid of the thresholded voxels as nibabel's affine or SimpleITK places them
# (skipped, saying why, without the peers' Python). Then the budget targets on every shared mesh
# and generated case, beside meshoptimizer (voxlod-budget's ignored `targets` test).
# Takes a few minutes; CI runs the moderate-resolution tests only.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --release -p voxlod-cli --test real_data -- --include-ignored --nocapture "$@"
cargo test --release -p voxlod-budget --test targets -- --include-ignored --nocapture
