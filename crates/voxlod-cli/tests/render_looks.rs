//! `voxlod render` of a glTF asset draws it with its looks: a textured square's texels, and
//! plain geometry when the asset is mixed with a mesh.

mod common;

use std::sync::Arc;

use common::{arg, json, stderr, voxlod};
use image::ImageEncoder;
use voxlod::asset::{Asset, AssetMesh, Image, Material, Sampler, TextureRef};
use voxlod::core::glam::{Vec2, Vec3};
use voxlod::gltf::{asset_glb, AssetGlbOptions};

/// A square in the z = 0 plane from (−1, −1) to (1, 1) with a 2 × 2 texture, red and green on
/// top, blue and yellow below, sampled nearest.
fn four_colour_square() -> Asset {
    let texels: [[u8; 3]; 4] = [[255, 0, 0], [0, 255, 0], [0, 0, 255], [255, 255, 0]];
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png)
        .write_image(texels.as_flattened(), 2, 2, image::ExtendedColorType::Rgb8)
        .unwrap();
    let positions = vec![
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(-1.0, 1.0, 0.0),
    ];
    let uv = (positions.iter())
        .map(|p| Vec2::new(0.5 + 0.5 * p.x, 0.5 - 0.5 * p.y))
        .collect();
    Asset {
        mesh: AssetMesh {
            normals: vec![Vec3::Z; 4],
            uv: [uv, Vec::new()],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            material: vec![0, 0],
            positions,
            ..Default::default()
        },
        materials: vec![Material {
            base_color_texture: Some(TextureRef {
                image: 0,
                tex_coord: 0,
                transform: None,
                sampler: Sampler {
                    linear: false,
                    ..Sampler::default()
                },
            }),
            metallic: 0.0,
            ..Material::default()
        }],
        images: vec![Image {
            name: "four".into(),
            mime: "image/png".into(),
            bytes: Arc::new(png),
        }],
        parts: Vec::new(),
    }
}

#[test]
fn render_draws_a_glb_asset_with_its_texture() {
    let dir = tempfile::tempdir().unwrap();
    let glb = dir.path().join("square.glb");
    let bytes = asset_glb(&[four_colour_square()], &AssetGlbOptions::default()).unwrap();
    std::fs::write(&glb, bytes).unwrap();
    let png = dir.path().join("square.png");
    let o = voxlod(&[
        "render",
        arg(&glb),
        "-o",
        arg(&png),
        "--view",
        "0,0,-1",
        "--size",
        "64x64",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report = json(&o);
    assert_eq!(report["looks"], true);
    assert_eq!(report["opaque_triangles"], 2);
    let picture = image::open(&png).unwrap().to_rgb8();
    // The square fills the middle of the view; each quadrant shows its texel, lit by the
    // headlight (dimmer than the texel, the same hue).
    let hue = |x: u32, y: u32| {
        let p = picture.get_pixel(x, y).0;
        p.map(|c| c > 100)
    };
    assert_eq!(hue(26, 26), [true, false, false], "top left: red");
    assert_eq!(hue(38, 26), [false, true, false], "top right: green");
    assert_eq!(hue(26, 38), [false, false, true], "bottom left: blue");
    assert_eq!(hue(38, 38), [true, true, false], "bottom right: yellow");

    // Mixed with a plain mesh, the asset is drawn as geometry, with a warning.
    let ply = dir.path().join("tri.ply");
    std::fs::write(
        &ply,
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
         property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\
         3 3 0\n4 3 0\n3 4 0\n3 0 1 2\n",
    )
    .unwrap();
    let o = voxlod(&["render", arg(&glb), arg(&ply), "-o", arg(&png), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report = json(&o);
    assert_eq!(report["looks"], false);
    assert!(report["warnings"][0]
        .as_str()
        .unwrap()
        .contains("drawn without their looks"));
}
