//! Distance on a pair of ~1 M-triangle meshes: a tessellated torus and a perturbed torus of
//! another tessellation, 1 M samples per side.
//!
//! Run: `cargo bench -p voxlod-metrics --bench distance`.

#[path = "../tests/common/mod.rs"]
mod common;

use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use glam::DVec3;
use voxlod_core::TriangleMesh;
use voxlod_metrics::{
    mesh_distance, DistanceOptions, MeshDistance, SampleLayout, SamplingOptions, SurfaceSampler,
};

fn meshes() -> (TriangleMesh, TriangleMesh) {
    let smooth = common::torus(1000, 500);
    let bumpy = common::torus_with(1001, 499, 2.0, |u, v| {
        1.0 + 0.02 * (7.0 * u).sin() * (5.0 * v).cos()
    });
    (smooth, bumpy)
}

fn bench(c: &mut Criterion) {
    let (a, b) = meshes();
    eprintln!(
        "meshes: {} and {} triangles, {} threads",
        a.triangles.len(),
        b.triangles.len(),
        rayon::current_num_threads()
    );
    let samples = 1_000_000;
    let mut group = c.benchmark_group("distance");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_secs(3))
        .measurement_time(Duration::from_secs(30));

    group.throughput(Throughput::Elements(a.triangles.len() as u64));
    group.bench_function("build 1M-triangle BVH", |bench| {
        bench.iter(|| MeshDistance::new(&a).unwrap())
    });

    let index = MeshDistance::new(&a).unwrap();
    let sampler = SurfaceSampler::new(&b).unwrap();
    let points = |layout| -> Vec<DVec3> {
        sampler
            .samples(&SamplingOptions {
                samples,
                layout,
                ..Default::default()
            })
            .unwrap()
            .iter()
            .map(|s| s.point)
            .collect()
    };
    group.throughput(Throughput::Elements(samples as u64));
    let in_triangle_order = points(SampleLayout::Stratified);
    group.bench_function("1M queries, samples in triangle order", |bench| {
        bench.iter(|| index.distances(&in_triangle_order))
    });
    let in_random_order = points(SampleLayout::Independent);
    group.bench_function("1M queries, samples in random order", |bench| {
        bench.iter(|| index.distances(&in_random_order))
    });

    group.throughput(Throughput::Elements(2 * samples as u64));
    let options = DistanceOptions::precise();
    let report = mesh_distance(&a, &b, &options).unwrap();
    eprintln!("{report}");
    group.bench_function("compare 1M-triangle pair, 1M samples per side", |bench| {
        bench.iter(|| mesh_distance(&a, &b, &options).unwrap())
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
