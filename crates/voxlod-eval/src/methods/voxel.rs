//! What the three voxel methods share (not a method itself): one level of the voxel pipeline
//! (He et al. 1995, §2) at a given resolution, and the search space of that resolution.
//!
//! Cost: a filtered density at the level's resolution, then marching cubes; about 0.2 s at
//! resolution 64 on the bunny.

use voxlod::core::TriangleMesh;
use voxlod::lod::{build_level, plan, LevelOptions, LodSource};
use voxlod::sampling::{Filter, PyramidOptions};

use super::SearchLimits;
use super::{MethodInput, ParameterGrid, RunFailure, SearchSpace};

/// The voxel pipeline's level of the input's solid at `resolution` samples across the longest
/// side, with `filter` of one voxel's radius and isodensity 0.5, without normals; and the
/// level's voxel size.
pub(super) fn voxel_level(
    input: &MethodInput,
    resolution: f64,
    filter: Filter,
) -> Result<(TriangleMesh, f64), RunFailure> {
    let mut pyramid = PyramidOptions::for_resolutions(vec![resolution as usize], filter);
    pyramid.lines_per_radius = input.lines_per_radius();
    let lod = LevelOptions {
        pyramid,
        iso: 0.5,
        normals: false,
        // The paper's levels are plain marching cubes; cleaning (beyond the paper) is measured
        // through the budget pipeline, which cleans its own levels.
        clean: None,
        snap: false,
    };
    let source = LodSource::Solid(input.solid()?);
    let plans = plan(&source, &lod)?;
    let level = build_level(&source, &plans[0], &lod)?.mesh;
    Ok((level, plans[0].voxel_size))
}

/// Resolutions from 2 to [`SearchLimits::max_resolution`], starting at 64; triangle counts
/// grow about as the square of the resolution.
pub(super) fn resolution_space(limits: &SearchLimits) -> SearchSpace {
    SearchSpace {
        lowest: 2.0,
        highest: limits.max_resolution as f64,
        first: 64.0,
        first_at_budget: false,
        exponent: 2.0,
        grid: ParameterGrid::Integers,
    }
}
