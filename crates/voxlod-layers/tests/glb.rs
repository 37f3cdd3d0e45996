//! The `.glb` export: read back exactly (by `voxlod_gltf::read_glb`), laid out as documented,
//! accepted by the Khronos glTF validator (run through the peers' venv when it is installed), and
//! nothing written for inconsistent orders. The reader's own tests are voxlod-gltf's.

mod common;

use std::path::Path;

use voxlod_gltf::read_glb;
use voxlod_layers::{write_glb, GlbOptions, Octant, ORDER_NAMES};

/// Runs the Khronos validator on `path`: (errors, warnings, report), or `None` to skip.
fn validate(path: &Path) -> Option<(u64, u64, String)> {
    let v = voxlod_testkit::gltf_validator::validate_gltf(path)?;
    Some((v.errors, v.warnings, v.report))
}

#[test]
fn glb_round_trips_and_passes_the_validator() {
    let l = common::layered_bolt(40);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bolt.glb");
    write_glb(&path, &l.mesh, &l.orders, &GlbOptions::default()).unwrap();
    let scene = read_glb(&path).unwrap();
    assert!(scene.is_layered());
    assert_eq!(scene.parts.len(), l.mesh.layers.len());
    let cat = l.mesh.concatenated();
    assert_eq!(scene.mesh.positions, cat.mesh.positions);
    assert_eq!(scene.mesh.triangles, cat.mesh.triangles);
    for (part, layer) in scene.parts.iter().zip(&l.mesh.layers) {
        assert_eq!(part.color[3], layer.alpha);
        assert!(part.blend);
        assert_eq!(part.vertex_count as usize, layer.mesh.positions.len());
    }
    assert_eq!(scene.parts[0].color[3], 1.0);
    // The orders are the triangles of the concatenation in the stored order.
    for o in Octant::ALL {
        let stored = scene.orders[o.index()].as_ref().unwrap();
        let expect: Vec<[u32; 3]> = l.orders[o.index()]
            .iter()
            .map(|&t| cat.mesh.triangles[t as usize])
            .collect();
        assert_eq!(stored, &expect, "{}", o.name());
    }
    // The grid comes back, and with it every triangle's cell.
    assert_eq!(scene.grid, Some(l.mesh.grid));
    let cells = voxlod_layers::recover_cells(
        &l.mesh.grid,
        &l.mesh.placement,
        &scene.mesh.positions,
        &scene.mesh.triangles,
    );
    assert_eq!(cells, cat.cells);
    // The accessor names are in the JSON as documented.
    let bytes = std::fs::read(&path).unwrap();
    let text = String::from_utf8_lossy(&bytes);
    for name in ORDER_NAMES {
        assert!(text.contains(&format!("\"name\":\"{name}\"")), "{name}");
    }
    if let Some((errors, warnings, report)) = validate(&path) {
        println!("validator: {report}");
        assert_eq!(errors, 0, "{report}");
        assert_eq!(warnings, 0, "{report}");
    }
}

#[test]
fn bunny_glb_passes_the_validator() {
    let Some(l) = common::layered_bunny(64, "bunny_glb_passes_the_validator") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bunny.glb");
    write_glb(&path, &l.mesh, &l.orders, &GlbOptions::default()).unwrap();
    if let Some((errors, _, report)) = validate(&path) {
        println!("validator: {report}");
        assert_eq!(errors, 0, "{report}");
    }
}

#[test]
fn wrong_orders_are_refused_before_anything_is_written() {
    let l = common::layered_bolt(24);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("x.glb");
    assert!(write_glb(&path, &l.mesh, &l.orders[..7], &GlbOptions::default()).is_err());
    assert!(!path.exists());
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}
