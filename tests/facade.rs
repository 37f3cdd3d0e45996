//! The facade's calls on generated shapes whose answers are known: a torus keeps genus 1 and
//! stays a closed manifold while its levels coarsen, a thresholded ball encloses 4/3·π·r³, a
//! callback can stop a job, and broken input is classed as bad input.

use std::f64::consts::PI;

use voxlod::core::glam::Vec3;
use voxlod::core::{Grid, TriangleMesh, Volume};
use voxlod::sampling::Filter;
use voxlod::{Control, ErrorClass, LodOptions, Source};
use voxlod_testkit::shapes::torus;

/// A torus of major radius 1 and tube 0.35: four levels from 48 samples.
#[test]
fn lod_of_a_torus_keeps_genus_one_and_falls_in_triangles() {
    let mesh = torus(96, 48, 1.0, 0.35);
    let options = LodOptions::halving(48, 4, Filter::Hypercone);
    let lod = voxlod::lod(&Source::Mesh(&mesh), &options).unwrap();
    assert_eq!(lod.levels.len(), 4);
    let counts: Vec<usize> = lod.levels.iter().map(|l| l.mesh.triangle_count()).collect();
    assert!(counts.windows(2).all(|w| w[1] < w[0]), "{counts:?}");
    for (k, level) in lod.levels.iter().enumerate() {
        assert_eq!(level.resolution, [48, 24, 12, 6][k]);
        if level.mesh.is_empty() {
            continue;
        }
        assert!(level.topology.is_closed_manifold(), "level {k}");
        assert!(level.topology.is_consistently_oriented(), "level {k}");
    }
    // The hole (0.65 across the tube's inside) is many voxels wide at the two fine levels.
    for level in &lod.levels[..2] {
        assert_eq!(level.topology.genus, Some(1), "{:?}", level.topology);
        assert_eq!(level.topology.components, 1);
    }
}

/// A ball of radius 1 sampled as a distance field, thresholded at the surface: the finest
/// level encloses the ball's volume within 3%.
#[test]
fn threshold_source_on_a_sphere_volume_encloses_its_volume() {
    let n = 49;
    let h = 3.0 / (n - 1) as f64;
    let grid = Grid::new([n; 3], [h; 3], [-1.5; 3]).unwrap();
    let mut values = Vec::with_capacity(n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let p = grid.position(i as f64, j as f64, k as f64);
                values.push((1.0 - p.length()) as f32);
            }
        }
    }
    let volume = Volume::from_vec(grid, values).unwrap();
    let source = Source::Threshold {
        volume: &volume,
        threshold: 0.0,
    };
    let lod = voxlod::lod(&source, &LodOptions::halving(64, 2, Filter::Hypercone)).unwrap();
    let fine = &lod.levels[0];
    assert!(fine.topology.is_closed_manifold());
    assert_eq!(fine.topology.genus, Some(0));
    let enclosed = fine.mesh.signed_volume();
    let ball = 4.0 / 3.0 * PI;
    let relative = (enclosed - ball).abs() / ball;
    assert!(relative < 0.03, "enclosed {enclosed}, ball {ball}");
}

#[test]
fn a_callback_that_stops_cancels_the_job() {
    let mesh = torus(48, 24, 1.0, 0.35);
    let options = LodOptions::halving(32, 3, Filter::Hypercone);
    let stop = |_: voxlod::Progress| Control::Stop;
    let err = voxlod::lod_with(&Source::Mesh(&mesh), &options, &stop).unwrap_err();
    assert!(matches!(err, voxlod::Error::Cancelled), "{err}");
    assert_eq!(err.class(), ErrorClass::Cancelled);
    // Stopping after the second step: the steps seen are counted, and no more.
    let seen = std::sync::atomic::AtomicUsize::new(0);
    let stop_after_two = |p: voxlod::Progress| {
        seen.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        if p.done >= 2 {
            Control::Stop
        } else {
            Control::Continue
        }
    };
    let err = voxlod::lod_with(&Source::Mesh(&mesh), &options, &stop_after_two).unwrap_err();
    assert_eq!(err.class(), ErrorClass::Cancelled);
    assert_eq!(seen.load(std::sync::atomic::Ordering::Relaxed), 3);
}

#[test]
fn broken_meshes_are_bad_input_and_bad_options_are_usage() {
    let mut nan = torus(24, 12, 1.0, 0.35);
    nan.positions[5] = Vec3::new(f32::NAN, 0.0, 0.0);
    let empty = TriangleMesh::new(vec![Vec3::ZERO], vec![]);
    let out_of_range = TriangleMesh::new(vec![Vec3::ZERO; 3], vec![[0, 1, 7]]);
    for (what, mesh) in [("nan", &nan), ("empty", &empty), ("index", &out_of_range)] {
        let err = voxlod::lod(&Source::Mesh(mesh), &LodOptions::preview()).unwrap_err();
        assert_eq!(err.class(), ErrorClass::BadInput, "{what}: {err}");
        let err = voxlod::inspect(mesh, &Default::default());
        if let Err(err) = err {
            assert_eq!(err.class(), ErrorClass::BadInput, "{what}: {err}");
        }
    }
    let message = voxlod::lod(&Source::Mesh(&nan), &LodOptions::preview())
        .unwrap_err()
        .to_string();
    assert!(message.contains("vertex 5"), "{message}");
    let mut zero = LodOptions::preview();
    zero.pyramid.resolutions = vec![];
    let err = voxlod::lod(&Source::Mesh(&empty), &zero).unwrap_err();
    assert_eq!(err.class(), ErrorClass::Usage, "{err}");
}

#[test]
fn files_round_trip_and_unreadable_files_are_classed() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = torus(24, 12, 1.0, 0.35);
    let path = dir.path().join("torus.ply");
    voxlod::write_mesh(&path, &mesh).unwrap();
    let back = voxlod::read_mesh(&path).unwrap();
    assert_eq!(back.triangle_count(), mesh.triangle_count());
    assert_eq!(back.positions, mesh.positions);
    let missing = voxlod::read_mesh(dir.path().join("missing.obj")).unwrap_err();
    assert_eq!(missing.class(), ErrorClass::Io, "{missing}");
    let garbage = dir.path().join("garbage.ply");
    std::fs::write(&garbage, b"ply\nformat nonsense\n").unwrap();
    let bad = voxlod::read_mesh(&garbage).unwrap_err();
    assert_eq!(bad.class(), ErrorClass::BadInput, "{bad}");
    assert!(bad.to_string().contains("garbage.ply"), "{bad}");
}

/// A 16³ ball (radius 5, values from −1 to 1) with three NaN corner samples (no data).
fn ball_with_nan_corners() -> Volume {
    let n = 16;
    let grid = Grid::new([n; 3], [1.0; 3], [0.0; 3]).unwrap();
    let mut values: Vec<f32> = (0..n * n * n)
        .map(|v| {
            let p = [v % n, v / n % n, v / (n * n)].map(|c| c as f32 - 7.5);
            (5.0 - (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt()).clamp(-1.0, 1.0)
        })
        .collect();
    for corner in [0, 1, n * n * n - 1] {
        values[corner] = f32::NAN;
    }
    Volume::from_vec(grid, values).unwrap()
}

/// Every volume route says how many samples were NaN and what it did with them, rather than
/// passing them over: the contour and the threshold count them as outside, the direct filter
/// spreads them.
#[test]
fn volume_jobs_name_the_nan_samples() {
    let volume = ball_with_nan_corners();
    let options = LodOptions::halving(16, 1, Filter::Hypercone);
    let threshold = Source::Threshold {
        volume: &volume,
        threshold: 0.0,
    };
    let direct = Source::Direct(&volume);
    for (source, fate) in [
        (threshold, "the threshold counts NaN"),
        (direct, "the filter spreads"),
    ] {
        let iso = matches!(source, Source::Direct(_)).then_some(0.0);
        let lod = voxlod::lod(
            &source,
            &LodOptions {
                iso,
                ..options.clone()
            },
        )
        .unwrap();
        let want = format!("3 samples are NaN (no data): {fate}");
        assert!(
            lod.warnings.iter().any(|w| w.starts_with(&want)),
            "{:?}",
            lod.warnings
        );
    }
}

/// NaN samples (no data) count as outside the surface, and the contour says how many there
/// were rather than passing them over.
#[test]
fn contour_names_the_nan_samples_it_counted_outside() {
    let volume = ball_with_nan_corners();
    let options = voxlod::ContourOptions {
        iso: 0.0,
        ..Default::default()
    };
    let contoured = voxlod::contour(&volume, &options).unwrap();
    assert!(contoured.topology.is_closed_manifold());
    assert!(
        contoured
            .warnings
            .iter()
            .any(|w| w
                .starts_with("3 samples are NaN (no data): marching cubes counts NaN as outside")),
        "{:?}",
        contoured.warnings
    );
}

/// A tetrahedron of volume 1/6 as the one mesh of a GLB, drawn by a node moved by (10, 0, 0)
/// and scaled by 2, as exporters place objects.
fn placed_tetrahedron_glb() -> Vec<u8> {
    let positions: [f32; 12] = [0., 0., 0., 1., 0., 0., 0., 1., 0., 0., 0., 1.];
    let indices: [u16; 12] = [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3];
    let mut bin: Vec<u8> = positions.iter().flat_map(|v| v.to_le_bytes()).collect();
    bin.extend(indices.iter().flat_map(|v| v.to_le_bytes()));
    let doc = serde_json::json!({
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "translation": [10.0, 0.0, 0.0], "scale": [2.0, 2.0, 2.0]}],
        "meshes": [{"name": "tetrahedron", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1]},
            {"bufferView": 1, "componentType": 5123, "count": 12, "type": "SCALAR"}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 24}],
        "buffers": [{"byteLength": 72}]
    });
    voxlod::gltf::to_glb(&doc, bin).unwrap()
}

#[test]
fn a_glb_from_another_tool_is_read_in_world_space() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("placed.glb");
    std::fs::write(&path, placed_tetrahedron_glb()).unwrap();
    let scene = voxlod::read_glb(&path).unwrap();
    assert!(!scene.is_layered());
    let bounds = scene.mesh.bounds();
    assert_eq!(
        (bounds.min.x, bounds.max.x, bounds.max.z),
        (10.0, 12.0, 2.0)
    );
    assert!((scene.mesh.signed_volume() - 8.0 / 6.0).abs() < 1e-9);
    assert_eq!(scene.parts.len(), 1);
    assert_eq!(
        (scene.parts[0].first_vertex, scene.parts[0].vertex_count),
        (0, 4)
    );
}
