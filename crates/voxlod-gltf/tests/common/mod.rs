//! A small real chain for the tests: a sphere of radius 1 through the voxel pyramid.

use glam::DVec3;
use voxlod::core::TriangleMesh;
use voxlod::lod::{build_level, plan, LodOptions, LodSource};
use voxlod::sampling::csg::{CsgSolid, Shape};
use voxlod::sampling::{Filter, PyramidOptions};

/// (level, mesh, voxel size) of a sphere at resolutions 24, 12, 6.
pub fn sphere_chain() -> Vec<(usize, TriangleMesh, f64)> {
    let solid = CsgSolid::new(Shape::sphere(DVec3::new(0.5, -0.25, 2.0), 1.0)).unwrap();
    let options = LodOptions {
        pyramid: PyramidOptions::with_resolutions(vec![24, 12, 6], Filter::Hypercone),
        ..Default::default()
    };
    let source = LodSource::Solid(&solid);
    plan(&source, &options)
        .unwrap()
        .iter()
        .map(|p| {
            let level = build_level(&source, p, &options).unwrap();
            (p.level, level.mesh, p.voxel_size)
        })
        .collect()
}

pub fn chain_levels(chain: &[(usize, TriangleMesh, f64)]) -> Vec<voxlod_gltf::ChainLevel<'_>> {
    chain
        .iter()
        .map(|(level, mesh, cell)| voxlod_gltf::ChainLevel {
            level: *level,
            mesh,
            cell_size: *cell,
        })
        .collect()
}
