#!/usr/bin/env bash
# Full-resolution runs of `voxlod lod` on every mesh of ../shared/data, on the CT head at both
# thresholds and on the other scans (6 levels, the command's defaults): every level must be a
# closed manifold, and the genus must never rise from a level to the next (each chain's
# resolutions and genus sequence are printed). Takes a few minutes; CI runs the
# moderate-resolution version.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --release -p voxlod-cli --test real_data -- --include-ignored --nocapture "$@"
