//! The use the voxel paper proposes for itself (He et al. 1995, §5): the voxel pipeline with the
//! hyper-cone filters away the small features and the genus, then simplification envelopes
//! within one voxel of that level remove the triangles marching cubes spends on flat regions,
//! keeping the genus the filter made. Its parameter is the resolution; ε is one voxel of it.
//!
//! Cost: a voxel level (see `voxel.rs`), then the envelope of its triangles. Envelope levels
//! within one voxel keep about a twentieth of marching cubes' triangles, and above resolution
//! 256 the envelope of millions of triangles costs minutes: resolutions above 256 are not tried.

use voxlod::core::PolyMesh;
use voxlod::envelope::Epsilon;
use voxlod::sampling::Filter;

use super::envelope::envelope_level;
use super::voxel::voxel_level;
use super::SearchLimits;
use super::{MethodInput, Needs, ParameterGrid, RunFailure, SearchSpace, Simplifier};

/// The voxel pipeline, then envelopes within one voxel (`voxel-envelope`).
#[derive(Clone, Copy, Debug, Default)]
pub struct VoxelEnvelope;

impl Simplifier for VoxelEnvelope {
    fn name(&self) -> &'static str {
        "voxel-envelope"
    }

    fn description(&self) -> &'static str {
        "the voxel pipeline with the hyper-cone filter, then simplification envelopes within \
         one voxel (He et al. 1995, §5)"
    }

    fn parameter_name(&self) -> &'static str {
        "resolution"
    }

    /// Resolutions from 4 to [`SearchLimits::max_resolution`] or 256, whichever is lower,
    /// starting at 128.
    fn search_space(&self, limits: &SearchLimits) -> SearchSpace {
        SearchSpace {
            lowest: 4.0,
            highest: limits.max_resolution.min(256) as f64,
            first: 128.0,
            first_at_budget: false,
            exponent: 2.0,
            grid: ParameterGrid::Integers,
        }
    }

    fn needs(&self) -> Needs {
        Needs {
            solid: true,
            ..Needs::default()
        }
    }

    fn run(&self, input: &MethodInput, resolution: f64) -> Result<PolyMesh, RunFailure> {
        let (level, voxel_size) = voxel_level(input, resolution, Filter::Hypercone)?;
        if level.triangles.is_empty() {
            return Ok(PolyMesh::from(level));
        }
        envelope_level(&level, Epsilon::Absolute(voxel_size))
    }
}
