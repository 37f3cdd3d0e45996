//! The budget stage per label (`SurfaceOptions::triangles`): on a hand-made map of two boxes
//! side by side on a slab, and on the same map speckled with labels full of edge contacts and
//! pinched corners, each label's mesh within the budget (or reported above it), closed and
//! consistently oriented, its volume kept, and the shared interfaces still used by both their
//! labels.

use std::collections::{HashMap, HashSet};

use voxlod_core::{mesh_topology, Grid, LabelVolume, TriangleMesh};
use voxlod_labels::surface_nets::{surface_nets, SurfaceNetsOptions};
use voxlod_labels::{
    budget_shared, label_surfaces, smooth, LabelSurfaces, LabelsError, SmoothingOptions, Surface,
    SurfaceOptions,
};
use voxlod_testkit::compare::{reversed_key, triangle_keys, TriangleKey};

fn map(dims: [usize; 3], label: impl Fn([usize; 3]) -> u32) -> LabelVolume {
    let grid = Grid::new(dims, [1.0; 3], [0.0; 3]).unwrap();
    let values = (0..grid.len())
        .map(|n| [n % dims[0], n / dims[0] % dims[1], n / (dims[0] * dims[1])])
        .map(label)
        .collect();
    LabelVolume::from_vec(grid, values).unwrap()
}

/// Box 1 (16 × 24 × 24 voxels) and box 2 (18 × 20 × 24) touching along x, both standing on
/// slab 3 (40 × 32 × 6): 5,376, 5,088 and 6,848 quads' triangles before smoothing.
fn boxes() -> LabelVolume {
    map([48, 40, 40], |[x, y, z]| {
        let inside =
            |lo: [usize; 3], hi: [usize; 3]| (0..3).all(|a| (lo[a]..hi[a]).contains(&[x, y, z][a]));
        if inside([6, 8, 8], [22, 32, 32]) {
            1
        } else if inside([22, 10, 8], [40, 30, 32]) {
            2
        } else if inside([4, 4, 2], [44, 36, 8]) {
            3
        } else {
            0
        }
    })
}

/// The boxes with speckles of labels 1–3 above them (one voxel in six, from a hash of its
/// position, some on the boxes' tops): edge contacts, pinched corners and voxels on their own
/// everywhere there.
fn speckled() -> LabelVolume {
    let plain = boxes();
    map(plain.grid.dims, |[x, y, z]| {
        let hash = (x as u32).wrapping_mul(73_856_093)
            ^ (y as u32).wrapping_mul(19_349_663)
            ^ (z as u32).wrapping_mul(83_492_791);
        let speck = hash.wrapping_mul(2_654_435_761) >> 16;
        if z >= 32 && speck.is_multiple_of(6) {
            speck / 6 % 3 + 1
        } else {
            plain.values[x + 48 * (y + 40 * z)]
        }
    })
}

fn options(surface: Surface, triangles: Option<usize>) -> SurfaceOptions {
    SurfaceOptions {
        surface,
        triangles,
        ..SurfaceOptions::default()
    }
}

fn shared(iterations: usize) -> Surface {
    Surface::Shared(SmoothingOptions {
        iterations,
        ..SmoothingOptions::default()
    })
}

fn by_label(surfaces: LabelSurfaces) -> Vec<(u32, TriangleMesh)> {
    surfaces
        .labels
        .into_iter()
        .map(|l| (l.label.value, l.mesh))
        .collect()
}

fn meshes(map: &LabelVolume, options: &SurfaceOptions) -> Vec<(u32, TriangleMesh)> {
    by_label(label_surfaces(map, options).unwrap())
}

fn closed_oriented(mesh: &TriangleMesh) -> bool {
    let t = mesh_topology(mesh);
    t.boundary_edges == 0 && t.is_consistently_oriented() && t.degenerate_triangles == 0
}

/// The area of `a`'s triangles that `b` uses turned round, and whether no triangle is used
/// twice the same way round by any two labels.
fn shared_area(labels: &[(u32, TriangleMesh)], a: usize, b: usize) -> (f64, bool) {
    let mut seen: HashMap<TriangleKey, usize> = HashMap::new();
    for (_, mesh) in labels {
        for key in triangle_keys(mesh) {
            *seen.entry(key).or_default() += 1;
        }
    }
    let once = seen.values().all(|&n| n == 1);
    let theirs: HashSet<TriangleKey> = triangle_keys(&labels[b].1).into_iter().collect();
    let mesh = &labels[a].1;
    let area = triangle_keys(mesh)
        .iter()
        .zip(&mesh.triangles)
        .filter(|(key, _)| theirs.contains(&reversed_key(key)))
        .map(|(_, t)| {
            let [p, q, r] = t.map(|v| mesh.positions[v as usize].as_dvec3());
            0.5 * (q - p).cross(r - p).length()
        })
        .sum();
    (area, once)
}

#[test]
fn shared_labels_meet_the_budget_closed_and_still_joined() {
    let map = boxes();
    let before = meshes(&map, &options(shared(8), None));
    let counts: Vec<usize> = before.iter().map(|(_, m)| m.triangles.len()).collect();
    assert!(counts.iter().all(|&n| n > 4000), "{counts:?}");
    let budget = 1000;
    let surfaces = label_surfaces(&map, &options(shared(8), Some(budget))).unwrap();
    let report = surfaces.budget.clone().unwrap();
    assert_eq!((report.triangles, report.above.clone()), (budget, vec![]));
    let after = by_label(surfaces);
    for ((label, mesh), (_, old)) in after.iter().zip(&before) {
        let n = mesh.triangles.len();
        assert!(
            n <= budget && n >= budget / 2,
            "label {label}: {n} triangles"
        );
        let t = mesh_topology(mesh);
        assert!(
            t.is_closed_manifold() && t.is_consistently_oriented(),
            "label {label}: {t:?}"
        );
        assert_eq!(t.genus, Some(0), "label {label}");
        let change = mesh.signed_volume() / old.signed_volume() - 1.0;
        assert!(change.abs() < 0.01, "label {label}: volume {change:+.4}");
    }
    // Each interface still used by both its labels, turned round, over (about) the same area;
    // no triangle used twice the same way round.
    for (a, b) in [(0, 1), (0, 2), (1, 2)] {
        let (was, _) = shared_area(&before, a, b);
        let (is, once) = shared_area(&after, a, b);
        assert!(once, "a triangle used twice the same way round");
        assert!(was > 300.0, "labels {a}, {b}: {was}");
        assert!(
            (is / was - 1.0).abs() < 0.02,
            "labels {a}, {b}: {is} of {was}"
        );
        let (back, _) = shared_area(&after, b, a);
        assert!((back - is).abs() < 1e-6 * is, "labels {a}, {b}");
    }
}

#[test]
fn a_budget_above_every_label_gives_the_surface_nets_own_meshes() {
    let map = speckled();
    let mut surface = surface_nets(&map, &SurfaceNetsOptions::default()).unwrap();
    smooth(&mut surface, &SmoothingOptions::default()).unwrap();
    let labels = [1, 2, 3];
    let plain = surface.label_meshes(&labels).unwrap();
    let (budgeted, kept) = budget_shared(&surface, &labels, usize::MAX).unwrap();
    assert_eq!(kept, 0);
    for ((p, b), label) in plain.iter().zip(&budgeted).zip(labels) {
        let sorted = |m: &TriangleMesh| {
            let mut keys = triangle_keys(m);
            keys.sort_unstable();
            keys
        };
        assert_eq!(sorted(p), sorted(b), "label {label}");
        // The singular corners are split alike: as many vertices, the same topology.
        assert_eq!(p.positions.len(), b.positions.len(), "label {label}");
        assert_eq!(mesh_topology(p), mesh_topology(b), "label {label}");
    }
}

#[test]
fn speckled_labels_stay_closed_and_joined_under_a_tight_budget() {
    let map = speckled();
    let before = meshes(&map, &options(shared(8), None));
    let surfaces = label_surfaces(&map, &options(shared(8), Some(300))).unwrap();
    // The speckles' junctions and singular corners are locked: every label stays above, the
    // largest first.
    let above = surfaces.budget.clone().unwrap().above;
    assert_eq!(above.len(), 3);
    assert!(above.windows(2).all(|w| w[0].1 >= w[1].1) && above[0].1 > 300);
    let after = by_label(surfaces);
    for ((label, mesh), (_, old)) in after.iter().zip(&before) {
        assert!(
            closed_oriented(mesh),
            "label {label}: {:?}",
            mesh_topology(mesh)
        );
        let (t, o) = (mesh_topology(mesh), mesh_topology(old));
        assert!(
            t.non_manifold_edges <= o.non_manifold_edges,
            "label {label}"
        );
        assert!(mesh.triangles.len() < old.triangles.len(), "label {label}");
        let change = mesh.signed_volume() / old.signed_volume() - 1.0;
        assert!(change.abs() < 0.01, "label {label}: volume {change:+.4}");
    }
    for (a, b) in [(0, 1), (0, 2), (1, 2)] {
        let (is, once) = shared_area(&after, a, b);
        let (back, _) = shared_area(&after, b, a);
        assert!(
            once && is > 0.0 && (back - is).abs() < 1e-6 * is,
            "labels {a}, {b}"
        );
    }
}

#[test]
fn marching_cubes_labels_meet_the_budget_closed() {
    let map = boxes();
    let before = meshes(&map, &options(Surface::MarchingCubes, None));
    let budget = 800;
    let surfaces = label_surfaces(&map, &options(Surface::MarchingCubes, Some(budget))).unwrap();
    assert_eq!(surfaces.budget.as_ref().unwrap().above, vec![]);
    for (l, (_, old)) in surfaces.labels.iter().zip(&before) {
        let mesh = &l.mesh;
        assert!(old.triangles.len() > 4 * budget);
        assert!(mesh.triangles.len() <= budget, "label {}", l.label.value);
        let t = mesh_topology(mesh);
        assert!(t.is_closed_manifold() && t.is_consistently_oriented());
        assert_eq!(t.unreferenced_vertices, 0);
        let change = mesh.signed_volume() / old.signed_volume() - 1.0;
        assert!(
            change.abs() < 0.02,
            "label {}: volume {change:+.4}",
            l.label.value
        );
    }
}

#[test]
fn a_budget_under_four_is_refused_by_name() {
    for surface in [Surface::MarchingCubes, shared(8)] {
        let error = label_surfaces(&boxes(), &options(surface, Some(3))).unwrap_err();
        assert!(
            matches!(
                error,
                LabelsError::InvalidOption {
                    option: "triangles",
                    ..
                }
            ),
            "{error}"
        );
    }
}
