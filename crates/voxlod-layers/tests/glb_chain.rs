//! Layered levels as one `MSFT_lod` chain: one mesh per level with a primitive per layer, each
//! level's eight orders, coverages from the 0.45 px radius rule; read back as its finest level;
//! accepted by the Khronos validator (when the peers' kit is installed); bad chains refused.

use glam::DVec3;
use serde_json::Value;
use voxlod_layers::{
    layer_solid, layered_chain_bytes, GlbOptions, Layered, LayeredLevel, LayersOptions, Octant,
    ORDER_NAMES, RADIUS_LIMIT_PIXELS,
};
use voxlod_sampling::{CsgSolid, Shape};

/// A ball of radius 1 layered at resolutions 16 and 8 (five hyper-cone layers each).
fn ball_levels() -> Vec<Layered> {
    let solid = CsgSolid::new(Shape::sphere(DVec3::new(0.5, 0.0, -1.0), 1.0)).unwrap();
    [16, 8]
        .iter()
        .map(|&resolution| {
            let options = LayersOptions {
                resolution,
                ..Default::default()
            };
            layer_solid(&solid, &options).unwrap()
        })
        .collect()
}

fn chain(levels: &[Layered]) -> Vec<LayeredLevel<'_>> {
    levels
        .iter()
        .map(|l| LayeredLevel {
            mesh: &l.mesh,
            orders: &l.orders,
            radius: l.mesh.grid.spacing[0],
            looks: None,
        })
        .collect()
}

fn json_of(glb: &[u8]) -> Value {
    let glb = gltf::binary::Glb::from_slice(glb).unwrap();
    serde_json::from_slice(&glb.json).unwrap()
}

#[test]
fn a_layered_chain_has_a_mesh_per_level_and_a_primitive_per_layer() {
    let levels = ball_levels();
    assert!(levels.iter().all(|l| l.mesh.layers.len() == 5));
    assert!(levels.iter().all(|l| l
        .mesh
        .layers
        .iter()
        .all(|layer| !layer.mesh.triangles.is_empty())));
    let bytes = layered_chain_bytes(&chain(&levels), &GlbOptions::default()).unwrap();
    let gltf = gltf::Gltf::from_slice(&bytes).unwrap();
    assert_eq!(gltf.meshes().count(), 2);
    assert_eq!(gltf.nodes().count(), 2);
    assert_eq!(gltf.scenes().next().unwrap().nodes().count(), 1);
    assert!(gltf.meshes().all(|m| m.primitives().count() == 5));
    // Per level: positions, normals and indices of five layers, and eight orders.
    assert_eq!(gltf.accessors().count(), 2 * (5 * 3 + 8));
    assert_eq!(gltf.materials().count(), 10);
    let doc = json_of(&bytes);
    assert_eq!(doc["extensionsUsed"], serde_json::json!(["MSFT_lod"]));
    assert_eq!(
        doc["nodes"][0]["extensions"]["MSFT_lod"]["ids"],
        serde_json::json!([1])
    );
    // Level 1 gives way to nothing; level 0 to level 1 once level 1's radius fits 0.45 px:
    // c = 0.45 · D / (1080 · r₁).
    let coverage = doc["nodes"][0]["extras"]["MSFT_screencoverage"]
        .as_array()
        .unwrap();
    let sc = &doc["scenes"][0]["extras"]["voxlod"]["screen_coverage"];
    let d = sc["diameter"].as_f64().unwrap();
    let r1 = levels[1].mesh.grid.spacing[0];
    let expect = RADIUS_LIMIT_PIXELS * d / (1080.0 * r1);
    assert!(
        (coverage[0].as_f64().unwrap() - expect).abs() < 1e-12,
        "{coverage:?}"
    );
    assert_eq!(coverage[1], 0.0);
    assert_eq!(sc["tolerance"], RADIUS_LIMIT_PIXELS);
    assert_eq!(sc["measure"], "filter radius");
    // Each level's extras list its eight order accessors, named by level and octant.
    for (k, level) in levels.iter().enumerate() {
        let orders = doc["meshes"][k]["extras"]["voxlod"]["orders"]
            .as_array()
            .unwrap();
        assert_eq!(orders.len(), 8);
        let cat = level.mesh.concatenated();
        for (o, a) in orders.iter().enumerate() {
            let acc = gltf.accessors().nth(a.as_u64().unwrap() as usize).unwrap();
            assert_eq!(
                acc.name(),
                Some(format!("level {k} {}", ORDER_NAMES[o]).as_str())
            );
            assert_eq!(acc.count(), cat.mesh.triangles.len() * 3);
        }
    }
}

#[test]
fn a_layered_chain_reads_back_as_its_finest_level() {
    let levels = ball_levels();
    let bytes = layered_chain_bytes(&chain(&levels), &GlbOptions::default()).unwrap();
    let scene = voxlod_gltf::parse_glb(&bytes).unwrap();
    let finest = &levels[0];
    let cat = finest.mesh.concatenated();
    assert!(scene.is_layered());
    assert_eq!(scene.parts.len(), 5);
    assert_eq!(scene.mesh.positions, cat.mesh.positions);
    assert_eq!(scene.mesh.triangles, cat.mesh.triangles);
    assert_eq!(scene.grid, Some(finest.mesh.grid));
    for o in Octant::ALL {
        let expect: Vec<[u32; 3]> = finest.orders[o.index()]
            .iter()
            .map(|&t| cat.mesh.triangles[t as usize])
            .collect();
        assert_eq!(
            scene.orders[o.index()].as_ref(),
            Some(&expect),
            "{}",
            o.name()
        );
    }
}

#[test]
fn a_layered_chain_passes_the_validator() {
    let levels = ball_levels();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("chain.glb");
    let bytes = layered_chain_bytes(&chain(&levels), &GlbOptions::default()).unwrap();
    std::fs::write(&path, bytes).unwrap();
    if let Some(v) = voxlod_testkit::gltf_validator::validate_gltf(&path) {
        assert_eq!((v.errors, v.warnings), (0, 0), "{}", v.report);
    }
}

#[test]
fn bad_layered_chains_are_refused() {
    let levels = ball_levels();
    let mut swapped = chain(&levels);
    swapped.reverse();
    let e = layered_chain_bytes(&swapped, &GlbOptions::default()).unwrap_err();
    assert!(e.to_string().contains("grow strictly"), "{e}");
    assert!(layered_chain_bytes(&[], &GlbOptions::default()).is_err());
    let mut short = chain(&levels);
    short[1].orders = &levels[1].orders[..7];
    let e = layered_chain_bytes(&short, &GlbOptions::default()).unwrap_err();
    assert!(e.to_string().contains("eight orders"), "{e}");
}
