//! A small real chain for the tests: a sphere of radius 1 through the voxel pyramid.

use glam::DVec3;
use voxlod::core::TriangleMesh;
use voxlod::lod::{build_level, plan, LevelOptions, LodSource};
use voxlod::sampling::csg::{CsgSolid, Shape};
use voxlod::sampling::{Filter, PyramidOptions};

/// (level, mesh, voxel size) of a sphere at resolutions 24, 12, 6.
pub fn sphere_chain() -> Vec<(usize, TriangleMesh, f64)> {
    let solid = CsgSolid::new(Shape::sphere(DVec3::new(0.5, -0.25, 2.0), 1.0)).unwrap();
    let options = LevelOptions {
        pyramid: PyramidOptions::for_resolutions(vec![24, 12, 6], Filter::Hypercone),
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
        .map(|(level, mesh, cell)| voxlod_gltf::ChainLevel::new(*level, mesh, *cell))
        .collect()
}

/// A level as clustering leaves it: a unit square of two triangles (vertices 0–3, normals +z),
/// two dangling edges from vertex 4 (widths 0.1 and 0.25) and two isolated points (vertices 6
/// and 7): (mesh, lines, widths, points).
#[allow(dead_code)] // not every test file uses it
pub fn lines_and_points() -> ClusterParts {
    use glam::Vec3;
    let positions = vec![
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(2.0, 0.0, 0.0),
        Vec3::new(3.0, 0.0, 0.0),
        Vec3::new(0.0, 2.0, 1.0),
        Vec3::new(-1.0, 2.0, 1.0),
    ];
    let mut mesh = TriangleMesh::new(positions, vec![[0, 1, 2], [0, 2, 3]]);
    mesh.normals = vec![Vec3::Z; 8];
    (mesh, vec![[4, 5], [4, 1]], vec![0.1, 0.25], vec![6, 7])
}

/// What [`lines_and_points`] gives.
pub type ClusterParts = (TriangleMesh, Vec<[u32; 2]>, Vec<f32>, Vec<u32>);

/// Two levels of [`lines_and_points`]: level 0 (cell 0.5) with everything, level 1 (cell 1)
/// with its triangles and points.
#[allow(dead_code)] // not every test file uses it
pub fn two_cluster_levels(parts: &ClusterParts) -> [voxlod_gltf::ChainLevel<'_>; 2] {
    let (mesh, lines, widths, points) = parts;
    [
        voxlod_gltf::ChainLevel::new(0, mesh, 0.5)
            .with_lines(lines, widths)
            .with_points(points),
        voxlod_gltf::ChainLevel::new(1, mesh, 1.0).with_points(points),
    ]
}
