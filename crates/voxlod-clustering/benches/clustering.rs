//! Clustering baselines on a mesh of about a million triangles at 64 cells per axis, the
//! configuration of the clustering speed target (BENCHMARKS.md).
//!
//! The mesh is, in order of preference: the file named by `VOXLOD_BENCH_MESH`; the peers'
//! sphereflake `/tmp/sf1M.ply` (make it with
//! `~/.cache/voxlod-peers/bin/python ../shared/peers/peers.py gen-mesh --field sphereflake --n 392 -o /tmp/sf1M.ply`,
//! 1.41 M triangles, and time the peers on the same file with `peers.py cluster /tmp/sf1M.ply --cells 64`);
//! otherwise a generated torus of 1 M triangles, so the bench runs anywhere.

use std::path::PathBuf;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use voxlod_clustering::{
    grade, low_tan, rossignac_borrel, ClusterOptions, FloatingCellOptions, Grading,
};
use voxlod_core::TriangleMesh;
use voxlod_testkit::shapes::torus;

fn bench_mesh() -> (String, TriangleMesh) {
    let candidates = std::env::var_os("VOXLOD_BENCH_MESH")
        .map(PathBuf::from)
        .into_iter()
        .chain([PathBuf::from("/tmp/sf1M.ply")]);
    for path in candidates {
        if path.is_file() {
            match voxlod_io::read_mesh(&path) {
                Ok(loaded) => return (path.display().to_string(), loaded.mesh),
                Err(e) => eprintln!("cannot read {}: {e}", path.display()),
            }
        }
    }
    ("generated torus".to_string(), torus(1000, 500, 1.0, 0.3))
}

fn clustering(c: &mut Criterion) {
    let (name, mesh) = bench_mesh();
    eprintln!(
        "clustering bench on {name}: {} vertices, {} triangles, {} threads",
        mesh.positions.len(),
        mesh.triangles.len(),
        rayon::current_num_threads()
    );
    let mut group = c.benchmark_group("clustering");
    group.sample_size(20);
    group.throughput(Throughput::Elements(mesh.triangles.len() as u64));
    let configs = [
        ("rossignac-borrel/mean/64", ClusterOptions::smoothing(64)),
        (
            "rossignac-borrel/max-weight/64",
            ClusterOptions::detail_removal(64),
        ),
        (
            "rossignac-borrel/series/64x4",
            ClusterOptions::series(64, 4),
        ),
    ];
    for (id, options) in configs {
        let levels = rossignac_borrel(&mesh, &options).unwrap();
        let r = &levels[0].report;
        eprintln!(
            "{id}: {} triangles, {} dangling edges, {} isolated points",
            r.triangles, r.dangling_edges, r.isolated_points
        );
        group.bench_function(id, |b| {
            b.iter(|| rossignac_borrel(&mesh, &options).unwrap())
        });
    }
    group.bench_function("grading/rossignac-borrel", |b| {
        b.iter(|| grade(&mesh, Grading::RossignacBorrel).unwrap())
    });
    group.sample_size(10);
    let options = FloatingCellOptions::single(64);
    let r = low_tan(&mesh, &options).unwrap()[0].report.clone();
    eprintln!(
        "low-tan/64: {} triangles, {} dangling edges, {} isolated points",
        r.triangles, r.dangling_edges, r.isolated_points
    );
    group.bench_function("low-tan/64", |b| {
        b.iter(|| low_tan(&mesh, &options).unwrap())
    });
    group.finish();
}

criterion_group!(benches, clustering);
criterion_main!(benches);
