//! `voxlod proxy`: a scene of three parts with three materials (two spheres passing through
//! each other, a third apart) becomes one `.glb` with one mesh, one material and one texture
//! set per level, in both layouts; the Khronos validator accepts it, our reader reads it back
//! textured, and the report gives per level the draw calls, the bake and the appearance. An
//! output that is not `.glb`, a budget under 4, a texture side of 0, gap widths, angles,
//! densities and JPEG qualities out of range are usage errors (exit 2) naming the flag; a
//! missing input is an I/O error (exit 4) naming the file. `--texel-density` sizes the texture
//! by the level's area, `--screen-size` by the pixels each level is drawn across; `--images
//! jpeg` writes JPEG colour maps that validate. A folder of meshes is one scene, what is not a
//! mesh in it left out with a warning; a folder without meshes is bad input (exit 1).

mod common;

use std::path::{Path, PathBuf};

use common::{arg, json, stderr, voxlod};
use voxlod::gltf::{asset_glb, read_scene, AssetGlbOptions};

/// The three-part scene written as `dir/scene.glb`.
fn scene_glb(dir: &Path) -> PathBuf {
    let path = dir.join("scene.glb");
    let scene = voxlod_testkit::assets::three_part_scene();
    std::fs::write(
        &path,
        asset_glb(&[scene], &AssetGlbOptions::default()).unwrap(),
    )
    .unwrap();
    path
}

#[test]
fn a_scene_proxy_is_one_draw_call_per_level_and_validates() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_glb(dir.path());
    for layout in ["msft-lod", "lod-nodes"] {
        let out = dir.path().join(format!("proxy-{layout}.glb"));
        let o = voxlod(&[
            "proxy",
            arg(&scene),
            "-o",
            arg(&out),
            "--triangles",
            "1500,400",
            "--texture",
            "256",
            "--layout",
            layout,
            "--json",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let report = json(&o);
        assert_eq!(report["input_draw_calls"], 3);
        // Every part shows from outside.
        assert_eq!(report["hidden_parts"], 0);
        assert_eq!(report["layout"], layout);
        let levels = report["levels"].as_array().unwrap();
        assert_eq!(levels.len(), 2);
        for (level, budget) in levels.iter().zip([1500.0, 400.0]) {
            assert_eq!(level["draw_calls"], 1);
            let n = level["triangles"].as_f64().unwrap();
            assert!((n / budget - 1.0).abs() <= 0.1, "{level}");
            assert_eq!(level["bake"]["width"], 256);
            assert!(level["bake"]["charts"].as_u64().unwrap() >= 1);
            assert!(level["psnr"].as_f64().unwrap() > 15.0, "{level}");
        }
        // Read back whole: one textured material per level.
        let back = read_scene(&out).unwrap().asset;
        assert_eq!(back.materials.len(), 2);
        assert!(back
            .materials
            .iter()
            .all(|m| m.base_color_texture.is_some()));
        assert!(!back.mesh.uv[0].is_empty());
        assert_validates(&out);
    }
}

#[test]
fn proxy_refuses_other_outputs_and_tiny_budgets_naming_the_flag() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_glb(dir.path());
    let obj = dir.path().join("proxy.obj");
    let o = voxlod(&["proxy", arg(&scene), "-o", arg(&obj), "--triangles", "500"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("-o"), "{}", stderr(&o));
    assert!(!obj.exists());
    let glb = dir.path().join("proxy.glb");
    let o = voxlod(&["proxy", arg(&scene), "-o", arg(&glb), "--triangles", "3"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("triangles"), "{}", stderr(&o));
    let o = proxy_500(&scene, &glb, &["--texture", "0"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--texture"), "{}", stderr(&o));
    let missing = dir.path().join("missing.glb");
    let o = voxlod(&[
        "proxy",
        arg(&missing),
        "-o",
        arg(&glb),
        "--triangles",
        "500",
    ]);
    assert_eq!(o.status.code(), Some(4), "{}", stderr(&o));
    assert!(stderr(&o).contains("missing.glb"), "{}", stderr(&o));
    assert!(!glb.exists());
}

#[test]
fn proxy_refuses_bad_gap_angle_and_density_values_naming_the_flag() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_glb(dir.path());
    let glb = dir.path().join("proxy.glb");
    for (flag, value) in [
        ("--close-gaps", "-1"),
        ("--close-gaps", "nan"),
        ("--hard-edges", "200"),
        ("--texel-density", "0"),
    ] {
        let o = proxy_500(&scene, &glb, &[flag, value]);
        assert_eq!(o.status.code(), Some(2), "{flag} {value}: {}", stderr(&o));
        assert!(stderr(&o).contains(flag), "{}", stderr(&o));
        assert!(!glb.exists());
    }
    // A density and a size together are a contradiction clap names.
    let both = ["--texture", "512", "--texel-density", "40"];
    assert_eq!(proxy_500(&scene, &glb, &both).status.code(), Some(2));
}

/// `voxlod proxy SCENE -o OUT --triangles 500` with `extra` flags.
fn proxy_500(scene: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    proxy_to(scene, out, "500", extra)
}

/// `voxlod proxy SCENE -o OUT --triangles TRIANGLES` with `extra` flags.
fn proxy_to(scene: &Path, out: &Path, triangles: &str, extra: &[&str]) -> std::process::Output {
    let args = [
        "proxy",
        arg(scene),
        "-o",
        arg(out),
        "--triangles",
        triangles,
    ];
    voxlod(&[&args[..], extra].concat())
}

#[test]
fn proxy_texel_density_sizes_the_texture_by_the_level_area() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_glb(dir.path());
    let side = |density: &str| {
        let out = dir.path().join(format!("proxy-{density}.glb"));
        let o = voxlod(&[
            "proxy",
            arg(&scene),
            "-o",
            arg(&out),
            "--triangles",
            "400",
            "--texel-density",
            density,
            "--no-appearance",
            "--json",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        json(&o)["levels"][0]["bake"]["width"].as_u64().unwrap()
    };
    // Twice the density, about twice the side (the charts' packing varies a little).
    let (low, high) = (side("40"), side("80"));
    let ratio = high as f64 / low as f64;
    assert!((1.6..=2.5).contains(&ratio), "{low} -> {high}");
}

#[test]
fn proxy_screen_size_gives_each_level_a_texel_per_pixel() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_glb(dir.path());
    let out = dir.path().join("proxy.glb");
    let sizes = ["--screen-size", "400,100", "--no-appearance", "--json"];
    let o = proxy_to(&scene, &out, "600,300", &sizes);
    assert!(o.status.success(), "{}", stderr(&o));
    let report = json(&o);
    let level = |i: usize| &report["levels"][i];
    assert_eq!(level(0)["screen_size"], 400);
    assert_eq!(level(1)["screen_size"], 100);
    // A quarter of the pixels across, a quarter of the texels a side (the two levels' areas
    // are close; the charts' packing varies a little).
    let side = |i: usize| level(i)["bake"]["width"].as_u64().unwrap() as f64;
    let ratio = side(0) / side(1);
    assert!((3.0..=5.3).contains(&ratio), "{} -> {}", side(0), side(1));
    // The scene's box has a diagonal of about 4.9 and its spheres about 18 square units:
    // 400 pixels ask for about 80 texels a unit, about 500 a side.
    assert!((200.0..=900.0).contains(&side(0)), "{}", side(0));
    // One size per budget, none of 0 pixels, and not beside a fixed size.
    for extra in [
        &["--screen-size", "400,100"][..],
        &["--screen-size", "0"],
        &["--screen-size", "400", "--texture", "512"],
    ] {
        let o = proxy_500(&scene, &out.with_extension("x.glb"), extra);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {}", stderr(&o));
        assert!(stderr(&o).contains("--screen-size"), "{}", stderr(&o));
    }
}

/// The three-part scene with photograph-like textures instead of its checkers, written as
/// `dir/grainy.glb`: 256² smooth colour ramps with a grain of ±16 levels, sampled linearly.
/// Flat colours and checkers are smaller as PNG; textures with grain, as scanned and painted
/// ones have, are where JPEG is smaller.
fn grainy_scene_glb(dir: &Path) -> PathBuf {
    let mut scene = voxlod_testkit::assets::three_part_scene();
    let grain = |x: u32, y: u32, k: u32| {
        let h =
            (x.wrapping_mul(73_856_093) ^ y.wrapping_mul(19_349_663) ^ k.wrapping_mul(83_492_791))
                .wrapping_mul(2_654_435_761);
        (h >> 24) as i32 / 8 - 16
    };
    for (i, image) in scene.images.iter_mut().enumerate() {
        let texels = image::RgbImage::from_fn(256, 256, |x, y| {
            let ramp = [x as i32 / 2 + 40, y as i32 / 2 + 40, 200 - 80 * i as i32];
            image::Rgb([0, 1, 2].map(|k| (ramp[k] + grain(x, y, k as u32)).clamp(0, 255) as u8))
        });
        let mut bytes = Vec::new();
        texels
            .write_to(
                &mut std::io::Cursor::new(&mut bytes),
                image::ImageFormat::Png,
            )
            .unwrap();
        image.bytes = std::sync::Arc::new(bytes);
    }
    for material in &mut scene.materials {
        if let Some(t) = material.base_color_texture.as_mut() {
            t.sampler.linear = true;
        }
    }
    let path = dir.join("grainy.glb");
    let glb = asset_glb(&[scene], &AssetGlbOptions::default()).unwrap();
    std::fs::write(&path, glb).unwrap();
    path
}

#[test]
fn proxy_images_jpeg_writes_smaller_jpeg_textures_that_validate() {
    let dir = tempfile::tempdir().unwrap();
    let scene = grainy_scene_glb(dir.path());
    let write = |images: &str| {
        let out = dir.path().join(format!("proxy-{images}.glb"));
        let flags = ["--images", images, "--no-appearance", "--json"];
        let o = proxy_500(&scene, &out, &flags);
        assert!(o.status.success(), "{}", stderr(&o));
        assert_eq!(
            json(&o)["bytes"].as_u64(),
            Some(out.metadata().unwrap().len())
        );
        out
    };
    let (png, jpeg) = (write("png"), write("jpeg"));
    let back = read_scene(&jpeg).unwrap().asset;
    let material = &back.materials[0];
    let texture = |t: &Option<voxlod::asset::TextureRef>| &back.images[t.as_ref().unwrap().image];
    let base = texture(&material.base_color_texture);
    assert_eq!(base.mime, "image/jpeg");
    assert!(base.bytes.starts_with(&[0xFF, 0xD8, 0xFF]));
    assert_eq!(texture(&material.normal_texture).mime, "image/png");
    assert!(!back.mesh.uv[0].is_empty());
    let png_back = read_scene(&png).unwrap().asset;
    assert!(png_back.images.iter().all(|i| i.mime == "image/png"));
    let (png_bytes, jpeg_bytes) = (
        png.metadata().unwrap().len(),
        jpeg.metadata().unwrap().len(),
    );
    assert!(
        jpeg_bytes < png_bytes,
        "JPEG {jpeg_bytes} B, PNG {png_bytes} B"
    );
    assert_validates(&jpeg);
}

#[test]
fn proxy_refuses_a_jpeg_quality_out_of_range_or_without_jpeg_images() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_glb(dir.path());
    let glb = dir.path().join("proxy.glb");
    for extra in [
        &["--images", "jpeg", "--jpeg-quality", "0"][..],
        &["--images", "jpeg", "--jpeg-quality", "101"],
        &["--jpeg-quality", "0"],
    ] {
        let o = proxy_500(&scene, &glb, extra);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {}", stderr(&o));
        assert!(stderr(&o).contains("--jpeg-quality"), "{}", stderr(&o));
        assert!(stderr(&o).contains("1 to 100"), "{}", stderr(&o));
        assert!(!glb.exists());
    }
    // A quality that would be ignored names both flags.
    let o = proxy_500(&scene, &glb, &["--jpeg-quality", "80"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    for flag in ["--jpeg-quality", "--images jpeg"] {
        assert!(stderr(&o).contains(flag), "{}", stderr(&o));
    }
    assert!(!glb.exists());
    let o = proxy_500(&scene, &glb, &["--images", "webp"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--images"), "{}", stderr(&o));
}

/// `--opacity-rays` beyond 256 is a usage error naming the flag; on a scene with no material
/// that masks or blends, it does not apply, and the report says so.
#[test]
fn proxy_opacity_rays_out_of_range_or_not_applying_is_said() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_glb(dir.path());
    let glb = dir.path().join("proxy.glb");
    let o = proxy_500(&scene, &glb, &["--opacity-rays", "300"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--opacity-rays 300"), "{}", stderr(&o));
    assert!(!glb.exists());
    let extra = [
        "--opacity-rays",
        "8",
        "--texture",
        "64",
        "--no-appearance",
        "--json",
    ];
    let o = proxy_500(&scene, &glb, &extra);
    assert!(o.status.success(), "{}", stderr(&o));
    let warnings = json(&o)["warnings"].to_string();
    assert!(
        warnings.contains("--opacity-rays 8 does not apply"),
        "{warnings}"
    );
}

/// The Khronos validator finds no error in `path` (skipped where it is not installed).
fn assert_validates(path: &Path) {
    if let Some(v) = voxlod_testkit::gltf_validator::validate_gltf(path) {
        assert_eq!(v.errors, 0, "{}", v.report);
    }
}

/// The box of a scene read back, in world coordinates (its origin added).
fn world_box(path: &Path) -> (voxlod::core::glam::DVec3, voxlod::core::glam::DVec3) {
    let read = read_scene(path).unwrap();
    let points = read.asset.mesh.positions.iter();
    let world = points.map(|p| p.as_dvec3() + read.origin);
    let inf = voxlod::core::glam::DVec3::splat(f64::INFINITY);
    world.fold((inf, -inf), |(lo, hi), p| (lo.min(p), hi.max(p)))
}

#[test]
fn a_scene_at_map_coordinates_gets_the_proxy_it_gets_at_the_origin_placed_where_it_is() {
    use voxlod::core::glam::DVec3;
    let dir = tempfile::tempdir().unwrap();
    let far = DVec3::new(4_000_000.3, 5_500_000.7, 250.1);
    let mut boxes = Vec::new();
    for (name, origin) in [("near", DVec3::ZERO), ("far", far)] {
        let scene = dir.path().join(format!("{name}.glb"));
        let options = AssetGlbOptions {
            origin,
            ..AssetGlbOptions::default()
        };
        let asset = voxlod_testkit::assets::three_part_scene();
        std::fs::write(&scene, asset_glb(&[asset], &options).unwrap()).unwrap();
        let out = dir.path().join(format!("{name}-proxy.glb"));
        let o = proxy_to(&scene, &out, "400", &["--no-appearance", "--json"]);
        assert!(o.status.success(), "{}", stderr(&o));
        let report = json(&o);
        match name {
            "near" => assert!(report.get("origin").is_none(), "{report}"),
            _ => {
                let o: Vec<f64> = (report["origin"].as_array().unwrap().iter())
                    .map(|x| x.as_f64().unwrap())
                    .collect();
                // Near the scene's centre (the scene spans a few units about `far`).
                assert!((DVec3::from_slice(&o) - far).length() < 8.0, "{o:?}");
            }
        }
        // Two pieces: the spheres passing through each other, and the third apart.
        let back = read_scene(&out).unwrap();
        let mut welded = back.asset.mesh.geometry();
        voxlod::core::weld::weld_vertices(&mut welded);
        let t = voxlod::core::mesh_topology(&welded);
        assert_eq!(t.components, 2, "{name}: {t:?}");
        assert!(t.is_closed_manifold(), "{name}: {t:?}");
        let (lo, hi) = world_box(&out);
        boxes.push((lo - origin, hi - origin));
    }
    // The same place relative to the scene, within a voxel of the 400-triangle level (the
    // sampling grid sits on each input's own box).
    let ((a_lo, a_hi), (b_lo, b_hi)) = (boxes[0], boxes[1]);
    let size = (a_hi - a_lo).length();
    assert!(
        (a_lo - b_lo).length() < 0.05 * size,
        "{a_lo} against {b_lo}"
    );
    assert!(
        (a_hi - b_hi).length() < 0.05 * size,
        "{a_hi} against {b_hi}"
    );
}

#[test]
fn a_folder_of_meshes_is_one_scene() {
    // Two spheres apart, one red through its material library, and a note that is no mesh.
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().join("props");
    std::fs::create_dir(&folder).unwrap();
    let at = |x: f32| voxlod_testkit::shapes::icosphere_at(3, 1.0, voxlod::core::glam::Vec3::X * x);
    voxlod::write_mesh(folder.join("a.obj"), &at(0.0)).unwrap();
    voxlod::write_mesh(folder.join("b.obj"), &at(3.0)).unwrap();
    let b = std::fs::read_to_string(folder.join("b.obj")).unwrap();
    std::fs::write(
        folder.join("b.obj"),
        format!("mtllib b.mtl\nusemtl red\n{b}"),
    )
    .unwrap();
    std::fs::write(folder.join("b.mtl"), "newmtl red\nKd 1 0 0\n").unwrap();
    std::fs::write(folder.join("notes.txt"), "not a mesh").unwrap();

    let out = dir.path().join("props.glb");
    let o = proxy_to(&folder, &out, "400", &["--texture", "128", "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report = json(&o);
    assert_eq!(report["input_draw_calls"], 2);
    let warnings = report["warnings"].to_string();
    assert!(warnings.contains("notes.txt"), "{warnings}");
    assert!(!warnings.contains("b.mtl"), "{warnings}");
    let level = &report["levels"][0];
    assert_eq!(level["draw_calls"], 1);
    assert!((level["triangles"].as_f64().unwrap() / 400.0 - 1.0).abs() <= 0.1);
    // Both spheres are in the proxy.
    let back = read_scene(&out).unwrap().asset;
    let xs = back.mesh.positions.iter().map(|p| p.x);
    let (lo, hi) = xs.fold((f32::MAX, f32::MIN), |(lo, hi), x| (lo.min(x), hi.max(x)));
    assert!(lo < -0.8 && hi > 3.8, "{lo} {hi}");

    // A folder without meshes is bad input naming it.
    let empty = dir.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    let o = proxy_to(&empty, &out, "400", &[]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("holds no mesh"), "{}", stderr(&o));
}
