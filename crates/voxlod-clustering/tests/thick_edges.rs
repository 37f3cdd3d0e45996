//! Thick-edge widths on thin parts of known cross-section.

mod common;

use std::f32::consts::PI;

use voxlod_clustering::thick_edges::{dynamic_normal, NORMAL, WIDTH};
use voxlod_clustering::{low_tan, rossignac_borrel, ClusterOptions, FloatingCellOptions, Level};
use voxlod_core::glam::Vec3;
use voxlod_core::{PolyMesh, TriangleMesh};

fn attribute<'a>(poly: &'a PolyMesh, name: &str) -> &'a [f32] {
    &poly
        .line_attributes
        .iter()
        .find(|a| a.name == name)
        .unwrap()
        .values
}

/// A rod of diameter 0.02 (a 32-gon) and 10 long: its cross-section perimeter is
/// 32 · 0.02 · sin(π/32), and Cauchy's mean width is that over π.
fn rod() -> (TriangleMesh, f32) {
    let d = 0.02;
    let mesh = common::prism(&common::round_section(32, d), 10.0, 0.1);
    (mesh, 32.0 * d * (PI / 32.0).sin() / PI)
}

/// A slab 0.04 wide and 0.01 thick, 10 long: mean width 2 (w + d) / π.
fn slab() -> (TriangleMesh, f32) {
    let (w, d) = (0.04, 0.01);
    let section = [
        (-w / 2.0, -d / 2.0),
        (w / 2.0, -d / 2.0),
        (w / 2.0, d / 2.0),
        (-w / 2.0, d / 2.0),
    ];
    (common::prism(&section, 10.0, 0.1), 2.0 * (w + d) / PI)
}

fn check_normals(level: &Level) {
    let poly = &level.mesh;
    for (i, &[a, b]) in poly.lines.iter().enumerate() {
        let n = Vec3::new(
            attribute(poly, NORMAL[0])[i],
            attribute(poly, NORMAL[1])[i],
            attribute(poly, NORMAL[2])[i],
        );
        let u = (poly.mesh.positions[b as usize] - poly.mesh.positions[a as usize]).normalize();
        assert!(
            (n.length() - 1.0).abs() < 1e-4 && n.dot(u).abs() < 1e-4,
            "normal {n} for edge {u}"
        );
        // Turned towards a viewer above, it faces up.
        let seen = dynamic_normal(
            poly.mesh.positions[a as usize],
            poly.mesh.positions[b as usize],
            n,
            Vec3::Z,
        );
        assert!(seen.z > 0.99, "{seen}");
    }
}

#[test]
fn grid_clustering_of_thin_parts_gives_their_width() {
    for (name, (mesh, expected)) in [("rod", rod()), ("slab", slab())] {
        // Cells of 1 along the 10-unit part: 10 clusters in a chain, 9 dangling edges.
        let level = rossignac_borrel(&mesh, &ClusterOptions::smoothing(10).with_thick_edges(true))
            .unwrap()
            .pop()
            .unwrap();
        common::assert_valid(&mesh, &level, name);
        assert_eq!(
            (
                level.report.triangles,
                level.report.dangling_edges,
                level.report.isolated_points
            ),
            (0, 9, 0),
            "{name}"
        );
        for &w in attribute(&level.mesh, WIDTH) {
            assert!(
                (w - expected).abs() < 1e-3 * expected,
                "{name}: width {w}, expected {expected}"
            );
        }
        check_normals(&level);
        // Without the option, no attributes.
        let plain = rossignac_borrel(&mesh, &ClusterOptions::smoothing(10))
            .unwrap()
            .pop()
            .unwrap();
        assert!(plain.mesh.line_attributes.is_empty());
        assert_eq!(plain.mesh.lines, level.mesh.lines);
    }
}

#[test]
fn floating_cells_of_thin_parts_give_their_width() {
    for (name, (mesh, expected)) in [("rod", rod()), ("slab", slab())] {
        let level = low_tan(&mesh, &FloatingCellOptions::single(10))
            .unwrap()
            .pop()
            .unwrap();
        common::assert_valid(&mesh, &level, name);
        assert_eq!(
            (level.report.triangles, level.report.isolated_points),
            (0, 0),
            "{name}"
        );
        assert!(
            level.report.dangling_edges >= 9,
            "{name}: {:?}",
            level.report
        );
        let widths = attribute(&level.mesh, WIDTH);
        let mut checked = 0;
        for (i, &[a, b]) in level.mesh.lines.iter().enumerate() {
            // An end cap's centre may make a cluster of its own; its edge is the flat cap.
            let on_cap = |v: u32| {
                let x = level.mesh.mesh.positions[v as usize].x;
                x == 0.0 || x == 10.0
            };
            if on_cap(a) || on_cap(b) {
                continue;
            }
            // The representatives sit on the surface, so the edge leans a little: 1 %.
            let w = widths[i];
            assert!(
                (w - expected).abs() < 1e-2 * expected,
                "{name}: width {w}, expected {expected}"
            );
            checked += 1;
        }
        assert!(checked >= 8, "{name}: {checked}");
        check_normals(&level);
    }
}
