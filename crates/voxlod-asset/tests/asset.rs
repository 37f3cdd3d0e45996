//! The asset's invariants and the texture transform, on hand-made cases.

use std::sync::Arc;

use voxlod_asset::{Asset, AssetMesh, Image, Material, Sampler, TextureRef, TextureTransform};
use voxlod_core::glam::{Vec2, Vec3};

/// One textured triangle with one material.
fn triangle() -> Asset {
    Asset {
        mesh: AssetMesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            triangles: vec![[0, 1, 2]],
            uv: [vec![Vec2::ZERO, Vec2::X, Vec2::Y], Vec::new()],
            material: vec![0],
            ..AssetMesh::default()
        },
        materials: vec![Material {
            base_color_texture: Some(TextureRef {
                image: 0,
                tex_coord: 0,
                transform: None,
                sampler: Sampler::default(),
            }),
            ..Material::default()
        }],
        images: vec![Image {
            name: "checker".into(),
            mime: "image/png".into(),
            bytes: Arc::new(vec![0; 8]),
        }],
        parts: Vec::new(),
    }
}

#[test]
fn a_well_formed_asset_validates() {
    triangle().validate().unwrap();
    assert_eq!(triangle().mesh.attribute_names(), ["TEXCOORD_0"]);
}

/// A way to break one invariant.
type Breaking = fn(&mut Asset);

#[test]
fn each_broken_invariant_is_named() {
    let cases: [(&str, Breaking); 6] = [
        ("2 colours for 3 vertices", |a| {
            a.mesh.colors = vec![Default::default(); 2]
        }),
        ("vertex 1 is not finite", |a| {
            a.mesh.positions[1].x = f32::NAN
        }),
        ("triangle 0 names a vertex beyond", |a| {
            a.mesh.triangles[0][2] = 3
        }),
        ("0 triangle materials for 1 triangles", |a| {
            a.mesh.material.clear()
        }),
        ("names a missing image", |a| a.images.clear()),
        ("reads texture coordinates 1", |a| {
            a.materials[0]
                .base_color_texture
                .as_mut()
                .unwrap()
                .tex_coord = 1
        }),
    ];
    for (words, break_it) in cases {
        let mut asset = triangle();
        break_it(&mut asset);
        let e = asset.validate().unwrap_err().to_string();
        assert!(e.contains(words), "{words}: {e}");
    }
}

#[test]
fn only_a_material_a_triangle_uses_needs_its_texture_coordinates() {
    // The textured material kept spare (no triangle names it) beside an untextured one, and
    // no texture coordinates: a file with a material it does not use.
    let mut spare = triangle();
    spare.mesh.uv[0].clear();
    spare.materials.push(Material::default());
    spare.mesh.material = vec![1];
    spare.validate().unwrap();
    spare.mesh.material = vec![0];
    let e = spare.validate().unwrap_err().to_string();
    assert!(e.contains("reads texture coordinates 0"), "{e}");
}

#[test]
fn the_texture_transform_scales_then_rotates_then_offsets() {
    let t = TextureTransform {
        offset: [0.5, 0.0],
        rotation: 0.0,
        scale: [2.0, 2.0],
        tex_coord: None,
    };
    assert_eq!(t.apply(Vec2::new(0.25, 0.25)), Vec2::new(1.0, 0.5));
    // A quarter turn: KHR_texture_transform's matrix takes u to -v.
    let quarter = TextureTransform {
        offset: [0.0, 0.0],
        rotation: std::f32::consts::FRAC_PI_2,
        scale: [1.0, 1.0],
        tex_coord: None,
    };
    let r = quarter.apply(Vec2::X);
    assert!((r - Vec2::new(0.0, -1.0)).length() < 1e-6, "{r}");
}

#[test]
fn an_untextured_copy_keeps_the_factors_and_drops_the_textures() {
    let m = Material {
        base_color: [0.5, 0.25, 1.0, 1.0],
        roughness: 0.3,
        ..triangle().materials[0].clone()
    };
    let u = m.untextured();
    assert_eq!(u.textures().count(), 0);
    assert_eq!((u.base_color, u.roughness), ([1.0; 4], 0.3));
}
