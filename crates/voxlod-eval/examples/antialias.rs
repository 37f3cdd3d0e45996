//! The antialiasing comparison of paper §3 on the bolt-like CSG part and the Stanford bunny:
//! single surface at 1 sample per pixel, five layers at 1 sample per pixel, single surface at
//! 16×16 samples per pixel (reference); RMS difference near silhouettes, for several image sizes
//! (so several filter radii in pixels). Writes `antialias-<shape>-<size>.png` (the three side by
//! side) into OUT_DIR.
//!
//!     cargo run --release -p voxlod-eval --example antialias -- [OUT_DIR] [--resolution N]
//!         [--filter hypercone|gaussian] [--blending composited|direct] [SIZE...]

use std::path::PathBuf;

use voxlod::layers::{bolt, Blending};
use voxlod::sampling::{CsgSolid, Filter, MeshSolid, Solid};
use voxlod_eval::antialias::{compare_antialiasing, CompareOptions};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut out = PathBuf::from("target/antialias");
    let mut options = CompareOptions::default();
    let mut sizes = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--resolution" => options.layers.resolution = args.next().ok_or("N")?.parse()?,
            "--filter" => {
                let f: Filter = args.next().ok_or("filter")?.parse()?;
                options.layers.plan.filter = f;
                // Five layers for either filter.
                options.layers.plan.error = if f == Filter::Hypercone { 0.025 } else { 0.02 };
            }
            "--blending" => {
                options.layers.plan.blending = args.next().ok_or("blending")?.parse::<Blending>()?
            }
            s if s.parse::<u32>().is_ok() => sizes.push(s.parse()?),
            s => out = PathBuf::from(s),
        }
    }
    if sizes.is_empty() {
        sizes = vec![96, 128, 160, 192];
    }
    std::fs::create_dir_all(&out)?;
    let mut shapes: Vec<(&str, Box<dyn Solid>)> = vec![("bolt", Box::new(CsgSolid::new(bolt())?))];
    if let Some(path) = voxlod_testkit::data::shared_data_or_skip(
        "meshes/stanford-bunny.obj",
        "the bunny comparison",
    ) {
        let mesh = voxlod::io::read_mesh(&path)?.mesh;
        shapes.push(("bunny", Box::new(MeshSolid::new(&mesh)?)));
    }
    println!(
        "resolution {}, {} filter, {:?} blending",
        options.layers.resolution,
        options.layers.plan.filter.name(),
        options.layers.plan.blending
    );
    println!(
        "{:<6} {:>5} {:>7} {:>7} {:>10} {:>10} {:>9} {:>9} {:>7}",
        "shape",
        "size",
        "R (px)",
        "edge px",
        "rms single",
        "rms layers",
        "all sgl",
        "all lay",
        "layers"
    );
    for (name, solid) in &shapes {
        for &size in &sizes {
            let c = compare_antialiasing(solid.as_ref(), &CompareOptions { size, ..options })?;
            let r = &c.report;
            println!(
                "{:<6} {:>5} {:>7.2} {:>7} {:>10.4} {:>10.4} {:>9.4} {:>9.4} {:>7}",
                name,
                size,
                r.radius_pixels,
                r.silhouette_pixels,
                r.rms_single,
                r.rms_layered,
                r.rms_single_all,
                r.rms_layered_all,
                r.layers
            );
            let png = c.montage().to_png()?;
            let path = out.join(format!("antialias-{name}-{size}.png"));
            voxlod::io::atomic::write_atomically(&path, |w| std::io::Write::write_all(w, &png))?;
        }
    }
    Ok(())
}
