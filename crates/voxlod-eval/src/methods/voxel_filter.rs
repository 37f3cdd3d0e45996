//! The voxel pipeline with one of the paper's two filters (He et al. 1995, §2): the input's
//! solid filtered at one voxel's radius and contoured by marching cubes at isodensity 0.5,
//! either with the hyper-cone of equation 3 ([`VOXEL_HYPERCONE`]) or the truncated Gaussian,
//! σ = R/3, of the paper's Tables 1 and 2 ([`VOXEL_GAUSSIAN`]). Its parameter is the
//! resolution, samples across the longest side. Cost: see `voxel.rs`.

use voxlod::core::PolyMesh;
use voxlod::sampling::Filter;

use super::voxel::{resolution_space, voxel_level};
use super::SearchLimits;
use super::{MethodInput, Needs, RunFailure, SearchSpace, Simplifier};

/// The voxel pipeline with one filter: the two methods differ only in it.
#[derive(Clone, Copy, Debug)]
pub struct VoxelFilter {
    filter: Filter,
    name: &'static str,
    description: &'static str,
}

/// The voxel pipeline with the hyper-cone filter (`voxel-hypercone`).
pub const VOXEL_HYPERCONE: VoxelFilter = VoxelFilter {
    filter: Filter::Hypercone,
    name: "voxel-hypercone",
    description: "the voxel pipeline with the hyper-cone filter (He et al. 1995)",
};

/// The voxel pipeline with the truncated Gaussian (`voxel-gaussian`).
pub const VOXEL_GAUSSIAN: VoxelFilter = VoxelFilter {
    filter: Filter::GAUSSIAN,
    name: "voxel-gaussian",
    description: "the voxel pipeline with the truncated Gaussian filter (He et al. 1995)",
};

impl Simplifier for VoxelFilter {
    fn name(&self) -> &'static str {
        self.name
    }

    fn description(&self) -> &'static str {
        self.description
    }

    fn parameter_name(&self) -> &'static str {
        "resolution"
    }

    fn search_space(&self, limits: &SearchLimits) -> SearchSpace {
        resolution_space(limits)
    }

    fn needs(&self) -> Needs {
        Needs {
            solid: true,
            ..Needs::default()
        }
    }

    fn run(&self, input: &MethodInput, resolution: f64) -> Result<PolyMesh, RunFailure> {
        Ok(PolyMesh::from(
            voxel_level(input, resolution, self.filter)?.0,
        ))
    }
}
