//! PLY and VTK PolyData export: per-vertex `opacity` and `layer`, read back through voxlod-io.

mod common;

use voxlod_layers::{to_poly_mesh, write_layered_mesh};

#[test]
fn ply_vtp_and_vtk_carry_opacity_and_layer() {
    let l = common::layered_bolt(24);
    let dir = tempfile::tempdir().unwrap();
    let expect = to_poly_mesh(&l.mesh, Some(&l.orders[2])).unwrap();
    for ext in ["ply", "vtp", "vtk"] {
        let path = dir.path().join(format!("bolt.{ext}"));
        write_layered_mesh(&path, &l.mesh, Some(&l.orders[2])).unwrap();
        let back = voxlod_io::read_poly_mesh(&path).unwrap();
        assert_eq!(back.mesh.triangles, expect.mesh.triangles, "{ext}");
        for name in ["opacity", "layer"] {
            let got = back
                .vertex_attributes
                .iter()
                .find(|a| a.name == name)
                .unwrap_or_else(|| panic!("{ext}: no {name}"));
            let want = expect
                .vertex_attributes
                .iter()
                .find(|a| a.name == name)
                .unwrap();
            assert_eq!(got.values, want.values, "{ext} {name}");
        }
    }
    // Layer indices and opacities agree with the layers.
    let mut start = 0;
    for (i, layer) in l.mesh.layers.iter().enumerate() {
        let n = layer.mesh.positions.len();
        assert!(expect.vertex_attributes[1].values[start..start + n]
            .iter()
            .all(|&x| x == i as f32));
        assert!(expect.vertex_attributes[0].values[start..start + n]
            .iter()
            .all(|&x| x == layer.alpha));
        start += n;
    }
    // Not a permutation: refused, nothing written.
    let path = dir.path().join("bad.ply");
    let mut order = l.orders[0].clone();
    order[0] = order[1];
    assert!(write_layered_mesh(&path, &l.mesh, Some(&order)).is_err());
    assert!(!path.exists());
}
