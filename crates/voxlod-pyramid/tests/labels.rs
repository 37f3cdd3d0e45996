//! The label maps' one call, `labels`, on hand-made maps: exact voxel counts and boxes, closed
//! meshes where the voxels put them, the order asked for, progress and stopping, and each
//! failure with its class.

use std::sync::atomic::{AtomicUsize, Ordering};

use voxlod_core::glam::DVec3;
use voxlod_core::{mesh_topology, Grid, TriangleMesh, Volume};
use voxlod_pyramid::labels::{labels, LabelOptions};
use voxlod_pyramid::{run_to_end, Control, ErrorClass, InvalidOption, PyramidError};

/// Spacing and origin of the test maps.
const SPACING: [f64; 3] = [1.0, 1.0, 1.5];
const ORIGIN: [f64; 3] = [3.0, -2.0, 1.0];

/// A 20 × 18 × 14 map: label 3 the index box 4..=9 × 3..=8 × 2..=6 (6 × 6 × 5 = 180 voxels),
/// label 8 the box 12..=16 × 10..=15 × 5..=10 (5 × 6 × 6 = 180 voxels) but for its corner
/// voxel (12, 10, 5), which holds label 21 (one voxel).
fn three_label_map() -> Volume {
    let grid = Grid::new([20, 18, 14], SPACING, ORIGIN).unwrap();
    let mut values = vec![0.0f32; grid.len()];
    for k in 0..14 {
        for j in 0..18 {
            for i in 0..20 {
                let label = if (i, j, k) == (12, 10, 5) {
                    21.0
                } else if (4..=9).contains(&i) && (3..=8).contains(&j) && (2..=6).contains(&k) {
                    3.0
                } else if (12..=16).contains(&i) && (10..=15).contains(&j) && (5..=10).contains(&k)
                {
                    8.0
                } else {
                    0.0
                };
                values[grid.index(i, j, k)] = label;
            }
        }
    }
    Volume::from_vec(grid, values).unwrap()
}

/// A sample's position in the map's world.
fn world(index: [f64; 3]) -> DVec3 {
    DVec3::from(std::array::from_fn(|a| ORIGIN[a] + SPACING[a] * index[a]))
}

/// The smallest and largest corner of a mesh's vertices.
fn extent(mesh: &TriangleMesh) -> (DVec3, DVec3) {
    mesh.positions.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(p.as_dvec3()), hi.max(p.as_dvec3())),
    )
}

#[test]
fn every_label_is_found_with_its_exact_voxels_and_box_and_meshed_closed_where_its_voxels_are() {
    let map = three_label_map();
    let meshes = labels(&map, &LabelOptions::for_levels(2), &run_to_end).unwrap();
    let found: Vec<(i64, usize, [usize; 3], [usize; 3])> = meshes
        .labels
        .iter()
        .map(|l| (l.label.value, l.label.voxels, l.label.min, l.label.max))
        .collect();
    assert_eq!(
        found,
        vec![
            (3, 180, [4, 3, 2], [9, 8, 6]),
            (8, 179, [12, 10, 5], [16, 15, 10]),
            (21, 1, [12, 10, 5], [12, 10, 5]),
        ]
    );
    for l in &meshes.labels {
        assert_eq!(
            l.voxel_volume,
            l.label.voxels as f64 * 1.5,
            "label {}",
            l.label.value
        );
        assert_eq!(l.levels.len(), 2, "label {}", l.label.value);
        assert_eq!(
            l.levels.iter().map(|v| v.plan.level).collect::<Vec<_>>(),
            vec![0, 1]
        );
    }
    // Label 3's level 0: one closed, outward shell. Trilinear interpolation of the indicator
    // puts each face halfway between the last voxel inside and the first outside, and a face of
    // a box filtered by a kernel symmetric about it keeps density ½ on that plane (paper §2):
    // the faces' centres lie on the planes at index 3.5, 9.5 (x), 2.5, 8.5 (y), 1.5, 6.5 (z),
    // the corners and edges rounded inward by the filter. Level 0 samples at the map's finest
    // spacing (1, here less than the slices' 1.5) and marching cubes interpolates the filtered
    // density linearly between samples: within a tenth of a level-0 voxel.
    let box3 = &meshes.labels[0].levels[0];
    let t = mesh_topology(&box3.mesh);
    assert!(
        t.is_closed_manifold()
            && t.is_consistently_oriented()
            && t.components == 1
            && t.genus == Some(0),
        "{t:?}"
    );
    assert!(box3.mesh.signed_volume() > 0.0, "outward");
    let (lo, hi) = extent(&box3.mesh);
    let (lo_expected, hi_expected) = (world([3.5, 2.5, 1.5]), world([9.5, 8.5, 6.5]));
    for a in 0..3 {
        let tolerance = 0.1 * box3.plan.voxel_size;
        assert!(
            (lo[a] - lo_expected[a]).abs() < tolerance,
            "axis {a}: {lo} vs {lo_expected}"
        );
        assert!(
            (hi[a] - hi_expected[a]).abs() < tolerance,
            "axis {a}: {hi} vs {hi_expected}"
        );
    }
    // Its centroid (of the enclosed solid) is the box's centre, by symmetry.
    let centre = world([6.5, 5.5, 4.0]);
    let centroid = solid_centroid(&box3.mesh);
    assert!(
        (centroid - centre).length() < 1e-3,
        "{centroid} vs {centre}"
    );
    // The filter rounds the 78 units of edges and the corners inward and moves nothing else:
    // the enclosed volume is below the voxels' (6 × 6 × 5 voxels of 1.5 = 270), by less than
    // 10 % (measured: 7.5 %).
    let v = box3.mesh.signed_volume();
    assert!(v < 270.0 && v > 0.9 * 270.0, "volume {v}");
    // Each coarser level is a closed shell too, with fewer triangles.
    let coarse = &meshes.labels[0].levels[1];
    assert!(coarse.topology.is_closed_manifold());
    assert!(coarse.mesh.triangles.len() < box3.mesh.triangles.len());
}

/// The centroid of the solid a closed, outward mesh encloses (signed tetrahedra from the origin).
fn solid_centroid(mesh: &TriangleMesh) -> DVec3 {
    let (mut sum, mut volume) = (DVec3::ZERO, 0.0);
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|v| mesh.positions[v as usize].as_dvec3());
        let v = a.dot(b.cross(c)) / 6.0;
        sum += v * (a + b + c) / 4.0;
        volume += v;
    }
    sum / volume
}

#[test]
fn the_labels_asked_for_come_back_in_the_order_asked_and_progress_counts_them() {
    let map = three_label_map();
    let options = LabelOptions {
        labels: Some(vec![8, 3]),
        ..LabelOptions::default()
    };
    let steps = AtomicUsize::new(0);
    let meshes = labels(&map, &options, &|p| {
        assert_eq!(p.total, 2);
        steps.fetch_max(p.done, Ordering::Relaxed);
        Control::Continue
    })
    .unwrap();
    let values: Vec<i64> = meshes.labels.iter().map(|l| l.label.value).collect();
    assert_eq!(values, vec![8, 3]);
    assert_eq!(steps.into_inner(), 2);
    assert!(meshes.labels.iter().all(|l| l.levels.len() == 1));
}

#[test]
fn a_callback_that_stops_cancels_the_job() {
    let map = three_label_map();
    let e = labels(&map, &LabelOptions::default(), &|p| {
        if p.done >= 1 {
            Control::Stop
        } else {
            Control::Continue
        }
    })
    .unwrap_err();
    assert!(matches!(e, PyramidError::Cancelled), "{e}");
    assert_eq!(e.class(), ErrorClass::Cancelled);
}

#[test]
fn a_missing_label_is_a_wrong_option_and_a_bad_map_is_bad_input() {
    let map = three_label_map();
    let options = LabelOptions {
        labels: Some(vec![3, 42]),
        ..LabelOptions::default()
    };
    let e = labels(&map, &options, &run_to_end).unwrap_err();
    assert_eq!(e.class(), ErrorClass::Usage, "{e}");
    match &e {
        PyramidError::InvalidOption(InvalidOption { option, value, .. }) => {
            assert_eq!((*option, value.as_str()), ("labels", "42"));
        }
        other => panic!("{other:?}"),
    }
    assert!(
        e.to_string().contains("no label 42 (it holds 3, 8, 21)"),
        "{e}"
    );

    let grid = Grid::new([4, 4, 4], [1.0; 3], [0.0; 3]).unwrap();
    let empty = Volume::filled(grid, 0.0, "a map of background").unwrap();
    let e = labels(&empty, &LabelOptions::default(), &run_to_end).unwrap_err();
    assert!(matches!(e, PyramidError::NoLabels), "{e}");
    assert_eq!(e.class(), ErrorClass::BadInput);

    let mut values = vec![0.0f32; grid.len()];
    values[grid.index(1, 2, 3)] = 2.5;
    let fractional = Volume::from_vec(grid, values).unwrap();
    let e = labels(&fractional, &LabelOptions::default(), &run_to_end).unwrap_err();
    match e {
        PyramidError::NotALabel { at, value } => assert_eq!((at, value), ([1, 2, 3], 2.5)),
        ref other => panic!("{other:?}"),
    }
    assert_eq!(e.class(), ErrorClass::BadInput);
}

#[test]
fn a_label_that_fails_is_named_and_keeps_its_class() {
    let map = three_label_map();
    let mut options = LabelOptions {
        labels: Some(vec![8]),
        ..LabelOptions::default()
    };
    options.lod.pyramid.radius_voxels = -1.0;
    let e = labels(&map, &options, &run_to_end).unwrap_err();
    assert!(e.to_string().starts_with("label 8: "), "{e}");
    assert_eq!(e.class(), ErrorClass::Usage, "{e}");
}
