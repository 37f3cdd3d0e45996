//! `voxlod_budget::separate`: pinches that `make_manifold` splits come apart when the level is
//! welded by position (two closed solids again, no triangle turned, each copy moved a tiny
//! step), while meshes without pinches, and seams a weld closes, keep every coordinate.

use voxlod_budget::separate::{separate_coincident, Separation, MOST, STEP};
use voxlod_budget::{levels, PortfolioOptions};
use voxlod_core::glam::{DVec3, Vec3};
use voxlod_core::manifold::make_manifold;
use voxlod_core::weld::weld_vertices;
use voxlod_core::{mesh_topology, TriangleMesh};
use voxlod_testkit::scenes;
use voxlod_testkit::shapes::{append, icosphere, torus, unit_cube};

/// `a` and `b` as one mesh, welded so that the points they share are one vertex each.
fn welded_pair(a: &TriangleMesh, b: &TriangleMesh) -> TriangleMesh {
    let mut both = a.clone();
    append(&mut both, b);
    weld_vertices(&mut both);
    both
}

fn moved(mesh: &TriangleMesh, by: Vec3) -> TriangleMesh {
    let mut m = mesh.clone();
    m.positions.iter_mut().for_each(|p| *p += by);
    m
}

/// The tetrahedron (0,0,0), (1,0,0), (0,1,0), (0,0,1), outward.
fn tetrahedron() -> TriangleMesh {
    TriangleMesh::new(
        vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z],
        vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    )
}

/// `mesh` with every triangle on its own three vertices.
fn soup(mesh: &TriangleMesh) -> TriangleMesh {
    let mut soup = TriangleMesh::default();
    for t in &mesh.triangles {
        let first = soup.positions.len() as u32;
        soup.positions.extend(t.map(|v| mesh.positions[v as usize]));
        soup.triangles.push([first, first + 1, first + 2]);
    }
    soup
}

fn unit_normal(mesh: &TriangleMesh, t: usize) -> DVec3 {
    let [a, b, c] = mesh.corners(t);
    (b - a).cross(c - a).normalize()
}

/// Cuts `mesh` with `make_manifold` (checking the copies it adds), separates it, and checks
/// the contract: welded by position it is a closed manifold of `components` parts; every
/// normal within 0.99 of its own before; every moved vertex within `reach` times its
/// shortest incident edge and every other vertex bit for bit where it was.
fn cut_and_separate(
    mut mesh: TriangleMesh,
    copies: usize,
    components: usize,
    reach: f32,
) -> Separation {
    assert!(!mesh_topology(&mesh).is_manifold());
    assert_eq!(make_manifold(&mut mesh).split_vertices, copies);
    assert!(mesh_topology(&mesh).is_closed_manifold());
    let before = mesh.clone();
    let done = separate_coincident(&mut mesh);
    assert_eq!(done.still_coincident, 0);
    assert_eq!(mesh.triangles, before.triangles);
    for t in 0..mesh.triangles.len() {
        let dot = unit_normal(&mesh, t).dot(unit_normal(&before, t));
        assert!(dot > 0.99, "triangle {t}: {dot}");
    }
    let mut moves = 0;
    for (v, (&p, &q)) in before.positions.iter().zip(&mesh.positions).enumerate() {
        if p.to_array().map(f32::to_bits) == q.to_array().map(f32::to_bits) {
            continue;
        }
        moves += 1;
        let shortest = shortest_edge(&before, v as u32);
        assert!(p.distance(q) <= reach * shortest, "{v}: {p} to {q}");
    }
    assert_eq!(moves, done.moved);
    let mut welded = mesh.clone();
    assert_eq!(
        weld_vertices(&mut welded).vertices_after,
        mesh.positions.len()
    );
    let t = mesh_topology(&welded);
    assert!(
        t.is_closed_manifold() && t.is_consistently_oriented(),
        "{t:?}"
    );
    assert_eq!(t.components, components);
    done
}

fn shortest_edge(mesh: &TriangleMesh, v: u32) -> f32 {
    let mut shortest = f32::INFINITY;
    for t in mesh.triangles.iter().filter(|t| t.contains(&v)) {
        for &w in t.iter().filter(|&&w| w != v) {
            shortest =
                shortest.min(mesh.positions[v as usize].distance(mesh.positions[w as usize]));
        }
    }
    shortest
}

#[test]
fn two_cubes_touching_at_a_corner_are_two_cubes_when_welded() {
    let cube = unit_cube();
    // 8 + 8 vertices, (1, 1, 1) shared: 15, one pinched vertex split into 2 copies.
    let pair = welded_pair(&cube, &moved(&cube, Vec3::ONE));
    assert_eq!(pair.positions.len(), 15);
    let mut cut = pair.clone();
    make_manifold(&mut cut);
    let done = cut_and_separate(pair, 1, 2, STEP as f32);
    assert_eq!(done.moved, 2);
    // Each copy moved into its own cube: one below (1, 1, 1) on every axis, one above.
    let mut mesh = cut;
    separate_coincident(&mut mesh);
    let copies: Vec<Vec3> = mesh.positions[..]
        .iter()
        .filter(|p| p.distance(Vec3::ONE) < 0.01)
        .copied()
        .collect();
    assert_eq!(copies.len(), 2);
    assert!(copies.iter().any(|p| p.max_element() < 1.0));
    assert!(copies.iter().any(|p| p.min_element() > 1.0));
}

#[test]
fn two_cubes_sharing_an_edge_are_two_cubes_when_welded() {
    let cube = unit_cube();
    // The edge (1, 1, 0)–(1, 1, 1) has four triangles: both its ends split.
    let pair = welded_pair(&cube, &moved(&cube, Vec3::new(1.0, 1.0, 0.0)));
    assert_eq!(pair.positions.len(), 14);
    assert_eq!(mesh_topology(&pair).non_manifold_edges, 1);
    let done = cut_and_separate(pair, 2, 2, STEP as f32);
    assert_eq!(done.moved, 4);
}

#[test]
fn two_tetrahedra_touching_at_a_vertex_are_two_when_welded() {
    let tet = tetrahedron();
    // Its point reflection through the origin, wound the other way to stay outward.
    let mut mirrored = tet.clone();
    mirrored.positions.iter_mut().for_each(|p| *p = -*p);
    mirrored.flip_orientation();
    let pair = welded_pair(&tet, &mirrored);
    assert_eq!(pair.positions.len(), 7);
    let done = cut_and_separate(pair, 1, 2, STEP as f32);
    assert_eq!(done.moved, 2);
}

#[test]
fn cubes_far_from_the_origin_come_apart_at_f32_resolution() {
    // Side 1/64 at 1024: a thousandth of the smallest height (1.1e-5) is below a unit in the
    // last place (1.2e-4), so the step grows to MOST of the height (1.7e-4), which rounds to
    // one unit per coordinate: at most twice MOST of the height, the side's √2 MOST.
    let mut small = unit_cube();
    small
        .positions
        .iter_mut()
        .for_each(|p| *p = *p / 64.0 + Vec3::splat(1024.0));
    let pair = welded_pair(&small, &moved(&small, Vec3::splat(1.0 / 64.0)));
    assert_eq!(pair.positions.len(), 15);
    let done = cut_and_separate(pair, 1, 2, 2f32.sqrt() * MOST as f32);
    assert_eq!(done.moved, 2);
}

#[test]
fn meshes_without_pinches_keep_every_coordinate() {
    for shape in [unit_cube(), icosphere(3), torus(48, 24, 1.0, 0.3)] {
        let mut mesh = shape.clone();
        assert_eq!(separate_coincident(&mut mesh), Separation::default());
        assert_eq!(mesh, shape);
    }
}

#[test]
fn seams_a_weld_closes_are_left_together() {
    // The cube as a soup: every corner's copies are joined by seams, so none moves and the
    // weld still gives the closed cube.
    let soup = soup(&unit_cube());
    let mut mesh = soup.clone();
    assert_eq!(separate_coincident(&mut mesh), Separation::default());
    assert_eq!(mesh, soup);
    weld_vertices(&mut mesh);
    assert!(mesh_topology(&mesh).is_closed_manifold());
}

#[test]
fn two_soups_sharing_an_edge_weld_into_two_cubes() {
    // Every edge a seam, the shared edge's positions holding four: each cube's corners stay
    // together (8 positions each), the two cubes' apart (16 after welding, not 14).
    let cube = unit_cube();
    let mut pair = soup(&cube);
    append(&mut pair, &soup(&moved(&cube, Vec3::new(1.0, 1.0, 0.0))));
    let done = separate_coincident(&mut pair);
    // The shared edge's ends, one soup copy per triangle there: the first cube's corners
    // (1, 1, 0) and (1, 1, 1) are in 5 and 3 triangles, the second's (its corners 0 and 4)
    // in 3 and 5.
    assert_eq!((done.moved, done.still_coincident), (5 + 3 + 3 + 5, 0));
    weld_vertices(&mut pair);
    assert_eq!(pair.positions.len(), 16);
    let t = mesh_topology(&pair);
    assert!(t.is_closed_manifold() && t.components == 2, "{t:?}");
}

#[test]
fn scene_levels_are_manifolds_when_welded() {
    // The room's and the building's collapses pinch walls together; cut and separated, every
    // level welded by position is the manifold its indices are.
    for scene in [scenes::room(), scenes::building()] {
        let run = levels(
            &scene.mesh.geometry(),
            &PortfolioOptions::for_triangles(&[2000, 500, 253]),
        )
        .unwrap();
        for level in &run.levels {
            let own = mesh_topology(&level.mesh);
            let mut welded = level.mesh.clone();
            weld_vertices(&mut welded);
            let t = mesh_topology(&welded);
            assert!(t.is_manifold(), "{}: {t:?}", level.report.budget);
            assert!(
                t.is_consistently_oriented(),
                "{}: {t:?}",
                level.report.budget
            );
            assert!(
                t.boundary_edges <= own.boundary_edges,
                "{}",
                level.report.budget
            );
        }
    }
}
