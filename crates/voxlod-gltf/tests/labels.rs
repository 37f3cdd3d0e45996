//! The labels' file: one node per label with triangles, named and coloured, each vertex
//! carrying its label; it reads back with the reader as one part per label.

use voxlod::core::TriangleMesh;
use voxlod_gltf::{labels_glb, parse_glb, LabelMesh};
use voxlod_testkit::shapes::{icosphere, unit_cube};

/// The JSON chunk of a `.glb`.
fn json_chunk(bytes: &[u8]) -> serde_json::Value {
    let length = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    serde_json::from_slice(&bytes[20..20 + length]).unwrap()
}

#[test]
fn every_label_with_triangles_is_one_named_coloured_node_with_its_value_per_vertex() {
    let cube = unit_cube();
    let ball = icosphere(2);
    let empty = TriangleMesh::default();
    let labels = [
        LabelMesh {
            value: 4,
            name: Some("Left Kidney"),
            color: Some([0.9, 0.1, 0.2]),
            mesh: &cube,
        },
        LabelMesh {
            value: 9,
            name: None,
            color: None,
            mesh: &empty,
        },
        LabelMesh {
            value: 12,
            name: None,
            color: None,
            mesh: &ball,
        },
    ];
    let bytes = labels_glb(&labels).unwrap();
    let doc = json_chunk(&bytes);
    let nodes = doc["nodes"].as_array().unwrap();
    assert_eq!(nodes.len(), 2, "the empty label gets no node");
    assert_eq!(nodes[0]["name"], "label 4 (Left Kidney)");
    assert_eq!(nodes[0]["extras"]["label"], 4);
    assert_eq!(nodes[0]["extras"]["name"], "Left Kidney");
    assert_eq!(nodes[1]["name"], "label 12");
    assert!(nodes[1]["extras"]["name"].is_null());
    assert!(doc.get("extensionsUsed").is_none(), "plain glTF");
    let scene = parse_glb(&bytes).unwrap();
    assert_eq!(scene.parts.len(), 2);
    for (part, (mesh, color)) in scene
        .parts
        .iter()
        .zip([(&cube, [0.9, 0.1, 0.2, 1.0]), (&ball, [0.8, 0.8, 0.8, 1.0])])
    {
        assert_eq!(part.triangle_count as usize, mesh.triangles.len());
        assert_eq!(part.vertex_count as usize, mesh.positions.len());
        assert_eq!(part.color, color);
    }
    assert_eq!(
        scene.mesh.triangles.len(),
        cube.triangles.len() + ball.triangles.len()
    );
    // `_LABEL`: one float per vertex, the label's value, as its bounds say.
    for (n, value) in [(0, 4.0), (1, 12.0)] {
        let mesh = &doc["meshes"][nodes[n]["mesh"].as_u64().unwrap() as usize];
        let accessor = &doc["accessors"][mesh["primitives"][0]["attributes"]["_LABEL"]
            .as_u64()
            .unwrap() as usize];
        assert_eq!(accessor["componentType"], 5126);
        assert_eq!(accessor["min"][0], value);
        assert_eq!(accessor["max"][0], value);
        assert_eq!(
            accessor["count"].as_u64().unwrap() as u32,
            scene.parts[n].vertex_count
        );
    }
}

#[test]
fn no_label_with_triangles_is_an_empty_scene() {
    let empty = TriangleMesh::default();
    let bytes = labels_glb(&[LabelMesh {
        value: 1,
        name: None,
        color: None,
        mesh: &empty,
    }])
    .unwrap();
    let doc = json_chunk(&bytes);
    assert!(doc["nodes"].as_array().unwrap().is_empty());
}
