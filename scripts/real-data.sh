#!/usr/bin/env bash
# Full-resolution runs of `voxlod lod` on every mesh of ../shared/data and on the CT head at
# both thresholds (6 levels from 256, the command's defaults): every level must be a closed
# manifold. Takes a minute or two; CI runs the moderate-resolution version.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --release -p voxlod-cli --test real_data -- --include-ignored "$@"
