//! Sparse against dense marching cubes on the same samples: the 512³ sphereflake
//! field of the peers' kit (most of it one value far from the spheres, so most bricks are
//! uniform) and the 256³ gyroid (a surface everywhere), geometry only. The conversion to bricks
//! is not timed.
//!
//!     cargo bench -p voxlod-contouring --bench sparse_marching_cubes

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use voxlod_contouring::{marching_cubes, sparse_marching_cubes, ContourOptions};
use voxlod_core::BrickVolume;
use voxlod_testkit::fields::{gyroid_field, sphereflake_field};

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("sparse_marching_cubes");
    group.sample_size(10);
    let options = ContourOptions::geometry_only(0.0);
    for (name, volume) in [
        ("sphereflake-512", sphereflake_field(512).unwrap()),
        ("gyroid-256", gyroid_field(256).unwrap()),
    ] {
        group.throughput(Throughput::Elements(volume.grid.len() as u64));
        let bricks = BrickVolume::from_volume(&volume, 8).unwrap();
        eprintln!(
            "{name}: {} of {} bricks are leaves",
            bricks.leaf_count(),
            bricks.brick_count()
        );
        group.bench_function(format!("{name}/dense"), |b| {
            b.iter(|| marching_cubes(&volume, &options).unwrap())
        });
        group.bench_function(format!("{name}/sparse-8"), |b| {
            b.iter(|| sparse_marching_cubes(&bricks, &options).unwrap())
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
