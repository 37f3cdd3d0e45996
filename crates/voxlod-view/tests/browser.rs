//! The page in a real browser: headless Chromium drawing WebGL2 through SwiftShader, with
//! screenshots read back. Skips with a printed reason where `/usr/bin/chromium` (Debian's
//! `chromium`, installed by `.ci/run`) is missing, or `VOXLOD_CHROMIUM` names another binary.
//!
//! - an MSFT_lod chain at three distances: the model is drawn (its pixels cover the disc the
//!   sphere projects to), and the level patch shows the level the pixel-size rule gives there,
//!   a different one at each distance;
//! - two layered squares seen from either side of the z = 0 plane: the octant order switches,
//!   so the nearer square is blended last and its colour dominates; and closer than the 0.45 px
//!   filter-radius limit the single surface is drawn opaque;
//! - a unit sphere whose primitive is Draco-compressed, drawn by a node under a GPU instance:
//!   decoded before the page is made, it covers the disc the sphere projects to;
//! - a layered chain (`voxlod layers --lod`) at three distances: the second patch shows the
//!   coarsest level whose filter radius spans at most 0.45 px, and closer than level 0 allows,
//!   the first patch turns black (level 0's single surface).

mod common;

use voxlod_testkit::browser::chromium;

use common::shots::{drawn_pixels, patch, screenshot, shots, FOV, SIZE};
use common::{write_layered_ball_chain, write_sphere_chain, write_two_layers, SPHERE_CELLS};
use image::RgbImage;
use voxlod_gltf::ChainOptions;
use voxlod_view::{write_page, ViewOptions, PATCH_COLORS};

/// The level the page must show: `voxlod select`'s rule for a 400-pixel viewport.
fn expected_level(distance: f64) -> usize {
    let pixel = 2.0 * distance * (FOV / 2.0).tan() / SIZE as f64;
    SPHERE_CELLS.iter().rposition(|&c| c <= pixel).unwrap_or(0)
}

/// The pixels the unit sphere's silhouette covers from `distance`: a disc of radius
/// f·tan(asin(1/d)) pixels.
fn sphere_disc(distance: f64) -> f64 {
    let focal = SIZE as f64 / 2.0 / (FOV / 2.0).tan();
    let radius = focal * (1.0 / distance).asin().tan();
    std::f64::consts::PI * radius * radius
}

#[test]
fn lod_page_draws_the_model_and_switches_levels_with_distance() {
    let Some(browser) = chromium() else {
        return;
    };
    let (_keep, dir) = shots();
    let glb = dir.join("sphere-lod.glb");
    write_sphere_chain(&glb, &ChainOptions::meshopt());
    let page = dir.join("sphere-lod.html");
    write_page(&[glb], &page, &ViewOptions::default()).unwrap();
    let mut seen = Vec::new();
    for distance in [3.0, 7.0, 14.0] {
        let png = dir.join(format!("sphere-lod-{distance}.png"));
        let img = screenshot(&browser, &page, distance, [0.3, 0.4, 1.0], &png);
        let level = expected_level(distance);
        assert_eq!(
            patch(&img),
            PATCH_COLORS[level],
            "distance {distance}: level {level}"
        );
        let disc = sphere_disc(distance);
        let drawn = drawn_pixels(&img) as f64;
        assert!(
            (drawn / disc - 1.0).abs() < 0.12,
            "distance {distance}: {drawn} pixels drawn, the sphere covers {disc:.0}"
        );
        seen.push(level);
    }
    assert_eq!(seen, vec![0, 1, 2], "three distances, three levels");
}

#[test]
fn layered_page_switches_the_order_across_an_octant_boundary() {
    let Some(browser) = chromium() else {
        return;
    };
    let (_keep, dir) = shots();
    let glb = dir.join("two-layers.glb");
    write_two_layers(&glb, 0.002);
    let page = dir.join("two-layers.html");
    write_page(&[glb], &page, &ViewOptions::default()).unwrap();
    let centre = |img: &RgbImage| img.get_pixel(SIZE / 2, SIZE / 2).0.map(i32::from);
    // Blue in front (eye at +z): blue last over red; red in front (eye at −z): the reverse.
    let front_blue = screenshot(
        &browser,
        &page,
        4.0,
        [0.05, 0.05, 1.0],
        &dir.join("two-layers-plus-z.png"),
    );
    let front_red = screenshot(
        &browser,
        &page,
        4.0,
        [0.05, 0.05, -1.0],
        &dir.join("two-layers-minus-z.png"),
    );
    // The octant of the sight (eye to centre): (−, −, −) is index 7, (−, −, +) index 6.
    assert_eq!(patch(&front_blue), PATCH_COLORS[7]);
    assert_eq!(patch(&front_red), PATCH_COLORS[6]);
    // 0.6 of the front colour over 0.4 × (0.6 of the back colour over white), shaded by
    // |n·v| ≈ 1 (0.3 + 0.7·0.9975).
    let shade = 0.3 + 0.7 * (1.0 / (1.0f64 + 2.0 * 0.0025).sqrt());
    let expect = |front: [f64; 3], back: [f64; 3]| -> [i32; 3] {
        std::array::from_fn(|c| {
            let under = 0.6 * back[c] * shade + 0.4;
            (255.0 * (0.6 * front[c] * shade + 0.4 * under)).round() as i32
        })
    };
    let (red, blue) = ([1.0, 0.0, 0.0], [0.0, 0.0, 1.0]);
    for (img, want) in [
        (&front_blue, expect(blue, red)),
        (&front_red, expect(red, blue)),
    ] {
        let got = centre(img);
        assert!(
            got.iter().zip(want).all(|(g, w)| (g - w).abs() <= 6),
            "centre pixel {got:?}, expected {want:?}"
        );
    }
    // Closer than the radius rule allows (0.002 / pixel > 0.45 px): the single surface, opaque.
    let near = screenshot(
        &browser,
        &page,
        1.0,
        [0.05, 0.05, 1.0],
        &dir.join("two-layers-near.png"),
    );
    assert_eq!(patch(&near), [0, 0, 0]);
    let got = centre(&near);
    assert!(
        got[0] > 200 && got[1] < 10 && got[2] < 10,
        "opaque red, got {got:?}"
    );
}

#[test]
fn layered_chain_page_draws_the_level_whose_radius_fits_045_px() {
    let Some(browser) = chromium() else {
        return;
    };
    let (_keep, dir) = shots();
    let glb = dir.join("ball-layered-chain.glb");
    let radii = write_layered_ball_chain(&glb);
    let page = dir.join("ball-layered-chain.html");
    write_page(&[glb], &page, &ViewOptions::default()).unwrap();
    // The distance at which a radius r spans `px` pixels of the 400-pixel-high view.
    let distance = |r: f64, px: f64| r / px * SIZE as f64 / (2.0 * (FOV / 2.0).tan());
    let level_patch = |img: &RgbImage| img.get_pixel(8, 32).0;
    for (d, level, layered) in [
        (distance(radii[1], 0.3), 1, true),  // level 1 fits
        (distance(radii[1], 0.6), 0, true),  // level 1 too wide on screen: level 0 (0.3 px)
        (distance(radii[0], 1.0), 0, false), // even level 0 too wide: its single surface
    ] {
        let png = dir.join(format!("ball-layered-chain-{d:.2}.png"));
        let img = screenshot(&browser, &page, d, [0.3, 0.4, 1.0], &png);
        assert_eq!(
            level_patch(&img),
            PATCH_COLORS[level],
            "distance {d}: level {level}"
        );
        // Layered: the octant patch of the sight (−, −, −); else black.
        let octant = if layered { PATCH_COLORS[7] } else { [0, 0, 0] };
        assert_eq!(patch(&img), octant, "distance {d}");
        assert!(drawn_pixels(&img) > 0, "distance {d}: nothing drawn");
    }
}

/// A unit sphere (icosphere 3) whose one primitive draco-core compressed (positions at 14 bits),
/// drawn by a node through one GPU instance (`EXT_mesh_gpu_instancing`), as a `.glb`.
fn write_draco_instanced_sphere(path: &std::path::Path) {
    use draco_core::{
        DataType, EncoderBuffer, EncoderOptions, GeometryAttributeType, Mesh, MeshEncoder,
        PointAttribute,
    };
    let sphere = voxlod_testkit::shapes::icosphere(3);
    let n = sphere.positions.len();
    let mut mesh = Mesh::new();
    mesh.set_num_points(n);
    let mut position = PointAttribute::new();
    position.init(
        GeometryAttributeType::Position,
        3,
        DataType::Float32,
        false,
        n,
    );
    let floats: Vec<u8> = (sphere.positions.iter())
        .flat_map(|p| p.to_array())
        .flat_map(f32::to_le_bytes)
        .collect();
    position.buffer_mut().write(0, &floats);
    let id = mesh.add_attribute(position);
    mesh.set_num_faces(sphere.triangles.len());
    mesh.set_faces_from_flat_indices(sphere.triangles.as_flattened());
    let mut options = EncoderOptions::new();
    options.set_attribute_quantization(id, 14);
    let unique = mesh.attribute(id).unique_id();
    let mut encoder = MeshEncoder::new();
    encoder.set_mesh(mesh);
    let mut stream = EncoderBuffer::new();
    encoder.encode(&options, &mut stream).unwrap();
    let mut bin = stream.data().to_vec();
    let length = bin.len();
    bin.resize(length.next_multiple_of(4), 0);
    let offset = bin.len();
    bin.extend([0.0f32; 3].iter().flat_map(|x| x.to_le_bytes()));
    let (draco, instancing) = ("KHR_draco_mesh_compression", "EXT_mesh_gpu_instancing");
    let doc = serde_json::json!({
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
        "extensionsUsed": [draco, instancing], "extensionsRequired": [draco, instancing],
        "nodes": [{"mesh": 0, "extensions": {instancing: {"attributes": {"TRANSLATION": 2}}}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1,
            "extensions": {draco: {"bufferView": 0, "attributes": {"POSITION": unique}}}}]}],
        "accessors": [
            {"componentType": 5126, "count": n, "type": "VEC3", "min": [-1, -1, -1], "max": [1, 1, 1]},
            {"componentType": 5125, "count": 3 * sphere.triangles.len(), "type": "SCALAR"},
            {"bufferView": 1, "componentType": 5126, "count": 1, "type": "VEC3"}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": length},
                        {"buffer": 0, "byteOffset": offset, "byteLength": 12}],
        "buffers": [{"byteLength": bin.len()}]
    });
    std::fs::write(path, voxlod_gltf::to_glb(&doc, bin).unwrap()).unwrap();
}

#[test]
fn a_draco_compressed_instanced_sphere_is_drawn_whole() {
    let Some(browser) = chromium() else {
        return;
    };
    let (_keep, dir) = shots();
    let glb = dir.join("sphere-draco.glb");
    write_draco_instanced_sphere(&glb);
    let page = dir.join("sphere-draco.html");
    write_page(&[glb], &page, &ViewOptions::default()).unwrap();
    let distance = 3.0;
    let img = screenshot(
        &browser,
        &page,
        distance,
        [0.3, 0.4, 1.0],
        &dir.join("sphere-draco.png"),
    );
    let disc = sphere_disc(distance);
    let drawn = drawn_pixels(&img) as f64;
    assert!(
        (drawn / disc - 1.0).abs() < 0.12,
        "{drawn} pixels drawn, the sphere covers {disc:.0}"
    );
}
