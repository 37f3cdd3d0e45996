//! Assets drawn with their looks: texels at their centres, vertex colours, alpha masks.

use std::sync::Arc;

use glam::{DVec3, Vec2, Vec3, Vec4};
use image::ImageEncoder;
use voxlod_asset::{AlphaMode, Asset, AssetMesh, Image, Material, Sampler, TextureRef};
use voxlod_core::Bounds;
use voxlod_render::{decode_textures, render, AssetItem, Camera, Projection, RenderOptions, Scene};

/// PNG bytes of `w × h` sRGB RGBA texels.
fn png(w: u32, h: u32, rgba: &[[u8; 4]]) -> Vec<u8> {
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(rgba.as_flattened(), w, h, image::ExtendedColorType::Rgba8)
        .unwrap();
    out
}

/// A square of side 4 in the z = 0 plane, (0, 0) to (4, 4), its texture coordinates spanning
/// the image once (v down the image, so world +y is the image's top).
fn textured_quad(texels: &[[u8; 4]], side: u32, alpha_mode: AlphaMode) -> Asset {
    let positions = vec![
        Vec3::ZERO,
        Vec3::new(4.0, 0.0, 0.0),
        Vec3::new(4.0, 4.0, 0.0),
        Vec3::new(0.0, 4.0, 0.0),
    ];
    let uv = positions
        .iter()
        .map(|p| Vec2::new(p.x / 4.0, 1.0 - p.y / 4.0))
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
                sampler: Sampler::default(),
            }),
            alpha_mode,
            ..Material::default()
        }],
        images: vec![Image {
            name: "texels".into(),
            mime: "image/png".into(),
            bytes: Arc::new(png(side, side, texels)),
        }],
        parts: Vec::new(),
    }
}

/// A camera looking down −z at the quad, `px` pixels per world unit, so that pixel
/// `px·i + (px − 1)/2` sits on texel `i`'s centre when `px` is odd.
fn head_on(px: u32) -> Camera {
    let frame = Bounds::new(DVec3::new(0.0, 0.0, -1.0), DVec3::new(4.0, 4.0, 1.0));
    let mut camera = Camera::fit(DVec3::NEG_Z, &frame, 4 * px, 4 * px, None).unwrap();
    camera.projection = Projection::Orthographic { half_height: 2.0 };
    camera
}

/// Full light everywhere: the shade is 1, so the picture is the surface's colour.
fn unlit() -> RenderOptions {
    RenderOptions {
        ambient: 1.0,
        ..Default::default()
    }
}

fn texel_grid() -> Vec<[u8; 4]> {
    (0..16u8)
        .map(|i| [i * 16 + 7, 255 - i * 13, (i * 71) % 251, 255])
        .collect()
}

#[test]
fn a_textured_quad_head_on_shows_its_texels_at_their_centres() {
    let texels = texel_grid();
    let asset = textured_quad(&texels, 4, AlphaMode::Opaque);
    let (textures, warnings) = decode_textures(&asset).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    let scene = Scene {
        assets: vec![AssetItem::new(&asset, &textures)],
        ..Default::default()
    };
    let px = 3;
    let image = render(&scene, &head_on(px), &unlit()).unwrap();
    let srgb = image.to_srgb8();
    for j in 0..4u32 {
        for i in 0..4u32 {
            let (x, y) = (px * i + px / 2, px * j + px / 2);
            let k = image.index(x, y);
            assert_eq!(image.coverage[k], 1.0);
            let want = texels[(j * 4 + i) as usize];
            for c in 0..3 {
                let got = srgb[3 * k + c] as i32;
                assert!(
                    (got - want[c] as i32).abs() <= 1,
                    "texel ({i}, {j}) channel {c}: {got} for {}",
                    want[c]
                );
            }
        }
    }
}

#[test]
fn alpha_mask_drops_the_texels_below_the_cutoff_and_opaque_ignores_alpha() {
    let mut texels = texel_grid();
    texels[5][3] = 0; // texel (1, 1) transparent
    texels[6][3] = 200; // texel (2, 1) above the default cutoff 0.5
    let px = 3;
    let at = |i: u32, j: u32, image: &voxlod_render::Image| image.index(px * i + 1, px * j + 1);
    for (mode, dropped) in [(AlphaMode::Mask, true), (AlphaMode::Opaque, false)] {
        let asset = textured_quad(&texels, 4, mode);
        let (textures, _) = decode_textures(&asset).unwrap();
        let scene = Scene {
            assets: vec![AssetItem::new(&asset, &textures)],
            ..Default::default()
        };
        let image = render(&scene, &head_on(px), &unlit()).unwrap();
        let hole = at(1, 1, &image);
        assert_eq!(
            image.coverage[hole],
            if dropped { 0.0 } else { 1.0 },
            "{mode:?}"
        );
        if dropped {
            assert_eq!(image.rgb[hole], RenderOptions::default().background);
        }
        assert_eq!(image.coverage[at(2, 1, &image)], 1.0, "{mode:?}");
    }
}

#[test]
fn vertex_colours_times_the_factor_are_drawn_without_a_texture() {
    let sphere = voxlod_testkit::shapes::icosphere(3);
    let colors: Vec<Vec4> = (sphere.positions.iter())
        .map(|p| {
            if p.y > 0.0 {
                Vec4::new(1.0, 0.0, 0.0, 1.0)
            } else {
                Vec4::new(0.0, 0.0, 1.0, 1.0)
            }
        })
        .collect();
    let normals = sphere.positions.iter().map(|p| p.normalize()).collect();
    let mut asset = Asset {
        mesh: AssetMesh {
            positions: sphere.positions.clone(),
            triangles: sphere.triangles.clone(),
            normals,
            colors,
            ..Default::default()
        },
        ..Default::default()
    };
    let camera = Camera::fit(DVec3::NEG_Z, &sphere.bounds(), 64, 64, None).unwrap();
    let draw = |asset: &Asset| {
        let scene = Scene {
            assets: vec![AssetItem::new(asset, &[])],
            ..Default::default()
        };
        render(&scene, &camera, &unlit()).unwrap()
    };
    let image = draw(&asset);
    // The sphere's outline has a radius of about 17 pixels about the centre.
    let (top, bottom) = (image.index(32, 22), image.index(32, 42));
    assert_eq!(image.rgb[top], [1.0, 0.0, 0.0]);
    assert_eq!(image.rgb[bottom], [0.0, 0.0, 1.0]);
    // A material's factor multiplies them.
    asset.materials = vec![Material {
        base_color: [0.5, 1.0, 1.0, 1.0],
        ..Material::default()
    }];
    asset.mesh.material = vec![0; asset.mesh.triangles.len()];
    let image = draw(&asset);
    assert_eq!(image.rgb[image.index(32, 22)], [0.5, 0.0, 0.0]);
    // Lit: the headlight darkens the rim, never brightens beyond the colour.
    let lit = render(
        &Scene {
            assets: vec![AssetItem::new(&asset, &[])],
            ..Default::default()
        },
        &camera,
        &RenderOptions::default(),
    )
    .unwrap();
    let rim = lit.rgb[lit.index(32, 16)];
    assert!(rim[0] > 0.0 && rim[0] < 0.5 && rim[2] == 0.0, "{rim:?}");
}

#[test]
fn a_texture_is_perspective_correct_under_a_slanted_perspective_camera() {
    // Two texel columns, black and white: under perspective, the border between them is where
    // the quad's middle (x = 2) projects, not the middle of the projected quad.
    let texels: Vec<[u8; 4]> = (0..4)
        .flat_map(|_| [[0, 0, 0, 255], [0, 0, 0, 255], [255; 4], [255; 4]])
        .collect();
    let mut asset = textured_quad(&texels, 4, AlphaMode::Opaque);
    asset.materials[0]
        .base_color_texture
        .as_mut()
        .unwrap()
        .sampler
        .linear = false;
    let (textures, _) = decode_textures(&asset).unwrap();
    let scene = Scene {
        assets: vec![AssetItem::new(&asset, &textures)],
        ..Default::default()
    };
    let frame = Bounds::new(DVec3::new(0.0, 0.0, -1.0), DVec3::new(4.0, 4.0, 1.0));
    let camera = Camera::fit(DVec3::new(0.8, 0.0, -1.0), &frame, 256, 256, Some(60.0)).unwrap();
    let image = render(&scene, &camera, &unlit()).unwrap();
    let middle = camera.project(DVec3::new(2.0, 2.0, 0.0)).unwrap();
    let (mx, y) = (middle.x.round() as u32, middle.y as u32);
    let lum = |x: u32| image.rgb[image.index(x, y)][0];
    assert_eq!(lum(mx - 2), 0.0);
    assert!(lum(mx + 2) > 0.999);
    // The projected quad's middle column lies off the border.
    let left = camera.project(DVec3::new(0.0, 2.0, 0.0)).unwrap().x;
    let right = camera.project(DVec3::new(4.0, 2.0, 0.0)).unwrap().x;
    assert!((0.5 * (left + right) - middle.x).abs() > 4.0);
}

#[test]
fn blend_composites_the_texel_over_what_lies_behind() {
    let texels: Vec<[u8; 4]> = vec![[255, 255, 255, 128]; 16];
    let asset = textured_quad(&texels, 4, AlphaMode::Blend);
    let (textures, _) = decode_textures(&asset).unwrap();
    let scene = Scene {
        assets: vec![AssetItem::new(&asset, &textures)],
        ..Default::default()
    };
    let image = render(&scene, &head_on(3), &unlit()).unwrap();
    let k = image.index(6, 6);
    let alpha = 128.0 / 255.0;
    let background = RenderOptions::default().background;
    assert!((image.coverage[k] - alpha).abs() < 1e-6);
    for (got, bg) in image.rgb[k].iter().zip(background) {
        let want = bg + (1.0 - bg) * alpha;
        assert!((got - want).abs() < 1e-5, "{:?}", image.rgb[k]);
    }
}

/// A white quad whose normal map tilts its normal by 40° about y, lit head-on with no ambient:
/// drawn with its normal map, every pixel has the shade cos 40° of the bent normal (as three.js
/// shades it); without the map (or the map not given), the shade 1 of its flat normal.
#[test]
fn a_normal_map_bends_the_shading_normal() {
    let tilt = 40.0f32.to_radians();
    // Tangent space: +x along +u (world +x), +y image-up (world +y), +z the normal.
    let m = Vec3::new(tilt.sin(), 0.0, tilt.cos());
    let stored = (m * 0.5 + Vec3::splat(0.5)) * 255.0;
    let texel = [
        stored.x.round() as u8,
        stored.y.round() as u8,
        stored.z.round() as u8,
        255,
    ];
    let mut asset = textured_quad(&[[255; 4]; 4], 2, AlphaMode::Opaque);
    asset.images.push(Image {
        name: "normals".into(),
        mime: "image/png".into(),
        bytes: Arc::new(png(2, 2, &[texel; 4])),
    });
    asset.materials[0].normal_texture = Some(TextureRef {
        image: 1,
        tex_coord: 0,
        transform: None,
        sampler: Sampler::default(),
    });
    asset.mesh.tangents = vec![Vec4::new(1.0, 0.0, 0.0, 1.0); 4];
    let options = RenderOptions {
        ambient: 0.0,
        light: Some(DVec3::Z),
        ..Default::default()
    };
    let (textures, _) = decode_textures(&asset).unwrap();
    let (maps, warnings) = voxlod_render::decode_normal_maps(&asset).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    let draw = |maps: &[Option<voxlod_asset::texture::Texels>]| {
        let scene = Scene {
            assets: vec![AssetItem::new(&asset, &textures).with_normal_maps(maps)],
            ..Default::default()
        };
        let image = render(&scene, &head_on(3), &options).unwrap();
        image.rgb[image.rgb.len() / 2 + image.width as usize / 2]
    };
    let bent = draw(&maps);
    assert!(
        (bent[0] - tilt.cos()).abs() < 0.01,
        "{bent:?}, cos {}",
        tilt.cos()
    );
    let flat = draw(&[]);
    assert!((flat[0] - 1.0).abs() < 1e-3, "{flat:?}");
}

/// A single-sided blended quad is drawn from its front and culled from its back (glTF 2.0
/// §3.9.4); made double-sided, it is drawn from both.
#[test]
fn a_single_sided_blended_quad_is_culled_from_behind() {
    let texels: Vec<[u8; 4]> = vec![[255, 255, 255, 128]; 16];
    let mut asset = textured_quad(&texels, 4, AlphaMode::Blend);
    let frame = Bounds::new(DVec3::new(0.0, 0.0, -1.0), DVec3::new(4.0, 4.0, 1.0));
    let mut behind = Camera::fit(DVec3::Z, &frame, 12, 12, None).unwrap();
    behind.projection = Projection::Orthographic { half_height: 2.0 };
    let alpha = 128.0 / 255.0;
    for (double_sided, camera, want) in [
        (false, head_on(3), alpha),
        (false, behind, 0.0),
        (true, behind, alpha),
    ] {
        asset.materials[0].double_sided = double_sided;
        let (textures, _) = decode_textures(&asset).unwrap();
        let scene = Scene {
            assets: vec![AssetItem::new(&asset, &textures)],
            ..Default::default()
        };
        let image = render(&scene, &camera, &unlit()).unwrap();
        let k = image.index(6, 6);
        assert!(
            (image.coverage[k] - want).abs() < 1e-6,
            "double-sided {double_sided}, looking along {:?}: coverage {}",
            camera.forward,
            image.coverage[k]
        );
    }
}
