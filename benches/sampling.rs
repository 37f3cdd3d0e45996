//! Sampling benchmarks against the peers (`../shared/peers/peers.py`):
//!
//! - `gaussian/sphereflake-512-sigma-1`: the separable Gaussian of a 512³ f32 volume at σ = 1
//!   voxel, truncated at 3σ, as `peers.py gauss` runs SciPy and VTK;
//! - `density/sphereflake-1M-at-128`: the filtered density (hyper-cone, radius one voxel) of a
//!   ~1 M-triangle mesh on a 128³ grid, where `peers.py occupancy --res 128` times Open3D's bare
//!   inside/outside occupancy of the same grid. The mesh is the sphereflake field's isosurface
//!   at 392³, as `peers.py gen-mesh --n 392` makes it.
//!
//!     cargo bench -p voxlod --bench sampling

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use voxlod::contouring::{marching_cubes, ContourOptions};
use voxlod::sampling::gaussian::gaussian_blur;
use voxlod::sampling::{filtered_density, level_grid, DensityOptions, Filter, MeshSolid, Solid};
use voxlod_testkit::fields::sphereflake_field;

fn gaussian(c: &mut Criterion) {
    let volume = sphereflake_field(512).unwrap();
    let sigma = volume.grid.spacing;
    let mut group = c.benchmark_group("gaussian");
    group.sample_size(10);
    group.throughput(Throughput::Elements(volume.grid.len() as u64));
    group.bench_function("sphereflake-512-sigma-1", |b| {
        b.iter(|| gaussian_blur(&volume, sigma, 3.0).unwrap())
    });
    group.finish();
}

fn density(c: &mut Criterion) {
    let field = sphereflake_field(392).unwrap();
    let mesh = marching_cubes(&field, &ContourOptions::geometry_only(0.0)).unwrap();
    drop(field);
    eprintln!("mesh: {} triangles", mesh.triangles.len());
    let mut group = c.benchmark_group("density");
    group.sample_size(10);
    group.bench_function("sphereflake-1M-at-128", |b| {
        b.iter(|| {
            let solid = MeshSolid::new(&mesh).unwrap();
            let bounds = solid.bounds();
            let h = bounds.longest_extent() / 128.0;
            let grid = level_grid(&bounds, 128, h).unwrap();
            filtered_density(&solid, &grid, &DensityOptions::new(Filter::Hypercone, h)).unwrap()
        })
    });
    group.finish();
}

criterion_group!(benches, gaussian, density);
criterion_main!(benches);
