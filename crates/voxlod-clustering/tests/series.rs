//! Series of levels: the octree merge of §4 must give what a fresh run on the coarser grid gives,
//! cluster membership must nest, and representatives must stay in their cells.

mod common;

use voxlod_clustering::{
    low_tan, rossignac_borrel, ClusterGrid, ClusterOptions, FloatingCellOptions, Level, Synthesis,
};
use voxlod_core::TriangleMesh;

fn test_meshes() -> Vec<(String, TriangleMesh)> {
    let mut meshes = vec![("torus".to_string(), common::torus(160, 48, 1.0, 0.3))];
    if let Some(p) = voxlod_testkit::data::shared_data_or_skip(
        "meshes/stanford-bunny.obj",
        "series on the bunny",
    ) {
        meshes.push(("bunny".to_string(), common::read_mesh(&p)));
    }
    meshes
}

fn assert_same_level(series: &Level, direct: &Level, what: &str) {
    assert_eq!(series.cluster_of, direct.cluster_of, "{what}: cluster map");
    assert_eq!(
        series.mesh.mesh.triangles, direct.mesh.mesh.triangles,
        "{what}: triangles"
    );
    assert_eq!(series.mesh.lines, direct.mesh.lines, "{what}: edges");
    assert_eq!(series.mesh.points, direct.mesh.points, "{what}: points");
    assert_eq!(series.report.cell_size, direct.report.cell_size, "{what}");
    assert_eq!(series.report.cells, direct.report.cells, "{what}");
    let worst = series
        .mesh
        .mesh
        .positions
        .iter()
        .zip(&direct.mesh.mesh.positions)
        .map(|(a, b)| (*a - *b).abs().max_element())
        .fold(0.0f32, f32::max);
    assert!(worst <= 1e-5, "{what}: representatives differ by {worst}");
}

#[test]
fn octree_levels_equal_fresh_runs_on_coarser_grids() {
    for (name, mesh) in test_meshes() {
        for synthesis in [Synthesis::Mean, Synthesis::MaxWeight] {
            let levels = rossignac_borrel(
                &mesh,
                &ClusterOptions::series(64, 5).with_synthesis(synthesis),
            )
            .unwrap();
            assert_eq!(levels.len(), 5);
            for (l, level) in levels.iter().enumerate() {
                let what = format!("{name} {synthesis:?} level {l}");
                common::assert_valid(&mesh, level, &what);
                assert_eq!(level.report.level, l);
                assert_eq!(level.report.cells, 64 >> l);
                let direct = rossignac_borrel(
                    &mesh,
                    &ClusterOptions::smoothing(64 >> l).with_synthesis(synthesis),
                )
                .unwrap()
                .pop()
                .unwrap();
                assert_same_level(level, &direct, &what);
                // The octree level is also what the paper's rules give for its clusters.
                assert_eq!(
                    common::as_sets(&level.mesh),
                    common::naive_elimination(&mesh.triangles, &level.cluster_of),
                    "{what}"
                );
            }
            // Fewer clusters and no more triangles as cells grow.
            for w in levels.windows(2) {
                assert!(w[1].report.clusters < w[0].report.clusters, "{name}");
                assert!(w[1].report.triangles <= w[0].report.triangles, "{name}");
                assert_eq!(w[1].report.cell_size, 2.0 * w[0].report.cell_size);
            }
        }
    }
}

#[test]
fn cluster_membership_nests() {
    for (name, mesh) in test_meshes() {
        let levels = rossignac_borrel(&mesh, &ClusterOptions::series(64, 7)).unwrap();
        for w in levels.windows(2) {
            let (fine, coarse) = (&w[0], &w[1]);
            let mut parent = vec![u32::MAX; fine.report.clusters];
            for (&f, &c) in fine.cluster_of.iter().zip(&coarse.cluster_of) {
                if f == u32::MAX {
                    assert_eq!(c, u32::MAX);
                    continue;
                }
                let p = &mut parent[f as usize];
                assert!(
                    *p == u32::MAX || *p == c,
                    "{name}: fine cluster {f} split between {p} and {c}"
                );
                *p = c;
            }
        }
        // The coarsest level has one cell along the longest axis.
        assert_eq!(levels.last().unwrap().report.cells, 1);
    }
}

#[test]
fn representatives_lie_in_their_cells() {
    for (name, mesh) in test_meshes() {
        for synthesis in [Synthesis::Mean, Synthesis::MaxWeight] {
            let levels = rossignac_borrel(
                &mesh,
                &ClusterOptions::series(32, 3).with_synthesis(synthesis),
            )
            .unwrap();
            let base = ClusterGrid::new(&mesh.bounds(), 32).unwrap();
            for (l, level) in levels.iter().enumerate() {
                let grid = base.coarsened(l as u32);
                // A member vertex of each cluster gives the cluster's cell.
                let mut cell = vec![None; level.report.clusters];
                for (v, &c) in level.cluster_of.iter().enumerate() {
                    if c != u32::MAX {
                        let here = grid.cell_of(mesh.positions[v]);
                        assert!(
                            cell[c as usize].is_none_or(|k| k == here),
                            "{name}: cluster {c} spans cells"
                        );
                        cell[c as usize] = Some(here);
                    }
                }
                let eps = 1e-5 * grid.cell_size;
                for (c, p) in level.mesh.mesh.positions.iter().enumerate() {
                    let k = cell[c].unwrap();
                    for axis in 0..3 {
                        let lo = grid.origin[axis] + k[axis] as f64 * grid.cell_size;
                        let x = p[axis] as f64;
                        assert!(
                            x >= lo - eps && x <= lo + grid.cell_size + eps,
                            "{name} {synthesis:?} level {l}: cluster {c} at {p} outside its cell"
                        );
                    }
                    if synthesis == Synthesis::MaxWeight {
                        assert!(mesh.positions.contains(p), "{name}: not an input vertex");
                    }
                }
            }
        }
    }
}

#[test]
fn floating_cell_series_doubles_the_cells() {
    for (name, mesh) in test_meshes() {
        let levels = low_tan(&mesh, &FloatingCellOptions::series(64, 4)).unwrap();
        assert_eq!(levels.len(), 4);
        for (l, level) in levels.iter().enumerate() {
            common::assert_valid(&mesh, level, &format!("{name} low-tan level {l}"));
            assert_eq!(
                common::as_sets(&level.mesh),
                common::naive_elimination(&mesh.triangles, &level.cluster_of),
                "{name} level {l}"
            );
            // Every cluster fits in a cube of the cell size around its representative, which is
            // one of its vertices.
            let half = 0.5 * level.report.cell_size as f32;
            for (v, &c) in level.cluster_of.iter().enumerate() {
                if c != u32::MAX {
                    let d = (mesh.positions[v] - level.mesh.mesh.positions[c as usize]).abs();
                    assert!(
                        d.max_element() <= half * (1.0 + 1e-6),
                        "{name}: vertex {v} outside its cell"
                    );
                }
            }
            assert!(level
                .mesh
                .mesh
                .positions
                .iter()
                .all(|p| mesh.positions.contains(p)));
        }
        for w in levels.windows(2) {
            assert_eq!(w[1].report.cell_size, 2.0 * w[0].report.cell_size);
            assert!(w[1].report.clusters < w[0].report.clusters, "{name}");
        }
    }
}
