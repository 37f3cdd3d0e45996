//! Scenes for the page tests, made in code.

#![allow(dead_code)] // each test file uses some of the helpers

pub mod shots;

use std::path::Path;

use serde_json::json;
use voxlod_core::TriangleMesh;
use voxlod_gltf::ORDER_NAMES;
use voxlod_gltf::{write_chain_glb, ChainLevel, ChainOptions};

/// Cell sizes of the three icosphere levels of [`write_sphere_chain`].
pub const SPHERE_CELLS: [f64; 3] = [0.005, 0.01, 0.02];

/// A unit sphere at the origin as a three-level MSFT_lod chain (icospheres 3, 2, 1 with
/// normals), cells [`SPHERE_CELLS`].
pub fn write_sphere_chain(path: &Path, options: &ChainOptions) -> Vec<TriangleMesh> {
    let meshes: Vec<TriangleMesh> = [3, 2, 1]
        .iter()
        .map(|&k| {
            let mut m = voxlod_testkit::shapes::icosphere(k);
            m.normals = m.positions.clone();
            m
        })
        .collect();
    let levels: Vec<ChainLevel> = meshes
        .iter()
        .zip(SPHERE_CELLS)
        .enumerate()
        .map(|(level, (mesh, cell_size))| ChainLevel::new(level, mesh, cell_size))
        .collect();
    write_chain_glb(path, &levels, options).unwrap();
    meshes
}

/// Two layered "shells" as the layers' .glb lays them out: layer 0 a red square at z = 0,
/// layer 1 a blue square at z = 0.5, both 2 × 2 and of opacity 0.6, with the eight orders
/// (back to front: for view directions with z ≥ 0 the square at z = 0.5 first), isodensities
/// 0.45 and 0.8 (layer 0 is the single surface). `radius` goes
/// in the scene extras as the filter radius.
pub fn write_two_layers(path: &Path, radius: f64) {
    let mut bin = Vec::new();
    for z in [0.0f32, 0.5] {
        for (x, y) in [(-1.0f32, -1.0f32), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            for c in [x, y, z] {
                bin.extend_from_slice(&c.to_le_bytes());
            }
        }
    }
    for _ in 0..8 {
        for c in [0.0f32, 0.0, 1.0] {
            bin.extend_from_slice(&c.to_le_bytes());
        }
    }
    let quad = |base: u32| [base, base + 1, base + 2, base, base + 2, base + 3];
    for _layer in 0..2 {
        for v in quad(0) {
            bin.extend_from_slice(&v.to_le_bytes());
        }
    }
    for octant in 0..8 {
        let z_negative = octant & 1 == 1;
        let (back, front) = if z_negative { (0, 4) } else { (4, 0) };
        for v in quad(back).into_iter().chain(quad(front)) {
            bin.extend_from_slice(&v.to_le_bytes());
        }
    }
    let mut accessors = vec![];
    for layer in 0..2 {
        let z = 0.5 * layer as f64;
        accessors.push(
            json!({"bufferView": 0, "byteOffset": 48 * layer, "componentType": 5126,
            "count": 4, "type": "VEC3", "min": [-1.0, -1.0, z], "max": [1.0, 1.0, z]}),
        );
        accessors.push(
            json!({"bufferView": 1, "byteOffset": 48 * layer, "componentType": 5126,
            "count": 4, "type": "VEC3"}),
        );
        accessors.push(
            json!({"bufferView": 2, "byteOffset": 24 * layer, "componentType": 5125,
            "count": 6, "type": "SCALAR"}),
        );
    }
    for (o, name) in ORDER_NAMES.iter().enumerate() {
        accessors.push(
            json!({"bufferView": 3, "byteOffset": 48 * o, "componentType": 5125,
            "count": 12, "type": "SCALAR", "name": name}),
        );
    }
    let colors = [[1.0, 0.0, 0.0, 0.6], [0.0, 0.0, 1.0, 0.6]];
    let doc = json!({
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 96, "byteStride": 12, "target": 34962},
            {"buffer": 0, "byteOffset": 96, "byteLength": 96, "byteStride": 12, "target": 34962},
            {"buffer": 0, "byteOffset": 192, "byteLength": 48, "target": 34963},
            {"buffer": 0, "byteOffset": 240, "byteLength": 384, "target": 34963},
        ],
        "accessors": accessors,
        "materials": colors.iter().map(|c| json!({"pbrMetallicRoughness": {"baseColorFactor": c},
            "alphaMode": "BLEND", "doubleSided": true})).collect::<Vec<_>>(),
        "meshes": (0..2).map(|i| json!({"name": format!("layer {i}"),
            "extras": {"layer": i, "isodensity": 0.45 + 0.35 * i as f64},
            "primitives": [{"attributes": {"POSITION": 3 * i, "NORMAL": 3 * i + 1},
                "indices": 3 * i + 2, "material": i}]})).collect::<Vec<_>>(),
        "nodes": [{"mesh": 0}, {"mesh": 1}],
        "scenes": [{"nodes": [0, 1], "extras": {"voxlod": {"radius": radius}}}],
        "scene": 0,
    });
    let bytes = voxlod_gltf::to_glb(&doc, bin).unwrap();
    std::fs::write(path, bytes).unwrap();
}

/// A ball of radius 1 at the origin as layered shells at resolutions 16 and 8, chained
/// (`voxlod layers --lod`); returns the two levels' filter radii.
pub fn write_layered_ball_chain(path: &Path) -> [f64; 2] {
    use voxlod_layers::{layer_solid, layered_chain_bytes, GlbOptions, LayeredLevel};
    let solid =
        voxlod_sampling::CsgSolid::new(voxlod_sampling::Shape::sphere(glam::DVec3::ZERO, 1.0))
            .unwrap();
    let levels: Vec<_> = [16, 8]
        .iter()
        .map(|&resolution| {
            let options = voxlod_layers::LayersOptions {
                resolution,
                ..Default::default()
            };
            layer_solid(&solid, &options).unwrap()
        })
        .collect();
    let radii = [
        levels[0].mesh.grid.spacing[0],
        levels[1].mesh.grid.spacing[0],
    ];
    let chain: Vec<LayeredLevel> = levels
        .iter()
        .zip(radii)
        .map(|(l, radius)| LayeredLevel {
            mesh: &l.mesh,
            orders: &l.orders,
            radius,
            looks: None,
        })
        .collect();
    let bytes = layered_chain_bytes(&chain, &GlbOptions::default()).unwrap();
    std::fs::write(path, bytes).unwrap();
    radii
}

/// The `.glb` `bytes` with its JSON chunk replaced by `edit` applied to it.
pub fn edit_glb(bytes: &[u8], edit: impl FnOnce(&mut serde_json::Value)) -> Vec<u8> {
    let glb = gltf::binary::Glb::from_slice(bytes).unwrap();
    let mut doc: serde_json::Value = serde_json::from_slice(&glb.json).unwrap();
    edit(&mut doc);
    let out = gltf::binary::Glb {
        header: glb.header,
        json: serde_json::to_vec(&doc).unwrap().into(),
        bin: glb.bin,
    };
    out.to_vec().unwrap()
}
