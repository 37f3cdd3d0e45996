//! Cleaning a level after marching cubes (`clean_mesh`), beside marching cubes itself: the
//! sphereflake and gyroid fields of the peers' kit at 256³.
//!
//!     cargo bench -p voxlod-contouring --bench clean_mesh

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use voxlod_contouring::{clean_mesh, marching_cubes, CleanOptions, ContourOptions};
use voxlod_testkit::fields::{gyroid_field, sphereflake_field};

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("clean_mesh");
    group.sample_size(10);
    for (name, volume) in [
        ("sphereflake-256", sphereflake_field(256).unwrap()),
        ("gyroid-256", gyroid_field(256).unwrap()),
    ] {
        let mesh = marching_cubes(&volume, &ContourOptions::at(0.0)).unwrap();
        let cell = volume.grid.spacing[0];
        let (_, report) = clean_mesh(&mesh, cell, &CleanOptions::default()).unwrap();
        eprintln!("{name}: {} triangles, {report:?}", mesh.triangles.len());
        group.throughput(Throughput::Elements(mesh.triangles.len() as u64));
        group.bench_function(format!("{name}/marching-cubes"), |b| {
            b.iter(|| marching_cubes(&volume, &ContourOptions::at(0.0)).unwrap())
        });
        group.bench_function(format!("{name}/clean"), |b| {
            b.iter(|| clean_mesh(&mesh, cell, &CleanOptions::default()).unwrap())
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
