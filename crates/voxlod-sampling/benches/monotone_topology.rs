//! The topology passes on a hollow sphere's pyramid level that perforates (radius 1 voxel at
//! resolution 36 after 44): the exact digital genus of a level, and `monotone_level` with the
//! previous level's shape (cavity filling, then the guarded threshold).
//!
//!     cargo bench -p voxlod-sampling --bench monotone_topology

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use glam::DVec3;
use voxlod_sampling::digital_topology::{digital_topology, inside_samples};
use voxlod_sampling::{
    filtered_density, monotone_level, plan_levels, CsgSolid, Filter, MonotoneOptions,
    PyramidOptions, Shape, Solid,
};

fn bench(c: &mut Criterion) {
    let shell = Shape::sphere(DVec3::ZERO, 1.0).minus(Shape::sphere(DVec3::ZERO, 0.93));
    let solid = CsgSolid::new(shell).unwrap();
    let pyramid = PyramidOptions::for_resolutions(vec![44, 36], Filter::Hypercone);
    let plans = plan_levels(&solid.bounds(), &pyramid).unwrap();
    let levels: Vec<_> = plans
        .iter()
        .map(|p| {
            let options = p.density_options(&pyramid);
            (
                filtered_density(&solid, &p.grid, &options).unwrap().0,
                options,
            )
        })
        .collect();
    let options = MonotoneOptions::default();
    let first = monotone_level(&levels[0].0, 0.5, &levels[0].1, None, &options).unwrap();
    let (volume, filter) = &levels[1];
    let record = monotone_level(volume, 0.5, filter, Some(&first.shape), &options)
        .unwrap()
        .record;
    eprintln!("{record:?}");
    let mut group = c.benchmark_group("monotone_topology");
    group.sample_size(10);
    group.throughput(Throughput::Elements(volume.grid.len() as u64));
    let inside = inside_samples(volume, 0.5).unwrap();
    group.bench_function("digital_topology", |b| {
        b.iter(|| digital_topology(volume.grid.dims, &inside).unwrap())
    });
    group.bench_function("monotone_level", |b| {
        b.iter(|| monotone_level(volume, 0.5, filter, Some(&first.shape), &options).unwrap())
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
