//! The corpus's cases are what their documentation says: exact counts of triangles,
//! components, boundary loops and genus (known by construction), orientation, scale, and the
//! faults of the scan and the soup before and after welding.

use voxlod_core::components::{submesh, triangle_components};
use voxlod_core::weld::weld_vertices;
use voxlod_core::{crossing_pairs, mesh_topology, Topology, TriangleMesh};
use voxlod_testkit::corpus;

/// What a case promises: triangles, components, boundary loops, genus (None: not an oriented
/// manifold), and the sign of its signed volume (0: open, not checked).
struct Facts {
    name: &'static str,
    triangles: usize,
    components: usize,
    boundary_loops: usize,
    genus: Option<i64>,
    volume_sign: f64,
}

const fn facts(
    name: &'static str,
    triangles: usize,
    components: usize,
    boundary_loops: usize,
    genus: Option<i64>,
    volume_sign: f64,
) -> Facts {
    Facts {
        name,
        triangles,
        components,
        boundary_loops,
        genus,
        volume_sign,
    }
}

/// Every case, in [`corpus::corpus`]'s order. The soup's rows are the unwelded soup: every
/// triangle its own component.
const EXPECTED: [Facts; 22] = [
    facts("sheet", 20_000, 1, 1, Some(0), 0.0),
    facts("sheet-curled", 18_000, 1, 1, Some(0), 0.0),
    facts("open-parts", 23_898, 30, 38, Some(0), 0.0),
    facts("many-parts", 38_784, 201, 0, Some(64), 1.0),
    facts("interpenetrating", 22_976, 6, 0, Some(1), 1.0),
    facts("cad-handles", 3_904, 1, 0, Some(4), 1.0),
    facts("cad-bracket", 3_072, 1, 0, Some(3), 1.0),
    facts("scan-holes", 36_188, 1, 9, Some(0), 0.0),
    facts("inside-out", 12_288, 1, 0, Some(1), -1.0),
    facts("soup", 3_248, 3_248, 3_248, Some(0), 0.0),
    facts("genus-rich", 19_828, 1, 0, Some(314), 1.0),
    facts("thin-tubes", 20_928, 79, 0, Some(0), 1.0),
    facts("sphere-fine", 81_920, 1, 0, Some(0), 1.0),
    facts("two-spheres", 10_240, 2, 0, Some(0), 1.0),
    facts("moebius", 1_920, 1, 1, None, 0.0),
    facts("far-away", 1_280, 1, 0, Some(0), 1.0),
    facts("rings", 32_256, 28, 0, Some(28), 1.0),
    facts("nested-shells", 6_400, 2, 0, Some(0), 1.0),
    facts("double-sided", 7_200, 2, 2, Some(0), 0.0),
    facts("open-tube", 15_360, 1, 2, Some(0), 0.0),
    facts("bumpy-box", 12_288, 1, 0, Some(0), 1.0),
    facts("thin-shell", 3_440, 1, 0, Some(0), 1.0),
];

#[test]
fn every_case_has_its_counts_and_orientation() {
    let cases = corpus::corpus();
    let names: Vec<&str> = cases.iter().map(|(name, _)| *name).collect();
    let expected: Vec<&str> = EXPECTED.iter().map(|f| f.name).collect();
    assert_eq!(names, expected);
    for ((name, mesh), facts) in cases.iter().zip(&EXPECTED) {
        mesh.validate().unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(mesh.normals.is_empty(), "{name}");
        let t = mesh_topology(mesh);
        let got = (t.triangles, t.components, t.boundary_loops, t.genus);
        let want = (
            facts.triangles,
            facts.components,
            facts.boundary_loops,
            facts.genus,
        );
        assert_eq!(got, want, "{name}: {t:?}");
        assert_eq!(t.unreferenced_vertices, 0, "{name}");
        if facts.volume_sign != 0.0 {
            assert!(t.is_closed_manifold(), "{name}: {t:?}");
            assert!(t.is_consistently_oriented(), "{name}: {t:?}");
            let volume = mesh.signed_volume();
            assert_eq!(volume.signum(), facts.volume_sign, "{name}: {volume}");
        }
    }
}

/// Triangles of `mesh` whose area is below 10⁻¹² of its extent squared (about the rounding of
/// f32 coordinates): collapsed triangles that the indices alone do not show.
fn flat_triangles(mesh: &TriangleMesh) -> usize {
    let limit = 1e-12 * extent(mesh).powi(2);
    (0..mesh.triangles.len())
        .filter(|&t| {
            let [a, b, c] = mesh.corners(t);
            0.5 * (b - a).cross(c - a).length() <= limit
        })
        .count()
}

#[test]
fn only_the_soup_has_flat_triangles() {
    for (name, mesh) in corpus::corpus() {
        let expected = if name == "soup" { 8 } else { 0 };
        assert_eq!(flat_triangles(&mesh), expected, "{name}");
    }
}

#[test]
fn the_corpus_is_deterministic() {
    for ((name, a), (_, b)) in corpus::corpus().iter().zip(corpus::corpus().iter()) {
        assert_eq!(a.triangles, b.triangles, "{name}");
        let bits = |m: &TriangleMesh| -> Vec<[u32; 3]> {
            m.positions
                .iter()
                .map(|p| p.to_array().map(f32::to_bits))
                .collect()
        };
        assert_eq!(bits(a), bits(b), "{name}");
    }
}

/// The largest side of a mesh's bounding box.
fn extent(mesh: &TriangleMesh) -> f64 {
    let b = mesh.bounds();
    (b.max - b.min).max_element()
}

#[test]
fn sizes_span_five_orders_of_magnitude() {
    assert_eq!(extent(&corpus::cad_handles()), 1200.0);
    let scaffold = extent(&corpus::genus_rich());
    assert!(scaffold > 0.009 && scaffold < 0.01, "{scaffold}");
    let scan = extent(&corpus::scan_holes());
    assert!(scan > 150.0 && scan < 200.0, "{scan}");
}

#[test]
fn the_sheets_are_single_open_discs() {
    let sheet = mesh_topology(&corpus::sheet());
    assert_eq!((sheet.vertices, sheet.boundary_edges), (10_201, 400));
    let curled = corpus::sheet_curled();
    let t = mesh_topology(&curled);
    assert_eq!((t.vertices, t.boundary_edges), (9_211, 420));
    assert!(t.is_manifold() && t.is_consistently_oriented());
    assert!(crossing_pairs(&curled).is_empty());
}

/// Each component's own topology.
fn parts(mesh: &TriangleMesh) -> Vec<Topology> {
    triangle_components(mesh)
        .iter()
        .map(|triangles| mesh_topology(&submesh(mesh, triangles)))
        .collect()
}

#[test]
fn open_parts_are_all_open_and_some_overlap() {
    let mesh = corpus::open_parts();
    let loops: Vec<usize> = parts(&mesh).iter().map(|t| t.boundary_loops).collect();
    assert_eq!(loops.len(), 30);
    assert_eq!(loops.iter().filter(|&&l| l == 1).count(), 22);
    assert_eq!(loops.iter().filter(|&&l| l == 2).count(), 8);
    assert!(!crossing_pairs(&mesh).is_empty());
}

#[test]
fn many_parts_are_closed_separate_and_apart() {
    let mesh = corpus::many_parts();
    let parts = parts(&mesh);
    assert_eq!(parts.len(), 201);
    assert!(parts.iter().all(|t| t.is_closed_manifold()));
    assert_eq!(parts.iter().filter(|t| t.genus == Some(1)).count(), 64);
    let biggest = parts.iter().map(|t| t.triangles).max();
    assert_eq!(biggest, Some(5_120));
    assert!(crossing_pairs(&mesh).is_empty());
}

#[test]
fn interpenetrating_shells_cross_each_other() {
    let mesh = corpus::interpenetrating();
    let crossings = crossing_pairs(&mesh);
    assert!(crossings.len() > 1000, "{}", crossings.len());
    let parts = parts(&mesh);
    let genera: Vec<Option<i64>> = parts.iter().map(|t| t.genus).collect();
    assert_eq!(
        genera,
        [Some(0), Some(0), Some(1), Some(0), Some(0), Some(0)]
    );
}

#[test]
fn cad_parts_are_clean_solids_of_their_holes() {
    let block = corpus::cad_handles();
    assert!(crossing_pairs(&block).is_empty());
    // The block minus discs of radius 85, 60 and 50 and a slot (a 100 × 100 square and two half
    // discs of radius 50), 200 deep; the polygons inscribed in the holes leave a little more.
    let pi = std::f64::consts::PI;
    let holes = pi * (85f64.powi(2) + 60f64.powi(2) + 50f64.powi(2)) + 100.0 * 100.0 + pi * 2500.0;
    let solid = (1200.0 * 500.0 - holes) * 200.0;
    let volume = block.signed_volume();
    assert!(
        volume > solid && volume < solid * 1.002,
        "{volume} vs {solid}"
    );

    let bracket = corpus::cad_bracket();
    assert!(crossing_pairs(&bracket).is_empty());
    let b = bracket.bounds();
    assert!((b.min.abs().max_element()) < 1e-7, "{b:?}");
    assert!(
        (b.max - voxlod_core::glam::DVec3::new(1.0, 0.6, 0.8))
            .abs()
            .max_element()
            < 1e-6
    );
}

#[test]
fn the_scan_has_six_holes_once_its_seams_are_welded() {
    let mut scan = corpus::scan_holes();
    let before = mesh_topology(&scan);
    assert!(before.is_manifold() && before.is_consistently_oriented());
    assert_eq!((before.boundary_loops, before.genus), (9, Some(0)));
    let report = weld_vertices(&mut scan);
    assert_eq!(report.vertices_before - report.vertices_after, 259);
    let after = mesh_topology(&scan);
    assert!(
        after.is_manifold() && after.is_consistently_oriented(),
        "{after:?}"
    );
    assert_eq!(
        (after.boundary_loops, after.components, after.genus),
        (6, 1, Some(0))
    );
    assert_eq!(after.triangles, before.triangles);
    assert!(crossing_pairs(&scan).is_empty());
}

#[test]
fn inside_out_is_a_closed_torus_wound_inwards() {
    let mut mesh = corpus::inside_out();
    let volume = mesh.signed_volume();
    assert!(volume < -2.0, "{volume}");
    assert!(crossing_pairs(&mesh).is_empty());
    mesh.flip_orientation();
    assert_eq!(mesh.signed_volume(), -volume);
}

#[test]
fn the_soup_welds_into_a_box_with_its_faults() {
    let mut soup = corpus::soup();
    assert_eq!(soup.positions.len(), 3 * soup.triangles.len());
    let report = weld_vertices(&mut soup);
    assert_eq!(report.vertices_after, 1_547);
    let t = mesh_topology(&soup);
    assert_eq!(t.components, 1);
    assert_eq!(t.duplicate_triangles, 154);
    assert_eq!(t.degenerate_triangles, 8);
    assert_eq!(t.inconsistent_edges, 36);
    assert_eq!(t.non_manifold_edges, 3 * 154 + 6);
    // The fin with T-junctions touches the box at its two base corners only.
    assert_eq!(t.non_manifold_vertices, 2);
    assert_eq!((t.boundary_edges, t.boundary_loops), (12, 2));
    assert_eq!(t.genus, None);
}

#[test]
fn the_scaffold_is_one_clean_surface_of_high_genus() {
    let mesh = corpus::genus_rich();
    let t = mesh_topology(&mesh);
    // 7 × 6 × 5 nodes, 6·6·5 + 7·5·5 + 7·6·4 struts.
    assert_eq!(t.genus, Some(523 - 210 + 1));
    assert!(t.non_manifold_vertices == 0 && t.non_manifold_edges == 0);
    assert!(crossing_pairs(&mesh).is_empty());
}

#[test]
fn thin_tubes_are_closed_shells_overlapping_at_the_joints() {
    let mesh = corpus::thin_tubes();
    let parts = parts(&mesh);
    assert!(parts
        .iter()
        .all(|t| t.is_closed_manifold() && t.genus == Some(0)));
    let trunk = parts.iter().filter(|t| t.triangles == 960).count();
    assert_eq!(trunk, 1);
    assert!(parts.iter().filter(|t| t.triangles == 256).count() == 78);
    assert!(!crossing_pairs(&mesh).is_empty());
}

#[test]
fn the_rings_are_linked_without_touching() {
    let rings = corpus::rings();
    assert!(crossing_pairs(&rings).is_empty());
    // The first standing ring (centre (0.65, 0, 0), in the plane y = 0) holds the points where
    // the flat rings at the origin and at (1.3, 0, 0) cross that plane, x = 0.5 and 0.8: 0.15
    // from its centre, well inside its hole (0.5 − 0.08).
    let standing = &rings.positions[16 * 576..17 * 576];
    assert!(standing.iter().all(|p| p.y.abs() < 0.09));
    let (lo, hi) = standing.iter().fold((f32::MAX, f32::MIN), |(lo, hi), p| {
        (lo.min(p.x), hi.max(p.x))
    });
    assert!(
        (lo - 0.07).abs() < 0.01 && (hi - 1.23).abs() < 0.01,
        "{lo} {hi}"
    );
}

#[test]
fn the_double_sided_sheet_is_one_sheet_twice_facing_away() {
    let mesh = corpus::double_sided();
    let half = mesh.positions.len() / 2;
    assert_eq!(mesh.positions[..half], mesh.positions[half..]);
    let (front, back) = mesh.triangles.split_at(mesh.triangles.len() / 2);
    for (f, b) in front.iter().zip(back) {
        let shift = |v: u32| v + half as u32;
        assert_eq!([shift(f[0]), shift(f[2]), shift(f[1])], *b);
    }
}

#[test]
fn the_thin_shell_is_one_closed_plate_a_ten_thousandth_thick() {
    let mesh = corpus::thin_shell();
    assert_eq!(mesh.triangles.len(), 3_440);
    let t = mesh_topology(&mesh);
    assert!(
        t.is_closed_manifold() && t.is_consistently_oriented(),
        "{t:?}"
    );
    assert_eq!((t.components, t.genus), (1, Some(0)));
    // Outward: its volume is the plate's, 2 × 1 × 10⁻⁴ lifted by the wave, within 1 %.
    let volume = mesh.signed_volume();
    assert!(
        volume > 0.0 && (volume / 2e-4 - 1.0).abs() < 0.01,
        "{volume}"
    );
    assert!(crossing_pairs(&mesh).is_empty());
    // Met since the plate candidates (voxlod-budget's module `plate`): in the corpus now.
    assert!(corpus::corpus().iter().any(|(n, _)| *n == "thin-shell"));
    assert!(corpus::known_misses().is_empty());
}
