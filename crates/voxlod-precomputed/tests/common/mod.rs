//! Shared fixtures: a small label map of two balls and their meshes, written as a layer.

#![allow(dead_code)]

use std::collections::{HashMap, HashSet};
use std::path::Path;

use voxlod_core::glam::{DVec3, Vec3};
use voxlod_core::{Grid, LabelVolume, TriangleMesh};
use voxlod_precomputed::layer::quantize_node;
use voxlod_precomputed::quantize::Lattice;
use voxlod_precomputed::{lods, write_layer, LayerReport, PrecomputedOptions};
use voxlod_testkit::shapes::icosphere_at;

/// World placement of the map: anisotropic voxels, an origin off the voxel lattice.
pub const SPACING: [f64; 3] = [2.0, 2.0, 3.0];
pub const ORIGIN: [f64; 3] = [10.0, -4.0, 6.7];
pub const DIMS: [usize; 3] = [40, 36, 30];

/// The balls: (label, centre, radius), in world units.
pub fn balls() -> Vec<(u32, Vec3, f32)> {
    vec![
        (7, Vec3::new(45.3, 30.1, 46.2), 22.0),
        (300, Vec3::new(72.0, 50.2, 70.9), 11.5),
    ]
}

/// The map: each voxel whose centre is inside a ball holds its label.
pub fn map() -> LabelVolume {
    let grid = Grid::new(DIMS, SPACING, ORIGIN).unwrap();
    let mut values = vec![0u32; grid.len()];
    for k in 0..DIMS[2] {
        for j in 0..DIMS[1] {
            for i in 0..DIMS[0] {
                let p = DVec3::from_array(ORIGIN)
                    + DVec3::from_array(SPACING) * DVec3::new(i as f64, j as f64, k as f64);
                for (label, centre, radius) in balls() {
                    if (p - centre.as_dvec3()).length() < radius as f64 {
                        values[(k * DIMS[1] + j) * DIMS[0] + i] = label;
                    }
                }
            }
        }
    }
    LabelVolume::from_vec(grid, values).unwrap()
}

/// The balls as icospheres (5120 triangles each).
pub fn meshes() -> Vec<(u32, TriangleMesh)> {
    balls()
        .into_iter()
        .map(|(label, centre, radius)| (label, icosphere_at(4, radius, centre)))
        .collect()
}

/// Stand-ins for the balls' filter pyramids: level k an icosphere of 4 − k subdivisions whose
/// radius shrinks by 0.7 voxels per level, so that no two levels share a vertex.
pub fn filtered_levels(lods: u32) -> Vec<(u32, Vec<TriangleMesh>)> {
    balls()
        .into_iter()
        .map(|(label, centre, radius)| {
            let level = |k: u32| icosphere_at(4 - k, radius - 0.7 * k as f32, centre);
            (label, (0..lods).map(level).collect())
        })
        .collect()
}

/// Options small enough that the balls span many nodes.
pub fn options() -> PrecomputedOptions {
    PrecomputedOptions {
        lods: 3,
        fragment_voxels: 4,
        chunk: [16, 16, 16],
        ..PrecomputedOptions::default()
    }
}

/// Writes the fixture layer into `dir` with `options`.
pub fn write(dir: &Path, options: &PrecomputedOptions) -> LayerReport {
    write_layer(dir, &map(), &meshes(), options).unwrap()
}

/// Checks that every vertex of `octree` on a face between two nodes of a level is used by both
/// nodes and quantized to the same global lattice point in both (`bits` per coordinate);
/// returns how many such vertices there were.
pub fn faces_shared(octree: &lods::Octree, bits: u32) -> usize {
    let mut checked = 0;
    for (k, level) in octree.levels.iter().enumerate() {
        let lattice = Lattice::new(octree.grid_origin, octree.chunk, k, bits);
        let max = lattice.max as u64;
        let by_position: HashMap<[u32; 3], &lods::Node> =
            level.values().map(|n| (n.position, n)).collect();
        for node in level.values() {
            let here = quantize_node(&octree.positions, &node.triangles, &lattice, node.position);
            let used: HashSet<u32> = node.triangles.iter().flatten().copied().collect();
            for &v in &used {
                let p = octree.positions[v as usize];
                for a in 0..3 {
                    let face =
                        octree.grid_origin[a] + lattice.node[a] * (node.position[a] + 1) as f64;
                    if p[a] != face {
                        continue;
                    }
                    let mut next = node.position;
                    next[a] += 1;
                    let other = by_position
                        .get(&next)
                        .unwrap_or_else(|| panic!("level {k}: no node {next:?}"));
                    assert!(
                        other.triangles.iter().flatten().any(|&w| w == v),
                        "{p:?} only on one side"
                    );
                    let there = quantize_node(&octree.positions, &other.triangles, &lattice, next);
                    // The same global lattice point (node · max + integers) on both sides.
                    let global = |f: &voxlod_precomputed::QuantizedFragment,
                                  cell: [u32; 3]|
                     -> HashSet<[u64; 3]> {
                        f.positions
                            .iter()
                            .map(|x| std::array::from_fn(|c| cell[c] as u64 * max + x[c] as u64))
                            .collect()
                    };
                    let q = lattice.quantize(p, node.position);
                    assert_eq!(q[a] as u64, max);
                    let g: [u64; 3] =
                        std::array::from_fn(|c| node.position[c] as u64 * max + q[c] as u64);
                    assert!(global(&here, node.position).contains(&g));
                    assert!(
                        global(&there, next).contains(&g),
                        "{p:?} quantized differently"
                    );
                    assert_eq!(
                        lattice.dequantize(q, node.position),
                        lattice.dequantize(lattice.quantize(p, next), next)
                    );
                    checked += 1;
                }
            }
        }
    }
    checked
}
