//! Timing of the layered shells' two speed targets, stage by stage (medians of several runs):
//! layering and ordering the bunny at 128³ with five layers (target < 1 s on 2 cores), and
//! rendering a layered mesh of about a million triangles at 1024×1024 (target < 2 s).
//!
//!     cargo run --release -p voxlod-layers --example layers_timing [RUNS]

use std::time::Instant;

use glam::DVec3;
use voxlod_layers::{bolt, render_layered};
use voxlod_layers::{
    filter_solid, layer_solid, layer_volume, ExtractOptions, LayersOptions, Octant,
};
use voxlod_render::{Camera, RenderOptions};
use voxlod_sampling::{CsgSolid, MeshSolid, Solid};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let runs: usize = std::env::args()
        .nth(1)
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(5);
    println!("{} threads", rayon::current_num_threads());
    let (name, solid): (&str, Box<dyn Solid>) = match voxlod_testkit::data::shared_data_or_skip(
        "meshes/stanford-bunny.obj",
        "the bunny timing (using the bolt)",
    ) {
        Some(path) => {
            let mesh = voxlod_io::read_mesh(&path)?.mesh;
            ("bunny", Box::new(MeshSolid::new(&mesh)?))
        }
        None => ("bolt", Box::new(CsgSolid::new(bolt())?)),
    };
    let options = LayersOptions::default();
    let mut sample = Vec::new();
    let mut volume = None;
    for _ in 0..runs {
        let t = Instant::now();
        let (v, _) = filter_solid(solid.as_ref(), &options)?;
        sample.push(t.elapsed().as_secs_f64());
        volume = Some(v);
    }
    let volume = volume.expect("runs >= 1");
    let (mut total, mut plan, mut extract, mut order, mut per_layer) =
        (vec![], vec![], vec![], vec![], vec![]);
    let mut last = None;
    for _ in 0..runs {
        let t = Instant::now();
        let l = layer_volume(&volume, &options.plan, &options.extract)?;
        total.push(t.elapsed().as_secs_f64());
        plan.push(l.timings.plan_seconds);
        extract.push(l.timings.extract_seconds);
        order.push(l.timings.order_seconds);
        let t = Instant::now();
        voxlod_layers::extract_layers(&volume, &l.plan, &ExtractOptions::per_layer())?;
        per_layer.push(t.elapsed().as_secs_f64());
        last = Some(l);
    }
    let l = last.expect("runs >= 1");

    println!(
        "{name} at {:?} samples, {} layers, {} triangles:",
        volume.grid.dims,
        l.plan.len(),
        l.mesh.triangle_count()
    );
    println!("  filtered density            {:.3} s", median(sample));
    println!(
        "  layers + 8 orders           {:.3} s  (plan {:.4}, extract {:.3} [one run per layer: {:.3}], orders {:.3})",
        median(total),
        median(plan),
        median(extract),
        median(per_layer),
        median(order)
    );

    // About a million triangles: the bolt at resolution 168, five layers.
    let big = layer_solid(
        &CsgSolid::new(bolt())?,
        &LayersOptions {
            resolution: 168,
            ..Default::default()
        },
    )?;
    let cat = big.mesh.concatenated();
    let alphas: Vec<f32> = big.mesh.layers.iter().map(|x| x.alpha).collect();
    let view = DVec3::new(-0.55, -0.8, -0.35);
    let order = &big.orders[Octant::of(view)?.index()];
    let camera = Camera::fit(view, &cat.mesh.bounds(), 1024, 1024, None)?;
    let mut render = Vec::new();
    for _ in 0..runs {
        let t = Instant::now();
        let img = render_layered(
            &cat.mesh,
            &cat.triangle_layer,
            &alphas,
            order,
            [0.85, 0.86, 0.9],
            &camera,
            &RenderOptions::default(),
        )?;
        render.push(t.elapsed().as_secs_f64());
        std::hint::black_box(img);
    }
    println!(
        "  render {} layered triangles at 1024x1024: {:.3} s",
        cat.mesh.triangles.len(),
        median(render)
    );
    Ok(())
}
