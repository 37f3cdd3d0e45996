//! Assets with looks for tests: a sphere textured red on its −x half and blue on its +x half;
//! a scene of three parts with their own materials (two checker textures, one plain colour).

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

/// A `size`² PNG of `cells`² squares alternating between `a` and `b`.
pub fn checker_png(size: u32, cells: u32, a: [u8; 3], b: [u8; 3]) -> Vec<u8> {
    let cell = (size / cells.max(1)).max(1);
    let img = image::RgbaImage::from_fn(size, size, |x, y| {
        let [r, g, bl] = if (x / cell + y / cell).is_multiple_of(2) {
            a
        } else {
            b
        };
        image::Rgba([r, g, bl, 255])
    });
    let mut bytes = Vec::new();
    img.write_to(&mut Cursor::new(&mut bytes), image::ImageFormat::Png)
        .expect("a PNG encodes");
    bytes
}

/// A small scene of three parts with their own materials, for proxies: a unit sphere with a
/// red and white checker, a sphere of radius 0.6 at (1.1, 0, 0) passing through it with a blue
/// and yellow checker of larger squares, and a plain green sphere of radius 0.4 apart at
/// (0, 2.2, 0). Texture coordinates are the points' (x, y) scaled into the unit square around
/// each sphere's centre; the textures are nearest-sampled and clamped.
pub fn three_part_scene() -> Asset {
    use crate::shapes::{append, icosphere_at};
    use glam::Vec3;
    let parts = [
        (Vec3::ZERO, 1.0, 0u32),
        (Vec3::new(1.1, 0.0, 0.0), 0.6, 1),
        (Vec3::new(0.0, 2.2, 0.0), 0.4, 2),
    ];
    let mut geometry = voxlod_core::TriangleMesh::default();
    let (mut uv, mut normals, mut material) = (Vec::new(), Vec::new(), Vec::new());
    for (centre, radius, m) in parts {
        let sphere = icosphere_at(4, radius, centre);
        for p in &sphere.positions {
            let d = (*p - centre) / radius;
            uv.push(Vec2::new((d.x + 1.0) / 2.0, (d.y + 1.0) / 2.0));
            normals.push(d.normalize());
        }
        material.extend(std::iter::repeat_n(m, sphere.triangles.len()));
        append(&mut geometry, &sphere);
    }
    let nearest = Sampler {
        wrap_u: Wrap::ClampToEdge,
        wrap_v: Wrap::ClampToEdge,
        linear: false,
    };
    let textured = |name: &str, image: usize| Material {
        name: name.into(),
        metallic: 0.0,
        base_color_texture: Some(TextureRef {
            image,
            tex_coord: 0,
            transform: None,
            sampler: nearest,
        }),
        ..Material::default()
    };
    let png = |name: &str, bytes: Vec<u8>| Image {
        name: name.into(),
        mime: "image/png".into(),
        bytes: Arc::new(bytes),
    };
    Asset {
        mesh: AssetMesh {
            positions: geometry.positions,
            triangles: geometry.triangles,
            normals,
            uv: [uv, Vec::new()],
            material,
            ..AssetMesh::default()
        },
        materials: vec![
            textured("red-white", 0),
            textured("blue-yellow", 1),
            Material {
                name: "green".into(),
                metallic: 0.0,
                base_color: [0.1, 0.6, 0.1, 1.0],
                ..Material::default()
            },
        ],
        images: vec![
            png(
                "red-white.png",
                checker_png(64, 8, [220, 30, 30], [240, 240, 240]),
            ),
            png(
                "blue-yellow.png",
                checker_png(64, 4, [30, 30, 200], [230, 210, 40]),
            ),
        ],
        parts: Vec::new(),
    }
}

/// A latitude-longitude sphere of `radius` around `centre`: `rings` × `segments` quads, the
/// meridian seam's vertices doubled, each pole a vertex per segment, the pole rows one
/// triangle per quad; unit normals, texture coordinates u 0..1 around (the segment's u at a
/// pole) and v 0..1 from pole to pole; no material.
pub fn uv_sphere(centre: glam::Vec3, radius: f32, rings: u32, segments: u32) -> AssetMesh {
    use std::f32::consts::{PI, TAU};
    let mut m = AssetMesh::default();
    for i in 0..=rings {
        for j in 0..=segments {
            let (v, u) = (i as f32 / rings as f32, j as f32 / segments as f32);
            let (theta, phi) = (v * PI, u * TAU);
            let n = glam::Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                -theta.sin() * phi.sin(),
            );
            m.positions.push(centre + n * radius);
            m.normals.push(n);
            m.uv[0].push(Vec2::new(u, v));
        }
    }
    let at = |i: u32, j: u32| i * (segments + 1) + j;
    for i in 0..rings {
        for j in 0..segments {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            if i != 0 {
                m.triangles.push([a, b, d]);
            }
            if i != rings - 1 {
                m.triangles.push([b, c, d]);
            }
        }
    }
    m
}
