//! The chain read back: with the `gltf` crate for plain files, through `decompress_glb` and the
//! meshopt decoder for compressed ones. One mesh per level, the MSFT_lod chain finest to
//! coarsest, coverages decreasing and agreeing with `voxlod::select`, triangle counts and
//! positions equal to the levels'.

mod common;

use common::{chain_levels, lines_and_points, sphere_chain, two_cluster_levels};
use glam::Vec3;
use serde_json::Value;
use voxlod::select::{select, SelectOptions, Selection};
use voxlod_gltf::{
    chain_glb_bytes, decompress_glb, pixel_size_at, ChainLevel, ChainOptions, Compression,
    CoverageOptions,
};

fn json_of(glb: &[u8]) -> Value {
    let glb = gltf::binary::Glb::from_slice(glb).unwrap();
    serde_json::from_slice(&glb.json).unwrap()
}

#[test]
fn plain_chain_reads_back_with_the_gltf_crate() {
    let chain = sphere_chain();
    let bytes = chain_glb_bytes(&chain_levels(&chain), &ChainOptions::default()).unwrap();
    let gltf = gltf::Gltf::from_slice(&bytes).unwrap();
    let blob = gltf.blob.clone().unwrap();
    assert_eq!(gltf.meshes().count(), chain.len());
    assert_eq!(gltf.scenes().next().unwrap().nodes().count(), 1);
    for (mesh, (_, level, _)) in gltf.meshes().zip(&chain) {
        let prim = mesh.primitives().next().unwrap();
        let reader = prim.reader(|b| (b.index() == 0).then_some(&blob[..]));
        let positions: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
        let normals: Vec<[f32; 3]> = reader.read_normals().unwrap().collect();
        let indices: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
        assert_eq!(indices.len(), level.triangles.len() * 3);
        assert_eq!(positions.len(), level.positions.len());
        assert_eq!(normals.len(), positions.len());
        let flat: Vec<u32> = level.triangles.iter().flatten().copied().collect();
        assert_eq!(indices, flat);
        for (p, q) in positions.iter().zip(&level.positions) {
            assert_eq!(
                Vec3::from(*p),
                *q,
                "positions are stored as given, in input units"
            );
        }
        for n in &normals {
            assert!((Vec3::from(*n).length() - 1.0).abs() < 1e-5);
        }
    }
}

#[test]
fn the_msft_lod_chain_runs_finest_to_coarsest_with_decreasing_coverage() {
    let chain = sphere_chain();
    let bytes = chain_glb_bytes(&chain_levels(&chain), &ChainOptions::default()).unwrap();
    let doc = json_of(&bytes);
    assert_eq!(doc["extensionsUsed"], serde_json::json!(["MSFT_lod"]));
    let node0 = &doc["nodes"][0];
    let ids: Vec<u64> = node0["extensions"]["MSFT_lod"]["ids"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_u64().unwrap())
        .collect();
    assert_eq!(ids, vec![1, 2]);
    let triangles: Vec<u64> = (0..3)
        .map(|n| {
            doc["nodes"][n]["extras"]["voxlod"]["triangles"]
                .as_u64()
                .unwrap()
        })
        .collect();
    assert!(
        triangles[0] > triangles[1] && triangles[1] > triangles[2],
        "{triangles:?}"
    );
    for (n, (_, mesh, _)) in chain.iter().enumerate() {
        assert_eq!(triangles[n], mesh.triangles.len() as u64);
    }
    let coverage: Vec<f64> = node0["extras"]["MSFT_screencoverage"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert_eq!(coverage.len(), 3);
    assert!(coverage[0] > coverage[1] && coverage[1] > coverage[2] && coverage[2] == 0.0);
}

/// Between two coverage entries, `voxlod select` picks exactly the level MSFT_lod draws there.
#[test]
fn coverage_bands_agree_with_voxlod_select() {
    let chain = sphere_chain();
    let options = ChainOptions::default();
    let doc = json_of(&chain_glb_bytes(&chain_levels(&chain), &options).unwrap());
    let coverage: Vec<f64> =
        serde_json::from_value(doc["nodes"][0]["extras"]["MSFT_screencoverage"].clone()).unwrap();
    let diameter = doc["scenes"][0]["extras"]["voxlod"]["screen_coverage"]["diameter"]
        .as_f64()
        .unwrap();
    let cells: Vec<f64> = chain.iter().map(|c| c.2).collect();
    let o = CoverageOptions::default();
    let upper = |k: usize| {
        if k == 0 {
            10.0 * coverage[0]
        } else {
            coverage[k - 1]
        }
    };
    for (k, &lower) in coverage.iter().enumerate() {
        for t in [0.01, 0.5, 0.99] {
            let c = lower + t * (upper(k) - lower);
            let pixel = pixel_size_at(c, diameter, &o);
            let picked = select(&cells, pixel, &SelectOptions::side()).unwrap();
            let expected = if k == 0 {
                [Selection::Original, Selection::Level(0)]
            } else {
                [Selection::Level(k); 2]
            };
            assert!(
                expected.contains(&picked),
                "coverage {c}: level {k} drawn, select says {picked:?}"
            );
        }
    }
}

#[test]
fn compressed_chain_decodes_to_the_same_triangles() {
    let chain = sphere_chain();
    let levels = chain_levels(&chain);
    let plain = chain_glb_bytes(&levels, &ChainOptions::default()).unwrap();
    let packed = chain_glb_bytes(&levels, &ChainOptions::meshopt()).unwrap();
    assert!(
        packed.len() * 2 < plain.len(),
        "{} vs {} bytes",
        packed.len(),
        plain.len()
    );
    let doc = json_of(&packed);
    assert_eq!(
        doc["extensionsRequired"],
        serde_json::json!(["EXT_meshopt_compression", "KHR_mesh_quantization"])
    );
    let decoded = decompress_glb(&packed).unwrap();
    let glb = gltf::binary::Glb::from_slice(&decoded).unwrap();
    let mut root: gltf::json::Root = gltf::json::deserialize::from_slice(&glb.json).unwrap();
    assert_eq!(
        root.extensions_required,
        vec!["KHR_mesh_quantization".to_string()]
    );
    root.extensions_required.clear(); // the gltf crate validates only what it decodes itself
    let document = gltf::Document::from_json(root).unwrap();
    let blob = glb.bin.unwrap().to_vec();
    for (node, (_, level, _)) in document.nodes().zip(&chain) {
        let (t, _, s) = node.transform().decomposed();
        let prim = node.mesh().unwrap().primitives().next().unwrap();
        let reader = prim.reader(|b| (b.index() == 0).then_some(&blob[..]));
        let acc = prim.get(&gltf::Semantic::Positions).unwrap();
        assert_eq!(
            acc.data_type(),
            gltf::accessor::DataType::U16,
            "quantized positions"
        );
        let view = acc.view().unwrap();
        let stride = view.stride().unwrap();
        let base = view.offset() + acc.offset();
        let positions: Vec<Vec3> = (0..acc.count())
            .map(|e| {
                let at = base + e * stride;
                let c =
                    |k: usize| u16::from_le_bytes([blob[at + 2 * k], blob[at + 2 * k + 1]]) as f32;
                Vec3::new(c(0), c(1), c(2))
            })
            .collect();
        let indices: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
        assert_eq!(indices.len(), level.triangles.len() * 3);
        // The decoded grid points, and the input's positions put on the node's grid.
        let (offset, step) = (Vec3::from(t), s[0]);
        let on_grid = |p: Vec3| ((p - offset) / step).round();
        let mut got: Vec<[[i64; 3]; 3]> = indices
            .chunks(3)
            .map(|c| canonical([0, 1, 2].map(|k| positions[c[k] as usize])))
            .collect();
        let mut want: Vec<[[i64; 3]; 3]> = level
            .triangles
            .iter()
            .map(|t| canonical(t.map(|v| on_grid(level.positions[v as usize]))))
            .collect();
        got.sort();
        want.sort();
        let differing = got.iter().zip(&want).filter(|(a, b)| a != b).count();
        assert_eq!(differing, 0, "the same triangles on the 14-bit grid");
    }
}

/// A triangle's corners (grid points), rotated to start at the smallest corner (orientation
/// kept).
fn canonical(t: [Vec3; 3]) -> [[i64; 3]; 3] {
    let q = t.map(|p| p.as_i64vec3().to_array());
    let m = (0..3).min_by_key(|&i| q[i]).unwrap();
    [q[m], q[(m + 1) % 3], q[(m + 2) % 3]]
}

#[test]
fn bad_chains_are_refused() {
    let chain = sphere_chain();
    let mut levels = chain_levels(&chain);
    levels[1].cell_size = levels[0].cell_size;
    assert!(chain_glb_bytes(&levels, &ChainOptions::default()).is_err());
    let empty = voxlod::core::TriangleMesh::default();
    let none = [voxlod_gltf::ChainLevel::new(0, &empty, 1.0)];
    let e = chain_glb_bytes(&none, &ChainOptions::default()).unwrap_err();
    assert!(e.to_string().contains("no level has a triangle"), "{e}");
    let o = ChainOptions {
        compression: Compression::Meshopt,
        ..Default::default()
    };
    assert!(chain_glb_bytes(&none, &o).is_err());
}

#[test]
fn corrupt_compressed_files_are_errors_not_panics() {
    let chain = sphere_chain();
    let packed = chain_glb_bytes(&chain_levels(&chain), &ChainOptions::meshopt()).unwrap();
    assert!(decompress_glb(&packed[..packed.len() / 2]).is_err());
    assert!(decompress_glb(b"glTF but not really").is_err());
    // Flip bytes in the middle of the binary chunk: either an error or a decoded file.
    let mut broken = packed.clone();
    let mid = broken.len() - 200;
    for b in &mut broken[mid..mid + 50] {
        *b ^= 0xA5;
    }
    let _ = decompress_glb(&broken);
}

#[test]
fn lines_and_points_are_primitives_of_their_own() {
    let parts = lines_and_points();
    let levels = two_cluster_levels(&parts);
    let bytes = chain_glb_bytes(&levels, &ChainOptions::default()).unwrap();
    let gltf = gltf::Gltf::from_slice(&bytes).unwrap();
    let blob = gltf.blob.clone().unwrap();
    // Level 0: triangles (positions, normals, indices), lines (positions, _WIDTH), points
    // (positions); level 1: triangles and points. Two materials: surface, edges and points.
    assert_eq!(gltf.accessors().count(), 3 + 2 + 1 + 3 + 1);
    assert_eq!(gltf.materials().count(), 2);
    let modes: Vec<Vec<gltf::mesh::Mode>> = gltf
        .meshes()
        .map(|m| m.primitives().map(|p| p.mode()).collect())
        .collect();
    use gltf::mesh::Mode::{Lines, Points, Triangles};
    assert_eq!(
        modes,
        vec![vec![Triangles, Lines, Points], vec![Triangles, Points]]
    );
    let level0 = gltf.meshes().next().unwrap();
    let prims: Vec<_> = level0.primitives().collect();
    let read = |p: &gltf::Primitive| -> Vec<[f32; 3]> {
        p.reader(|b| (b.index() == 0).then_some(&blob[..]))
            .read_positions()
            .unwrap()
            .collect()
    };
    // The lines' own vertices, two per line, in order; their widths twice each.
    assert_eq!(
        read(&prims[1]),
        vec![
            [2.0, 0.0, 0.0],
            [3.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [1.0, 0.0, 0.0]
        ]
    );
    assert!(prims[1].indices().is_none());
    let width = prims[1]
        .attributes()
        .find(|(s, _)| *s == gltf::Semantic::Extras("WIDTH".into()))
        .map(|(_, a)| a)
        .unwrap();
    assert_eq!(
        (width.count(), width.data_type()),
        (4, gltf::accessor::DataType::F32)
    );
    let view = width.view().unwrap();
    let at = view.offset() + width.offset();
    let w: Vec<f32> = blob[at..at + 16]
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    assert_eq!(w, vec![0.1, 0.1, 0.25, 0.25]);
    assert_eq!(read(&prims[2]), vec![[0.0, 2.0, 1.0], [-1.0, 2.0, 1.0]]);
    // The triangles keep all eight vertices (the ones of lines and points included).
    assert_eq!(read(&prims[0]).len(), 8);
}

#[test]
fn bad_lines_and_points_are_refused() {
    let (mesh, lines, widths, points) = lines_and_points();
    let chain = |level: ChainLevel| chain_glb_bytes(&[level], &ChainOptions::default());
    let e = chain(ChainLevel::new(0, &mesh, 1.0).with_lines(&lines, &widths[..1])).unwrap_err();
    assert!(e.to_string().contains("1 line widths for 2 lines"), "{e}");
    let far = [[0, 8]];
    let e = chain(ChainLevel::new(0, &mesh, 1.0).with_lines(&far, &[])).unwrap_err();
    assert!(e.to_string().contains("beyond"), "{e}");
    let e = chain(ChainLevel::new(0, &mesh, 1.0).with_points(&[9])).unwrap_err();
    assert!(e.to_string().contains("beyond"), "{e}");
    let nan = [f32::NAN, 1.0];
    let e = chain(ChainLevel::new(0, &mesh, 1.0).with_lines(&lines, &nan)).unwrap_err();
    assert!(e.to_string().contains("not finite"), "{e}");
    let packed = ChainLevel::new(0, &mesh, 1.0).with_points(&points);
    let e = chain_glb_bytes(&[packed], &ChainOptions::meshopt()).unwrap_err();
    assert!(e.to_string().contains("without compression"), "{e}");
    // A level of points only is a chain level of its own.
    let empty = voxlod::core::TriangleMesh::new(mesh.positions.clone(), vec![]);
    let only_points = chain(ChainLevel::new(0, &empty, 1.0).with_points(&points));
    assert!(only_points.is_ok(), "{only_points:?}");
}
