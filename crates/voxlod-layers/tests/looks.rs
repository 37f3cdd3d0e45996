//! Layered shells of a textured asset take its base colour: every layer baked onto its own
//! atlas, written with texture coordinates and a base colour texture, the orders still naming
//! every triangle once per octant, the texels the asset's colours; plain layers unchanged.

use std::collections::HashMap;

use glam::Vec2;
use voxlod_asset::texture::decode;
use voxlod_asset::Asset;
use voxlod_layers::{
    bake_layers, baked_glb_bytes, glb_bytes, has_base_colour, layer_solid, write_baked_glb,
    BakedLayers, GlbOptions, Layered, LayersOptions, LooksOptions, Octant, PlanOptions,
};
use voxlod_sampling::{Filter, MeshSolid};
use voxlod_testkit::assets::{textured_sphere, three_part_scene};

/// The layered shells of `asset`'s geometry at `resolution`, ε = 0.05 (three hyper-cone
/// layers).
fn layered(asset: &Asset, resolution: usize) -> Layered {
    let solid = MeshSolid::new(&asset.mesh.geometry()).unwrap();
    let options = LayersOptions {
        resolution,
        plan: PlanOptions::new(Filter::Hypercone, 0.05),
        ..Default::default()
    };
    layer_solid(&solid, &options).unwrap()
}

fn baked(asset: &Asset, l: &Layered, texture: u32) -> BakedLayers {
    let options = LooksOptions {
        texture,
        ..Default::default()
    };
    bake_layers(asset, &l.mesh, &options).unwrap()
}

/// The JSON chunk of a `.glb`.
fn json_of(bytes: &[u8]) -> serde_json::Value {
    let glb = gltf::binary::Glb::from_slice(bytes).unwrap();
    serde_json::from_slice(&glb.json).unwrap()
}

#[test]
fn textured_layers_carry_texture_coordinates_and_a_base_colour_texture() {
    let asset = textured_sphere(3);
    let l = layered(&asset, 20);
    assert_eq!(l.mesh.layers.len(), 3);
    let b = baked(&asset, &l, 128);
    let bytes = baked_glb_bytes(&b, &l.orders, &GlbOptions::default()).unwrap();
    let doc = json_of(&bytes);
    let meshes = doc["meshes"].as_array().unwrap();
    assert_eq!(meshes.len(), 3);
    assert_eq!(doc["images"].as_array().unwrap().len(), 3);
    assert_eq!(doc["textures"].as_array().unwrap().len(), 3);
    assert_eq!(doc["samplers"].as_array().unwrap().len(), 1);
    for (i, mesh) in meshes.iter().enumerate() {
        let p = &mesh["primitives"][0];
        let uv = p["attributes"]["TEXCOORD_0"].as_u64().unwrap() as usize;
        let vertices = b.mesh.layers[i].mesh.positions.len() as u64;
        assert_eq!(doc["accessors"][uv]["count"], vertices);
        assert_eq!(doc["accessors"][uv]["type"], "VEC2");
        let m = &doc["materials"][p["material"].as_u64().unwrap() as usize];
        let pbr = &m["pbrMetallicRoughness"];
        let t = pbr["baseColorTexture"]["index"].as_u64().unwrap() as usize;
        let image = &doc["images"][doc["textures"][t]["source"].as_u64().unwrap() as usize];
        assert_eq!(image["mimeType"], "image/png");
        assert!(image["bufferView"].is_u64());
        let alpha = l.mesh.layers[i].alpha as f64;
        let factor: Vec<f64> = serde_json::from_value(pbr["baseColorFactor"].clone()).unwrap();
        assert_eq!(factor, vec![1.0, 1.0, 1.0, alpha]);
        assert_eq!(m["alphaMode"], "BLEND");
    }
    // Each texture is the bake's 128² base colour.
    for look in b.looks.iter().flatten() {
        let t = decode(&look.base_color).unwrap();
        assert_eq!((t.width, t.height), (128, 128));
        assert_eq!(
            look.uv.len(),
            look.uv.iter().filter(|p| in_unit(**p)).count()
        );
    }
}

fn in_unit(p: Vec2) -> bool {
    (0.0..=1.0).contains(&p.x) && (0.0..=1.0).contains(&p.y)
}

/// The seams split vertices, so the baked layers have more of them, and the same triangles
/// (by their corners' positions) in the same order, with the same cells.
#[test]
fn baked_layers_keep_every_triangle_in_its_place() {
    let asset = textured_sphere(3);
    let l = layered(&asset, 20);
    let b = baked(&asset, &l, 128);
    for (before, after) in l.mesh.layers.iter().zip(&b.mesh.layers) {
        assert!(after.mesh.positions.len() > before.mesh.positions.len());
        assert_eq!(after.mesh.triangles.len(), before.mesh.triangles.len());
        assert_eq!(after.cells, before.cells);
        assert_eq!(after.alpha, before.alpha);
        for (t, u) in before.mesh.triangles.iter().zip(&after.mesh.triangles) {
            let p =
                |m: &voxlod_core::TriangleMesh, c: &[u32; 3]| c.map(|v| m.positions[v as usize]);
            assert_eq!(p(&before.mesh, t), p(&after.mesh, u));
        }
    }
}

/// xatlas keeps a layer's triangles in their order (what the orders rely on; the layers crate
/// matches them by corners where it would not).
#[test]
fn the_atlas_keeps_each_layers_triangle_order() {
    let asset = textured_sphere(3);
    let l = layered(&asset, 24);
    for layer in &l.mesh.layers {
        let options = voxlod_bake::AtlasOptions::for_texture(256);
        let atlas = voxlod_bake::atlas(&layer.mesh, &options).unwrap();
        assert_eq!(atlas.triangles.len(), layer.mesh.triangles.len());
        let copies = |t: &[u32; 3]| t.map(|v| atlas.level_vertex[v as usize]);
        let kept = atlas
            .triangles
            .iter()
            .zip(&layer.mesh.triangles)
            .filter(|(a, t)| copies(a) == **t)
            .count();
        assert_eq!(kept, layer.mesh.triangles.len());
    }
}

/// Read back: the same layers, and each order holds every triangle exactly once, with its
/// indices in range and the unbaked order's triangle at each place.
#[test]
fn written_orders_hold_every_triangle_once_and_the_validator_is_clean() {
    let asset = textured_sphere(3);
    let l = layered(&asset, 20);
    let b = baked(&asset, &l, 128);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("layers.glb");
    write_baked_glb(&path, &b, &l.orders, &GlbOptions::default()).unwrap();
    let scene = voxlod_gltf::read_glb(&path).unwrap();
    assert!(scene.is_layered());
    assert_eq!(scene.parts.len(), l.mesh.layers.len());
    let triangles = &scene.mesh.triangles;
    assert_eq!(triangles.len(), l.mesh.triangle_count());
    let index: HashMap<[u32; 3], usize> =
        triangles.iter().enumerate().map(|(i, t)| (*t, i)).collect();
    assert_eq!(index.len(), triangles.len());
    let cat = b.mesh.concatenated();
    let vertices = scene.mesh.positions.len() as u32;
    assert_eq!(vertices as usize, b.mesh.vertex_count());
    for o in Octant::ALL {
        let order = scene.orders[o.index()].as_ref().unwrap();
        assert!(order.iter().flatten().all(|&v| v < vertices));
        let mut seen = vec![0u32; triangles.len()];
        for t in order {
            seen[index[t]] += 1;
        }
        assert!(seen.iter().all(|&n| n == 1), "{}", o.name());
        let expect: Vec<[u32; 3]> = l.orders[o.index()]
            .iter()
            .map(|&t| cat.mesh.triangles[t as usize])
            .collect();
        assert_eq!(order, &expect, "{}", o.name());
    }
    if let Some(v) = voxlod_testkit::gltf_validator::validate_gltf(&path) {
        println!("validator: {}", v.report);
        assert_eq!(v.errors, 0, "{}", v.report);
    }
}

/// At most this share of a layer's area may show another colour than the asset's at its
/// triangles' centroids: slivers of marching cubes (a texel or less across, some lying over
/// two charts) may; the rest of a layer may not (at most 0.015 % of a layer's area, 33
/// triangles, measured in the cases below).
const OFF_COLOUR_AREA: f64 = 0.001;

/// A triangle's centroid, area and the colour of the texture there.
struct Sampled {
    centroid: glam::Vec3,
    area: f64,
    colour: glam::Vec3,
}

/// The linear RGB of `texels` (bilinear, clamped) at the centroid of each triangle of `mesh`
/// whose centroid `keep` takes.
fn centroid_colours(
    mesh: &voxlod_core::TriangleMesh,
    uv: &[Vec2],
    texels: &voxlod_asset::texture::Texels,
    keep: impl Fn(glam::Vec3) -> bool,
) -> Vec<Sampled> {
    let sampler = voxlod_asset::Sampler {
        wrap_u: voxlod_asset::Wrap::ClampToEdge,
        wrap_v: voxlod_asset::Wrap::ClampToEdge,
        linear: true,
    };
    let mean3 = |t: &[u32; 3], f: &dyn Fn(usize) -> glam::Vec3| {
        t.iter().map(|&v| f(v as usize)).sum::<glam::Vec3>() / 3.0
    };
    mesh.triangles
        .iter()
        .filter_map(|t| {
            let centroid = mean3(t, &|v| mesh.positions[v]);
            let at = mean3(t, &|v| uv[v].extend(0.0)).truncate();
            let [a, b, c] = t.map(|v| mesh.positions[v as usize]);
            keep(centroid).then(|| Sampled {
                centroid,
                area: (b - a).cross(c - a).length() as f64 / 2.0,
                colour: texels.sample_at(at, &sampler).truncate(),
            })
        })
        .collect()
}

/// Asserts that at most [`OFF_COLOUR_AREA`] of the area of `sampled` (at least `at_least`
/// triangles of layer `layer`) has a colour `right` refuses (given the centroid and the
/// colour).
fn assert_colours(
    layer: usize,
    sampled: &[Sampled],
    at_least: usize,
    right: impl Fn(glam::Vec3, glam::Vec3) -> bool,
) {
    let all = sampled.len();
    let off: Vec<&Sampled> = sampled
        .iter()
        .filter(|s| !right(s.centroid, s.colour))
        .collect();
    let area = |s: &mut dyn Iterator<Item = &Sampled>| s.map(|s| s.area).sum::<f64>();
    let share = area(&mut off.iter().copied()) / area(&mut sampled.iter());
    let n = off.len();
    println!("layer {layer}: {n} of {all} triangles off colour, {share:.5} of the area");
    assert!(all >= at_least, "{all}");
    assert!(share <= OFF_COLOUR_AREA, "{share}");
}

/// The two-halves sphere (red where x < 0, blue where x > 0), read back from the file: at the
/// triangles a fifth of the radius or more from the seam, every layer's texture is the
/// asset's red on the left and blue on the right.
#[test]
fn every_layer_is_red_on_the_left_and_blue_on_the_right() {
    let asset = textured_sphere(3);
    let l = layered(&asset, 20);
    let b = baked(&asset, &l, 256);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("halves.glb");
    write_baked_glb(&path, &b, &l.orders, &GlbOptions::default()).unwrap();
    let read = voxlod_gltf::read_scene(&path).unwrap().asset;
    assert_eq!(read.mesh.triangles.len(), l.mesh.triangle_count());
    assert_eq!(read.materials.len(), 3);
    let right = |p: glam::Vec3, c: glam::Vec3| {
        let (ours, other) = if p.x < 0.0 { (c.x, c.z) } else { (c.z, c.x) };
        ours > 0.9 && other < 0.1 && c.y < 0.05
    };
    for (m, material) in read.materials.iter().enumerate() {
        let slot = material.base_color_texture.as_ref().unwrap();
        let texels = decode(&read.images[slot.image]).unwrap();
        let mut part = read.mesh.clone();
        let mine = |t: &usize| read.mesh.material[*t] as usize == m;
        let triangles = (0..read.mesh.triangles.len()).filter(mine);
        let triangles: Vec<[u32; 3]> = triangles.map(|t| read.mesh.triangles[t]).collect();
        part.triangles = triangles;
        let geometry = part.geometry();
        let colours = centroid_colours(&geometry, &part.uv[0], &texels, |p| p.x.abs() >= 0.2);
        assert_colours(m, &colours, 2000, right);
    }
}

/// The three-part scene: the layers around the plain green sphere apart at (0, 2.2, 0) take
/// its green (linear (0.1, 0.6, 0.1), stored as sRGB).
#[test]
fn a_plain_coloured_part_gives_its_colour() {
    let asset = three_part_scene();
    let l = layered(&asset, 40);
    let b = baked(&asset, &l, 256);
    let green = glam::Vec3::new(0.1, 0.6, 0.1);
    for (i, (layer, look)) in b.mesh.layers.iter().zip(&b.looks).enumerate() {
        let look = look.as_ref().unwrap();
        let texels = decode(&look.base_color).unwrap();
        let colours = centroid_colours(&layer.mesh, &look.uv, &texels, |p| p.y >= 1.9);
        assert_colours(i, &colours, 500, |_, c| {
            (c - green).abs().max_element() < 0.02
        });
    }
}

/// A plain mesh's layers as before: no texture coordinate, image, texture or sampler.
#[test]
fn plain_layers_have_no_looks() {
    let asset = textured_sphere(2);
    assert!(has_base_colour(&asset));
    let plain = Asset {
        mesh: voxlod_asset::AssetMesh {
            positions: asset.mesh.positions.clone(),
            triangles: asset.mesh.triangles.clone(),
            ..Default::default()
        },
        ..Default::default()
    };
    assert!(!has_base_colour(&plain));
    let l = layered(&asset, 16);
    let bytes = glb_bytes(&l.mesh, &l.orders, &GlbOptions::default()).unwrap();
    let doc = json_of(&bytes);
    for key in ["images", "textures", "samplers"] {
        assert!(doc.get(key).is_none(), "{key}");
    }
    let text = String::from_utf8_lossy(&bytes);
    assert!(!text.contains("TEXCOORD"));
    assert!(!text.contains("baseColorTexture"));
}

#[test]
fn bad_looks_are_refused() {
    let asset = textured_sphere(2);
    let l = layered(&asset, 16);
    for texture in [4, 20000] {
        let options = LooksOptions {
            texture,
            ..Default::default()
        };
        let e = bake_layers(&asset, &l.mesh, &options).unwrap_err();
        assert!(e.to_string().contains("8 to 16384"), "{e}");
    }
    let mut b = baked(&asset, &l, 64);
    b.looks[1] = None;
    let e = baked_glb_bytes(&b, &l.orders, &GlbOptions::default()).unwrap_err();
    assert!(
        e.to_string().contains("layer 1 has triangles and no looks"),
        "{e}"
    );
    let mut b = baked(&asset, &l, 64);
    b.looks[0].as_mut().unwrap().uv.pop();
    let e = baked_glb_bytes(&b, &l.orders, &GlbOptions::default()).unwrap_err();
    assert!(e.to_string().contains("texture coordinates for"), "{e}");
}
