//! Scene proxies beside gltfpack, by appearance: on the generated scenes of
//! `voxlod_testkit::scenes` (a room, a machine, a tree, a building, instanced props) at 5 % and
//! 1 % of their triangles, and on Spot at 20 %, 5 % and 1 %, voxlod's baked proxy level
//! (`voxlod::proxy`, 1024² textures, or `PROXY_BENCH_TEXTURE`) and gltfpack's `-si R -noq`,
//! `-si R -se 1 -noq` (its error limit lifted, so that it aims at the ratio where its topology
//! lets it) and `-si R -sa -noq` on the same scene written as `.glb`, every level written and read back, measured against the input
//! over 14 views of 512² (`voxlod_eval::appearance`: PSNR, SSIM), with the draw calls it needs
//! (materials its triangles use), its triangles, whether it welds into a closed manifold, its
//! seconds, and the mean angle between its shaded normal (with its normal map where its
//! material has one) and the input's shading normal over the pixels where both are seen in the
//! same 14 views (z-buffered at 256², one sample a pixel; a face seen from behind has its
//! normal turned over, since both faces are drawn). Where gltfpack stops more than 2 % away
//! from a target (`-si` at its error limit), voxlod runs again at each count gltfpack reached
//! (`voxlod @gltf`), so that the two are also compared at equal counts.
//!
//! Usage: `proxy_bench OUT_DIR GLTFPACK SPOT_OBJ` (Spot skipped with a message when absent;
//! writes every input and level as `.glb` and `proxy-bench.json` into `OUT_DIR`, prints the
//! table), or `proxy_bench --time-1m OUT_DIR` (the time target alone: `scene_1m` to three
//! proxy levels of 20 000, 5 000 and 1 000 triangles with 2048² textures; writes
//! `proxy-bench-1m.json`; run it under `/usr/bin/time -v` for its peak memory).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use serde_json::{json, Value};
use voxlod::asset::Asset;
use voxlod::core::glam::{Vec2, Vec3, Vec4, Vec4Swizzles};
use voxlod::core::weld::weld_vertices;
use voxlod::core::{mesh_topology, TriangleMesh};
use voxlod::gltf::{asset_glb, read_scene, AssetGlbOptions};
use voxlod::render::raster::{raster_fragments, ScreenVertex, Tile};
use voxlod::render::{view_directions, Camera};
use voxlod::{proxy, ProxyOptions};
use voxlod_eval::appearance::{AppearanceOptions, AppearanceReference};
use voxlod_eval::evaluate::draw_calls;
use voxlod_testkit::scenes;

type Res<T> = Result<T, Box<dyn std::error::Error>>;

/// Side of the square ray grid per view of the normal measure.
const NORMAL_GRID: usize = 256;

fn main() -> Res<()> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() == 3 && args[1] == "--time-1m" {
        return time_1m(Path::new(&args[2]));
    }
    if args.len() != 4 {
        return Err("usage: proxy_bench OUT_DIR GLTFPACK SPOT_OBJ | --time-1m OUT_DIR".into());
    }
    let out = PathBuf::from(&args[1]);
    let gltfpack = PathBuf::from(&args[2]);
    std::fs::create_dir_all(&out)?;
    let load_before = load_average();
    let mut inputs: Vec<(&str, Asset, Vec<f64>)> = vec![
        ("room", scenes::room(), vec![0.05, 0.01]),
        ("machine", scenes::machine(), vec![0.05, 0.01]),
        ("tree", scenes::tree(), vec![0.05, 0.01]),
        ("building", scenes::building(), vec![0.05, 0.01]),
        ("props", scenes::props(), vec![0.05, 0.01]),
    ];
    // PROXY_BENCH_INPUTS=tree,spot runs only the inputs named.
    let only = std::env::var("PROXY_BENCH_INPUTS").ok();
    let wanted = |name: &str| {
        only.as_ref()
            .is_none_or(|o| o.split(',').any(|n| n == name))
    };
    inputs.retain(|(name, _, _)| wanted(name));
    let spot = Path::new(&args[3]);
    if !wanted("spot") {
        println!("spot skipped: not in PROXY_BENCH_INPUTS");
    } else if spot.exists() {
        let asset = voxlod::io::read_asset(spot)?.asset;
        inputs.push(("spot", asset, vec![0.2, 0.05, 0.01]));
    } else {
        println!("spot skipped: {} is absent", spot.display());
    }
    println!(
        "{:<9} {:<18} {:>5} {:>6} {:>6} {:>6} {:>7} {:<7} {:>5} {:>6} {:>7} {:>7}",
        "input",
        "method",
        "ratio",
        "target",
        "tris",
        "draws",
        "PSNR",
        "SSIM",
        "closed",
        "angle",
        "no-map",
        "seconds"
    );
    let mut rows = Vec::new();
    for (name, asset, ratios) in inputs {
        rows.extend(bench_input(name, &asset, &ratios, &out, &gltfpack)?);
    }
    let report = json!({
        "views": 14, "size": 512, "supersample": 2, "normal_grid": NORMAL_GRID,
        "texture": 1024, "rows": rows,
        "cores": std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1),
        "load_average_before": load_before, "load_average_after": load_average(),
    });
    let file = out.join("proxy-bench.json");
    std::fs::write(&file, serde_json::to_string_pretty(&report)?)?;
    println!(
        "load average before {load_before}, after {}",
        load_average()
    );
    Ok(())
}

/// `/proc/loadavg`'s first three fields.
fn load_average() -> String {
    let text = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    text.split_whitespace()
        .take(3)
        .collect::<Vec<_>>()
        .join(" ")
}

/// Every method at every ratio on one input (written as `.glb` and read back first).
fn bench_input(
    name: &str,
    asset: &Asset,
    ratios: &[f64],
    out: &Path,
    gltfpack: &Path,
) -> Res<Vec<Value>> {
    let file = out.join(format!("{name}.glb"));
    let glb = asset_glb(std::slice::from_ref(asset), &AssetGlbOptions::default())?;
    std::fs::write(&file, glb)?;
    let input = read_scene(&file)?.asset;
    let total = input.mesh.triangles.len();
    let options = AppearanceOptions {
        views: 14,
        size: 512,
        supersample: 2,
    };
    let reference = AppearanceReference::new(&input, &options)?;
    let shading = Shading::new(&input);
    let mut rows = Vec::new();
    let mut measure = |method: &str, ratio: f64, target: usize, made: Made| -> Res<usize> {
        let mut row = json!({
            "input": name, "input_triangles": total, "input_draws": draw_calls(&input),
            "method": method, "ratio": ratio, "target": target, "seconds": made.seconds,
        });
        let level = match made.level {
            Ok(level) => level,
            Err(why) => {
                println!("{name:<9} {method:<18} {ratio:>5} {target:>6} failed: {why}");
                row["error"] = why.into();
                rows.push(row);
                return Ok(0);
            }
        };
        let looks = reference.compare(&level)?;
        let angles = normal_angles(&shading, &Shading::new(&level), &input)?;
        let closed = is_closed(&level);
        let (tris, draws) = (level.mesh.triangles.len(), draw_calls(&level));
        println!(
            "{name:<9} {method:<18} {ratio:>5} {target:>6} {tris:>6} {draws:>6} {:>7.2} \
             {:<7.4} {:>5} {:>6.1} {:>7.1} {:>7.2}",
            looks.psnr, looks.ssim, closed, angles.mapped, angles.unmapped, made.seconds
        );
        row["triangles"] = tris.into();
        row["draws"] = draws.into();
        row["psnr"] = looks.psnr.into();
        row["ssim"] = looks.ssim.into();
        row["per_view_psnr"] = looks.per_view.iter().map(|v| v.psnr).collect();
        row["closed_manifold"] = closed.into();
        row["normal_angle_degrees"] = angles.mapped.into();
        row["normal_angle_without_map_degrees"] = angles.unmapped.into();
        row["normal_pixels"] = angles.pixels.into();
        row["details"] = made.details;
        rows.push(row);
        Ok(tris)
    };
    for &ratio in ratios {
        let target = ((total as f64 * ratio).round() as usize).max(1);
        measure(
            "voxlod proxy",
            ratio,
            target,
            proxy_level(&input, target, out, name),
        )?;
        let mut reached = Vec::new();
        for (method, flags) in GLTFPACK_RUNS {
            let made = gltfpack_level(gltfpack, &file, name, ratio, flags, out);
            reached.push(measure(method, ratio, target, made)?);
        }
        // Where gltfpack stopped away from the target, voxlod at the count it reached.
        reached.sort_unstable();
        reached.dedup();
        for tris in reached {
            if tris > 0 && tris < total && tris.abs_diff(target) as f64 > 0.02 * target as f64 {
                let made = proxy_level(&input, tris, out, name);
                measure("voxlod @gltf", ratio, tris, made)?;
            }
        }
    }
    Ok(rows)
}

/// gltfpack's runs beside the proxy: the method's name in the table and the flags after
/// `-si R -noq`.
const GLTFPACK_RUNS: [(&str, &[&str]); 3] = [
    ("gltfpack -si", &[]),
    ("gltfpack -si -se 1", &["-se", "1"]),
    ("gltfpack -sa", &["-sa"]),
];

/// Texels a side of the proxies' textures: `PROXY_BENCH_TEXTURE`, or 1024.
fn texture() -> u32 {
    let given = std::env::var("PROXY_BENCH_TEXTURE").ok();
    given.and_then(|t| t.parse().ok()).unwrap_or(1024)
}

/// A level made by one method, read back from the file it was written to, or why not.
struct Made {
    level: Result<Asset, String>,
    seconds: f64,
    details: Value,
}

/// voxlod's proxy level of `input` at `target` triangles with [`texture`]² textures, written
/// as `.glb` and read back; its seconds are the proxy call's.
fn proxy_level(input: &Asset, target: usize, out: &Path, name: &str) -> Made {
    let start = Instant::now();
    let made = proxy(input, &ProxyOptions::for_triangles(&[target], texture()));
    let seconds = start.elapsed().as_secs_f64();
    let fail = |why: String| Made {
        level: Err(why),
        seconds,
        details: Value::Null,
    };
    let made = match made {
        Ok(made) => made,
        Err(e) => return fail(format!("voxlod::proxy: {e}")),
    };
    let Some(level) = made.levels.into_iter().next() else {
        return fail("voxlod::proxy made no level".into());
    };
    if level.asset.mesh.triangles.is_empty() {
        return fail("voxlod::proxy made an empty level".into());
    }
    let details = json!({
        "method": format!("{:?}", level.report.method), "resolution": level.report.resolution,
        "boundary_loops": level.report.boundary_loops, "genus": level.report.genus,
        "components": level.report.components, "bake": level.bake, "warnings": made.warnings,
    });
    let file = out.join(format!("{name}-voxlod-{target}.glb"));
    let written = asset_glb(&[level.asset], &AssetGlbOptions::default())
        .map_err(|e| e.to_string())
        .and_then(|glb| std::fs::write(&file, glb).map_err(|e| e.to_string()))
        .and_then(|()| read_scene(&file).map_err(|e| e.to_string()));
    Made {
        level: written.map(|r| r.asset),
        seconds,
        details,
    }
}

/// gltfpack's `-si ratio -noq` level of `file` with `flags` after, read back; its seconds
/// are gltfpack's wall time.
fn gltfpack_level(
    gltfpack: &Path,
    file: &Path,
    name: &str,
    ratio: f64,
    flags: &[&str],
    out: &Path,
) -> Made {
    let tag: String = flags.concat();
    let level_file = out.join(format!("{name}-gltfpack{tag}-{ratio}.glb"));
    let start = Instant::now();
    let mut cmd = Command::new(gltfpack);
    cmd.arg("-i").arg(file).arg("-o").arg(&level_file);
    cmd.arg("-si").arg(ratio.to_string()).arg("-noq");
    cmd.args(flags);
    let run = cmd.output();
    let seconds = start.elapsed().as_secs_f64();
    let level = match run {
        Ok(o) if o.status.success() => read_scene(&level_file)
            .map(|r| r.asset)
            .map_err(|e| e.to_string()),
        Ok(o) => Err(format!(
            "gltfpack failed: {}",
            String::from_utf8_lossy(&o.stderr).trim()
        )),
        Err(e) => Err(format!("cannot run {}: {e}", gltfpack.display())),
    };
    Made {
        level,
        seconds,
        details: Value::Null,
    }
}

/// Whether the asset's triangles, welded by position, are a closed manifold.
fn is_closed(asset: &Asset) -> bool {
    let mut mesh = asset.mesh.geometry();
    weld_vertices(&mut mesh);
    mesh_topology(&mesh).is_closed_manifold()
}

/// An asset prepared for the normal measure: its geometry and its normal maps (raw 8-bit,
/// as tangent-space maps are stored, no sRGB decoding).
struct Shading<'a> {
    asset: &'a Asset,
    geometry: TriangleMesh,
    normal_maps: Vec<Option<image::RgbImage>>,
}

impl<'a> Shading<'a> {
    fn new(asset: &'a Asset) -> Shading<'a> {
        let normal_maps = (asset.materials.iter())
            .map(|m| {
                let t = m.normal_texture.as_ref()?;
                let bytes = asset.images.get(t.image)?.bytes.as_slice();
                Some(image::load_from_memory(bytes).ok()?.to_rgb8())
            })
            .collect();
        Shading {
            asset,
            geometry: asset.mesh.geometry(),
            normal_maps,
        }
    }

    /// The surface seen at each pixel of `camera`'s view (the renderer's z-buffer, one sample
    /// a pixel, both faces drawn, alpha masks ignored): its triangle and barycentric weights.
    fn visible(&self, camera: &Camera) -> Vec<Option<(usize, [f32; 3])>> {
        let side = camera.width as usize;
        let mut tile = Tile::new(side);
        let screen = |v: u32| {
            let p = camera.project(self.geometry.positions[v as usize].as_dvec3())?;
            Some(ScreenVertex {
                x: p.x as f32,
                y: p.y as f32,
                z: p.depth_key as f32,
                w: p.w_inv as f32,
                shade: 0.0,
            })
        };
        for (t, tri) in self.geometry.triangles.iter().enumerate() {
            let [Some(a), Some(b), Some(c)] = tri.map(screen) else {
                continue;
            };
            raster_fragments(&mut tile, [a, b, c], 1, 0.0, false, |w, _| {
                Some([t as f32, w[0], w[1], 1.0])
            });
        }
        (tile.color.iter().zip(&tile.coverage))
            .map(|(c, &covered)| {
                (covered > 0.0).then(|| (c[0] as usize, [c[1], c[2], 1.0 - c[1] - c[2]]))
            })
            .collect()
    }

    /// The shading normal at a point seen from `view` (towards the viewer): vertex normals
    /// interpolated (the face's where the asset has none), then, with `mapped` and where the
    /// triangle's material has a normal map and the mesh has tangents, the map's
    /// tangent-space normal applied; turned over where the face is seen from behind (both
    /// faces are drawn).
    fn normal(&self, t: usize, w: [f32; 3], mapped: bool, view: Vec3) -> Vec3 {
        let n = self.shading_normal(t, w, mapped);
        let [a, b, c] = self.geometry.triangles[t].map(|v| self.geometry.positions[v as usize]);
        if (b - a).cross(c - a).dot(view) < 0.0 {
            -n
        } else {
            n
        }
    }

    /// [`Shading::normal`] before it is turned to the viewer.
    fn shading_normal(&self, t: usize, w: [f32; 3], mapped: bool) -> Vec3 {
        let mesh = &self.asset.mesh;
        let tri = mesh.triangles[t].map(|v| v as usize);
        let lerp3 = |a: &[Vec3]| tri.iter().zip(w).map(|(&v, w)| a[v] * w).sum::<Vec3>();
        let face = {
            let [a, b, c] = tri.map(|v| self.geometry.positions[v]);
            (b - a).cross(c - a).normalize_or_zero()
        };
        let n = if mesh.normals.is_empty() {
            face
        } else {
            lerp3(&mesh.normals).normalize_or(face)
        };
        let material = mesh.material.get(t).map_or(0, |&m| m as usize);
        let map = self.normal_maps.get(material).and_then(|m| m.as_ref());
        let (Some(map), true, false) = (map, mapped, mesh.tangents.is_empty()) else {
            return n;
        };
        let tangent4 = tri
            .iter()
            .zip(w)
            .map(|(&v, w)| mesh.tangents[v] * w)
            .sum::<Vec4>();
        let tangent = (tangent4.xyz() - n * n.dot(tangent4.xyz())).normalize_or_zero();
        let sign = if mesh.tangents[tri[0]].w < 0.0 {
            -1.0
        } else {
            1.0
        };
        let bitangent = n.cross(tangent) * sign;
        let uv = tri
            .iter()
            .zip(w)
            .map(|(&v, w)| mesh.uv[0][v] * w)
            .sum::<Vec2>();
        let scale = self.asset.materials[material].normal_scale;
        let m = sample(map, uv);
        let local = Vec3::new(m.x * scale, m.y * scale, m.z);
        (tangent * local.x + bitangent * local.y + n * local.z).normalize_or(n)
    }
}

/// The tangent-space normal of `map` at `uv` (bilinear, clamped), from (0..255) to −1..1.
fn sample(map: &image::RgbImage, uv: Vec2) -> Vec3 {
    let (w, h) = (map.width() as f32, map.height() as f32);
    let (x, y) = (uv.x * w - 0.5, uv.y * h - 0.5);
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let at = |i: f32, j: f32| {
        let (i, j) = (i.clamp(0.0, w - 1.0) as u32, j.clamp(0.0, h - 1.0) as u32);
        let p = map.get_pixel(i, j).0;
        Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32) / 255.0 * 2.0 - Vec3::ONE
    };
    let top = at(x0, y0).lerp(at(x0 + 1.0, y0), fx);
    let bottom = at(x0, y0 + 1.0).lerp(at(x0 + 1.0, y0 + 1.0), fx);
    top.lerp(bottom, fy)
}

/// The mean angles of the normal measure, in degrees, and the pixels they are over.
struct Angles {
    mapped: f64,
    unmapped: f64,
    pixels: usize,
}

/// The mean angle between `level`'s shaded normal (with and without its normal map) and
/// `input`'s shading normal, over the pixels of 14 orthographic views framing `frame`'s box
/// where both surfaces are seen. Cost: two z-buffer renders and two normal lookups a pixel.
fn normal_angles(input: &Shading, level: &Shading, frame: &Asset) -> Res<Angles> {
    let bounds = frame.mesh.geometry().bounds();
    let side = NORMAL_GRID as u32;
    let (mut sum_mapped, mut sum_unmapped, mut pixels) = (0.0f64, 0.0f64, 0usize);
    for d in view_directions(14) {
        let camera = Camera::fit(d, &bounds, side, side, None)?;
        let seen = input
            .visible(&camera)
            .into_iter()
            .zip(level.visible(&camera));
        for (a, b) in seen {
            let (Some(a), Some(b)) = (a, b) else {
                continue;
            };
            let view = -d.as_vec3();
            let truth = input.normal(a.0, a.1, true, view);
            let angle = |n: Vec3| n.dot(truth).clamp(-1.0, 1.0).acos().to_degrees() as f64;
            sum_mapped += angle(level.normal(b.0, b.1, true, view));
            sum_unmapped += angle(level.normal(b.0, b.1, false, view));
            pixels += 1;
        }
    }
    let n = pixels.max(1) as f64;
    Ok(Angles {
        mapped: sum_mapped / n,
        unmapped: sum_unmapped / n,
        pixels,
    })
}

/// The time target: `scene_1m` to proxy levels of 20 000, 5 000 and 1 000 triangles with
/// 2048² textures; prints and writes the seconds of the call and of each bake.
fn time_1m(out: &Path) -> Res<()> {
    std::fs::create_dir_all(out)?;
    let load_before = load_average();
    let scene = scenes::scene_1m();
    let budgets = [20_000, 5_000, 1_000];
    let start = Instant::now();
    let made = proxy(&scene, &ProxyOptions::for_triangles(&budgets, 2048))?;
    let seconds = start.elapsed().as_secs_f64();
    let levels: Vec<Value> = (made.levels.iter())
        .map(|l| {
            json!({
                "budget": l.report.budget, "triangles": l.asset.mesh.triangles.len(),
                "method": format!("{:?}", l.report.method), "closed": is_closed(&l.asset),
                "texture": [l.bake.width, l.bake.height], "bake_seconds": l.bake.seconds,
                "atlas_seconds": l.bake.atlas_seconds, "charts": l.bake.charts,
                "utilisation": l.bake.utilisation,
            })
        })
        .collect();
    println!(
        "scene_1m: {} triangles, {} parts -> {:?} triangles, 2048² textures: {seconds:.2} s \
         (bakes {:.2} s)",
        scene.mesh.triangles.len(),
        scene.parts.len(),
        made.levels
            .iter()
            .map(|l| l.asset.mesh.triangles.len())
            .collect::<Vec<_>>(),
        made.levels.iter().map(|l| l.bake.seconds).sum::<f64>()
    );
    let report = json!({
        "input_triangles": scene.mesh.triangles.len(), "budgets": budgets, "texture": 2048,
        "seconds": seconds, "levels": levels, "warnings": made.warnings,
        "load_average_before": load_before, "load_average_after": load_average(),
        "cores": std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1),
    });
    let file = out.join("proxy-bench-1m.json");
    std::fs::write(file, serde_json::to_string_pretty(&report)?)?;
    Ok(())
}
