//! Surface nets over all labels: hand-counted cases, placement in the world, and on random
//! maps every label closed, outward, manifold, of exactly its voxel volume, with every interface
//! triangle used by exactly the two labels it separates.

use std::collections::HashMap;
use voxlod_testkit::compare::{triangle_key, TriangleKey};

use voxlod_core::glam::{DMat3, DVec3};
use voxlod_core::{mesh_topology, Frame, Grid, LabelVolume, Orientation, TriangleMesh};
use voxlod_labels::surface_nets::{surface_nets, SharedSurface, SurfaceNetsOptions};

fn map(dims: [usize; 3], values: Vec<u32>) -> LabelVolume {
    LabelVolume::from_vec(Grid::unit(dims).unwrap(), values).unwrap()
}

fn nets(map: &LabelVolume) -> SharedSurface {
    surface_nets(map, &SurfaceNetsOptions::default()).unwrap()
}

/// The enclosed volume summed exactly (each term is exact for corners on half-integers; one
/// rounding at the end).
fn volume(mesh: &TriangleMesh) -> f64 {
    let sum: f64 = (0..mesh.triangles.len())
        .map(|t| {
            let [a, b, c] = mesh.corners(t);
            a.dot(b.cross(c))
        })
        .sum();
    sum / 6.0
}

/// Closed and consistently oriented: every directed edge matched by its reverse as often, and
/// a positive volume. (Manifold too except at edge contacts that splitting vertices cannot
/// resolve, see the module docs; [`assert_closed_outward`] asks for that as well.)
fn assert_closed_oriented(mesh: &TriangleMesh, what: &str) -> usize {
    let mut directed: HashMap<(u32, u32), i64> = HashMap::new();
    for t in &mesh.triangles {
        for n in 0..3 {
            let (a, b) = (t[n], t[(n + 1) % 3]);
            *directed.entry((a.min(b), a.max(b))).or_insert(0) += if a < b { 1 } else { -1 };
        }
    }
    assert!(
        directed.values().all(|&d| d == 0),
        "{what}: unmatched edges"
    );
    let topology = mesh_topology(mesh);
    assert_eq!(topology.boundary_edges, 0, "{what}");
    assert_eq!(topology.degenerate_triangles, 0, "{what}");
    assert!(volume(mesh) > 0.0, "{what}: inside out");
    topology.non_manifold_edges
}

fn assert_closed_outward(mesh: &TriangleMesh, what: &str) {
    let topology = mesh_topology(mesh);
    assert!(topology.is_closed_manifold(), "{what}: {topology:?}");
    assert!(topology.is_consistently_oriented(), "{what}: {topology:?}");
    assert!(mesh.signed_volume() > 0.0, "{what}: inside out");
}

#[test]
fn a_single_voxel_is_a_cube_of_six_quads() {
    let surface = nets(&map([1, 1, 1], vec![3]));
    assert_eq!(surface.positions.len(), 8);
    assert_eq!(surface.triangles.len(), 12);
    assert!(surface.sides.iter().all(|&s| s == [3, 0]));
    assert_eq!(surface.labels(), vec![3]);
    let mesh = surface.label_mesh(3);
    assert_eq!((mesh.positions.len(), mesh.triangles.len()), (8, 12));
    assert_eq!(volume(&mesh), 1.0);
    assert_closed_outward(&mesh, "one voxel");
    for p in &mesh.positions {
        assert!(p.to_array().iter().all(|c| c.abs() == 0.5), "{p}");
    }
    assert!(surface.label_mesh(7).triangles.is_empty());
}

#[test]
fn two_neighbours_share_their_face_once_with_opposite_windings() {
    let surface = nets(&map([2, 1, 1], vec![1, 2]));
    assert_eq!(surface.positions.len(), 12);
    assert_eq!(surface.triangles.len(), 22);
    let shared: Vec<usize> = (0..surface.sides.len())
        .filter(|&t| surface.sides[t] == [1, 2])
        .collect();
    assert_eq!(shared.len(), 2);
    for t in shared {
        // The shared face lies at x = 0.5, its normal from label 1 (x < 0.5) towards label 2.
        let [a, b, c] = surface.triangles[t].map(|v| surface.positions[v as usize]);
        assert!([a, b, c].iter().all(|p| p.x == 0.5));
        assert!((b - a).cross(c - a).x > 0.0);
    }
    let (one, two) = (surface.label_mesh(1), surface.label_mesh(2));
    assert_eq!((one.triangles.len(), two.triangles.len()), (12, 12));
    assert_eq!((volume(&one), volume(&two)), (1.0, 1.0));
    assert_closed_outward(&one, "label 1");
    assert_closed_outward(&two, "label 2");
    assert_interfaces_shared(&surface);
}

#[test]
fn a_checkerboard_splits_edge_contacts_into_separate_cubes() {
    let values: Vec<u32> = (0..8)
        .map(|n| 1 + ((n & 1) ^ (n >> 1 & 1) ^ (n >> 2)) as u32)
        .collect();
    let surface = nets(&map([2, 2, 2], values));
    // 27 corners, all touching two labels (the border ones touch the outside); 12 inner faces
    // between labels, 24 on the border.
    assert_eq!(surface.positions.len(), 27);
    assert_eq!(surface.triangles.len(), 2 * (12 + 24));
    for label in [1, 2] {
        let mesh = surface.label_mesh(label);
        // Four cubes touching along edges or at the centre: split into 4 × 8 vertices.
        assert_eq!(
            (mesh.positions.len(), mesh.triangles.len()),
            (32, 48),
            "label {label}"
        );
        assert_eq!(volume(&mesh), 4.0);
        assert_closed_outward(&mesh, "checkerboard");
        assert_eq!(mesh_topology(&mesh).components, 4);
    }
    assert_interfaces_shared(&surface);
}

#[test]
fn a_block_filling_the_volume_closes_on_the_border() {
    let surface = nets(&map([3, 4, 2], vec![5; 24]));
    let mesh = surface.label_mesh(5);
    assert_eq!(mesh.triangles.len(), 2 * 2 * (12 + 6 + 8));
    assert_eq!(volume(&mesh), 24.0);
    assert_closed_outward(&mesh, "block");
    let faces = surface
        .flags
        .iter()
        .filter(|f| f.border_axes() != 0)
        .count();
    assert_eq!(faces, surface.positions.len());
}

#[test]
fn a_map_of_one_label_inside_background_only_and_of_background_only() {
    assert!(nets(&map([3, 3, 3], vec![0; 27])).triangles.is_empty());
    assert!(nets(&map([2, 2, 2], vec![0; 8])).labels().is_empty());
}

#[test]
fn spacing_origin_and_direction_place_the_corners() {
    let grid = Grid::new([1, 1, 1], [2.0, 3.0, 4.0], [10.0, 20.0, 30.0]).unwrap();
    for direction in [
        DMat3::from_rotation_z(0.5),
        DMat3::from_cols(DVec3::X, DVec3::Y, -DVec3::Z),
    ] {
        let orientation = Orientation {
            direction,
            frame: Frame::Lps,
        };
        let map = LabelVolume::from_vec(grid, vec![9])
            .unwrap()
            .oriented(orientation);
        let surface = nets(&map);
        for (p, c) in surface.positions.iter().zip(&surface.corners) {
            let index = DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64) - 0.5;
            let hand =
                DVec3::new(10.0, 20.0, 30.0) + direction * (DVec3::new(2.0, 3.0, 4.0) * index);
            assert!((p.as_dvec3() - hand).length() < 1e-5, "{p} {hand}");
        }
        let mesh = surface.label_mesh(9);
        assert!(
            (mesh.signed_volume() - 24.0).abs() < 1e-3,
            "{}",
            mesh.signed_volume()
        );
        assert_closed_outward(&mesh, "placed voxel");
    }
}

/// A deterministic generator (splitmix64).
struct Random(u64);

impl Random {
    fn draw(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e3779b97f4a7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58476d1ce4e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d049bb133111eb);
        z ^ (z >> 31)
    }
}

/// Labels 0..labels in random blobs: random voxels, then each voxel takes the label most of its
/// neighbourhood holds a few times over, so the map has runs, edge contacts and junctions.
fn random_map(n: usize, labels: u64, seed: u64) -> LabelVolume {
    let mut random = Random(seed);
    let mut values: Vec<u32> = (0..n * n * n)
        .map(|_| (random.draw() % labels) as u32)
        .collect();
    for _ in 0..2 {
        let old = values.clone();
        for k in 0..n {
            for j in 0..n {
                for i in 0..n {
                    let mut votes = [0u32; 8];
                    for (di, dj, dk) in [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)] {
                        let (a, b, c) = (
                            (i + di).min(n - 1),
                            (j + dj).min(n - 1),
                            (k + dk).min(n - 1),
                        );
                        votes[old[(c * n + b) * n + a] as usize] += 1;
                    }
                    let best = (0..8).max_by_key(|&l| (votes[l], l)).unwrap();
                    values[(k * n + j) * n + i] = best as u32;
                }
            }
        }
    }
    map([n, n, n], values)
}

fn voxel_counts(map: &LabelVolume) -> HashMap<u32, usize> {
    let mut counts = HashMap::new();
    for &v in map.values.iter().filter(|&&v| v != 0) {
        *counts.entry(v).or_insert(0) += 1;
    }
    counts
}

/// Every shared triangle with sides [A, B] is in A's mesh as it is and in B's reversed (by
/// positions), and no label mesh has a triangle the shared surface lacks.
fn assert_interfaces_shared(surface: &SharedSurface) {
    type Key = TriangleKey;
    let key = triangle_key;
    let labels = surface.labels();
    let meshes = surface.label_meshes(&labels).unwrap();
    let mut used: HashMap<(Key, u32), usize> = HashMap::new();
    for (&label, mesh) in labels.iter().zip(&meshes) {
        for t in &mesh.triangles {
            *used
                .entry((key(t.map(|v| mesh.positions[v as usize])), label))
                .or_insert(0) += 1;
        }
    }
    let mut expected: HashMap<(Key, u32), usize> = HashMap::new();
    for (t, &[inside, outside]) in surface.triangles.iter().zip(&surface.sides) {
        let p = t.map(|v| surface.positions[v as usize]);
        *expected.entry((key(p), inside)).or_insert(0) += 1;
        if outside != 0 {
            *expected
                .entry((key([p[0], p[2], p[1]]), outside))
                .or_insert(0) += 1;
        }
    }
    assert_eq!(used, expected);
}

#[test]
fn random_maps_give_closed_outward_labels_of_their_voxel_volume_sharing_every_interface() {
    for seed in 0..6 {
        let map = random_map(14, 2 + seed % 4, seed);
        let surface = nets(&map);
        let counts = voxel_counts(&map);
        let labels = surface.labels();
        let mut expected: Vec<u32> = counts.keys().copied().collect();
        expected.sort_unstable();
        assert_eq!(labels, expected);
        let meshes = surface.label_meshes(&labels).unwrap();
        for (label, mesh) in labels.iter().zip(&meshes) {
            assert_closed_oriented(mesh, &format!("seed {seed} label {label}"));
            assert_eq!(
                volume(mesh),
                counts[label] as f64,
                "seed {seed} label {label}"
            );
            assert_eq!(mesh, &surface.label_mesh(*label));
        }
        assert_interfaces_shared(&surface);
        // The slab split does not change the output.
        let thin = surface_nets(
            &map,
            &SurfaceNetsOptions {
                slab_planes: 1,
                ..SurfaceNetsOptions::default()
            },
        )
        .unwrap();
        assert_eq!(thin, surface);
    }
}

#[test]
fn label_meshes_copy_their_shared_vertices() {
    let map = random_map(10, 3, 42);
    let surface = nets(&map);
    for label in surface.labels() {
        let (mesh, sources) = surface.label_mesh_with_sources(label);
        assert_eq!(mesh.positions.len(), sources.len());
        for (p, &s) in mesh.positions.iter().zip(&sources) {
            assert_eq!(*p, surface.positions[s as usize]);
        }
    }
}
