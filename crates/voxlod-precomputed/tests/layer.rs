//! The layer's files checked against the format and against hand-computed values.

mod common;

use std::collections::{HashMap, HashSet};

use voxlod_core::glam::{DMat3, DVec3, Vec3};
use voxlod_core::{Grid, LabelVolume, Orientation, TriangleMesh};
use voxlod_precomputed::read::{read_mesh, PlacedFragment};
use voxlod_precomputed::{
    lods, morton, write_layer, PrecomputedError, PrecomputedOptions, Sharding,
};

fn fragments(dir: &std::path::Path, label: u64) -> Vec<PlacedFragment> {
    read_mesh(dir, label).unwrap().fragments().unwrap()
}

#[test]
fn the_manifest_of_one_triangle_is_the_hand_computed_bytes() {
    // Unit voxels at the origin: voxel_offset 0, a world point w stored at w + 0.5.
    let grid = Grid::new([8, 8, 8], [1.0; 3], [0.0; 3]).unwrap();
    let map = LabelVolume::from_vec(grid, vec![0; 512]).unwrap();
    let triangle = TriangleMesh::new(
        vec![
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(2.0, 1.0, 1.0),
            Vec3::new(1.0, 2.0, 1.0),
        ],
        vec![[0, 1, 2]],
    );
    let options = PrecomputedOptions {
        lods: 2,
        fragment_voxels: 4,
        ..PrecomputedOptions::default()
    };
    let dir = tempfile::tempdir().unwrap();
    let layer = dir.path().join("layer");
    write_layer(&layer, &map, &[(5, triangle)], &options).unwrap();
    let data = std::fs::read(layer.join("mesh/5")).unwrap();
    let stored = read_mesh(&layer, 5).unwrap();
    let sizes = [
        stored.manifest.fragment_sizes[0][0],
        stored.manifest.fragment_sizes[1][0],
    ];
    assert_eq!((sizes[0] + sizes[1]) as usize, data.len());
    let mut expected: Vec<u8> = Vec::new();
    let f = |v: &mut Vec<u8>, x: f32| v.extend_from_slice(&x.to_le_bytes());
    let u = |v: &mut Vec<u8>, x: u32| v.extend_from_slice(&x.to_le_bytes());
    [4.0, 4.0, 4.0, 0.0, 0.0, 0.0]
        .iter()
        .for_each(|&x| f(&mut expected, x)); // shape, origin
    u(&mut expected, 2); // lods
    [1.0, 2.0].iter().for_each(|&x| f(&mut expected, x)); // lod scales
    (0..6).for_each(|_| f(&mut expected, 0.0)); // vertex offsets
    [1, 1].iter().for_each(|&x| u(&mut expected, x)); // fragments per lod
    for size in sizes {
        (0..3).for_each(|_| u(&mut expected, 0)); // node (0, 0, 0)
        u(&mut expected, size);
    }
    assert_eq!(std::fs::read(layer.join("mesh/5.index")).unwrap(), expected);
    // Stored corners (1.5, 1.5, 1.5), (2.5, 1.5, 1.5), (1.5, 2.5, 1.5); level 0 nodes of 4:
    // 1.5 / 4 · 65535 = 24575.625 → 24576, 2.5 / 4 · 65535 = 40959.375 → 40959; level 1
    // nodes of 8: 12287.8125 → 12288 and 20479.6875 → 20480.
    let frags = stored.fragments().unwrap();
    let corners = |f: &PlacedFragment| {
        let t = f.fragment.triangles[0];
        t.map(|v| f.fragment.positions[v as usize])
    };
    let (a, b) = (24576, 40959);
    let lod0 = corners(&frags[0]);
    let lod1 = corners(&frags[1]);
    let rotations = |t: [[u32; 3]; 3]| (0..3).map(move |r| [t[r], t[(r + 1) % 3], t[(r + 2) % 3]]);
    assert!(
        rotations(lod0).any(|t| t == [[a, a, a], [b, a, a], [a, b, a]]),
        "{lod0:?}"
    );
    let (c, d) = (12288, 20480);
    assert!(
        rotations(lod1).any(|t| t == [[c, c, c], [d, c, c], [c, d, c]]),
        "{lod1:?}"
    );
}

#[test]
fn nodes_are_in_z_order_and_every_node_has_its_parent() {
    let dir = tempfile::tempdir().unwrap();
    let layer = dir.path().join("layer");
    common::write(&layer, &common::options());
    for (label, _) in common::meshes() {
        let m = read_mesh(&layer, label as u64).unwrap().manifest;
        for (k, nodes) in m.fragment_positions.iter().enumerate() {
            assert!(
                nodes.len() > 1,
                "label {label} lod {k}: {} nodes",
                nodes.len()
            );
            let codes: Vec<u128> = nodes.iter().map(|&p| morton::code(p)).collect();
            assert!(
                codes.windows(2).all(|w| w[0] < w[1]),
                "lod {k} not in Z order"
            );
            if k + 1 < m.num_lods() {
                let parents: HashSet<[u32; 3]> =
                    m.fragment_positions[k + 1].iter().copied().collect();
                for p in nodes {
                    assert!(parents.contains(&p.map(|c| c >> 1)), "{p:?} has no parent");
                }
            }
        }
    }
}

#[test]
fn vertices_on_a_node_face_are_in_the_neighbour_bit_for_bit() {
    let octree = ball_octree(3);
    for bits in [10, 16] {
        let checked = common::faces_shared(&octree, bits);
        assert!(checked > 300, "only {checked} face vertices");
    }
}

#[test]
fn no_coarse_triangle_crosses_its_node_s_two_by_two_by_two_split() {
    let dir = tempfile::tempdir().unwrap();
    let layer = dir.path().join("layer");
    common::write(&layer, &common::options());
    // Neuroglancer's split: a coordinate below (2^bits − 1) / 2 + 1 = 32768 is in the low half,
    // above it in the high half, equal to it in both.
    let split = 32768;
    for (label, _) in common::meshes() {
        for f in fragments(&layer, label as u64).iter().filter(|f| f.lod > 0) {
            for t in &f.fragment.triangles {
                for a in 0..3 {
                    let c = t.map(|v| f.fragment.positions[v as usize][a]);
                    let low = c.iter().any(|&x| x < split);
                    let high = c.iter().any(|&x| x > split);
                    assert!(
                        !(low && high),
                        "lod {} node {:?}: {c:?} crosses",
                        f.lod,
                        f.node
                    );
                }
            }
        }
    }
}

/// Stored-space test mesh: a ball off the grid, level-0 nodes of 4 voxels.
fn ball_octree(lods: usize) -> lods::Octree {
    let mesh = voxlod_testkit::shapes::icosphere_at(4, 13.3, Vec3::new(20.2, 19.7, 21.1));
    let positions: Vec<DVec3> = mesh.positions.iter().map(|p| p.as_dvec3()).collect();
    let options = lods::OctreeOptions {
        grid_origin: DVec3::ZERO,
        chunk: DVec3::splat(4.0),
        lods,
        ratio: 0.25,
    };
    lods::build(&positions, &mesh.triangles, &options).unwrap()
}

/// The open edges of each piece drawn on its own: per level-`k − 1` node position, the
/// directed edges whose reverse the piece does not have. For level `k − 1` the pieces are its
/// nodes; for level `k`, the parts simplified from each of them.
fn open_edges(octree: &lods::Octree, k: usize, parts_of: bool) -> HashSet<([u32; 3], u32, u32)> {
    let mut out = HashSet::new();
    let mut add = |cell: [u32; 3], triangles: &[[u32; 3]]| {
        let directed: HashSet<(u32, u32)> = triangles
            .iter()
            .flat_map(|t| (0..3).map(move |e| (t[e], t[(e + 1) % 3])))
            .collect();
        for &(u, v) in &directed {
            if !directed.contains(&(v, u)) {
                out.insert((cell, u, v));
            }
        }
    };
    for node in octree.levels[k].values() {
        if parts_of {
            let mut start = 0;
            for &(child, end) in &node.parts {
                add(child, &node.triangles[start..end]);
                start = end;
            }
        } else {
            add(node.position, &node.triangles);
        }
    }
    out
}

#[test]
fn each_level_keeps_the_finer_levels_cross_sections_on_its_split_planes() {
    let octree = ball_octree(4);
    for k in 1..4 {
        // Level k is drawn beside finer levels along the faces of level k − 1's nodes: the
        // boundary of each eighth of a level-k node must be the boundary of the finer node.
        let coarse = open_edges(&octree, k, true);
        let fine = open_edges(&octree, k - 1, false);
        assert!(fine.len() > 50, "level {k}: {} open edges", fine.len());
        assert_eq!(coarse.len(), fine.len(), "level {k}");
        assert!(
            coarse == fine,
            "level {k} differs from level {} on its planes",
            k - 1
        );
        let kept: usize = octree.levels[k].values().map(|n| n.triangles.len()).sum();
        let before: usize = octree.levels[k - 1]
            .values()
            .map(|n| n.triangles.len())
            .sum();
        assert!(kept < before, "level {k} kept {kept} of {before} triangles");
    }
}

#[test]
fn the_level_zero_cut_keeps_the_area_and_closes_up() {
    let octree = ball_octree(1);
    let mesh = voxlod_testkit::shapes::icosphere_at(4, 13.3, Vec3::new(20.2, 19.7, 21.1));
    let triangles: Vec<[u32; 3]> = octree.levels[0]
        .values()
        .flat_map(|n| n.triangles.clone())
        .collect();
    let cut = TriangleMesh::new(
        octree.positions.iter().map(|p| p.as_vec3()).collect(),
        triangles,
    );
    assert!((cut.area() - mesh.area()).abs() < 1e-3 * mesh.area());
    assert!((cut.signed_volume() - mesh.signed_volume()).abs() < 1e-3 * mesh.signed_volume());
    let mut edges: HashMap<(u32, u32), i32> = HashMap::new();
    for t in &cut.triangles {
        for e in 0..3 {
            *edges.entry((t[e], t[(e + 1) % 3])).or_default() += 1;
        }
    }
    // Closed and consistently oriented: every directed edge once, and its reverse once.
    for (&(u, v), &n) in &edges {
        assert_eq!(n, 1);
        assert_eq!(edges.get(&(v, u)), Some(&1), "edge {u}-{v} has no twin");
    }
}

#[test]
fn sharded_and_plain_layers_hold_the_same_meshes() {
    let dir = tempfile::tempdir().unwrap();
    let (plain, sharded) = (dir.path().join("plain"), dir.path().join("sharded"));
    common::write(&plain, &common::options());
    let options = PrecomputedOptions {
        sharding: Sharding::Always,
        ..common::options()
    };
    let report = common::write(&sharded, &options);
    let spec = report.sharding.expect("sharded");
    assert!(sharded.join("mesh").join(spec.file_name(0)).is_file());
    assert!(!sharded.join("mesh/7.index").exists());
    for (label, _) in common::meshes() {
        assert_eq!(
            read_mesh(&plain, label as u64).unwrap(),
            read_mesh(&sharded, label as u64).unwrap()
        );
    }
}

#[test]
fn bad_input_is_refused_before_anything_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let layer = dir.path().join("layer");
    let write = |map: &LabelVolume, meshes: &[(u32, TriangleMesh)], o: &PrecomputedOptions| {
        write_layer(&layer, map, meshes, o).unwrap_err().to_string()
    };
    let (map, meshes, options) = (common::map(), common::meshes(), common::options());
    let oblique = map.clone().oriented(Orientation {
        direction: DMat3::from_rotation_z(0.3),
        ..Orientation::default()
    });
    assert!(write(&oblique, &meshes, &options).contains("axis-aligned"));
    let zero = vec![(0, meshes[0].1.clone())];
    assert!(write(&map, &zero, &options).contains("label 0 is the background"));
    let twice = vec![meshes[0].clone(), meshes[0].clone()];
    assert!(write(&map, &twice, &options).contains("mesh of label 7: given twice"));
    let bits = PrecomputedOptions {
        quantization_bits: 12,
        ..options.clone()
    };
    assert!(write(&map, &meshes, &bits).contains("quantization_bits is 12"));
    let mut broken = meshes[0].1.clone();
    broken.triangles.push([0, 1, 999_999]);
    assert!(write(&map, &[(9, broken)], &options).contains("mesh of label 9"));
    assert!(!layer.exists());
    assert!(!dir.path().join("layer.partial").exists());
}

#[test]
fn a_folder_that_is_not_a_layer_is_not_replaced_but_a_layer_is() {
    let dir = tempfile::tempdir().unwrap();
    let layer = dir.path().join("layer");
    std::fs::create_dir(&layer).unwrap();
    std::fs::write(layer.join("notes.txt"), "mine").unwrap();
    let error = write_layer(
        &layer,
        &common::map(),
        &common::meshes(),
        &common::options(),
    )
    .unwrap_err();
    assert!(matches!(error, PrecomputedError::Io { .. }));
    assert!(
        error.to_string().contains("not a precomputed layer"),
        "{error}"
    );
    assert_eq!(
        std::fs::read_to_string(layer.join("notes.txt")).unwrap(),
        "mine"
    );
    assert!(!dir.path().join("layer.partial").exists());
    std::fs::remove_file(layer.join("notes.txt")).unwrap();
    common::write(&layer, &common::options());
    let report = common::write(
        &layer,
        &PrecomputedOptions {
            lods: 2,
            ..common::options()
        },
    );
    assert_eq!(report.labels[0].lods.len(), 2);
    assert_eq!(read_mesh(&layer, 7).unwrap().manifest.num_lods(), 2);
}

#[test]
fn the_report_adds_up_to_the_files() {
    let dir = tempfile::tempdir().unwrap();
    let layer = dir.path().join("layer");
    let report = common::write(&layer, &common::options());
    for label in &report.labels {
        let data = std::fs::metadata(layer.join("mesh").join(label.label.to_string())).unwrap();
        let bytes: u64 = label.lods.iter().map(|l| l.bytes).sum();
        assert_eq!(bytes, data.len());
        let triangles: Vec<usize> = label.lods.iter().map(|l| l.triangles).collect();
        assert!(triangles.windows(2).all(|w| w[1] < w[0]), "{triangles:?}");
    }
    let volume: u64 = common::DIMS.iter().product::<usize>() as u64 * 4;
    assert_eq!(report.volume_bytes, volume);
}

/// The volume a closed piece of triangles encloses (divergence theorem).
fn enclosed_volume(positions: &[DVec3], triangles: &[[u32; 3]]) -> f64 {
    let p = |i: u32| positions[i as usize];
    triangles
        .iter()
        .map(|t| p(t[0]).dot(p(t[1]).cross(p(t[2]))) / 6.0)
        .sum()
}

#[test]
fn a_small_label_is_carried_not_flattened_or_dropped() {
    // Balls of radius 0.7 to 2.5 voxels, each inside one level-0 node of 8 voxels: simplified
    // within 2, 4, 8 voxels, meshoptimizer alone flattens the small ones to two triangles back
    // to back (no volume), then drops them. Every level must keep each ball with volume and
    // without such a pair, a level that would have none holding the finer one's pieces.
    for (radius, centre) in [(0.7f64, 4.1f32), (1.2, 3.9), (2.5, 4.2)] {
        let mesh = voxlod_testkit::shapes::icosphere_at(1, radius as f32, Vec3::splat(centre));
        let positions: Vec<DVec3> = mesh.positions.iter().map(|p| p.as_dvec3()).collect();
        let options = lods::OctreeOptions {
            grid_origin: DVec3::ZERO,
            chunk: DVec3::splat(8.0),
            lods: 4,
            ratio: 0.25,
        };
        let octree = lods::build(&positions, &mesh.triangles, &options).unwrap();
        let count =
            |k: usize| -> usize { octree.levels[k].values().map(|n| n.triangles.len()).sum() };
        for k in 1..4 {
            assert_eq!(
                octree.carried[k],
                count(k) == count(k - 1),
                "radius {radius}, level {k}"
            );
        }
        if radius < 1.0 {
            assert!(
                octree.carried[3],
                "the smallest ball is carried to the last level"
            );
        }
        for (k, level) in octree.levels.iter().enumerate() {
            let triangles: Vec<[u32; 3]> =
                level.values().flat_map(|n| n.triangles.clone()).collect();
            assert!(
                triangles.len() >= 4,
                "radius {radius}, level {k}: {triangles:?}"
            );
            let mut sets: Vec<[u32; 3]> = (triangles.iter())
                .map(|t| {
                    let mut s = *t;
                    s.sort_unstable();
                    s
                })
                .collect();
            sets.sort_unstable();
            assert!(
                sets.windows(2).all(|w| w[0] != w[1]),
                "radius {radius}, level {k}: two triangles back to back"
            );
            let volume = enclosed_volume(&octree.positions, &triangles);
            assert!(
                volume > 0.05 * radius.powi(3),
                "radius {radius}, level {k}: {volume}"
            );
        }
    }
}
