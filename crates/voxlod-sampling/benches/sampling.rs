//! The plain pyramid's sampling, part by part (the speed targets of BENCHMARKS.md):
//!
//! - `crossings/*`: the lattice crossings of the three line families ([`Solid::crossings`]):
//!   a thresholded scan (the trilinear walk of `threshold.rs`) and a triangle mesh (the BVH
//!   and watertight line tests of `mesh_solid.rs`);
//! - `density/*`: the whole [`filtered_density`] of the same, crossings and the line kernel's
//!   integration (`density.rs`, `line_kernel.rs`) together.
//!
//! Inputs are generated: the gyroid field at 160³ thresholded at 0 (a surface through every
//! part of the scan, as a CT's bone is), sampled at full resolution with the hyper-cone of one
//! voxel; the torus of 131 072 triangles at resolution 256, six levels' worth of the finest.
//!
//!     cargo bench -p voxlod-sampling --bench sampling

use criterion::{criterion_group, criterion_main, Criterion};
use voxlod_core::{Axis, Grid};
use voxlod_sampling::lattice::LineFamily;
use voxlod_sampling::{
    filtered_density, level_grid, DensityOptions, Filter, MeshSolid, Solid, ThresholdSolid,
};
use voxlod_testkit::fields::gyroid_field;
use voxlod_testkit::shapes::torus;

/// The grid of `resolution` samples across `solid`'s box, hyper-cone of one voxel.
fn level(solid: &dyn Solid, resolution: usize) -> (Grid, DensityOptions) {
    let bounds = solid.bounds();
    let h = bounds.longest_extent() / resolution as f64;
    let grid = level_grid(&bounds, resolution, h).unwrap();
    (grid, DensityOptions::new(Filter::Hypercone, h))
}

fn all_crossings(solid: &dyn Solid, grid: &Grid, options: &DensityOptions) -> usize {
    let q = options.lines_per_voxel(grid.spacing[0]);
    [Axis::X, Axis::Y, Axis::Z]
        .iter()
        .map(|&a| {
            solid
                .crossings(&LineFamily::new(a, *grid, q))
                .unwrap()
                .len()
        })
        .sum()
}

fn sampling(c: &mut Criterion) {
    let scan = gyroid_field(160).unwrap();
    let threshold = ThresholdSolid::new(&scan, 0.0).unwrap();
    let mesh = MeshSolid::new(&torus(512, 128, 2.0, 0.7)).unwrap();
    let cases: [(&str, &dyn Solid, usize); 2] = [
        ("threshold-gyroid-160", &threshold, 160),
        ("mesh-torus-at-256", &mesh, 256),
    ];
    let mut group = c.benchmark_group("sampling");
    group.sample_size(10);
    for (name, solid, resolution) in cases {
        let (grid, options) = level(solid, resolution);
        group.bench_function(format!("crossings/{name}"), |b| {
            b.iter(|| all_crossings(solid, &grid, &options))
        });
        group.bench_function(format!("density/{name}"), |b| {
            b.iter(|| filtered_density(solid, &grid, &options).unwrap())
        });
    }
    group.finish();
}

criterion_group!(benches, sampling);
criterion_main!(benches);
