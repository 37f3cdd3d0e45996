//! `label_surfaces`, the stage's one call, on generated maps: both surfaces closed and outward
//! for every label, the shared one meeting its neighbours exactly, volumes against the voxels,
//! the frame and the labels asked for honoured.

use std::collections::HashMap;

use voxlod_core::glam::{DMat3, DVec3};
use voxlod_core::world::{Frame, Orientation};
use voxlod_core::{mesh_topology, Grid, LabelVolume, TriangleMesh};
use voxlod_labels::{label_surfaces, LabelsError, SmoothingOptions, Surface, SurfaceOptions};
use voxlod_testkit::compare::{reversed_key, triangle_keys, TriangleKey};

fn map(dims: [usize; 3], spacing: [f64; 3], label: impl Fn([f64; 3]) -> u32) -> LabelVolume {
    let grid = Grid::new(dims, spacing, [0.0; 3]).unwrap();
    let values = (0..grid.len())
        .map(|n| [n % dims[0], n / dims[0] % dims[1], n / (dims[0] * dims[1])])
        .map(|at| label(at.map(|a| a as f64)))
        .collect();
    LabelVolume::from_vec(grid, values).unwrap()
}

/// Three balls of different radii, two of them overlapping (the later drawn over the earlier),
/// and a slab along the map's border.
fn scene() -> LabelVolume {
    map([40, 36, 30], [1.0, 1.0, 1.5], |[x, y, z]| {
        let ball = |c: [f64; 3], r: f64| {
            ((x - c[0]).powi(2) + (y - c[1]).powi(2) + ((z - c[2]) * 1.5).powi(2)).sqrt() <= r
        };
        if ball([26.0, 18.0, 14.0], 9.0) {
            3
        } else if ball([14.0, 18.0, 14.0], 10.0) {
            2
        } else if x < 3.0 {
            7
        } else {
            u32::from(ball([30.0, 8.0, 6.0], 4.0))
        }
    })
}

fn closed_outward(mesh: &TriangleMesh) -> bool {
    let t = mesh_topology(mesh);
    t.is_closed_manifold() && t.is_consistently_oriented() && mesh.signed_volume() > 0.0
}

fn shared() -> SurfaceOptions {
    SurfaceOptions {
        surface: Surface::Shared(SmoothingOptions::default()),
        ..SurfaceOptions::default()
    }
}

#[test]
fn every_label_closes_outward_by_either_surface() {
    for options in [SurfaceOptions::default(), shared()] {
        let surfaces = label_surfaces(&scene(), &options).unwrap();
        let values: Vec<u32> = surfaces.labels.iter().map(|l| l.label.value).collect();
        assert_eq!(values, [1, 2, 3, 7]);
        for l in &surfaces.labels {
            assert!(
                closed_outward(&l.mesh),
                "{:?} label {}",
                options.surface,
                l.label.value
            );
        }
    }
}

#[test]
fn shared_surfaces_keep_the_voxel_volume_within_a_percent() {
    let surfaces = label_surfaces(&scene(), &shared()).unwrap();
    assert!(surfaces.smoothing.is_some());
    for l in &surfaces.labels {
        let error = l.mesh.signed_volume() / l.voxel_volume - 1.0;
        assert!(
            error.abs() < 0.01,
            "label {}: {:+.3} %",
            l.label.value,
            100.0 * error
        );
    }
}

#[test]
fn neighbours_of_the_shared_surface_use_the_same_triangles_reversed() {
    let surfaces = label_surfaces(&scene(), &shared()).unwrap();
    let mut uses: HashMap<TriangleKey, Vec<u32>> = HashMap::new();
    for l in &surfaces.labels {
        for t in triangle_keys(&l.mesh) {
            uses.entry(t).or_default().push(l.label.value);
        }
    }
    // Labels 2 and 3 touch: every triangle of 2's that 3 also has, 3 has reversed.
    let (mut between, mut overlaps) = (0, 0);
    for (t, labels) in &uses {
        overlaps += usize::from(labels.len() > 1);
        if labels == &[2] && uses.get(&reversed_key(t)).is_some_and(|o| o == &[3]) {
            between += 1;
        }
    }
    assert_eq!(overlaps, 0, "a triangle used twice the same way round");
    assert!(between > 100, "{between} triangles between labels 2 and 3");
}

#[test]
fn a_mirrored_map_in_another_frame_stays_outward() {
    let mirror = Orientation {
        direction: DMat3::from_diagonal(DVec3::new(-1.0, 1.0, 1.0)),
        frame: Frame::Lps,
    };
    for surface in [
        Surface::MarchingCubes,
        Surface::Shared(SmoothingOptions::default()),
    ] {
        let options = SurfaceOptions {
            surface,
            frame: Some(Frame::Ras),
            ..SurfaceOptions::default()
        };
        let surfaces = label_surfaces(&scene().oriented(mirror), &options).unwrap();
        for l in &surfaces.labels {
            assert!(closed_outward(&l.mesh), "label {}", l.label.value);
        }
        // LPS to RAS negates x and y: the mirrored x comes back positive, y goes negative.
        let mesh = &surfaces.labels[1].mesh;
        assert!(mesh.positions.iter().all(|p| p.x > 0.0 && p.y < 0.0));
    }
}

#[test]
fn the_labels_asked_for_come_in_their_order_and_a_missing_one_is_named() {
    let options = SurfaceOptions {
        labels: Some(vec![7, 2]),
        ..shared()
    };
    let surfaces = label_surfaces(&scene(), &options).unwrap();
    let values: Vec<u32> = surfaces.labels.iter().map(|l| l.label.value).collect();
    assert_eq!(values, [7, 2]);
    let options = SurfaceOptions {
        labels: Some(vec![5]),
        ..SurfaceOptions::default()
    };
    let error = label_surfaces(&scene(), &options).unwrap_err();
    assert!(matches!(error, LabelsError::Missing(5, _)), "{error}");
    let empty = map([3, 3, 3], [1.0; 3], |_| 0);
    let error = label_surfaces(&empty, &SurfaceOptions::default()).unwrap_err();
    assert!(matches!(error, LabelsError::NoLabels));
}

#[test]
fn the_owned_call_gives_the_borrowed_call_s_meshes() {
    for options in [SurfaceOptions::default(), shared()] {
        let borrowed = label_surfaces(&scene(), &options).unwrap();
        let owned = voxlod_labels::label_surfaces_owned(scene(), &options).unwrap();
        assert_eq!(borrowed.labels.len(), owned.labels.len());
        for (a, b) in borrowed.labels.iter().zip(&owned.labels) {
            assert_eq!(
                (a.label.value, a.voxel_volume),
                (b.label.value, b.voxel_volume)
            );
            assert_eq!(a.mesh.triangles, b.mesh.triangles);
            assert_eq!(a.mesh.positions, b.mesh.positions);
        }
        assert_eq!(borrowed.smoothing.is_some(), owned.smoothing.is_some());
    }
}
