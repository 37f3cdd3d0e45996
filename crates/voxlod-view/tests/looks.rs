//! The page draws levels with their looks, in headless Chromium (skips with a printed reason
//! where no browser is installed, as `browser.rs` does):
//! - the two-halves textured sphere (`voxlod_testkit::assets::textured_sphere`, red where
//!   x < 0, blue where x > 0) seen from +z: red left of centre, blue right of it, plain and
//!   meshopt-compressed over quantized texture coordinates; the same in the emissive slot of a
//!   black material;
//! - the same image as a data URI under `KHR_texture_transform`: mirrored (the halves swap),
//!   turned a quarter (red below, blue above), and scaled by −1 (repeated: swapped; clamped:
//!   red everywhere, the sampler's wrap);
//! - a level coloured per vertex (green where x < 0, magenta where x > 0) through `COLOR_0`,
//!   float and quantized;
//! - alpha: a base colour of alpha 0.3 under `MASK` with cutoff 0.5 draws nothing, under
//!   `BLEND` a colour between the surface's and the white background, once where the material
//!   is single-sided (its back culled), twice where it is double-sided;
//! - the `LOD0, LOD1, …` node layout switches levels by screen coverage exactly as the same
//!   levels in an `MSFT_lod` chain do, at the distances the coverage rule predicts;
//! - a normal map tilting a square's normal up or down brightens or darkens it as seen from
//!   above, by the head light's analytic shade, with `TANGENT` and without.

mod common;

use std::path::Path;

use base64::Engine;
use common::edit_glb;
use common::shots::{drawn_pixels, mean_around, patch, screenshot, shots, FOV, SIZE};
use serde_json::json;
use voxlod_asset::{AlphaMode, Asset, AssetMesh, Material};
use voxlod_gltf::{asset_glb, AssetGlbOptions, Layout};
use voxlod_testkit::assets::{textured_sphere, two_halves_png};
use voxlod_testkit::browser::chromium;
use voxlod_view::{write_page, ViewOptions, PATCH_COLORS};

/// The screen column of a point at `x` on the plane z = `z` seen from `distance` along +z
/// (the camera's right is +x there).
fn column(x: f64, z: f64, distance: f64) -> u32 {
    let focal = SIZE as f64 / 2.0 / (FOV / 2.0).tan();
    (SIZE as f64 / 2.0 + focal * x / (distance - z)).round() as u32
}

/// The mean colours a half-way left (x = −0.5) and right (x = +0.5) on the unit sphere's
/// front, seen from +z at distance 3.
fn left_and_right(img: &image::RgbImage) -> ([f64; 3], [f64; 3]) {
    let z = 0.75f64.sqrt();
    let row = SIZE / 2;
    (
        mean_around(img, column(-0.5, z, 3.0), row),
        mean_around(img, column(0.5, z, 3.0), row),
    )
}

fn is_red(c: [f64; 3]) -> bool {
    c[0] > 180.0 && c[1] < 60.0 && c[2] < 60.0
}

fn is_blue(c: [f64; 3]) -> bool {
    c[2] > 180.0 && c[0] < 60.0 && c[1] < 60.0
}

/// Writes `levels` as a `.glb` and a page showing it; returns the page.
fn page_of(
    dir: &Path,
    name: &str,
    levels: &[Asset],
    options: &AssetGlbOptions,
) -> std::path::PathBuf {
    let glb = dir.join(format!("{name}.glb"));
    std::fs::write(&glb, asset_glb(levels, options).unwrap()).unwrap();
    let page = dir.join(format!("{name}.html"));
    write_page(&[glb], &page, &ViewOptions::default()).unwrap();
    page
}

/// The colours left and right of centre ([`left_and_right`]) of page `name` showing `levels`,
/// seen from +z at distance 3.
fn halves_seen(
    browser: &Path,
    dir: &Path,
    name: &str,
    levels: &[Asset],
    options: &AssetGlbOptions,
) -> ([f64; 3], [f64; 3]) {
    let page = page_of(dir, name, levels, options);
    let png = dir.join(format!("{name}.png"));
    left_and_right(&screenshot(browser, &page, 3.0, [0.0, 0.0, 1.0], &png))
}

/// The two-halves sphere black, its halves in the emissive slot (factor 1): red and blue at
/// full strength whatever the shade.
fn glowing_sphere() -> Asset {
    let mut sphere = textured_sphere(4);
    let m = &mut sphere.materials[0];
    m.emissive_texture = m.base_color_texture.take();
    m.emissive = [1.0; 3];
    m.base_color = [0.0, 0.0, 0.0, 1.0];
    sphere
}

fn is_green(c: [f64; 3]) -> bool {
    c[1] > 180.0 && c[0] < 60.0 && c[2] < 60.0
}

fn is_magenta(c: [f64; 3]) -> bool {
    c[0] > 180.0 && c[2] > 180.0 && c[1] < 60.0
}

#[test]
fn textures_and_vertex_colours_show_plain_and_compressed() {
    let Some(browser) = chromium() else {
        return;
    };
    let (_keep, dir) = shots();
    type Test = fn([f64; 3]) -> bool;
    let cases: [(&str, Asset, Test, Test); 3] = [
        ("halves", textured_sphere(4), is_red, is_blue),
        ("glowing", glowing_sphere(), is_red, is_blue),
        (
            "coloured",
            coloured_sphere(1.0, AlphaMode::Opaque),
            is_green,
            is_magenta,
        ),
    ];
    for (what, sphere, left_test, right_test) in cases {
        for (packing, options) in [
            ("plain", AssetGlbOptions::default()),
            ("meshopt", AssetGlbOptions::meshopt()),
        ] {
            let name = format!("{what}-{packing}");
            let level = std::slice::from_ref(&sphere);
            let (left, right) = halves_seen(&browser, &dir, &name, level, &options);
            assert!(left_test(left), "{name}: left of centre {left:?}");
            assert!(right_test(right), "{name}: right of centre {right:?}");
        }
    }
}

/// The mean colours a half-way down (y = −0.5) and up (y = +0.5) on the unit sphere's front,
/// seen from +z at distance 3.
fn below_and_above(img: &image::RgbImage) -> ([f64; 3], [f64; 3]) {
    let z = 0.75f64.sqrt();
    let col = SIZE / 2;
    // Rows grow downwards: y = −0.5 is the column of x = +0.5 mirrored.
    (
        mean_around(img, col, column(0.5, z, 3.0)),
        mean_around(img, col, column(-0.5, z, 3.0)),
    )
}

#[test]
fn texture_transforms_and_samplers_apply_to_a_data_uri_image() {
    let Some(browser) = chromium() else {
        return;
    };
    let (_keep, dir) = shots();
    let plain = asset_glb(&[textured_sphere(4)], &AssetGlbOptions::default()).unwrap();
    let uri = format!(
        "data:image/png;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(two_halves_png())
    );
    let (clamp, repeat) = (33071, 10497);
    let half_turn = std::f64::consts::FRAC_PI_2;
    // (name, transform, wrap along u, test of left, right, below, above). The texture's u is
    // (x + 1) / 2, v is (y + 1) / 2; texel 0 (u < 0.5) red, texel 1 blue.
    type Test = fn([f64; 3]) -> bool;
    let any: Test = |_| true;
    let cases: [(&str, serde_json::Value, u32, [Test; 4]); 4] = [
        // u' = 1 − u: the halves swap.
        (
            "mirrored",
            json!({"offset": [1.0, 0.0], "scale": [-1.0, 1.0]}),
            clamp,
            [is_blue, is_red, any, any],
        ),
        // u' = v: red below, blue above.
        (
            "rotated",
            json!({"rotation": half_turn}),
            clamp,
            [any, any, is_red, is_blue],
        ),
        // u' = −u: repeated, 1 − u (swapped); clamped, 0 everywhere (red).
        (
            "repeated",
            json!({"scale": [-1.0, 1.0]}),
            repeat,
            [is_blue, is_red, any, any],
        ),
        (
            "clamped",
            json!({"scale": [-1.0, 1.0]}),
            clamp,
            [is_red, is_red, any, any],
        ),
    ];
    for (name, transform, wrap, tests) in cases {
        let edited = edit_glb(&plain, |doc| {
            doc["images"][0] = json!({"uri": uri});
            doc["samplers"][0]["wrapS"] = json!(wrap);
            doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"] =
                json!({"KHR_texture_transform": transform});
            doc["extensionsUsed"] = json!(["KHR_texture_transform"]);
            doc["extensionsRequired"] = json!(["KHR_texture_transform"]);
        });
        let glb = dir.join(format!("halves-{name}.glb"));
        std::fs::write(&glb, edited).unwrap();
        let page = dir.join(format!("halves-{name}.html"));
        write_page(&[glb], &page, &ViewOptions::default()).unwrap();
        let png = dir.join(format!("halves-{name}.png"));
        let img = screenshot(&browser, &page, 3.0, [0.0, 0.0, 1.0], &png);
        let (left, right) = left_and_right(&img);
        let (below, above) = below_and_above(&img);
        let seen = [
            ("left", left),
            ("right", right),
            ("below", below),
            ("above", above),
        ];
        for ((what, colour), test) in seen.into_iter().zip(tests) {
            assert!(test(colour), "{name}: {what} of centre {colour:?}");
        }
    }
}

/// The unit icosphere coloured per vertex: linear green where x < 0, magenta where x > 0 (a
/// band across x = 0 between), under one white material with `alpha`.
fn coloured_sphere(alpha: f32, mode: AlphaMode) -> Asset {
    let s = voxlod_testkit::shapes::icosphere(4);
    let n = s.triangles.len();
    let colors = s
        .positions
        .iter()
        .map(|p| {
            let t = (p.x * 4.0 + 0.5).clamp(0.0, 1.0);
            glam::Vec4::new(t, 1.0 - t, t, 1.0)
        })
        .collect();
    Asset {
        mesh: AssetMesh {
            normals: s.positions.iter().map(|p| p.normalize()).collect(),
            positions: s.positions,
            triangles: s.triangles,
            colors,
            material: vec![0; n],
            ..AssetMesh::default()
        },
        materials: vec![Material {
            base_color: [1.0, 1.0, 1.0, alpha],
            alpha_mode: mode,
            metallic: 0.0,
            ..Material::default()
        }],
        ..Asset::default()
    }
}

#[test]
fn alpha_mask_cuts_and_blend_mixes_with_the_background() {
    let Some(browser) = chromium() else {
        return;
    };
    let (_keep, dir) = shots();
    let options = AssetGlbOptions::default();
    let masked = page_of(
        &dir,
        "masked",
        &[coloured_sphere(0.3, AlphaMode::Mask)],
        &options,
    );
    let img = screenshot(
        &browser,
        &masked,
        3.0,
        [0.0, 0.0, 1.0],
        &dir.join("masked.png"),
    );
    assert_eq!(
        drawn_pixels(&img),
        0,
        "alpha 0.3 under a 0.5 cutoff draws nothing"
    );
    // Green at alpha 0.3 over white leaves 0.7 of the white in red and blue (178 of 255) where
    // the single-sided sphere's back is culled, 0.49 (125) where it is double-sided and drawn
    // twice (front and back); the opaque sphere leaves none.
    for (double_sided, want) in [(false, 178.0), (true, 125.0)] {
        let mut sphere = coloured_sphere(0.3, AlphaMode::Blend);
        sphere.materials[0].double_sided = double_sided;
        let name = format!("blended-{double_sided}");
        let (left, _) = halves_seen(&browser, &dir, &name, &[sphere], &options);
        let near = |v: f64| (v - want).abs() < 25.0;
        assert!(
            near(left[0]) && near(left[2]) && left[1] > 200.0,
            "double-sided {double_sided}: left {left:?}, expected about ({want}, 250, {want})"
        );
    }
}

/// The level the page shows at `distance` for levels of `triangles` (finest first) with the
/// writer's default coverages (half the square root of the next level's share), in a
/// 400-pixel-high view whose coverages are for a 1080-pixel one.
fn expected_level(triangles: &[usize], diameter: f64, distance: f64) -> usize {
    let coverage = diameter / (2.0 * distance * (FOV / 2.0).tan()) * SIZE as f64 / 1080.0;
    let n = triangles.len();
    (0..n)
        .find(|&k| {
            let threshold = if k + 1 == n {
                0.0
            } else {
                0.5 * (triangles[k + 1] as f64 / triangles[0] as f64).sqrt()
            };
            coverage > threshold
        })
        .unwrap_or(n - 1)
}

#[test]
fn lod_nodes_switch_levels_as_the_msft_lod_chain_does() {
    let Some(browser) = chromium() else {
        return;
    };
    let (_keep, dir) = shots();
    let levels: Vec<Asset> = [4, 2, 1].map(textured_sphere).to_vec();
    let triangles: Vec<usize> = levels.iter().map(|l| l.mesh.triangles.len()).collect();
    let (lo, hi) = levels[0]
        .mesh
        .positions
        .iter()
        .fold((glam::Vec3::MAX, glam::Vec3::MIN), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    let diameter = (hi - lo).length() as f64;
    let mut seen = Vec::new();
    for distance in [6.0, 18.0, 40.0] {
        let level = expected_level(&triangles, diameter, distance);
        for layout in [Layout::LodNodes, Layout::MsftLod] {
            let name = format!("halves-{layout:?}");
            let options = AssetGlbOptions {
                layout,
                ..AssetGlbOptions::default()
            };
            let page = page_of(&dir, &name, &levels, &options);
            let png = dir.join(format!("{name}-{distance}.png"));
            let img = screenshot(&browser, &page, distance, [0.0, 0.0, 1.0], &png);
            assert_eq!(
                patch(&img),
                PATCH_COLORS[level],
                "{layout:?} at distance {distance}: level {level}"
            );
            let row = SIZE / 2;
            let (left, right) = (
                mean_around(&img, column(-0.4, 0.9, distance), row),
                mean_around(&img, column(0.4, 0.9, distance), row),
            );
            assert!(
                left[0] > left[2] + 100.0,
                "{layout:?} {distance}: left {left:?}"
            );
            assert!(
                right[2] > right[0] + 100.0,
                "{layout:?} {distance}: right {right:?}"
            );
        }
        seen.push(level);
    }
    assert_eq!(seen, vec![0, 1, 2], "three distances, three levels");
}

/// A 2 × 2 white square in the plane z = 0 facing +z, texture coordinates u along +x and v down
/// the image as y rises (glTF's image-down v), with a normal map of one texel: the normal tilted
/// by 40° towards +y (`up`) or −y; with `TANGENT` (+x, w = +1: bitangent cross(N, T) = +y) or
/// without.
fn normal_mapped_square(up: bool, tangents: bool) -> Asset {
    let corners = [(-1.0f32, -1.0f32), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
    let tilt = 40f64.to_radians();
    let y = if up { tilt.sin() } else { -tilt.sin() };
    let texel = [0.0, y, tilt.cos()].map(|c| ((c + 1.0) / 2.0 * 255.0).round() as u8);
    let img = image::RgbaImage::from_pixel(1, 1, image::Rgba([texel[0], texel[1], texel[2], 255]));
    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    Asset {
        mesh: AssetMesh {
            positions: corners.map(|(x, y)| glam::Vec3::new(x, y, 0.0)).to_vec(),
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            normals: vec![glam::Vec3::Z; 4],
            tangents: if tangents {
                vec![glam::Vec4::new(1.0, 0.0, 0.0, 1.0); 4]
            } else {
                Vec::new()
            },
            uv: [
                corners
                    .map(|(x, y)| glam::Vec2::new((x + 1.0) / 2.0, (1.0 - y) / 2.0))
                    .to_vec(),
                Vec::new(),
            ],
            material: vec![0; 2],
            ..AssetMesh::default()
        },
        materials: vec![Material {
            metallic: 0.0,
            double_sided: true,
            normal_texture: Some(voxlod_asset::TextureRef {
                image: 0,
                tex_coord: 0,
                transform: None,
                sampler: voxlod_asset::Sampler::default(),
            }),
            ..Material::default()
        }],
        images: vec![voxlod_asset::Image {
            name: "tilt.png".into(),
            mime: "image/png".into(),
            bytes: std::sync::Arc::new(png),
        }],
        parts: Vec::new(),
    }
}

/// Seen from above the square (eye along (0, 1, 0.6)), a normal tilted 40° up faces the eye
/// more than the plain one (shade 0.3 + 0.7·|n·v|: 0.96 against 0.66; sRGB 250 against 212),
/// one tilted down less (0.41; 171); through `TANGENT` and through screen-space derivatives
/// alike.
#[test]
fn a_normal_map_tilts_the_shading_the_way_gltf_orients_it() {
    let Some(browser) = chromium() else {
        return;
    };
    let (_keep, dir) = shots();
    let eye = [0.0, 1.0, 0.6];
    let mut plain = normal_mapped_square(true, true);
    plain.materials[0].normal_texture = None;
    let options = AssetGlbOptions::default();
    let shade_of = |name: &str, square: Asset| -> f64 {
        let page = page_of(&dir, name, &[square], &options);
        let img = screenshot(&browser, &page, 3.0, eye, &dir.join(format!("{name}.png")));
        mean_around(&img, SIZE / 2, SIZE / 2)[0]
    };
    let flat = shade_of("square-plain", plain);
    assert!((flat - 212.0).abs() < 6.0, "plain square: {flat}");
    for tangents in [true, false] {
        let up = shade_of(
            &format!("square-up-{tangents}"),
            normal_mapped_square(true, tangents),
        );
        let down = shade_of(
            &format!("square-down-{tangents}"),
            normal_mapped_square(false, tangents),
        );
        assert!(
            (up - 250.0).abs() < 6.0,
            "tangents {tangents}: tilted up {up}, plain {flat}"
        );
        assert!(
            (down - 171.0).abs() < 6.0,
            "tangents {tangents}: tilted down {down}, plain {flat}"
        );
    }
}
