//! Every shared mesh (the bad ones included) at 16, 32, 64 and 128 cells, both methods: no
//! panic, valid output, and the output the paper's rules give for the clusters found. Skips with
//! a printed reason when ../shared/data is absent.

mod common;

use voxlod_clustering::{
    low_tan, rossignac_borrel, ClusterOptions, FloatingCellOptions, Level, Synthesis,
};
use voxlod_core::TriangleMesh;

fn check(mesh: &TriangleMesh, levels: &[Level], what: &str) {
    for level in levels {
        let what = format!("{what} level {}", level.report.level);
        common::assert_valid(mesh, level, &what);
        assert_eq!(
            common::as_sets(&level.mesh),
            common::naive_elimination(&mesh.triangles, &level.cluster_of),
            "{what}"
        );
        if !level.mesh.line_attributes.is_empty() {
            let width = &level.mesh.line_attributes[0];
            assert!(
                width.values.iter().all(|w| w.is_finite() && *w >= 0.0),
                "{what}: widths"
            );
        }
    }
}

#[test]
fn every_shared_mesh_at_every_resolution() {
    let files = common::shared_meshes("every_shared_mesh_at_every_resolution");
    for path in &files {
        let mesh = common::read_mesh(path);
        let name = path.file_name().unwrap().to_string_lossy();
        for cells in [16, 32, 64, 128] {
            for synthesis in [Synthesis::Mean, Synthesis::MaxWeight] {
                let options = ClusterOptions::smoothing(cells)
                    .with_synthesis(synthesis)
                    .with_thick_edges(synthesis == Synthesis::MaxWeight);
                let levels = rossignac_borrel(&mesh, &options).unwrap();
                check(
                    &mesh,
                    &levels,
                    &format!("{name} rossignac-borrel {synthesis:?} {cells}"),
                );
            }
            let levels = low_tan(&mesh, &FloatingCellOptions::single(cells)).unwrap();
            check(&mesh, &levels, &format!("{name} low-tan {cells}"));
            let r = &levels[0].report;
            eprintln!(
                "{name:32} {cells:4} cells  low-tan: {:6} clusters {:6} triangles {:5} edges {:4} points",
                r.clusters, r.triangles, r.dangling_edges, r.isolated_points
            );
        }
        // Series from 128 cells down to 8, and from 16 down to 1.
        let levels = rossignac_borrel(&mesh, &ClusterOptions::series(128, 5)).unwrap();
        check(&mesh, &levels, &format!("{name} rossignac-borrel series"));
        let levels = rossignac_borrel(&mesh, &ClusterOptions::full_series(16)).unwrap();
        assert_eq!(levels.len(), 5);
        check(
            &mesh,
            &levels,
            &format!("{name} rossignac-borrel full series"),
        );
        for r in voxlod_clustering::reports(&levels) {
            eprintln!(
                "{name:32} {:4} cells  rossignac-borrel: {:6} clusters {:6} triangles {:5} edges {:4} points",
                r.cells, r.clusters, r.triangles, r.dangling_edges, r.isolated_points
            );
        }
    }
    if let Some(listed) = files.first().and_then(|f| meshes_listed(f)) {
        assert_eq!(files.len(), listed, "the shared data README's mesh table");
    }
}

/// The meshes that the shared data README's table lists (rows whose first cell is a mesh
/// file name), beside `any` (a file of the meshes folder).
fn meshes_listed(any: &std::path::Path) -> Option<usize> {
    let readme = any.parent()?.parent()?.join("README.md");
    let text = std::fs::read_to_string(readme).ok()?;
    let rows = text.lines().filter(|l| {
        let first = l
            .trim_start_matches('|')
            .split('|')
            .next()
            .unwrap_or("")
            .trim();
        [".obj", ".off", ".stl"].iter().any(|e| first.ends_with(e))
    });
    Some(rows.count())
}
