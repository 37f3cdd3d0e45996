//! Baking against analytic looks: a checker-textured cube onto a slightly larger copy of
//! itself, texel by texel against the checker; a cube with one colour per face, where no
//! texel of a chart (inside, at its border or in its gutter) takes another face's colour;
//! normal maps from flat, tilted and normal-mapped sources; material factors and emission;
//! a finely tiled texture averaged over each texel's footprint; the result written as glTF
//! unchanged.

use std::io::Cursor;
use std::sync::Arc;

use voxlod_asset::texture::srgb_to_linear;
use voxlod_asset::{Asset, AssetMesh, Image, Material, Sampler, TextureRef, Wrap};
use voxlod_bake::raster::UNCOVERED;
use voxlod_bake::{bake, BakeOptions, Baked};
use voxlod_core::glam::{DVec3, Vec2, Vec3};
use voxlod_core::TriangleMesh;
use voxlod_testkit::shapes::{subdivided, unit_cube};

const CHECKER: u32 = 64;
const CELL: u32 = 8;
const DARK: [u8; 3] = [220, 40, 40];
const LIGHT: [u8; 3] = [30, 90, 200];

fn png(width: u32, height: u32, texel: impl Fn(u32, u32) -> [u8; 4]) -> Vec<u8> {
    let img = image::RgbaImage::from_fn(width, height, |x, y| image::Rgba(texel(x, y)));
    let mut bytes = Vec::new();
    img.write_to(&mut Cursor::new(&mut bytes), image::ImageFormat::Png)
        .unwrap();
    bytes
}

fn checker_colour(x: u32, y: u32) -> [u8; 3] {
    if (x / CELL + y / CELL).is_multiple_of(2) {
        DARK
    } else {
        LIGHT
    }
}

/// The axes of a cube face whose normal is `sign` along axis `k`: (u axis, v axis), with
/// u × v along the normal.
fn face_axes(k: usize, sign: f32) -> (usize, usize) {
    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
    if sign > 0.0 {
        (i, j)
    } else {
        (j, i)
    }
}

/// A face's texture coordinates at point `p`: ((p_u + 1) / 2, (p_v + 1) / 2).
fn face_uv(p: Vec3, k: usize, sign: f32) -> Vec2 {
    let (a, b) = face_axes(k, sign);
    Vec2::new((p[a] + 1.0) / 2.0, (p[b] + 1.0) / 2.0)
}

const FACES: [(usize, f32); 6] = [
    (0, 1.0),
    (0, -1.0),
    (1, 1.0),
    (1, -1.0),
    (2, 1.0),
    (2, -1.0),
];

/// The cube [−1, 1]³, each face its own four vertices with texture coordinates
/// [`face_uv`] and material `material(face)`.
fn cube_source(material: impl Fn(usize) -> u32) -> AssetMesh {
    let mut mesh = AssetMesh::default();
    for (f, &(k, sign)) in FACES.iter().enumerate() {
        let (a, b) = face_axes(k, sign);
        let first = mesh.positions.len() as u32;
        for (u, v) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            let mut p = Vec3::ZERO;
            p[k] = sign;
            p[a] = u;
            p[b] = v;
            mesh.positions.push(p);
            mesh.normals.push(
                p.with_x(0.0).with_y(0.0).with_z(0.0) + {
                    let mut n = Vec3::ZERO;
                    n[k] = sign;
                    n
                },
            );
            mesh.uv[0].push(face_uv(p, k, sign));
        }
        mesh.triangles.push([first, first + 1, first + 2]);
        mesh.triangles.push([first, first + 2, first + 3]);
        mesh.material.extend([material(f); 2]);
    }
    mesh
}

fn texture(image: usize) -> Option<TextureRef> {
    Some(TextureRef {
        image,
        tex_coord: 0,
        transform: None,
        sampler: Sampler {
            wrap_u: Wrap::ClampToEdge,
            wrap_v: Wrap::ClampToEdge,
            linear: true,
        },
    })
}

/// The cube [−scale, scale]³ with each face split into 2·4^levels triangles, welded.
fn proxy_cube(levels: u32, scale: f64) -> TriangleMesh {
    let cube = unit_cube();
    subdivided(
        cube.positions
            .iter()
            .map(|p| (p.as_dvec3() * 2.0 - 1.0) * scale)
            .collect(),
        cube.triangles,
        levels,
        |p: DVec3| p,
    )
}

/// The decoded image `k` of a baked asset, RGBA.
fn decoded(baked: &Baked, k: usize) -> image::RgbaImage {
    image::load_from_memory(&baked.asset.images[k].bytes)
        .unwrap()
        .into_rgba8()
}

/// Each covered texel's surface point, inside (not border) flag, chart and face normal.
fn texel_points(baked: &Baked) -> Vec<Option<(Vec3, bool, u32, Vec3)>> {
    let atlas = &baked.atlas;
    atlas
        .coverage()
        .texels
        .iter()
        .map(|c| {
            (c.triangle != UNCOVERED).then(|| {
                let tri = atlas.triangles[c.triangle as usize];
                let [a, b, d] = tri.map(|v| atlas.positions[v as usize]);
                let p = a * c.weights[0] + b * c.weights[1] + d * c.weights[2];
                let n = (b - a).cross(d - a).normalize();
                (p, !c.border, atlas.chart[c.triangle as usize], n)
            })
        })
        .collect()
}

#[test]
fn a_checker_bakes_to_its_own_colours() {
    let source = Asset {
        mesh: cube_source(|_| 0),
        materials: vec![Material {
            base_color_texture: texture(0),
            metallic: 0.0,
            ..Material::default()
        }],
        images: vec![Image {
            name: "checker.png".into(),
            mime: "image/png".into(),
            bytes: Arc::new(png(CHECKER, CHECKER, |x, y| {
                let [r, g, b] = checker_colour(x, y);
                [r, g, b, 255]
            })),
        }],
        parts: Vec::new(),
    };
    let baked = bake(
        &source,
        &proxy_cube(2, 1.02),
        &BakeOptions::for_texture(512),
    )
    .unwrap();
    assert_eq!(baked.report.charts, 6);
    let image = decoded(&baked, 0);
    let (mut compared, mut wrong) = (0, 0);
    for (i, t) in texel_points(&baked).iter().enumerate() {
        let Some((p, true, _, _)) = *t else { continue };
        // The ray along the face normal meets the source face with the other two coordinates.
        let k = (0..3)
            .max_by(|&a, &b| p[a].abs().total_cmp(&p[b].abs()))
            .unwrap();
        let sign = p[k].signum();
        let mut hit = p;
        hit[k] = sign;
        if hit.abs().max_element() > 1.0 || [0, 1, 2].iter().any(|&a| a != k && hit[a].abs() > 0.97)
        {
            continue;
        }
        let texel = face_uv(hit, k, sign) * CHECKER as f32;
        // Away from cell edges by two checker texels: one for the bilinear filter and one for
        // the bake texel's own footprint (about a third of a checker texel here).
        let to_edge = |c: f32| {
            let m = c.rem_euclid(CELL as f32);
            m.min(CELL as f32 - m)
        };
        if to_edge(texel.x) < 2.0 || to_edge(texel.y) < 2.0 {
            continue;
        }
        let expected = checker_colour(texel.x as u32, texel.y as u32);
        let got = image.get_pixel((i % 512) as u32, (i / 512) as u32).0;
        compared += 1;
        if (0..3).any(|c| (got[c] as i32 - expected[c] as i32).abs() > 1) {
            wrong += 1;
        }
    }
    assert!(compared > 20_000, "{compared} texels compared");
    assert_eq!(
        wrong, 0,
        "{wrong} of {compared} texels differ from the checker"
    );
    // Only where the larger copy overhangs the source's faces (a band of 0.02 of 2.04 along
    // each face edge, 4 % of the area) do the rays miss and the nearest point stand in.
    let report = &baked.report;
    assert_eq!(report.texels_hit + report.texels_fallback, report.texels);
    assert!(
        report.texels_fallback as f64 <= 0.06 * report.texels as f64,
        "{report:?}"
    );
}

#[test]
fn no_texel_of_a_chart_takes_another_charts_colour() {
    let colours: Vec<[u8; 3]> = vec![
        [255, 0, 0],
        [0, 255, 0],
        [0, 0, 255],
        [255, 255, 0],
        [0, 255, 255],
        [255, 0, 255],
    ];
    let source = Asset {
        mesh: cube_source(|f| f as u32),
        materials: colours
            .iter()
            .map(|c| Material {
                base_color: [c[0], c[1], c[2]]
                    .map(|v| srgb_to_linear(v as f32 / 255.0))
                    .into_iter()
                    .chain([1.0])
                    .collect::<Vec<_>>()
                    .try_into()
                    .unwrap(),
                ..Material::default()
            })
            .collect(),
        images: Vec::new(),
        parts: Vec::new(),
    };
    let baked = bake(
        &source,
        &proxy_cube(1, 1.01),
        &BakeOptions::for_texture(128),
    )
    .unwrap();
    let image = decoded(&baked, 0);
    let points = texel_points(&baked);
    let face_colour = |n: Vec3| {
        let k = (0..3)
            .max_by(|&a, &b| n[a].abs().total_cmp(&n[b].abs()))
            .unwrap();
        let f = FACES
            .iter()
            .position(|&(fk, s)| fk == k && s == n[k].signum())
            .unwrap();
        colours[f]
    };
    // Every covered texel, border ones too, shows the colour of its own face.
    let mut chart_colour = vec![None; baked.atlas.chart_count];
    for (i, t) in points.iter().enumerate() {
        let Some((_, _, chart, n)) = *t else { continue };
        let got = image.get_pixel((i % 128) as u32, (i / 128) as u32).0;
        assert_eq!(&got[..3], &face_colour(n)[..], "texel {i}");
        chart_colour[chart as usize] = Some(face_colour(n));
    }
    // A gutter texel shows one chart's colour, never a mix; within the padding of a chart, the
    // colour of one of the charts nearest to it.
    let covered: Vec<(usize, usize, u32)> = points
        .iter()
        .enumerate()
        .filter_map(|(i, t)| t.map(|(_, _, c, _)| (i % 128, i / 128, c)))
        .collect();
    for (i, t) in points.iter().enumerate() {
        if t.is_some() {
            continue;
        }
        let (x, y) = ((i % 128) as f64, (i / 128) as f64);
        let d = |&(cx, cy, _): &(usize, usize, u32)| {
            ((cx as f64 - x).powi(2) + (cy as f64 - y).powi(2)).sqrt()
        };
        let nearest = covered.iter().map(d).fold(f64::INFINITY, f64::min);
        let allowed: Vec<[u8; 3]> = covered
            .iter()
            .filter(|c| d(c) <= nearest + 1.5)
            .map(|c| chart_colour[c.2 as usize].unwrap())
            .collect();
        let got = image.get_pixel(x as u32, y as u32).0;
        assert!(
            colours.iter().any(|c| c[..] == got[..3]),
            "gutter texel ({x}, {y}) is {got:?}"
        );
        if nearest <= 4.0 {
            assert!(
                allowed.iter().any(|a| a[..] == got[..3]),
                "gutter texel ({x}, {y}) is {got:?}"
            );
        }
    }
}

/// The unit square at height `z`, split into 2·4^levels triangles, facing +z.
fn square(levels: u32, z: f64) -> TriangleMesh {
    let corners = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
    subdivided(
        corners.iter().map(|&(x, y)| DVec3::new(x, y, z)).collect(),
        vec![[0, 1, 2], [0, 2, 3]],
        levels,
        |p: DVec3| p,
    )
}

/// The unit square as a source with shading normal `normal` everywhere, texture coordinates
/// (x, 1 − y) (so the image's up is +y), and `material`.
fn flat_source(normal: Vec3, material: Material, images: Vec<Image>) -> Asset {
    let plane = square(0, 0.0);
    Asset {
        mesh: AssetMesh {
            uv: [
                plane
                    .positions
                    .iter()
                    .map(|p| Vec2::new(p.x, 1.0 - p.y))
                    .collect(),
                Vec::new(),
            ],
            normals: vec![normal; plane.positions.len()],
            material: vec![0; plane.triangles.len()],
            positions: plane.positions,
            triangles: plane.triangles,
            ..AssetMesh::default()
        },
        materials: vec![material],
        images,
        parts: Vec::new(),
    }
}

/// Each inside texel's decoded tangent-space normal, with the unit directions of +u and of
/// image-up (−v) on its triangle, from the atlas's positions and coordinates.
fn baked_normals(baked: &Baked) -> Vec<(Vec3, Vec3, Vec3)> {
    let image = decoded(
        baked,
        baked.asset.materials[0]
            .normal_texture
            .as_ref()
            .unwrap()
            .image,
    );
    let atlas = &baked.atlas;
    let cover = atlas.coverage();
    let mut out = Vec::new();
    for (i, c) in cover.texels.iter().enumerate() {
        if c.triangle == UNCOVERED || c.border {
            continue;
        }
        let px = image
            .get_pixel((i % cover.width) as u32, (i / cover.width) as u32)
            .0;
        let m = Vec3::new(px[0] as f32, px[1] as f32, px[2] as f32) / 255.0 * 2.0 - 1.0;
        let [a, b, d] = atlas.triangles[c.triangle as usize].map(|v| v as usize);
        let (e1, e2) = (
            atlas.positions[b] - atlas.positions[a],
            atlas.positions[d] - atlas.positions[a],
        );
        let (t1, t2) = (atlas.uv[b] - atlas.uv[a], atlas.uv[d] - atlas.uv[a]);
        let det = t1.x * t2.y - t1.y * t2.x;
        let dp_du = (e1 * t2.y - e2 * t1.y) / det;
        let dp_dv = (e2 * t1.x - e1 * t2.x) / det;
        out.push((m, dp_du.normalize(), -dp_dv.normalize()));
    }
    out
}

/// The world normal a renderer shades with: the tangent-space normal in the frame of +u and
/// image-up on a surface facing +z.
fn shaded((m, right, up): &(Vec3, Vec3, Vec3)) -> Vec3 {
    (*right * m.x + *up * m.y + Vec3::Z * m.z).normalize()
}

#[test]
fn a_flat_source_bakes_a_flat_normal_map() {
    let source = flat_source(Vec3::Z, Material::default(), Vec::new());
    let baked = bake(&source, &square(3, 0.01), &BakeOptions::for_texture(128)).unwrap();
    let normals = baked_normals(&baked);
    assert!(normals.len() > 3000, "{}", normals.len());
    for (m, _, _) in &normals {
        // (0.5, 0.5, 1) stored: 128, 128, 255.
        assert!(
            (m.x.abs() < 0.01) && (m.y.abs() < 0.01) && m.z > 0.999,
            "{m}"
        );
    }
    assert_eq!(baked.report.texels_fallback, 0, "{:?}", baked.report);
}

#[test]
fn a_tilted_source_bakes_its_tilt() {
    for (tilt, degrees) in [
        (Vec3::X, 20.0f32),
        (Vec3::Y, 35.0),
        (Vec3::new(-0.6, 0.8, 0.0), 10.0),
    ] {
        let r = degrees.to_radians();
        let normal = tilt * r.sin() + Vec3::Z * r.cos();
        let source = flat_source(normal, Material::default(), Vec::new());
        let baked = bake(&source, &square(3, 0.01), &BakeOptions::for_texture(128)).unwrap();
        for texel in baked_normals(&baked) {
            assert!(
                (texel.0.z - r.cos()).abs() < 0.01,
                "{tilt} {degrees}°: {}",
                texel.0
            );
            let angle = shaded(&texel).angle_between(normal).to_degrees();
            assert!(
                angle < 1.0,
                "{tilt} {degrees}°: shaded {} for {normal}",
                shaded(&texel)
            );
        }
    }
}

/// A double-sided source seen from its back shades with its normal reversed (glTF §3.9.4): a
/// level below the square, facing down, bakes the reversed tilted normal; a single-sided
/// source keeps its normal, which faces away and is folded onto the level's side.
#[test]
fn a_double_sided_source_seen_from_its_back_bakes_its_reversed_normal() {
    let r = 25.0f32.to_radians();
    let normal = Vec3::X * r.sin() + Vec3::Z * r.cos();
    let mut below = square(3, -0.01);
    below.triangles.iter_mut().for_each(|t| t.swap(1, 2));
    let shaded_below = |(m, right, up): &(Vec3, Vec3, Vec3)| {
        (*right * m.x + *up * m.y - Vec3::Z * m.z).normalize()
    };
    let angles = |double_sided: bool| -> Vec<f32> {
        let material = Material {
            double_sided,
            ..Material::default()
        };
        let source = flat_source(normal, material, Vec::new());
        let baked = bake(&source, &below, &BakeOptions::for_texture(128)).unwrap();
        let texels = baked_normals(&baked);
        assert!(texels.len() > 3000, "{}", texels.len());
        texels
            .iter()
            .map(|t| shaded_below(t).angle_between(-normal).to_degrees())
            .collect()
    };
    let reversed = angles(true);
    assert!(reversed.iter().all(|&a| a < 1.0), "{:?}", &reversed[..4]);
    let kept = angles(false);
    assert!(kept.iter().all(|&a| a > 20.0), "{:?}", &kept[..4]);
}

#[test]
fn a_normal_mapped_source_bakes_its_mapped_normals() {
    // The map bends the normal toward the image's right (+x here) or up (+y here).
    for (towards, degrees) in [(Vec3::X, 25.0f32), (Vec3::Y, 30.0)] {
        let r = degrees.to_radians();
        let stored = (towards * r.sin() + Vec3::Z * r.cos()) * 0.5 + 0.5;
        let texel = stored.to_array().map(|v| (v * 255.0).round() as u8);
        let material = Material {
            normal_texture: texture(0),
            ..Material::default()
        };
        let image = Image {
            name: "bent.png".into(),
            mime: "image/png".into(),
            bytes: Arc::new(png(4, 4, |_, _| [texel[0], texel[1], texel[2], 255])),
        };
        let source = flat_source(Vec3::Z, material, vec![image]);
        let baked = bake(&source, &square(3, 0.01), &BakeOptions::for_texture(128)).unwrap();
        let expected = towards * r.sin() + Vec3::Z * r.cos();
        for texel in baked_normals(&baked) {
            let angle = shaded(&texel).angle_between(expected).to_degrees();
            assert!(
                angle < 1.5,
                "{towards}: shaded {} for {expected}",
                shaded(&texel)
            );
        }
    }
}

#[test]
fn a_finely_tiled_texture_bakes_to_its_mean_not_to_moire() {
    // A black and white checker of single texels, 64² and tiled 32 times across the unit
    // square: 2048 source texels per unit against about 100 baked texels per unit, so each
    // baked texel covers some 20 × 20 source texels. Sampled at a point, every texel would be
    // black or white (moiré); averaged over its footprint (the mipmaps), each is the mean:
    // linear 0.5, sRGB 188.
    let checker = png(64, 64, |x, y| match (x + y) % 2 {
        0 => [0, 0, 0, 255],
        _ => [255, 255, 255, 255],
    });
    let material = Material {
        base_color_texture: Some(TextureRef {
            sampler: Sampler::default(),
            ..texture(0).unwrap()
        }),
        metallic: 0.0,
        ..Material::default()
    };
    let image = Image {
        name: "fine.png".into(),
        mime: "image/png".into(),
        bytes: Arc::new(checker),
    };
    let mut source = flat_source(Vec3::Z, material, vec![image]);
    source.mesh.uv[0].iter_mut().for_each(|uv| *uv *= 32.0);
    let baked = bake(&source, &square(2, 0.01), &BakeOptions::for_texture(128)).unwrap();
    let image = decoded(&baked, 0);
    let inside: Vec<u8> = (texel_points(&baked).iter().enumerate())
        .filter(|(_, t)| t.is_some_and(|(_, inside, _, _)| inside))
        .map(|(i, _)| image.as_raw()[4 * i])
        .collect();
    assert!(inside.len() > 3000, "{}", inside.len());
    for &red in &inside {
        assert!((180..=196).contains(&red), "a texel of {red}");
    }
}

/// A ray that meets a texel an alpha-masked source shows nothing at passes on, as a viewer's
/// would: a level over a card whose left half is clear, with a blue square under the card,
/// bakes blue on the left (where the card alone would leave it clear) and the card's red on
/// the right, every texel opaque (the texels' alpha from the bake ray, not view rays).
#[test]
fn rays_pass_the_clear_texels_of_a_masked_source() {
    let card = png(8, 8, |x, _| match x < 4 {
        true => [0, 0, 0, 0],
        false => [230, 20, 20, 255],
    });
    let masked = Material {
        base_color_texture: texture(0),
        alpha_mode: voxlod_asset::AlphaMode::Mask,
        metallic: 0.0,
        ..Material::default()
    };
    let blue = Material {
        base_color: [0.0, 0.0, 1.0, 1.0],
        metallic: 0.0,
        ..Material::default()
    };
    let image = Image {
        name: "card.png".into(),
        mime: "image/png".into(),
        bytes: Arc::new(card),
    };
    let mut source = flat_source(Vec3::Z, masked, vec![image]);
    source.materials.push(blue);
    let under = square(0, -0.05);
    let base = source.mesh.positions.len() as u32;
    source.mesh.positions.extend(under.positions);
    source.mesh.normals.extend([Vec3::Z; 4]);
    source.mesh.uv[0].extend([Vec2::ZERO; 4]);
    for t in under.triangles {
        source.mesh.triangles.push(t.map(|v| v + base));
        source.mesh.material.push(1);
    }
    let options = BakeOptions {
        cage: Some(0.2),
        opacity_rays: 0,
        ..BakeOptions::for_texture(128)
    };
    let baked = bake(&source, &square(3, 0.02), &options).unwrap();
    let image = decoded(&baked, 0);
    let (mut left, mut right) = (0, 0);
    for (i, texel) in texel_points(&baked).iter().enumerate() {
        let Some((p, true, _, _)) = texel else {
            continue;
        };
        let rgba = &image.as_raw()[4 * i..4 * i + 4];
        if p.x < 0.4 {
            assert!(
                rgba[2] > 200 && rgba[0] < 40 && rgba[3] == 255,
                "left {p}: {rgba:?}"
            );
            left += 1;
        } else if p.x > 0.6 {
            assert!(
                rgba[0] > 200 && rgba[2] < 60 && rgba[3] == 255,
                "right {p}: {rgba:?}"
            );
            right += 1;
        }
    }
    assert!(left > 1000 && right > 1000, "{left} {right}");
}

/// A viewer sees a double-sided card from its back too, so a ray from the level meets it
/// there: a level 0.01 below a red card (facing up, away from the level) and 0.03 above a
/// blue square facing down, as the level does, bakes red where the card is double-sided and
/// blue where it is single-sided (its back is the inside of a solid).
#[test]
fn rays_meet_a_double_sided_card_from_its_back() {
    let colour = |double_sided: bool| -> [u8; 3] {
        let red = Material {
            base_color: [1.0, 0.0, 0.0, 1.0],
            metallic: 0.0,
            double_sided,
            ..Material::default()
        };
        let blue = Material {
            base_color: [0.0, 0.0, 1.0, 1.0],
            metallic: 0.0,
            ..Material::default()
        };
        let mut source = flat_source(Vec3::Z, red, Vec::new());
        source.materials.push(blue);
        let mut under = square(0, -0.04);
        under.triangles.iter_mut().for_each(|t| t.swap(1, 2));
        let base = source.mesh.positions.len() as u32;
        source.mesh.positions.extend(under.positions);
        source.mesh.normals.extend([-Vec3::Z; 4]);
        source.mesh.uv[0].extend([Vec2::ZERO; 4]);
        for t in under.triangles {
            source.mesh.triangles.push(t.map(|v| v + base));
            source.mesh.material.push(1);
        }
        let mut level = square(2, -0.01);
        level.triangles.iter_mut().for_each(|t| t.swap(1, 2));
        let options = BakeOptions {
            cage: Some(0.2),
            ..BakeOptions::for_texture(64)
        };
        let baked = bake(&source, &level, &options).unwrap();
        assert_eq!(baked.report.texels_fallback, 0, "{:?}", baked.report);
        let image = decoded(&baked, 0);
        let inside: Vec<[u8; 3]> = (texel_points(&baked).iter().enumerate())
            .filter(|(_, t)| matches!(t, Some((_, true, _, _))))
            .map(|(i, _)| [0, 1, 2].map(|k| image.as_raw()[4 * i + k]))
            .collect();
        assert!(inside.len() > 500, "{}", inside.len());
        assert!(inside.iter().all(|c| c == &inside[0]), "{:?}", &inside[..4]);
        inside[0]
    };
    let two_sided = colour(true);
    assert!(two_sided[0] > 200 && two_sided[2] < 40, "{two_sided:?}");
    let one_sided = colour(false);
    assert!(one_sided[2] > 200 && one_sided[0] < 40, "{one_sided:?}");
}

/// A closed part's back faces are its inside, which no viewer sees, double-sided material or
/// not: a level just under the top of a closed cube, facing down, bakes the cube's bottom (blue,
/// 0.98 away), not the back of its top (red, 0.02 away), though both are double-sided.
#[test]
fn rays_pass_the_back_faces_of_a_closed_double_sided_part() {
    let cube = voxlod_testkit::shapes::unit_cube();
    let material = |rgb: [f32; 3]| Material {
        base_color: [rgb[0], rgb[1], rgb[2], 1.0],
        metallic: 0.0,
        double_sided: true,
        ..Material::default()
    };
    let top = |t: &[u32; 3]| t.iter().all(|&v| v >= 4);
    let source = Asset {
        mesh: AssetMesh {
            uv: [vec![Vec2::ZERO; 8], Vec::new()],
            normals: vec![Vec3::Z; 8],
            material: cube.triangles.iter().map(|t| u32::from(!top(t))).collect(),
            positions: cube.positions,
            triangles: cube.triangles,
            ..AssetMesh::default()
        },
        materials: vec![material([1.0, 0.0, 0.0]), material([0.0, 0.0, 1.0])],
        images: Vec::new(),
        parts: Vec::new(),
    };
    let mut level = square(2, 0.98);
    level.triangles.iter_mut().for_each(|t| t.swap(1, 2));
    let options = BakeOptions {
        cage: Some(2.0),
        ..BakeOptions::for_texture(64)
    };
    let baked = bake(&source, &level, &options).unwrap();
    let image = decoded(&baked, 0);
    let inside: Vec<[u8; 3]> = (texel_points(&baked).iter().enumerate())
        .filter(|(_, t)| matches!(t, Some((p, true, _, _)) if p.x > 0.1 && p.x < 0.9 && p.y > 0.1 && p.y < 0.9))
        .map(|(i, _)| [0, 1, 2].map(|k| image.as_raw()[4 * i + k]))
        .collect();
    assert!(inside.len() > 300, "{}", inside.len());
    // Only a ray that meets nothing takes the nearest point (the top's back, 0.02 away): a ray
    // exactly through the bottom's diagonal can slip between its two triangles.
    let odd = inside.iter().filter(|c| !(c[2] > 200 && c[0] < 40)).count();
    let fallback = baked.report.texels_fallback;
    assert!(
        odd <= fallback && fallback * 100 < inside.len(),
        "{odd}, {fallback} of {}",
        inside.len()
    );
}

/// An atlas baked onto another level than its own is refused with a message, not baked.
#[test]
fn an_atlas_of_another_level_is_refused() {
    let source = Asset {
        mesh: cube_source(|_| 0),
        materials: vec![Material::default()],
        ..Asset::default()
    };
    let (small, large) = (proxy_cube(1, 1.0), proxy_cube(2, 1.0));
    let options = BakeOptions::for_texture(64);
    let made = voxlod_bake::atlas(&small, &options.atlas_options()).unwrap();
    let err = voxlod_bake::bake_on(&source, &large, made.clone(), &options).unwrap_err();
    assert!(
        err.to_string().contains("not made from this level"),
        "{err}"
    );
    assert!(voxlod_bake::bake_on(&source, &small, made, &options).is_ok());
}
