//! The layered shells' two speed targets (BENCHMARKS.md) as criterion benches (2 cores):
//! - `layers/bunny-128`: planning, extracting and ordering (all eight octants) five layers of
//!   the bunny filtered at 128³ (target < 1 s; the filtering itself is `layers/filter-bunny-128`);
//! - `render/layered-1M-1024`: drawing a layered mesh of about a million triangles (the bolt at
//!   resolution 168, five layers) at 1024×1024, one sample per pixel (target < 2 s).
//!
//! Without the shared data the bolt stands in for the bunny.
//!
//!     cargo bench -p voxlod-layers --bench layers

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use glam::DVec3;
use voxlod_layers::{bolt, render_layered};
use voxlod_layers::{filter_solid, layer_solid, layer_volume, LayersOptions, Octant};
use voxlod_render::{Camera, RenderOptions};
use voxlod_sampling::{CsgSolid, MeshSolid, Solid};

fn bench(c: &mut Criterion) {
    let (name, solid): (&str, Box<dyn Solid>) = match voxlod_testkit::data::shared_data_or_skip(
        "meshes/stanford-bunny.obj",
        "the bunny bench",
    ) {
        Some(path) => (
            "bunny",
            Box::new(MeshSolid::new(&voxlod_io::read_mesh(&path).unwrap().mesh).unwrap()),
        ),
        None => ("bolt", Box::new(CsgSolid::new(bolt()).unwrap())),
    };
    let options = LayersOptions::default();
    let (volume, _) = filter_solid(solid.as_ref(), &options).unwrap();

    let mut group = c.benchmark_group("layers");
    group.sample_size(10);
    group.bench_function(format!("filter-{name}-128"), |b| {
        b.iter(|| filter_solid(solid.as_ref(), &options).unwrap())
    });
    let triangles = layer_volume(&volume, &options.plan, &options.extract)
        .unwrap()
        .mesh
        .triangle_count();
    eprintln!("{name}: {triangles} triangles in five layers");
    group.throughput(Throughput::Elements(triangles as u64));
    group.bench_function(format!("{name}-128"), |b| {
        b.iter(|| layer_volume(&volume, &options.plan, &options.extract).unwrap())
    });
    group.finish();

    let big = layer_solid(
        &CsgSolid::new(bolt()).unwrap(),
        &LayersOptions {
            resolution: 168,
            ..Default::default()
        },
    )
    .unwrap();
    let cat = big.mesh.concatenated();
    let alphas: Vec<f32> = big.mesh.layers.iter().map(|x| x.alpha).collect();
    let view = DVec3::new(-0.55, -0.8, -0.35);
    let order = &big.orders[Octant::of(view).unwrap().index()];
    let camera = Camera::fit(view, &cat.mesh.bounds(), 1024, 1024, None).unwrap();
    eprintln!("render: {} layered triangles", cat.mesh.triangles.len());
    let mut group = c.benchmark_group("render");
    group.sample_size(10);
    group.throughput(Throughput::Elements(cat.mesh.triangles.len() as u64));
    group.bench_function("layered-1M-1024", |b| {
        b.iter(|| {
            render_layered(
                &cat.mesh,
                &cat.triangle_layer,
                &alphas,
                order,
                [0.85, 0.86, 0.9],
                &camera,
                &RenderOptions::default(),
            )
            .unwrap()
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
