//! Marching cubes on the peers' test fields (`../shared/peers/peers.py mc`): the 512³
//! sphereflake field and the 256³ gyroid, with and without normals. VTK's vtkFlyingEdges3D runs
//! with normals off; compare `geometry` with it. `skimage-outputs` adds what the Python
//! package's `voxlod.marching_cubes` returns besides normals: each vertex's corner range
//! (scikit-image's `values`).
//!
//!     cargo bench -p voxlod-contouring --bench marching_cubes

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use voxlod_contouring::marching_cubes::{marching_cubes_of_samples, Wanted};
use voxlod_contouring::{marching_cubes, ContourOptions};
use voxlod_testkit::fields::{gyroid_field, sphereflake_field};

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("marching_cubes");
    group.sample_size(10);
    for (name, volume) in [
        ("sphereflake-512", sphereflake_field(512).unwrap()),
        ("gyroid-256", gyroid_field(256).unwrap()),
    ] {
        group.throughput(Throughput::Elements(volume.grid.len() as u64));
        let triangles = marching_cubes(&volume, &ContourOptions::geometry_only(0.0))
            .unwrap()
            .triangles
            .len();
        eprintln!("{name}: {triangles} triangles");
        group.bench_function(format!("{name}/geometry"), |b| {
            b.iter(|| marching_cubes(&volume, &ContourOptions::geometry_only(0.0)).unwrap())
        });
        group.bench_function(format!("{name}/with-normals"), |b| {
            b.iter(|| marching_cubes(&volume, &ContourOptions::at(0.0)).unwrap())
        });
        let wanted = Wanted {
            normals: true,
            cells: false,
            corner_ranges: true,
        };
        group.bench_function(format!("{name}/skimage-outputs"), |b| {
            b.iter(|| marching_cubes_of_samples(volume.as_slice(), &volume.grid, 0.0, wanted))
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
