//! A layer whose levels are given, one mesh per level (the filter pyramid's), checked against
//! the format and the meshes given.

mod common;

use std::collections::{HashMap, HashSet};

use voxlod_core::glam::{DVec3, Vec3};
use voxlod_core::TriangleMesh;
use voxlod_precomputed::filtered::{build_filtered, LevelMesh};
use voxlod_precomputed::lods::{Octree, OctreeOptions};
use voxlod_precomputed::read::read_mesh;
use voxlod_precomputed::{morton, write_layer_filtered, PrecomputedError};
use voxlod_testkit::shapes::icosphere_at;

/// Stand-ins for a ball's pyramid: level k an icosphere of 4 − k subdivisions whose radius
/// shrinks by 0.7 voxels per level, so no two levels share a vertex (and no pole touches a
/// node's face: a vertex on a face used by one side only, which the check of shared faces
/// would not allow).
fn ball_levels(lods: usize) -> Vec<TriangleMesh> {
    (0..lods)
        .map(|k| {
            icosphere_at(
                4 - k as u32,
                13.3 - 0.7 * k as f32,
                Vec3::new(20.2, 19.7, 21.1),
            )
        })
        .collect()
}

/// The octree of `levels` on level-0 nodes of 4 voxels from the origin.
fn octree_of(levels: &[TriangleMesh]) -> Octree {
    let stored: Vec<Vec<DVec3>> = (levels.iter())
        .map(|m| m.positions.iter().map(|p| p.as_dvec3()).collect())
        .collect();
    let meshes: Vec<LevelMesh> = (stored.iter().zip(levels))
        .map(|(positions, m)| LevelMesh {
            positions,
            triangles: &m.triangles,
        })
        .collect();
    let options = OctreeOptions {
        grid_origin: DVec3::ZERO,
        chunk: DVec3::splat(4.0),
        lods: levels.len(),
        ratio: 1.0,
    };
    build_filtered(&meshes, &options).unwrap()
}

/// Level `k` of the octree as one mesh.
fn level_mesh(octree: &Octree, k: usize) -> TriangleMesh {
    let triangles: Vec<[u32; 3]> = (octree.levels[k].values())
        .flat_map(|n| n.triangles.clone())
        .collect();
    let positions = octree.positions.iter().map(|p| p.as_vec3()).collect();
    TriangleMesh::new(positions, triangles)
}

#[test]
fn each_level_is_its_own_mesh_cut_and_closed() {
    let levels = ball_levels(3);
    let octree = octree_of(&levels);
    for (k, given) in levels.iter().enumerate() {
        let cut = level_mesh(&octree, k);
        assert!(
            cut.triangle_count() > given.triangle_count(),
            "level {k}: {} pieces of {} triangles",
            cut.triangle_count(),
            given.triangle_count()
        );
        assert!(
            (cut.area() - given.area()).abs() < 1e-4 * given.area(),
            "level {k}"
        );
        let (v, w) = (cut.signed_volume(), given.signed_volume());
        assert!(
            (v - w).abs() < 1e-4 * w,
            "level {k}: volume {v} against {w}"
        );
        // Closed and consistently oriented: every directed edge once, and its reverse once.
        let mut edges: HashMap<(u32, u32), i32> = HashMap::new();
        for t in &cut.triangles {
            for e in 0..3 {
                *edges.entry((t[e], t[(e + 1) % 3])).or_default() += 1;
            }
        }
        for (&(u, v), &n) in &edges {
            assert_eq!(n, 1, "level {k}");
            assert_eq!(edges.get(&(v, u)), Some(&1), "level {k}: edge {u}-{v} open");
        }
    }
}

#[test]
fn no_coarse_triangle_crosses_its_node_s_eighths() {
    let octree = octree_of(&ball_levels(3));
    for k in 1..3 {
        let eighth = 4.0 * (1u64 << (k - 1)) as f64;
        let mut parts = 0;
        for node in octree.levels[k].values() {
            let mut start = 0;
            for &(child, end) in &node.parts {
                assert_eq!(child.map(|c| c >> 1), node.position);
                for t in &node.triangles[start..end] {
                    for &v in t {
                        let p = octree.positions[v as usize];
                        for a in 0..3 {
                            let (lo, hi) =
                                (child[a] as f64 * eighth, (child[a] + 1) as f64 * eighth);
                            assert!(p[a] >= lo && p[a] <= hi, "level {k}: {p} outside {child:?}");
                        }
                    }
                }
                start = end;
                parts += 1;
            }
            assert_eq!(start, node.triangles.len());
        }
        assert!(parts > 8, "level {k}: {parts} eighths");
    }
}

#[test]
fn vertices_on_a_node_face_are_in_the_neighbour_bit_for_bit() {
    let octree = octree_of(&ball_levels(3));
    for bits in [10, 16] {
        let checked = common::faces_shared(&octree, bits);
        assert!(checked > 300, "only {checked} face vertices");
    }
}

#[test]
fn a_level_with_nothing_still_parents_the_finer_nodes() {
    // The coarsest level vanished (a part thinner than its filter): its nodes are empty.
    let mut levels = ball_levels(3);
    levels[2] = TriangleMesh::default();
    let octree = octree_of(&levels);
    assert!(octree.levels[2].values().all(|n| n.triangles.is_empty()));
    for k in 0..2 {
        let parents: HashSet<[u32; 3]> =
            octree.levels[k + 1].values().map(|n| n.position).collect();
        for node in octree.levels[k].values() {
            let parent = node.position.map(|c| c >> 1);
            assert!(
                parents.contains(&parent),
                "level {k}: {:?} has no parent",
                node.position
            );
        }
        let codes: Vec<u128> = octree.levels[k]
            .values()
            .map(|n| morton::code(n.position))
            .collect();
        assert!(codes.windows(2).all(|w| w[0] < w[1]));
    }
}

#[test]
fn the_layer_holds_each_given_level_and_refuses_a_wrong_count() {
    let dir = tempfile::tempdir().unwrap();
    let layer = dir.path().join("layer");
    let options = common::options();
    let levels = common::filtered_levels(3);
    let report = write_layer_filtered(&layer, &common::map(), &levels, &options).unwrap();
    for ((label, meshes), r) in levels.iter().zip(&report.labels) {
        let stored = read_mesh(&layer, *label as u64).unwrap();
        assert_eq!(stored.manifest.num_lods(), 3);
        let fragments = stored.fragments().unwrap();
        for (k, given) in meshes.iter().enumerate() {
            let triangles: usize = (fragments.iter())
                .filter(|f| f.lod == k)
                .map(|f| f.fragment.triangles.len())
                .sum();
            assert_eq!(triangles, r.lods[k].triangles, "label {label} level {k}");
            assert!(
                triangles >= given.triangle_count(),
                "label {label} level {k}: {triangles} of {}",
                given.triangle_count()
            );
        }
    }
    let mut short = levels.clone();
    short[1].1.pop();
    let err = write_layer_filtered(&dir.path().join("other"), &common::map(), &short, &options)
        .unwrap_err();
    assert!(
        matches!(&err, PrecomputedError::Mesh { label: 300, reason } if reason.contains("2 levels")),
        "{err}"
    );
    assert!(!dir.path().join("other").exists());
}

#[test]
fn a_level_given_without_triangles_holds_the_finer_surface() {
    let dir = tempfile::tempdir().unwrap();
    let layer = dir.path().join("layer");
    let mut levels = common::filtered_levels(3);
    levels[1].1[2] = TriangleMesh::default();
    let report = write_layer_filtered(&layer, &common::map(), &levels, &common::options()).unwrap();
    let carried: Vec<Vec<bool>> = (report.labels.iter())
        .map(|l| l.lods.iter().map(|d| d.carried).collect())
        .collect();
    assert_eq!(carried, [vec![false; 3], vec![false, false, true]]);
    // The carried level is level 1's surface cut on level 2's grid: the same area.
    let fragments = read_mesh(&layer, 300).unwrap().fragments().unwrap();
    let area = |lod: usize| -> f64 {
        (fragments.iter())
            .filter(|f| f.lod == lod)
            .map(|f| {
                let positions = f.positions.iter().map(|p| p.as_vec3()).collect();
                TriangleMesh::new(positions, f.fragment.triangles.clone()).area()
            })
            .sum()
    };
    let (a1, a2) = (area(1), area(2));
    assert!(
        a2 > 0.0 && (a1 - a2).abs() < 0.01 * a1,
        "areas {a1} and {a2}"
    );
}
