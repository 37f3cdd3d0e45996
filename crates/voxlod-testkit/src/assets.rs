//! Assets with looks for tests: a sphere textured red on its −x half and blue on its +x half.

use std::io::Cursor;
use std::sync::Arc;

use glam::Vec2;
use voxlod_asset::{Asset, AssetMesh, Image, Material, Sampler, TextureRef, Wrap};

use crate::shapes::icosphere;

/// A 2 × 1 PNG: texel 0 red, texel 1 blue.
pub fn two_halves_png() -> Vec<u8> {
    let img = image::RgbaImage::from_fn(2, 1, |x, _| {
        if x == 0 {
            image::Rgba([255, 0, 0, 255])
        } else {
            image::Rgba([0, 0, 255, 255])
        }
    });
    let mut bytes = Vec::new();
    img.write_to(&mut Cursor::new(&mut bytes), image::ImageFormat::Png)
        .expect("a PNG encodes");
    bytes
}

/// The unit icosphere of `levels` with texture coordinates (x + 1) / 2, (y + 1) / 2 and the
/// two-halves texture (clamped, nearest): red where x < 0, blue where x > 0. One dielectric
/// material, so that a light shows its base colour.
pub fn textured_sphere(levels: u32) -> Asset {
    let s = icosphere(levels);
    let n = s.triangles.len();
    Asset {
        mesh: AssetMesh {
            uv: [
                s.positions
                    .iter()
                    .map(|p| Vec2::new((p.x + 1.0) / 2.0, (p.y + 1.0) / 2.0))
                    .collect(),
                Vec::new(),
            ],
            normals: s.positions.iter().map(|p| p.normalize()).collect(),
            positions: s.positions,
            triangles: s.triangles,
            material: vec![0; n],
            ..AssetMesh::default()
        },
        materials: vec![Material {
            name: "halves".into(),
            metallic: 0.0,
            base_color_texture: Some(TextureRef {
                image: 0,
                tex_coord: 0,
                transform: None,
                sampler: Sampler {
                    wrap_u: Wrap::ClampToEdge,
                    wrap_v: Wrap::ClampToEdge,
                    linear: false,
                },
            }),
            ..Material::default()
        }],
        images: vec![Image {
            name: "halves.png".into(),
            mime: "image/png".into(),
            bytes: Arc::new(two_halves_png()),
        }],
        parts: Vec::new(),
    }
}
