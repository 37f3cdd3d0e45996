//! Looks taken from the nearest input point: a sphere coloured by hemisphere onto a smaller
//! sphere, and a textured square onto a copy of itself, against the colours the texels give.

use std::io::Cursor;
use std::sync::Arc;

use voxlod_asset::texture::srgb_to_linear;
use voxlod_asset::{transfer, Asset, AssetMesh, Image, Material, Sampler, TextureRef, Wrap};
use voxlod_core::glam::{Vec2, Vec3, Vec4};
use voxlod_core::TriangleMesh;
use voxlod_testkit::shapes::icosphere;

/// The unit icosphere, red above z = 0 and blue below by vertex colour, its hemispheres two
/// materials (grey and white factors).
fn coloured_sphere() -> Asset {
    let sphere = icosphere(4);
    let colors = sphere
        .positions
        .iter()
        .map(|p| {
            if p.z >= 0.0 {
                Vec4::new(1.0, 0.0, 0.0, 1.0)
            } else {
                Vec4::new(0.0, 0.0, 1.0, 1.0)
            }
        })
        .collect();
    let material = sphere
        .triangles
        .iter()
        .map(|t| {
            u32::from(
                t.iter()
                    .map(|&v| sphere.positions[v as usize].z)
                    .sum::<f32>()
                    < 0.0,
            )
        })
        .collect();
    Asset {
        mesh: AssetMesh {
            positions: sphere.positions.clone(),
            triangles: sphere.triangles.clone(),
            normals: sphere.positions.iter().map(|p| p.normalize()).collect(),
            colors,
            material,
            ..AssetMesh::default()
        },
        materials: vec![
            Material {
                name: "top".into(),
                base_color: [0.5, 0.5, 0.5, 1.0],
                ..Material::default()
            },
            Material {
                name: "bottom".into(),
                ..Material::default()
            },
        ],
        images: Vec::new(),
        parts: Vec::new(),
    }
}

#[test]
fn each_level_vertex_takes_the_colour_and_normal_of_the_nearest_input_point() {
    let input = coloured_sphere();
    let mut level = icosphere(2);
    for p in &mut level.positions {
        *p *= 0.95;
    }
    let out = transfer(&input, &level).unwrap();
    out.asset.validate().unwrap();
    let m = &out.asset.mesh;
    for (v, p) in m.positions.iter().enumerate() {
        // Away from the equator the colour is the hemisphere's times its material's factor.
        let c = m.colors[v];
        if p.z > 0.1 {
            assert!(
                (c - Vec4::new(0.5, 0.0, 0.0, 1.0)).abs().max_element() < 1e-5,
                "{p}: {c}"
            );
        } else if p.z < -0.1 {
            assert!(
                (c - Vec4::new(0.0, 0.0, 1.0, 1.0)).abs().max_element() < 1e-5,
                "{p}: {c}"
            );
        }
        assert!(m.normals[v].dot(p.normalize()) > 0.99, "normal at {p}");
    }
    // Materials: both kept, by the hemisphere of each triangle, textures none.
    assert_eq!(out.asset.materials.len(), 2);
    for (t, corners) in m.triangles.iter().enumerate() {
        let z: f32 = corners
            .iter()
            .map(|&v| m.positions[v as usize].z)
            .sum::<f32>()
            / 3.0;
        let name = &out.asset.materials[m.material[t] as usize].name;
        if z.abs() > 0.1 {
            assert_eq!(name, if z > 0.0 { "top" } else { "bottom" }, "triangle {t}");
        }
    }
}

/// A 4 × 4 PNG whose texel (i, j) has red 60·i and green 60·j (sRGB).
fn ramp_png() -> Vec<u8> {
    let img = image::RgbaImage::from_fn(4, 4, |i, j| {
        image::Rgba([60 * i as u8, 60 * j as u8, 0, 255])
    });
    let mut bytes = Vec::new();
    img.write_to(&mut Cursor::new(&mut bytes), image::ImageFormat::Png)
        .unwrap();
    bytes
}

/// The unit square in z = 0 with texture coordinates (x, y), textured with the ramp.
fn textured_square() -> Asset {
    Asset {
        mesh: AssetMesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            uv: [vec![Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y], Vec::new()],
            material: vec![0, 0],
            ..AssetMesh::default()
        },
        materials: vec![Material {
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
            name: "ramp".into(),
            mime: "image/png".into(),
            bytes: Arc::new(ramp_png()),
        }],
        parts: Vec::new(),
    }
}

#[test]
fn a_textured_input_gives_the_texels_colours_never_grey() {
    let input = textured_square();
    // Level vertices at the centres of texels (i, j), slightly above the square.
    let mut level = TriangleMesh::default();
    for (i, j) in [(0, 0), (3, 0), (1, 2), (3, 3)] {
        level.positions.push(Vec3::new(
            (i as f32 + 0.5) / 4.0,
            (j as f32 + 0.5) / 4.0,
            0.01,
        ));
    }
    level.triangles = vec![[0, 1, 2], [0, 2, 3]];
    let out = transfer(&input, &level).unwrap();
    assert!(out.warnings.is_empty(), "{:?}", out.warnings);
    for (v, (i, j)) in [(0, 0), (3, 0), (1, 2), (3, 3)].into_iter().enumerate() {
        let want = Vec4::new(
            srgb_to_linear(60.0 * i as f32 / 255.0),
            srgb_to_linear(60.0 * j as f32 / 255.0),
            0.0,
            1.0,
        );
        let got = out.asset.mesh.colors[v];
        assert!(
            (got - want).abs().max_element() < 1e-5,
            "texel ({i}, {j}): {got} vs {want}"
        );
    }
    assert_eq!(out.asset.materials[0].textures().count(), 0);
}

#[test]
fn an_image_that_cannot_be_decoded_is_named_and_its_factor_stands_in() {
    let mut input = textured_square();
    input.images[0] = Image {
        name: "broken.png".into(),
        mime: "image/png".into(),
        bytes: Arc::new(vec![1, 2, 3]),
    };
    input.materials[0].base_color = [0.2, 0.4, 0.6, 1.0];
    let level = TriangleMesh::new(
        vec![
            Vec3::new(0.2, 0.2, 0.0),
            Vec3::new(0.8, 0.2, 0.0),
            Vec3::new(0.5, 0.8, 0.0),
        ],
        vec![[0, 1, 2]],
    );
    let out = transfer(&input, &level).unwrap();
    assert_eq!(out.warnings.len(), 1);
    assert!(out.warnings[0].contains("broken.png"), "{:?}", out.warnings);
    assert_eq!(out.asset.mesh.colors[0], Vec4::new(0.2, 0.4, 0.6, 1.0));
}
