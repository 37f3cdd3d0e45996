//! Spot baked onto voxel levels of itself: each level of a halving chain (the paper's filter
//! and marching cubes) gets an atlas and textures cast from Spot, and its appearance (PSNR and
//! SSIM over 14 views, `voxlod_eval::appearance`) is printed beside that of the same level
//! with per-vertex colours taken from Spot's nearest points (`voxlod_asset::transfer`).
//!
//! `cargo run --release -p voxlod-bake --example bake_spot [SPOT_OBJ [OUT_DIR]]`; Spot is read
//! from `../shared/data/assets/spot/spot.obj` beside the checkout by default, and the run is
//! skipped with a reason when it is not there. With OUT_DIR, each baked level is written there
//! as `spot-baked-R.glb`.

use std::path::{Path, PathBuf};
use std::time::Instant;

use voxlod::sampling::Filter;
use voxlod::{LodOptions, Source};
use voxlod_asset::transfer;
use voxlod_bake::{bake, BakeOptions};
use voxlod_eval::appearance::{AppearanceOptions, AppearanceReference};
use voxlod_gltf::{asset_glb, AssetGlbOptions};

type Res<T> = Result<T, Box<dyn std::error::Error>>;

fn main() -> Res<()> {
    let args: Vec<String> = std::env::args().collect();
    let default =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/assets/spot/spot.obj");
    let spot = args.get(1).map_or(default, PathBuf::from);
    if !spot.exists() {
        println!(
            "skipped: Spot is not at {} (pass its spot.obj)",
            spot.display()
        );
        return Ok(());
    }
    let out = args.get(2).map(PathBuf::from);
    let input = voxlod::io::read_asset(&spot)?.asset;
    let geometry = input.mesh.geometry();
    let lod = voxlod::lod(
        &Source::Mesh(&geometry),
        &LodOptions::halving(128, 4, Filter::Hypercone),
    )?;
    let reference = AppearanceReference::new(&input, &AppearanceOptions::default())?;
    println!(
        "Spot: {} triangles; {} cores, load {}",
        input.mesh.triangles.len(),
        std::thread::available_parallelism().map_or(1, |n| n.get()),
        std::fs::read_to_string("/proc/loadavg")
            .unwrap_or_default()
            .trim()
    );
    println!(
        "{:>4} {:>7} {:>9} {:>6} {:>6} {:>9} {:>9} {:>7} {:>7}   {:>13} {:>13}",
        "res",
        "tris",
        "texture",
        "charts",
        "util",
        "hit",
        "fallback",
        "atlas s",
        "bake s",
        "PSNR vertex",
        "PSNR baked"
    );
    for level in &lod.levels {
        let transferred = transfer(&input, &level.mesh)?.asset;
        let options = BakeOptions {
            voxel_size: Some(level.plan.voxel_size as f32),
            ..BakeOptions::for_texture(1024)
        };
        let start = Instant::now();
        let baked = bake(&input, &level.mesh, &options)?;
        let seconds = start.elapsed().as_secs_f64();
        let vertex = reference.compare(&transferred)?;
        let textured = reference.compare(&baked.asset)?;
        let r = &baked.report;
        println!(
            "{:>4} {:>7} {:>9} {:>6} {:>6.3} {:>9} {:>9} {:>7.2} {:>7.2}   {:>6.2} {:.4} {:>6.2} {:.4}",
            level.resolution,
            level.mesh.triangles.len(),
            format!("{}x{}", r.width, r.height),
            r.charts,
            r.utilisation,
            r.texels_hit,
            r.texels_fallback,
            r.atlas_seconds,
            seconds,
            vertex.psnr,
            vertex.ssim,
            textured.psnr,
            textured.ssim
        );
        for w in &r.warnings {
            println!("     warning: {w}");
        }
        if let Some(dir) = &out {
            std::fs::create_dir_all(dir)?;
            let glb = asset_glb(
                std::slice::from_ref(&baked.asset),
                &AssetGlbOptions::default(),
            )?;
            std::fs::write(
                dir.join(format!("spot-baked-{}.glb", level.resolution)),
                glb,
            )?;
        }
    }
    Ok(())
}
