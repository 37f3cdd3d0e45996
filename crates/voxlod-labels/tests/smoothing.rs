//! Smoothing of the shared surface: volumes kept within 1 %, every vertex in its box, the two
//! labels of an interface still on the same positions, a sphere closer to the sphere, and
//! junctions and borders held.

use std::collections::HashMap;
use voxlod_testkit::compare::{triangle_key, TriangleKey};

use voxlod_core::glam::Vec3;
use voxlod_core::{mesh_topology, Grid, LabelVolume};
use voxlod_labels::smoothing::{smooth, SmoothingOptions, SmoothingReport};
use voxlod_labels::surface_nets::{surface_nets, SharedSurface, SurfaceNetsOptions, VertexKind};
use voxlod_labels::LabelsError;

fn map_of(
    dims: [usize; 3],
    spacing: [f64; 3],
    label: impl Fn(usize, usize, usize) -> u32,
) -> LabelVolume {
    let mut values = Vec::with_capacity(dims[0] * dims[1] * dims[2]);
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                values.push(label(i, j, k));
            }
        }
    }
    LabelVolume::from_vec(Grid::new(dims, spacing, [0.0; 3]).unwrap(), values).unwrap()
}

fn smoothed(
    map: &LabelVolume,
    options: &SmoothingOptions,
) -> (SharedSurface, SharedSurface, SmoothingReport) {
    let blocky = surface_nets(map, &SurfaceNetsOptions::default()).unwrap();
    let mut surface = blocky.clone();
    let report = smooth(&mut surface, options).unwrap();
    (blocky, surface, report)
}

fn voxel_volumes(map: &LabelVolume) -> HashMap<u32, f64> {
    let voxel: f64 = map.grid.spacing.iter().product();
    let mut counts = HashMap::new();
    for &v in map.values.iter().filter(|&&v| v != 0) {
        *counts.entry(v).or_insert(0.0) += voxel;
    }
    counts
}

/// Every label's mesh closed and of its voxel volume within `tolerance` (relative).
fn assert_volumes(surface: &SharedSurface, map: &LabelVolume, tolerance: f64, at_least: f64) {
    let volumes = voxel_volumes(map);
    let voxel: f64 = map.grid.spacing.iter().product();
    for label in surface.labels() {
        let mesh = surface.label_mesh(label);
        assert_eq!(mesh_topology(&mesh).boundary_edges, 0);
        let (got, want) = (mesh.signed_volume(), volumes[&label]);
        if want >= at_least * voxel {
            assert!(
                (got / want - 1.0).abs() <= tolerance,
                "label {label}: {got} against {want} voxels' volume"
            );
        }
    }
}

/// Every vertex within `constraint` voxels of its corner (per axis), and on its border planes.
fn assert_in_boxes(surface: &SharedSurface, spacing: [f64; 3], constraint: f64) {
    for (v, p) in surface.positions.iter().enumerate() {
        let c = surface.corners[v];
        let border = surface.flags[v].border_axes();
        for a in 0..3 {
            let start = (c[a] as f64 - 0.5) * spacing[a];
            let room = if border >> a & 1 == 1 {
                0.0
            } else {
                constraint * spacing[a]
            };
            let off = (p[a] as f64 - start).abs();
            assert!(
                off <= room + 1e-4,
                "vertex {v} axis {a}: {off} beyond {room}"
            );
        }
    }
}

/// The two labels of every interface triangle see it on the same positions, reversed.
fn assert_shared(surface: &SharedSurface) {
    type Key = TriangleKey;
    let key = triangle_key;
    let labels = surface.labels();
    let meshes = surface.label_meshes(&labels).unwrap();
    let mut seen: HashMap<Key, Vec<u32>> = HashMap::new();
    for (&label, mesh) in labels.iter().zip(&meshes) {
        for t in &mesh.triangles {
            seen.entry(key(t.map(|v| mesh.positions[v as usize])))
                .or_default()
                .push(label);
        }
    }
    for (t, &[inside, outside]) in surface.triangles.iter().zip(&surface.sides) {
        let p = t.map(|v| surface.positions[v as usize]);
        assert_eq!(seen.get(&key(p)), Some(&vec![inside]), "triangle {t:?}");
        if outside != 0 {
            assert_eq!(seen.get(&key([p[0], p[2], p[1]])), Some(&vec![outside]));
        }
    }
}

fn sphere(radius: f64) -> LabelVolume {
    let n = (2.0 * radius).ceil() as usize + 4;
    let c = n as f64 / 2.0;
    map_of([n; 3], [1.0; 3], |i, j, k| {
        let d = [i, j, k].map(|x| x as f64 + 0.5 - c);
        (d[0] * d[0] + d[1] * d[1] + d[2] * d[2] <= radius * radius) as u32
    })
}

/// Mean |distance to the centre − r| over the vertices of a sphere map's surface.
fn roughness(surface: &SharedSurface, radius: f64) -> f64 {
    let n = surface.dims[0] as f64;
    let centre = Vec3::splat((n / 2.0 - 0.5) as f32);
    let total: f64 = surface
        .positions
        .iter()
        .map(|p| ((*p - centre).length() as f64 - radius).abs())
        .sum();
    total / surface.positions.len() as f64
}

#[test]
fn a_sphere_keeps_its_volume_and_comes_closer_to_the_sphere() {
    let map = sphere(10.0);
    let (blocky, surface, report) = smoothed(&map, &SmoothingOptions::default());
    assert_volumes(&surface, &map, 0.01, 1000.0);
    assert!(report.worst.unwrap().relative().abs() <= 0.01, "{report:?}");
    assert_in_boxes(&surface, [1.0; 3], 0.5);
    let (before, after) = (roughness(&blocky, 10.0), roughness(&surface, 10.0));
    assert!(
        after < 0.5 * before,
        "mean distance to the sphere {before} -> {after}"
    );
    let mesh = surface.label_mesh(1);
    assert!(mesh_topology(&mesh).is_closed_manifold());
    // The voxel volume itself is within 1 % of the ball's.
    let ball = 4.0 / 3.0 * std::f64::consts::PI * 1000.0;
    assert!((mesh.signed_volume() / ball - 1.0).abs() < 0.01);
}

#[test]
fn without_restoring_the_filter_alone_drifts_and_restoring_brings_it_back() {
    let map = sphere(6.0);
    let plain = SmoothingOptions {
        keep_volume: false,
        ..SmoothingOptions::default()
    };
    let (_, _, drift) = smoothed(&map, &plain);
    let (_, _, kept) = smoothed(&map, &SmoothingOptions::default());
    let (d, k) = (
        drift.worst.unwrap().relative(),
        kept.worst.unwrap().relative(),
    );
    assert!(
        k.abs() < 1e-3 && k.abs() < d.abs(),
        "plain {d}, restored {k}"
    );
    assert!(kept.restore_rounds >= 1);
}

/// A box of `n`³ voxels per label split into 8 labels at its centre, inside a background
/// margin of one voxel when `margin`.
fn octants(n: usize, margin: bool) -> LabelVolume {
    let m = margin as usize;
    let size = 2 * n + 2 * m;
    map_of([size; 3], [1.0, 0.8, 1.3], |i, j, k| {
        let inside = |x: usize| x >= m && x < m + 2 * n;
        if !(inside(i) && inside(j) && inside(k)) {
            return 0;
        }
        let o = [i, j, k].map(|x| ((x - m) >= n) as u32);
        1 + o[0] + 2 * o[1] + 4 * o[2]
    })
}

#[test]
fn eight_labels_keep_their_volumes_their_boxes_and_their_shared_boundaries() {
    for margin in [false, true] {
        let map = octants(8, margin);
        let (_, surface, report) = smoothed(&map, &SmoothingOptions::default());
        assert_eq!(report.volumes.len(), 8);
        assert_volumes(&surface, &map, 0.01, 0.0);
        assert_in_boxes(&surface, [1.0, 0.8, 1.3], 0.5);
        assert_shared(&surface);
    }
}

#[test]
fn junction_vertices_stay_on_their_junction_lines() {
    // The three inner junction lines of the 8 labels are the axis lines through the centre:
    // a vertex on one keeps its two coordinates across the line; the centre stays. (On the
    // outer faces, where the junction lines turn round the box's edges, they are smoothed
    // along themselves.)
    let n = 6;
    let map = octants(n, true);
    let (blocky, surface, _) = smoothed(&map, &SmoothingOptions::default());
    let centre = (n as f32 + 1.0 - 0.5) * Vec3::new(1.0, 0.8, 1.3);
    let mut curves = 0;
    for v in 0..surface.positions.len() {
        let (before, after) = (blocky.positions[v], surface.positions[v]);
        match surface.flags[v].kind() {
            VertexKind::Fixed => assert_eq!(before, after, "vertex {v}"),
            VertexKind::Curve
                if surface.corners[v]
                    .iter()
                    .all(|&c| c > 1 && c < 2 * n as u32 + 1) =>
            {
                curves += 1;
                let moved = after - before;
                let off_line = (0..3).filter(|&a| moved[a].abs() > 1e-6).count();
                assert!(off_line <= 1, "vertex {v} moved {moved}");
            }
            _ => {}
        }
    }
    assert!(curves > 0);
    let at_centre = (0..surface.positions.len())
        .find(|&v| (blocky.positions[v] - centre).length() < 1e-4)
        .unwrap();
    assert_eq!(surface.flags[at_centre].kind(), VertexKind::Fixed);
}

#[test]
fn border_vertices_stay_on_the_border() {
    let map = octants(5, false);
    let (_, surface, _) = smoothed(&map, &SmoothingOptions::default());
    for (v, p) in surface.positions.iter().enumerate() {
        let c = surface.corners[v];
        let border = surface.flags[v].border_axes();
        for a in 0..3 {
            if border >> a & 1 == 1 {
                let start = (c[a] as f32 - 0.5) * [1.0, 0.8, 1.3][a];
                assert!((p[a] - start).abs() < 1e-5, "vertex {v}");
            }
        }
    }
}

/// Blobs of random labels: every label of at least 1000 voxels within 1 % after smoothing.
#[test]
fn a_voronoi_map_keeps_every_sizeable_label_within_one_percent() {
    let mut seed = 7u64;
    let mut next = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 33) as f64 / (1u64 << 31) as f64
    };
    let n = 40;
    let sites: Vec<[f64; 3]> = (0..20)
        .map(|_| [next(), next(), next()].map(|x| x * n as f64))
        .collect();
    let map = map_of([n; 3], [1.0; 3], |i, j, k| {
        let p = [i, j, k].map(|x| x as f64 + 0.5);
        let d = |s: &[f64; 3]| (0..3).map(|a| (p[a] - s[a]).powi(2)).sum::<f64>();
        (0..sites.len())
            .min_by(|&a, &b| d(&sites[a]).total_cmp(&d(&sites[b])))
            .unwrap() as u32
            + 1
    });
    let (_, surface, report) = smoothed(&map, &SmoothingOptions::default());
    assert_volumes(&surface, &map, 0.01, 1000.0);
    assert_in_boxes(&surface, [1.0; 3], 0.5);
    assert_shared(&surface);
    assert!(report.constrained_vertices < surface.positions.len());
    // The meshes taken out together (triangles sorted by label in chunks, two-plane windows)
    // equal those taken out one by one (a filter over every triangle).
    let labels = surface.labels();
    let together = surface.label_meshes(&labels).unwrap();
    for (&label, mesh) in labels.iter().zip(&together) {
        assert_eq!(mesh, &surface.label_mesh(label), "label {label}");
    }
}

/// Positions, triangles, report and label meshes bit for bit the same on 1 and 3 threads.
#[test]
fn the_result_does_not_depend_on_the_number_of_threads() {
    let map = octants(7, true);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let (_, surface, report) = smoothed(&map, &SmoothingOptions::default());
            let meshes = surface.label_meshes(&surface.labels()).unwrap();
            (
                surface.positions.clone(),
                surface.triangles.clone(),
                report,
                meshes,
            )
        })
    };
    let (one, three) = (run(1), run(3));
    assert!(one.2.iterations > 0 && one.2.restore_rounds > 0);
    assert_eq!(one, three);
}

#[test]
fn options_out_of_range_are_refused() {
    let map = sphere(3.0);
    let mut surface = surface_nets(&map, &SurfaceNetsOptions::default()).unwrap();
    for bad in [
        SmoothingOptions {
            lambda: 1.5,
            ..SmoothingOptions::default()
        },
        SmoothingOptions {
            pass_band: f64::NAN,
            ..SmoothingOptions::default()
        },
        SmoothingOptions {
            constraint: -1.0,
            ..SmoothingOptions::default()
        },
    ] {
        let error = smooth(&mut surface, &bad).unwrap_err();
        assert!(
            matches!(error, LabelsError::InvalidOption { option, .. } if option.starts_with("smoothing ")),
            "{error}"
        );
    }
    let report = smooth(&mut surface, &SmoothingOptions::none()).unwrap();
    assert!(report.volumes.iter().all(|v| v.before == v.after));
}
