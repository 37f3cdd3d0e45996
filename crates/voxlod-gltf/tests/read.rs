//! The reader: a chain reads back as its finest level, layered shells as their layers with the
//! orders, and a broken file is refused with an error, never a panic.

mod common;

use std::path::Path;

use common::{chain_levels, sphere_chain};
use voxlod::layers::{glb_bytes, layer_solid, GlbOptions, LayersOptions};
use voxlod::sampling::csg::{CsgSolid, Shape};
use voxlod_gltf::{chain_glb_bytes, parse_glb, read_glb, ChainOptions, ORDER_NAMES};

#[test]
fn a_chain_reads_back_as_its_finest_level() {
    let chain = sphere_chain();
    let bytes = chain_glb_bytes(&chain_levels(&chain), &ChainOptions::default()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sphere.glb");
    std::fs::write(&path, &bytes).unwrap();
    let scene = read_glb(&path).unwrap();
    let finest = &chain[0].1;
    assert_eq!(scene.parts.len(), 1);
    assert_eq!(scene.mesh.positions, finest.positions);
    assert_eq!(scene.mesh.triangles, finest.triangles);
    assert_eq!(
        scene.parts[0].triangle_count as usize,
        finest.triangles.len()
    );
    assert!(!scene.is_layered());
    assert!(scene.orders.iter().all(Option::is_none));
    assert_eq!(scene.grid, None);
}

/// A layered file of a small ball: eight orders, five layers.
fn layered_ball() -> Vec<u8> {
    let solid = CsgSolid::new(Shape::sphere(glam::DVec3::ZERO, 1.0)).unwrap();
    let options = LayersOptions {
        resolution: 24,
        ..Default::default()
    };
    let layered = layer_solid(&solid, &options).unwrap();
    glb_bytes(&layered.mesh, &layered.orders, &GlbOptions::default()).unwrap()
}

#[test]
fn broken_files_are_refused_without_panic() {
    let chain = sphere_chain();
    let plain = chain_glb_bytes(&chain_levels(&chain), &ChainOptions::default()).unwrap();
    for bytes in [plain, layered_ball()] {
        assert!(parse_glb(&bytes).is_ok());
        // Truncations, a corrupted length, garbage.
        for cut in [0, 11, 20, bytes.len() / 2, bytes.len() - 1] {
            assert!(parse_glb(&bytes[..cut]).is_err(), "cut at {cut}");
        }
        let mut bad = bytes.clone();
        bad[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(parse_glb(&bad).is_err());
        // A BIN chunk shorter than the accessors need: shrink the chunk length and the file.
        let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
        let bin_at = 20 + json_len;
        let mut short = bytes[..bin_at + 8 + 64].to_vec();
        short[bin_at..bin_at + 4].copy_from_slice(&64u32.to_le_bytes());
        let total = short.len() as u32;
        short[8..12].copy_from_slice(&total.to_le_bytes());
        let e = parse_glb(&short).unwrap_err().to_string();
        assert!(e.contains("beyond"), "{e}");
    }
    assert!(parse_glb(b"glTF not really").is_err());
    let e = read_glb(Path::new("/nonexistent/x.glb"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("/nonexistent/x.glb"), "{e}");
}

#[test]
fn orders_are_read_by_name_and_checked() {
    let bytes = layered_ball();
    let scene = parse_glb(&bytes).unwrap();
    assert!(scene.is_layered());
    // Without the first order's name, the other seven are still read.
    let renamed = with_order(&bytes, |order| order["name"] = "not an order".into());
    let scene = parse_glb(&renamed).unwrap();
    assert!(!scene.is_layered());
    assert!(scene.orders[0].is_none() && scene.orders[1..].iter().all(Option::is_some));
    // An order of two indices is no triangle list: refused, naming the order.
    let short = with_order(&bytes, |order| order["count"] = 2.into());
    let e = parse_glb(&short).unwrap_err().to_string();
    assert!(
        e.contains(ORDER_NAMES[0]) && e.contains("not a triangle list"),
        "{e}"
    );
}

/// The file with the accessor of the first order changed by `change`.
fn with_order(bytes: &[u8], change: impl FnOnce(&mut serde_json::Value)) -> Vec<u8> {
    let glb = gltf::binary::Glb::from_slice(bytes).unwrap();
    let mut doc: serde_json::Value = serde_json::from_slice(&glb.json).unwrap();
    let accessors = doc["accessors"].as_array_mut().unwrap();
    let order = accessors
        .iter_mut()
        .find(|a| a["name"] == ORDER_NAMES[0])
        .unwrap();
    change(order);
    voxlod_gltf::to_glb(&doc, glb.bin.unwrap().into_owned()).unwrap()
}
