//! The antialiasing of a layered chain at the distances `voxlod view` draws it: levels
//! at resolutions 256 and 128 (hyper-cone of one voxel, five layers), each drawn at
//! the image sizes where its filter radius spans 0.3, 0.45, 0.6 and 0.9 px. The viewer's rule
//! draws a level only up to 0.45 px and switches to the finer level beyond (level 0 at 0.45 px
//! is level 1 at 0.9 px: the same distance); the pixel-size rule of `voxlod select` on the cell
//! size (one voxel per pixel) would keep level 1 up to 1 px. For each, near-silhouette RMS of
//! the single surface and of the layers against the level's single surface at 16×16 samples
//! per pixel (crate doc of `voxlod_eval::antialias`).
//!
//! The viewer's distance for a pixel size p on a 1080-pixel viewport (45° field of view) is
//! d = p · 1080 / (2 tan 22.5°); the table gives it in diameters of the object's box.
//!
//!     cargo run --release -p voxlod-eval --example antialias_chain -- [OUT_DIR]

use std::path::PathBuf;

use voxlod::layers::bolt;
use voxlod::sampling::{CsgSolid, MeshSolid, Solid};
use voxlod::LayersOptions;
use voxlod_eval::antialias::{
    compare_filtered, filter_for_comparison, size_for_radius, CompareOptions,
};

/// Resolutions of the chain's two levels, finest first.
const LEVELS: [usize; 2] = [256, 128];
/// Filter radii on screen, in pixels, at which each level is measured.
const RADII_PX: [f64; 4] = [0.3, 0.45, 0.6, 0.9];
/// The viewer's assumed viewport height and field of view.
const VIEWPORT: f64 = 1080.0;
const FOV: f64 = std::f64::consts::FRAC_PI_4;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args()
        .nth(1)
        .map_or_else(|| PathBuf::from("target/antialias-chain"), PathBuf::from);
    std::fs::create_dir_all(&out)?;
    println!(
        "{:<8} {:>5} {:>5} {:>7} {:>9} {:>7} {:>10} {:>10} {:>7}",
        "shape",
        "level",
        "res",
        "R (px)",
        "d / diam",
        "edge px",
        "rms single",
        "rms layers",
        "change"
    );
    measure("bolt", &CsgSolid::new(bolt())?, &out)?;
    if let Some(path) =
        voxlod_testkit::data::shared_data_or_skip("meshes/stanford-bunny.obj", "the bunny's chain")
    {
        let mesh = voxlod::io::read_mesh(&path)?.mesh;
        measure("bunny", &MeshSolid::new(&mesh)?, &out)?;
    }
    if let Some(volume) = voxlod_testkit::volumes::shared_ct_head("the CT head's chain") {
        // The skull: bone at 1500 (the README's example).
        let source = voxlod::Source::Threshold {
            volume: &volume,
            threshold: 1500.0,
        };
        let prepared = source.prepare()?;
        let solid = prepared.solid().ok_or("the CT head is not a solid")?;
        measure("CT head", solid, &out)?;
    }
    Ok(())
}

/// The rows of one shape; montages into `out`.
fn measure(
    name: &str,
    solid: &dyn Solid,
    out: &std::path::Path,
) -> Result<(), Box<dyn std::error::Error>> {
    let b = solid.bounds();
    let diameter = (b.max - b.min).length();
    for (level, &resolution) in LEVELS.iter().enumerate() {
        let layers = LayersOptions {
            resolution,
            ..Default::default()
        };
        let filtered = filter_for_comparison(solid, &layers)?;
        for target in RADII_PX {
            let base = CompareOptions::default();
            let size = size_for_radius(&filtered, base.view, target)?;
            let c = compare_filtered(&filtered, &CompareOptions { size, ..base })?;
            let r = &c.report;
            let pixel = filtered.radius / r.radius_pixels;
            let distance = pixel * VIEWPORT / (2.0 * (FOV / 2.0).tan());
            println!(
                "{:<8} {:>5} {:>5} {:>7.2} {:>9.1} {:>7} {:>10.4} {:>10.4} {:>+6.0}%",
                name,
                level,
                resolution,
                r.radius_pixels,
                distance / diameter,
                r.silhouette_pixels,
                r.rms_single,
                r.rms_layered,
                100.0 * (r.rms_layered / r.rms_single - 1.0)
            );
            let png = c.montage().to_png()?;
            let file = format!("{}-{resolution}-{target}.png", name.replace(' ', "-"));
            voxlod::io::atomic::write_atomically(&out.join(file), |w| {
                std::io::Write::write_all(w, &png)
            })?;
        }
    }
    Ok(())
}
