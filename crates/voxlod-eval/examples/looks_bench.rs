//! Levels of textured assets by triangle budget, voxlod's against gltfpack's `-si`, by
//! appearance: for Spot (its OBJ written once as `.glb`) and two generated multi-part textured
//! scenes (one with vertex colours), at 50 %, 20 %, 5 % and 1 % of the triangles, voxlod's
//! budget levels with their looks (`voxlod::asset_lod_by_budget`) and gltfpack's `-si R` on the same
//! `.glb`, both read back from the files they wrote, each measured against the input over the
//! 14 views (`voxlod_eval::appearance`: PSNR, SSIM), with its triangles, whether it is textured
//! or coloured, and its seconds. Where gltfpack stops short of a ratio at its error limit, it
//! runs again with `-sa`, and voxlod runs again at each count gltfpack reached, so that the two
//! are compared at equal counts.
//!
//! Usage: `looks_bench OUT_DIR GLTFPACK SPOT_OBJ` (writes the inputs, every level's `.glb`,
//! `looks-bench.json` into `OUT_DIR`, and prints the table).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Arc;
use std::time::Instant;

use serde_json::json;
use voxlod::asset::{Asset, AssetMesh, Image, Material, Part, TextureRef};
use voxlod::core::glam::{Vec2, Vec3, Vec4};
use voxlod::gltf::{asset_glb, read_scene, AssetGlbOptions};
use voxlod::{asset_lod_by_budget, run_to_end, BudgetOptions};
use voxlod_eval::appearance::{AppearanceOptions, AppearanceReference};

type Res<T> = Result<T, Box<dyn std::error::Error>>;

const RATIOS: [f64; 4] = [0.5, 0.2, 0.05, 0.01];

fn main() -> Res<()> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 4 {
        return Err("usage: looks_bench OUT_DIR GLTFPACK SPOT_OBJ".into());
    }
    let out = PathBuf::from(&args[1]);
    let gltfpack = PathBuf::from(&args[2]);
    std::fs::create_dir_all(&out)?;
    let spot = voxlod::io::read_asset(Path::new(&args[3]))?.asset;
    let inputs = [
        ("spot", spot),
        ("scene-textured", textured_scene(false)),
        ("scene-coloured", textured_scene(true)),
    ];
    let mut rows = Vec::new();
    println!(
        "{:<15} {:<14} {:>6} {:>7} {:>7} {:>7} {:<11} {:<16} {:>7}",
        "input", "method", "ratio", "target", "tris", "PSNR", "SSIM", "looks", "seconds"
    );
    for (name, asset) in inputs {
        let file = out.join(format!("{name}.glb"));
        let glb = asset_glb(std::slice::from_ref(&asset), &AssetGlbOptions::default())?;
        std::fs::write(&file, glb)?;
        let input = read_scene(&file)?.asset;
        let total = input.mesh.triangles.len();
        let reference = AppearanceReference::new(&input, &AppearanceOptions::default())?;
        let mut measure =
            |method: &str, ratio: f64, target: usize, level: &Asset, looks: &str, s| {
                let report = reference.compare(level)?;
                let row = json!({
                    "input": name, "input_triangles": total, "method": method, "ratio": ratio,
                    "target": target, "triangles": level.mesh.triangles.len(),
                    "psnr": report.psnr, "ssim": report.ssim, "looks": looks,
                    "appearance": appearance_of(level), "seconds": s,
                "per_view_psnr": report.per_view.iter().map(|v| v.psnr).collect::<Vec<_>>(),
                });
                println!(
                    "{:<15} {:<14} {:>6} {:>7} {:>7} {:>7.2} {:<11.4} {:<16} {:>7.2}",
                    name,
                    method,
                    ratio,
                    target,
                    level.mesh.triangles.len(),
                    report.psnr,
                    report.ssim,
                    format!("{looks}/{}", appearance_of(level)),
                    s
                );
                rows.push(row);
                Ok::<(), Box<dyn std::error::Error>>(())
            };
        for ratio in RATIOS {
            let target = ((total as f64 * ratio).round() as usize).max(1);
            let (level, looks, s) = voxlod_level(&input, target, &out, name)?;
            measure("voxlod", ratio, target, &level, &looks, s)?;
            let mut reached = Vec::new();
            for aggressive in [false, true] {
                let tag = if aggressive {
                    "gltfpack -sa"
                } else {
                    "gltfpack"
                };
                let level_file = out.join(format!(
                    "{name}-gltfpack{}-{ratio}.glb",
                    if aggressive { "-sa" } else { "" }
                ));
                let (level, s) = gltfpack_level(&gltfpack, &file, &level_file, ratio, aggressive)?;
                let tris = level.mesh.triangles.len();
                measure(tag, ratio, target, &level, "-", s)?;
                reached.push(tris);
                // Within 10 % of the target: no need for the aggressive mode.
                if !aggressive && tris as f64 <= target as f64 * 1.1 {
                    break;
                }
            }
            for tris in reached {
                if tris.abs_diff(target) as f64 > 0.02 * target as f64 && tris < total {
                    let (level, looks, s) = voxlod_level(&input, tris, &out, name)?;
                    measure("voxlod @gltfpack", ratio, tris, &level, &looks, s)?;
                }
            }
        }
    }
    let report = json!({
        "views": 14, "size": 512, "ratios": RATIOS, "rows": rows,
        "cores": std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1),
        "load_average": std::fs::read_to_string("/proc/loadavg").unwrap_or_default().trim(),
    });
    std::fs::write(
        out.join("looks-bench.json"),
        serde_json::to_string_pretty(&report)?,
    )?;
    Ok(())
}

/// voxlod's level of `input` at `target` triangles, written as `.glb` and read back, with how
/// it got its looks and its seconds (the level's making only).
fn voxlod_level(input: &Asset, target: usize, out: &Path, name: &str) -> Res<(Asset, String, f64)> {
    let options = BudgetOptions::for_triangles(&[target]);
    let start = Instant::now();
    let made = asset_lod_by_budget(input, &options, &run_to_end)?;
    let s = start.elapsed().as_secs_f64();
    let level = made.assets.into_iter().next().ok_or("no level")?;
    let asset = level.asset.ok_or("an empty level")?;
    let file = out.join(format!("{name}-voxlod-{target}.glb"));
    std::fs::write(&file, asset_glb(&[asset], &AssetGlbOptions::default())?)?;
    let back = read_scene(&file)?.asset;
    Ok((back, format!("{:?}", level.looks).to_lowercase(), s))
}

/// `textured`, `coloured`, both, or `plain` (grey: neither a texture nor vertex colours nor a
/// material colour other than white).
fn appearance_of(a: &Asset) -> &'static str {
    let used = |m: &Material| {
        a.mesh
            .material
            .iter()
            .any(|&k| a.materials[k as usize] == *m)
    };
    let textured = !a.mesh.uv[0].is_empty()
        && a.materials
            .iter()
            .any(|m| m.base_color_texture.is_some() && used(m));
    let coloured = !a.mesh.colors.is_empty()
        || a.materials
            .iter()
            .any(|m| m.base_color != [1.0; 4] && used(m));
    match (textured, coloured) {
        (true, true) => "textured+col",
        (true, false) => "textured",
        (false, true) => "coloured",
        (false, false) => "plain",
    }
}

/// gltfpack's `-si ratio` level of `file` (`-sa` when `aggressive`), written to `level_file`
/// and read back, with gltfpack's wall seconds.
fn gltfpack_level(
    gltfpack: &Path,
    file: &Path,
    level_file: &Path,
    ratio: f64,
    aggressive: bool,
) -> Res<(Asset, f64)> {
    let start = Instant::now();
    let mut cmd = Command::new(gltfpack);
    cmd.arg("-i").arg(file).arg("-o").arg(level_file);
    cmd.arg("-si").arg(ratio.to_string()).arg("-noq");
    if aggressive {
        cmd.arg("-sa");
    }
    let status = cmd.output()?;
    let s = start.elapsed().as_secs_f64();
    if !status.status.success() {
        return Err(format!(
            "gltfpack failed on {}: {}",
            file.display(),
            String::from_utf8_lossy(&status.stderr)
        )
        .into());
    }
    Ok((read_scene(level_file)?.asset, s))
}

/// A generated multi-part scene: UV spheres and subdivided boxes, each with its own material
/// and generated texture (checks, stripes, rings, a gradient), one part with a plain colour
/// factor; with `colours`, every vertex has a colour too (a smooth tint over the scene, and
/// the untextured parts coloured by position alone).
fn textured_scene(colours: bool) -> Asset {
    let mut asset = Asset::default();
    add_scene_materials(&mut asset);
    let mut mesh = AssetMesh::default();
    let mut add = |name: &str, part: AssetMesh, material: u32, parts: &mut Vec<Part>| {
        let base = mesh.positions.len() as u32;
        parts.push(Part {
            name: name.into(),
            first_triangle: mesh.triangles.len() as u32,
            triangle_count: part.triangles.len() as u32,
        });
        mesh.positions.extend(&part.positions);
        mesh.normals.extend(&part.normals);
        mesh.uv[0].extend(&part.uv[0]);
        (mesh.triangles).extend(part.triangles.iter().map(|t| t.map(|i| i + base)));
        mesh.material
            .extend(std::iter::repeat_n(material, part.triangles.len()));
    };
    let mut parts = Vec::new();
    add(
        "ball checks",
        sphere(Vec3::new(0.0, 0.0, 0.0), 1.0, 48, 96),
        0,
        &mut parts,
    );
    add(
        "box stripes",
        cube(Vec3::new(2.4, -0.2, 0.3), Vec3::new(0.8, 0.8, 0.6), 24),
        1,
        &mut parts,
    );
    add(
        "ball rings",
        sphere(Vec3::new(-1.8, 0.6, 1.2), 0.7, 40, 80),
        2,
        &mut parts,
    );
    add(
        "box gradient",
        cube(Vec3::new(0.2, -1.6, -0.4), Vec3::new(1.4, 0.4, 0.9), 20),
        3,
        &mut parts,
    );
    add(
        "ball plain",
        sphere(Vec3::new(1.2, 1.6, -1.0), 0.6, 32, 64),
        4,
        &mut parts,
    );
    if colours {
        mesh.colors = (mesh.positions.iter())
            .map(|p| {
                let t =
                    (p.normalize_or_zero() * 0.5 + Vec3::splat(0.5)).clamp(Vec3::ZERO, Vec3::ONE);
                Vec4::new(0.4 + 0.6 * t.x, 0.4 + 0.6 * t.y, 0.4 + 0.6 * t.z, 1.0)
            })
            .collect();
    }
    asset.mesh = mesh;
    asset.parts = parts;
    asset.validate().expect("a valid generated scene");
    asset
}

/// The scene's materials: four textured by generated images (checks, stripes, rings, a
/// gradient) and one plain orange.
fn add_scene_materials(asset: &mut Asset) {
    let textures: [fn(u32, u32) -> [u8; 3]; 4] = [
        |x, y| {
            if (x / 32 + y / 32) % 2 == 0 {
                [220, 40, 40]
            } else {
                [240, 230, 200]
            }
        },
        |x, _| {
            if (x / 24) % 2 == 0 {
                [30, 90, 200]
            } else {
                [250, 210, 40]
            }
        },
        |x, y| {
            let (dx, dy) = (x as f32 - 128.0, y as f32 - 128.0);
            let r = (dx * dx + dy * dy).sqrt();
            if ((r / 18.0) as u32).is_multiple_of(2) {
                [20, 150, 60]
            } else {
                [230, 240, 230]
            }
        },
        |x, y| [x as u8, y as u8, (255 - x.max(y)) as u8],
    ];
    for (k, texel) in textures.iter().enumerate() {
        let img = image::RgbImage::from_fn(256, 256, |x, y| image::Rgb(texel(x, y)));
        let mut png = Vec::new();
        img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
            .expect("PNG in memory");
        asset.images.push(Image {
            name: format!("texture {k}"),
            mime: "image/png".into(),
            bytes: Arc::new(png),
        });
        asset.materials.push(Material {
            name: format!("textured {k}"),
            base_color_texture: Some(TextureRef {
                image: k,
                tex_coord: 0,
                transform: None,
                sampler: Default::default(),
            }),
            metallic: 0.0,
            roughness: 0.8,
            ..Material::default()
        });
    }
    asset.materials.push(Material {
        name: "plain orange".into(),
        base_color: [0.9, 0.35, 0.05, 1.0],
        metallic: 0.0,
        ..Material::default()
    });
}

/// A latitude-longitude sphere (voxlod-testkit's), u running 0..2 around.
fn sphere(centre: Vec3, radius: f32, rings: u32, segments: u32) -> AssetMesh {
    let mut m = voxlod_testkit::assets::uv_sphere(centre, radius, rings, segments);
    for uv in &mut m.uv[0] {
        uv.x *= 2.0;
    }
    m
}

/// A box of half-extents `half` around `centre`, each face an `n` × `n` grid of its own
/// vertices (the edges doubled), texture coordinates 0..1 per face.
fn cube(centre: Vec3, half: Vec3, n: u32) -> AssetMesh {
    let mut m = AssetMesh::default();
    let axes = [Vec3::X, Vec3::Y, Vec3::Z];
    for (k, normal) in axes.iter().flat_map(|&a| [a, -a]).enumerate() {
        let (u_axis, v_axis) = (axes[(k / 2 + 1) % 3], axes[(k / 2 + 2) % 3]);
        let (u_axis, v_axis) = if normal.dot(u_axis.cross(v_axis)) > 0.0 {
            (u_axis, v_axis)
        } else {
            (v_axis, u_axis)
        };
        let base = m.positions.len() as u32;
        for i in 0..=n {
            for j in 0..=n {
                let (s, t) = (j as f32 / n as f32, i as f32 / n as f32);
                let p = normal + u_axis * (2.0 * s - 1.0) + v_axis * (2.0 * t - 1.0);
                m.positions.push(centre + p * half);
                m.normals.push(normal);
                m.uv[0].push(Vec2::new(s, t));
            }
        }
        let at = |i: u32, j: u32| base + i * (n + 1) + j;
        for i in 0..n {
            for j in 0..n {
                m.triangles.push([at(i, j), at(i, j + 1), at(i + 1, j + 1)]);
                m.triangles.push([at(i, j), at(i + 1, j + 1), at(i + 1, j)]);
            }
        }
    }
    m
}
