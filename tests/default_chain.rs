//! The default chain of `voxlod::lod`: it starts at or below the
//! input's triangle count, its levels are clean (no crossing triangles by the testkit's
//! independent test, no triangle under a thousandth of a cell², closed and outward-facing), a
//! first level that would vanish moves the start finer with a warning, and an empty level's
//! warning reaches the library's report.

use voxlod::core::glam::Vec3;
use voxlod::core::TriangleMesh;
use voxlod::sampling::Filter;
use voxlod::{LodOptions, Source};
use voxlod_testkit::intersections::{self_intersections, triangles_smaller_than};
use voxlod_testkit::shapes::{icosphere, unit_cube};

#[test]
fn a_sphere_starts_at_or_below_its_triangles_with_clean_levels() {
    // 20 480 triangles; the former fixed 256 would give about 3π · 256² = 617 000.
    let sphere = icosphere(5);
    let lod = voxlod::lod(&Source::Mesh(&sphere), &LodOptions::default()).unwrap();
    let finest = lod.finest.expect("chosen from the input's triangles");
    assert_eq!(finest.input_triangles, 20480);
    assert_eq!(lod.levels[0].resolution, finest.resolution);
    assert!(lod.levels[0].mesh.triangle_count() <= 20480);
    // Not far below either: the estimate is within 15 % on smooth shapes.
    assert!(lod.levels[0].mesh.triangle_count() >= 20480 * 7 / 10);
    for level in lod.levels.iter().filter(|l| !l.mesh.is_empty()) {
        let t = &level.topology;
        let cell = level.plan.voxel_size;
        assert!(
            t.is_closed_manifold() && t.is_consistently_oriented(),
            "{t:?}"
        );
        assert_eq!(t.genus, Some(0));
        assert!(level.mesh.signed_volume() > 0.0);
        assert!(self_intersections(&level.mesh).is_empty());
        assert_eq!(triangles_smaller_than(&level.mesh, 1e-3 * cell * cell), 0);
    }
}

#[test]
fn a_given_resolution_is_kept() {
    let sphere = icosphere(3);
    let options = LodOptions::halving(40, 2, Filter::Hypercone);
    let lod = voxlod::lod(&Source::Mesh(&sphere), &options).unwrap();
    assert!(lod.finest.is_none());
    assert_eq!(lod.levels[0].resolution, 40);
}

#[test]
fn a_plate_too_thin_for_the_chosen_start_starts_finer() {
    // A 2 × 2 × 0.02 plate of 12 triangles: its count gives the floor of 16 samples, where a
    // voxel (0.125) is six times the plate, which the filter removes; at 256 it has a surface.
    let cube = unit_cube();
    let positions = (cube.positions.iter())
        .map(|p| Vec3::new(2.0 * p.x, 2.0 * p.y, 0.02 * p.z))
        .collect();
    let plate = TriangleMesh::new(positions, cube.triangles);
    let lod = voxlod::lod(&Source::Mesh(&plate), &LodOptions::default()).unwrap();
    let finest = lod.finest.unwrap();
    assert!(
        finest.resolution > 16 && finest.resolution <= 256,
        "{finest:?}"
    );
    assert_eq!(lod.levels[0].resolution, finest.resolution);
    assert!(!lod.levels[0].mesh.is_empty());
    assert!(
        lod.warnings[0].contains("the chain starts at resolution"),
        "{:?}",
        lod.warnings
    );
    // A resolution one coarser than the start has no surface (the search's bisection).
    let coarser = LodOptions::halving(finest.resolution - 1, 1, Filter::Hypercone);
    let e = voxlod::lod(&Source::Mesh(&plate), &coarser).unwrap_err();
    assert!(
        matches!(
            e,
            voxlod::Error::Pyramid(voxlod::PyramidError::NoSurface { .. })
        ),
        "{e}"
    );
}

#[test]
fn an_empty_level_is_in_the_warnings() {
    let cube = unit_cube();
    let options = LodOptions {
        pyramid: voxlod::sampling::PyramidOptions::for_resolutions(
            vec![16, 8, 1],
            Filter::Hypercone,
        ),
        finest: voxlod::Finest::Given,
        ..LodOptions::default()
    };
    let lod = voxlod::lod(&Source::Mesh(&cube), &options).unwrap();
    assert!(lod.levels[2].mesh.is_empty());
    assert_eq!(lod.warnings.len(), 1, "{:?}", lod.warnings);
    assert!(lod.warnings[0].starts_with("level 2: the filter of radius"));
}
