//! Shared fixtures: a small label map of two balls and their meshes, written as a layer.

#![allow(dead_code)]

use std::path::Path;

use voxlod_core::glam::{DVec3, Vec3};
use voxlod_core::{Grid, LabelVolume, TriangleMesh};
use voxlod_precomputed::{write_layer, LayerReport, PrecomputedOptions};
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
