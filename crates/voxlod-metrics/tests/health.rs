//! Health reports on shapes with known topology and volume, and on the shared real meshes.

mod common;

use glam::Vec3;
use voxlod_core::validate::MeshDefect;
use voxlod_core::{CoreError, TriangleMesh};
use voxlod_metrics::{mesh_report, welded_mesh_report, MetricsError};
use voxlod_testkit::data::shared_data_or_skip;

#[test]
fn cube_is_a_closed_genus_zero_shell_of_volume_one() {
    let r = mesh_report(&common::unit_cube()).unwrap();
    let t = &r.topology;
    assert_eq!((t.vertices, t.edges, t.triangles), (8, 18, 12));
    assert_eq!(
        (t.euler_characteristic, t.genus, t.components),
        (2, Some(0), 1)
    );
    assert_eq!(t.boundary_loops, 0);
    assert!((r.volume - 1.0).abs() < 1e-12 && (r.area - 6.0).abs() < 1e-12);
    assert!(r.volume_is_enclosed && !r.inside_out && r.closed_manifold);
    assert_eq!(r.zero_area_triangles, 0);
    assert_eq!(r.bounds.min, [0.0; 3]);
    assert_eq!(r.bounds.max, [1.0; 3]);
    assert!((r.diagonal - 3f64.sqrt()).abs() < 1e-12);
    assert!(r.notes().is_empty(), "{:?}", r.notes());
}

#[test]
fn inside_out_cube_has_negative_volume_and_says_so() {
    let mut cube = common::unit_cube();
    cube.flip_orientation();
    let r = mesh_report(&cube).unwrap();
    assert!((r.volume + 1.0).abs() < 1e-12);
    assert!(r.inside_out && r.volume_is_enclosed && r.consistently_oriented);
    assert_eq!(r.topology.genus, Some(0));
    assert!(r.to_string().contains("the shell is inside out"), "{r}");
}

#[test]
fn open_box_has_one_boundary_loop_and_no_enclosed_volume() {
    let mut cube = common::unit_cube();
    cube.triangles.truncate(10); // drop the x = 0 side
    let r = mesh_report(&cube).unwrap();
    assert_eq!(r.topology.boundary_loops, 1);
    assert_eq!(r.topology.boundary_edges, 4);
    assert_eq!(r.topology.genus, Some(0));
    assert!(!r.volume_is_enclosed && !r.inside_out && !r.closed_manifold);
    assert!(
        r.to_string()
            .contains("the surface is open: 4 boundary edges in 1 loop, so"),
        "{r}"
    );
}

#[test]
fn a_fin_on_a_closed_cube_is_one_loop_through_its_base() {
    // The fin's base is a cube edge, then used three times; its two free edges and the base
    // close one loop (hand-counted). Notes say it in the singular where it is one.
    let mut m = common::unit_cube();
    let (a, b) = (m.triangles[0][0], m.triangles[0][1]);
    m.positions.push(Vec3::new(0.5, -1.0, -1.0));
    m.triangles.push([a, b, 8]);
    let r = mesh_report(&m).unwrap();
    let t = &r.topology;
    assert_eq!((t.boundary_edges, t.boundary_loops), (2, 1));
    let text = r.to_string();
    assert!(
        text.contains("2 boundary edges in 1 loop (a loop closes through"),
        "{text}"
    );
    assert!(
        text.contains(
            "not a manifold: 1 edge shared by three or more triangles, 0 pinched vertices"
        ),
        "{text}"
    );
}

#[test]
fn torus_has_genus_one_and_the_volume_of_its_polyhedron() {
    let (n, m) = (64, 32);
    let r = mesh_report(&common::torus(n, m)).unwrap();
    assert_eq!(r.topology.genus, Some(1));
    assert_eq!(r.topology.euler_characteristic, 0);
    assert!(r.closed_manifold && r.volume_is_enclosed && !r.inside_out);
    // The true torus encloses 2π²Rr² = 4π² and has area 4π²Rr = 8π²; the inscribed polyhedron
    // a little less of each.
    let pi2 = std::f64::consts::PI.powi(2);
    assert!(
        r.volume < 4.0 * pi2 && r.volume > 0.99 * 4.0 * pi2,
        "{}",
        r.volume
    );
    assert!(
        r.area < 8.0 * pi2 && r.area > 0.99 * 8.0 * pi2,
        "{}",
        r.area
    );
}

#[test]
fn zero_area_triangles_are_counted_apart_from_index_degenerate_ones() {
    let mut cube = common::unit_cube();
    cube.positions.push(Vec3::new(2.0, 0.0, 0.0)); // collinear with vertices 0 and 1
    cube.positions.push(Vec3::new(1.0, 0.0, 0.0)); // same place as vertex 1, not welded
    cube.triangles.push([0, 1, 8]); // collinear corners
    cube.triangles.push([1, 9, 2]); // two coincident corners
    cube.triangles.push([0, 0, 2]); // a repeated index: degenerate, not "zero area"
    let r = mesh_report(&cube).unwrap();
    assert_eq!(r.zero_area_triangles, 2);
    assert_eq!(r.topology.degenerate_triangles, 1);
    assert!((r.area - 6.0).abs() < 1e-12);
}

#[test]
fn welding_is_applied_and_recorded() {
    // The cube as a triangle soup: 36 vertices, every edge a boundary until welded.
    let cube = common::unit_cube();
    let mut soup = TriangleMesh::default();
    for t in 0..cube.triangles.len() {
        let base = soup.positions.len() as u32;
        soup.positions.extend(
            cube.triangles[t]
                .iter()
                .map(|&v| cube.positions[v as usize]),
        );
        soup.triangles.push([base, base + 1, base + 2]);
    }
    assert_eq!(mesh_report(&soup).unwrap().topology.boundary_edges, 36);
    let r = welded_mesh_report(&soup).unwrap();
    let weld = r.welding.unwrap();
    assert_eq!((weld.vertices_before, weld.vertices_after), (36, 8));
    assert_eq!(r.topology.genus, Some(0));
    assert!(r.closed_manifold);
    assert!(r.to_string().contains("36 vertices became 8"));
}

#[test]
fn json_has_the_keys_the_command_line_promises() {
    let r = mesh_report(&common::torus(8, 6)).unwrap();
    let json = serde_json::to_value(&r).unwrap();
    for key in [
        "components",
        "boundary_loops",
        "genus",
        "volume",
        "area",
        "vertices",
        "triangles",
        "non_manifold_edges",
        "non_manifold_vertices",
        "duplicate_triangles",
        "zero_area_triangles",
        "euler_characteristic",
        "inside_out",
        "diagonal",
    ] {
        assert!(json.get(key).is_some(), "missing {key} in {json}");
    }
    assert_eq!(json["genus"], 1);
    let mut pinched = common::unit_cube();
    pinched.triangles[0].swap(1, 2);
    let json = serde_json::to_value(mesh_report(&pinched).unwrap()).unwrap();
    assert!(json["genus"].is_null());
}

#[test]
fn refuses_what_it_cannot_report() {
    assert!(matches!(
        mesh_report(&TriangleMesh::default()),
        Err(MetricsError::Core(CoreError::Mesh(MeshDefect::NoTriangles)))
    ));
    let mut cube = common::unit_cube();
    cube.positions[2] = Vec3::NAN;
    assert!(mesh_report(&cube)
        .unwrap_err()
        .to_string()
        .starts_with("vertex 2 has a non-finite coordinate"));
    // No area is reported, not refused.
    let flat = TriangleMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::X * 2.0], vec![[0, 1, 2]]);
    let r = mesh_report(&flat).unwrap();
    assert_eq!((r.area, r.zero_area_triangles), (0.0, 1));
}

#[test]
fn real_meshes_match_their_documented_shape() {
    let test = "real_meshes_match_their_documented_shape";
    if let Some(path) = shared_data_or_skip("meshes/rocker-arm.obj", test) {
        let r = welded_mesh_report(&common::read_obj(&path)).unwrap();
        assert_eq!(r.topology.triangles, 20_088);
        assert_eq!(r.topology.genus, Some(1));
        assert!(r.closed_manifold && !r.inside_out && r.volume > 0.0);
    }
    if let Some(path) = shared_data_or_skip("meshes/stanford-bunny.obj", test) {
        let r = welded_mesh_report(&common::read_obj(&path)).unwrap();
        assert_eq!(r.topology.unreferenced_vertices, 1_113);
        assert_eq!(r.topology.boundary_loops, 5);
        assert!(!r.volume_is_enclosed);
    }
    if let Some(path) = shared_data_or_skip("meshes/thingi10k-68247.stl", test) {
        let r = welded_mesh_report(&common::read_ascii_stl(&path)).unwrap();
        assert_eq!(r.topology.triangles, 78);
        assert!(r.closed_manifold && r.consistently_oriented);
        assert!(r.inside_out && r.volume < 0.0, "{r}");
    }
    if let Some(path) = shared_data_or_skip("meshes/thingi10k-42722.stl", test) {
        let r = welded_mesh_report(&common::read_ascii_stl(&path)).unwrap();
        eprintln!("thingi10k-42722.stl:\n{r}");
        assert!(r.zero_area_triangles + r.topology.degenerate_triangles > 0);
        assert!(r.topology.non_manifold_edges > 0 && r.topology.inconsistent_edges > 0);
        assert!(r.topology.genus.is_none());
        // Four boundary edges, each between two edges used three times: two rims that close
        // through 12 and 8 of those edges (counted by hand from the welded file).
        assert_eq!(
            (r.topology.boundary_edges, r.topology.boundary_loops),
            (4, 2)
        );
    }
}
