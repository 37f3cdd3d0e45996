//! A texel's opacity measured by view rays: a closed level around a masked card takes, where it
//! looks through the card, an opacity in proportion to the share of the card that shows
//! (half for a fine checker of clear and opaque texels), none where it sees the card's back
//! (a single-sided card), and is drawn blended and single-sided; with no view rays it masks
//! as the source does. `smooth` averages within a chart, never across charts.

use std::io::Cursor;
use std::sync::Arc;

use voxlod_asset::{AlphaMode, Asset, AssetMesh, Image, Material, Sampler, TextureRef, Wrap};
use voxlod_bake::opacity::{smooth, Seen};
use voxlod_bake::raster::UNCOVERED;
use voxlod_bake::{bake, BakeOptions, Baked};
use voxlod_core::glam::{DVec3, Vec2, Vec3};
use voxlod_core::TriangleMesh;
use voxlod_testkit::shapes::{subdivided, unit_cube};

/// A 64² texture whose texels are opaque where `show(x, y)`, clear elsewhere.
fn mask_png(show: impl Fn(u32, u32) -> bool) -> Vec<u8> {
    let img = image::RgbaImage::from_fn(64, 64, |x, y| {
        image::Rgba(if show(x, y) {
            [40, 200, 60, 255]
        } else {
            [0, 0, 0, 0]
        })
    });
    let mut bytes = Vec::new();
    img.write_to(&mut Cursor::new(&mut bytes), image::ImageFormat::Png)
        .unwrap();
    bytes
}

/// A single-sided card [−0.8, 0.8]² at z = 0 facing +z, masked by `png`.
fn card(png: Vec<u8>) -> Asset {
    let positions = [(-0.8, -0.8), (0.8, -0.8), (0.8, 0.8), (-0.8, 0.8)]
        .map(|(x, y)| Vec3::new(x, y, 0.0))
        .to_vec();
    Asset {
        mesh: AssetMesh {
            uv: [
                positions
                    .iter()
                    .map(|p| Vec2::new(p.x / 1.6 + 0.5, 0.5 - p.y / 1.6))
                    .collect(),
                Vec::new(),
            ],
            normals: vec![Vec3::Z; 4],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            material: vec![0, 0],
            positions,
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
            alpha_mode: AlphaMode::Mask,
            metallic: 0.0,
            ..Material::default()
        }],
        images: vec![Image {
            name: "card.png".into(),
            mime: "image/png".into(),
            bytes: Arc::new(png),
        }],
        parts: Vec::new(),
    }
}

/// The closed cube [−1, 1]³, each face split into 32 triangles.
fn level() -> TriangleMesh {
    let cube = unit_cube();
    let corners = cube.positions.iter();
    subdivided(
        corners.map(|p| p.as_dvec3() * 2.0 - 1.0).collect(),
        cube.triangles,
        2,
        |p: DVec3| p,
    )
}

fn baked(source: &Asset, rays: u32) -> Baked {
    let options = BakeOptions {
        cage: Some(0.5),
        opacity_rays: rays,
        ..BakeOptions::for_texture(128)
    };
    bake(source, &level(), &options).unwrap()
}

/// The mean alpha (0 to 1) of the inside texels on the cube's face of normal `normal`, within
/// 0.5 of its middle.
fn mean_alpha(baked: &Baked, normal: Vec3) -> f64 {
    let atlas = &baked.atlas;
    let image = image::load_from_memory(&baked.asset.images[0].bytes)
        .unwrap()
        .into_rgba8();
    let (mut sum, mut count) = (0.0, 0usize);
    for (i, c) in atlas.coverage().texels.iter().enumerate() {
        if c.triangle == UNCOVERED || c.border {
            continue;
        }
        let [a, b, d] = atlas.triangles[c.triangle as usize].map(|v| atlas.positions[v as usize]);
        let p = a * c.weights[0] + b * c.weights[1] + d * c.weights[2];
        let n = (b - a).cross(d - a).normalize();
        if n.dot(normal) > 0.99 && (p - normal).length() < 0.5 {
            sum += image.as_raw()[4 * i + 3] as f64 / 255.0;
            count += 1;
        }
    }
    assert!(count > 200, "{count} texels");
    sum / count as f64
}

#[test]
fn a_level_takes_the_opacity_of_the_share_of_a_card_that_shows() {
    let opaque = baked(&card(mask_png(|_, _| true)), 4);
    let checker = baked(&card(mask_png(|x, y| (x + y) % 2 == 0)), 4);
    let material = &checker.asset.materials[0];
    assert_eq!(material.alpha_mode, AlphaMode::Blend);
    assert!(!material.double_sided);
    assert!(checker.report.texels_opacity > 0, "{:?}", checker.report);
    let (full, half) = (mean_alpha(&opaque, Vec3::Z), mean_alpha(&checker, Vec3::Z));
    // From the top, the view lines (within 30° of the normal) through the middle meet the
    // card, but for a few near the middle's edge that pass beside it.
    assert!(full > 0.9, "{full}");
    assert!((half / full - 0.5).abs() < 0.08, "{half} of {full}");
    // From below, the lines meet the single-sided card's back: nothing shows.
    assert_eq!(mean_alpha(&opaque, -Vec3::Z), 0.0);
}

#[test]
fn without_view_rays_the_level_masks_as_the_source_does() {
    let plain = baked(&card(mask_png(|x, y| (x + y) % 2 == 0)), 0);
    assert_eq!(plain.asset.materials[0].alpha_mode, AlphaMode::Mask);
    assert_eq!(plain.report.texels_opacity, 0);
}

#[test]
fn smooth_averages_within_a_chart_never_across() {
    let seen = |opacity: f32, colour: Vec3| Some(Seen { colour, opacity });
    let (red, blue) = (Vec3::X, Vec3::Z);
    // One row: two texels of chart 0, one of chart 1, one not measured.
    let row = [seen(1.0, red), seen(0.5, blue), seen(0.25, blue), None];
    let smoothed = smooth(&row, &[0, 0, 1, 1], 4, 1);
    let first = smoothed[0].unwrap();
    assert!((first.opacity - 0.75).abs() < 1e-6);
    // Colours weighted by opacity: (1 · red + 0.5 · blue) / 1.5.
    assert!((first.colour - (red + 0.5 * blue) / 1.5).length() < 1e-6);
    assert_eq!(smoothed[1], smoothed[0]);
    assert_eq!(smoothed[2], seen(0.25, blue));
    assert_eq!(smoothed[3], None);
}
