//! A baked level as an asset: the textures a source's materials call for (alpha, occlusion-
//! roughness-metallic, emission) with the values its materials give, and the asset written
//! as glTF by voxlod-gltf, clean by the Khronos validator (where the peers' kit has it), and
//! read back unchanged.

use voxlod_asset::texture::srgb_to_linear;
use voxlod_asset::{AlphaMode, Asset, Material};
use voxlod_bake::raster::UNCOVERED;
use voxlod_bake::{bake, BakeOptions, Baked};
use voxlod_core::glam::Vec3;
use voxlod_gltf::{asset_glb, read_scene, AssetGlbOptions};
use voxlod_testkit::assets::textured_sphere;
use voxlod_testkit::gltf_validator::validate_gltf;
use voxlod_testkit::shapes::icosphere;

/// The two-halves sphere whose upper half (z > 0) is a second material: half transparent,
/// smoother, glowing orange at strength 4.
fn glowing_sphere() -> Asset {
    let mut sphere = textured_sphere(3);
    let top = Material {
        base_color: [1.0, 1.0, 1.0, 0.5],
        roughness: 0.3,
        emissive: [0.5, 0.2, 0.0],
        emissive_strength: 4.0,
        alpha_mode: AlphaMode::Blend,
        ..sphere.materials[0].clone()
    };
    sphere.materials.push(top);
    let mesh = &mut sphere.mesh;
    for (t, tri) in mesh.triangles.iter().enumerate() {
        if tri.iter().all(|&v| mesh.positions[v as usize].z > 0.0) {
            mesh.material[t] = 1;
        }
    }
    sphere
}

/// The decoded texture of a material slot, RGBA.
fn slot_image(baked: &Baked, image: usize) -> image::RgbaImage {
    image::load_from_memory(&baked.asset.images[image].bytes)
        .unwrap()
        .into_rgba8()
}

#[test]
fn each_channel_holds_its_materials_values() {
    let source = glowing_sphere();
    let mut level = icosphere(3);
    level.positions.iter_mut().for_each(|p| *p *= 1.01);
    let baked = bake(&source, &level, &BakeOptions::for_texture(256)).unwrap();
    let m = &baked.asset.materials[0];
    assert_eq!(baked.asset.materials.len(), 1);
    assert_eq!(
        baked.asset.images.len(),
        4,
        "base colour, normal, ORM, emissive"
    );
    assert_eq!(m.alpha_mode, AlphaMode::Blend);
    assert_eq!(m.emissive_strength, 2.0, "the largest emission, 0.5 × 4");
    assert_eq!((m.metallic, m.roughness), (1.0, 1.0));
    assert!(m.occlusion_texture.is_none(), "the source has no occlusion");
    let base = slot_image(&baked, m.base_color_texture.as_ref().unwrap().image);
    let orm = slot_image(&baked, m.metallic_roughness_texture.as_ref().unwrap().image);
    let emissive = slot_image(&baked, m.emissive_texture.as_ref().unwrap().image);
    let srgb = |v: f32| {
        (0..=255u8)
            .min_by(|&a, &b| {
                (srgb_to_linear(a as f32 / 255.0) - v)
                    .abs()
                    .total_cmp(&(srgb_to_linear(b as f32 / 255.0) - v).abs())
            })
            .unwrap()
    };
    let atlas = &baked.atlas;
    let mut seen = [0usize; 2];
    for (i, c) in atlas.coverage().texels.iter().enumerate() {
        if c.triangle == UNCOVERED || c.border {
            continue;
        }
        let tri = atlas.triangles[c.triangle as usize];
        let p: Vec3 = (0..3)
            .map(|k| atlas.positions[tri[k] as usize] * c.weights[k])
            .sum();
        let (x, y) = ((i % 256) as u32, (i / 256) as u32);
        let near = |got: u8, want: u8| (got as i32 - want as i32).abs() <= 1;
        if p.z > 0.3 {
            seen[0] += 1;
            assert!(
                near(base.get_pixel(x, y)[3], 128),
                "alpha {:?}",
                base.get_pixel(x, y)
            );
            assert!(
                near(orm.get_pixel(x, y)[1], 77),
                "roughness 0.3: {:?}",
                orm.get_pixel(x, y)
            );
            let e = emissive.get_pixel(x, y);
            assert!(
                near(e[0], 255) && near(e[1], srgb(0.4)) && e[2] == 0,
                "emission {e:?}"
            );
        } else if p.z < -0.3 {
            seen[1] += 1;
            assert_eq!(base.get_pixel(x, y)[3], 255);
            assert_eq!(orm.get_pixel(x, y)[1], 255, "roughness 1");
            assert_eq!(emissive.get_pixel(x, y).0, [0, 0, 0, 255]);
        }
        assert_eq!(orm.get_pixel(x, y)[2], 0, "metalness 0");
    }
    assert!(seen.iter().all(|&n| n > 5000), "{seen:?}");
}

#[test]
fn the_asset_is_written_as_gltf_unchanged() {
    let source = textured_sphere(3);
    let mut level = icosphere(2);
    level.positions.iter_mut().for_each(|p| *p *= 0.99);
    let baked = bake(&source, &level, &BakeOptions::for_texture(128)).unwrap();
    assert_eq!(baked.asset.images.len(), 2, "base colour and normal only");
    baked.asset.validate().unwrap();
    let glb = asset_glb(
        std::slice::from_ref(&baked.asset),
        &AssetGlbOptions::default(),
    )
    .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("proxy.glb");
    std::fs::write(&path, glb).unwrap();
    if let Some(validation) = validate_gltf(&path) {
        assert_eq!(validation.errors, 0, "{}", validation.report);
        assert_eq!(validation.warnings, 0, "{}", validation.report);
    }
    let read = read_scene(&path).unwrap().asset;
    assert_eq!(read.mesh.triangles.len(), level.triangles.len());
    assert_eq!(read.mesh.uv[0].len(), read.mesh.positions.len());
    assert_eq!(read.mesh.tangents.len(), read.mesh.positions.len());
    assert_eq!(read.images.len(), 2);
    for (a, b) in read.images.iter().zip(&baked.asset.images) {
        assert_eq!(a.bytes, b.bytes, "{}", b.name);
    }
    assert_eq!(
        read.materials[0].normal_texture,
        baked.asset.materials[0].normal_texture
    );
}
