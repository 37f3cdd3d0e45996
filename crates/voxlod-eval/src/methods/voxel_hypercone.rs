//! The voxel pipeline with the hyper-cone filter of equation 3 (He et al. 1995, §2): the
//! input's solid filtered at one voxel's radius and contoured by marching cubes at isodensity
//! 0.5. Its parameter is the resolution, samples across the longest side. Cost: see `voxel.rs`.

use voxlod::core::PolyMesh;
use voxlod::sampling::Filter;

use super::voxel::{resolution_space, voxel_level};
use super::{MethodInput, Needs, RunFailure, SearchSpace, Simplifier};
use crate::evaluate::EvaluateOptions;

/// The voxel pipeline with the hyper-cone filter (`voxel-hypercone`).
#[derive(Clone, Copy, Debug, Default)]
pub struct VoxelHypercone;

impl Simplifier for VoxelHypercone {
    fn name(&self) -> &'static str {
        "voxel-hypercone"
    }

    fn description(&self) -> &'static str {
        "the voxel pipeline with the hyper-cone filter (He et al. 1995)"
    }

    fn parameter_name(&self) -> &'static str {
        "resolution"
    }

    fn search_space(&self, options: &EvaluateOptions) -> SearchSpace {
        resolution_space(options)
    }

    fn needs(&self) -> Needs {
        Needs {
            solid: true,
            ..Needs::default()
        }
    }

    fn run(&self, input: &MethodInput, resolution: f64) -> Result<PolyMesh, RunFailure> {
        Ok(PolyMesh::from(
            voxel_level(input, resolution, Filter::Hypercone)?.0,
        ))
    }
}
