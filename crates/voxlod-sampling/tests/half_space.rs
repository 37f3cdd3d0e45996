//! The sampled density of a half-space must follow the analytic profile of paper equation 5
//! within 0.01, for both filters, every level and any orientation of the plane, whether the
//! solid is given exactly (CSG) or as a triangle mesh.

use glam::{DMat3, DVec3, Vec3};
use voxlod_core::TriangleMesh;
use voxlod_sampling::{
    filtered_density, level_grid, CsgSolid, DensityOptions, Filter, MeshSolid, Shape, Solid,
};

/// The plane `normal · p = offset`, checked within `FACE_HALF` of `centre`.
struct Plane {
    normal: DVec3,
    offset: f64,
    centre: DVec3,
}

const FACE_HALF: f64 = 1.0;

/// Largest |f - d(r)| over the samples whose support meets the plane away from other faces.
fn worst_error(
    solid: &dyn Solid,
    plane: &Plane,
    filter: Filter,
    resolution: usize,
    radius_voxels: f64,
) -> f64 {
    let (normal, offset, centre) = (plane.normal, plane.offset, plane.centre);
    let bounds = solid.bounds();
    let h = bounds.longest_extent() / resolution as f64;
    let radius = radius_voxels * h;
    let grid = level_grid(&bounds, resolution, radius).unwrap();
    let (density, _) =
        filtered_density(solid, &grid, &DensityOptions::new(filter, radius)).unwrap();
    let mut worst = 0.0f64;
    let mut checked = 0;
    for k in 0..grid.dims[2] {
        for j in 0..grid.dims[1] {
            for i in 0..grid.dims[0] {
                let p = grid.position(i as f64, j as f64, k as f64);
                let r = normal.dot(p) - offset;
                if r.abs() > radius * 1.2 {
                    continue;
                }
                // Stay clear of the region's other faces: only the plane within the support.
                let along = (p - centre) - normal * normal.dot(p - centre);
                if along.length() > FACE_HALF - 2.0 * radius {
                    continue;
                }
                let expected = filter.half_space_density(r, radius);
                let got = density.get(i, j, k) as f64;
                worst = worst.max((got - expected).abs());
                checked += 1;
            }
        }
    }
    assert!(checked > 50, "only {checked} samples checked");
    worst
}

fn orientations() -> Vec<DVec3> {
    vec![
        DVec3::X,
        DVec3::Z,
        DVec3::new(1.0, 1.0, 0.0).normalize(),
        DVec3::new(1.0, 1.0, 1.0).normalize(),
        DVec3::new(0.3, -0.8, 0.52).normalize(),
        DVec3::new(-0.05, 0.2, 0.98).normalize(),
    ]
}

/// A rotation taking +z to `n`.
fn frame(n: DVec3) -> DMat3 {
    let helper = if n.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
    let a = n.cross(helper).normalize();
    let b = n.cross(a);
    DMat3::from_cols(a, b, n)
}

#[test]
fn csg_half_space_matches_equation_5() {
    let centre = DVec3::new(0.137, -0.071, 0.05);
    for filter in [Filter::Hypercone, Filter::GAUSSIAN] {
        for (o, n) in orientations().into_iter().enumerate() {
            // The half-space n·p <= offset, cut to a ball-like region by a box around it.
            let offset = n.dot(centre) + 0.0123 * o as f64;
            let shape = Shape::Intersection(vec![
                Shape::HalfSpace { normal: n, offset },
                Shape::cuboid(centre - DVec3::splat(1.0), centre + DVec3::splat(1.0)),
            ]);
            let solid = CsgSolid::new(shape).unwrap();
            for (resolution, radius_voxels) in [(24usize, 1.0), (48, 1.0), (24, 2.0), (33, 1.5)] {
                let plane = Plane {
                    normal: n,
                    offset,
                    centre,
                };
                let err = worst_error(&solid, &plane, filter, resolution, radius_voxels);
                assert!(
                    err <= 0.01,
                    "{} normal {n:?} resolution {resolution} radius {radius_voxels}: error {err}",
                    filter.name()
                );
            }
        }
    }
}

/// A closed box mesh with one face on the plane through `centre` with normal `n`.
fn slab_mesh(n: DVec3, centre: DVec3, half: f64) -> TriangleMesh {
    let r = frame(n);
    // Box from z = -2 half to z = 0 in the frame, so that its +z face is the plane.
    let corners: Vec<Vec3> = (0..8)
        .map(|c| {
            let local = DVec3::new(
                if c & 1 == 1 { half } else { -half },
                if c & 2 == 2 { half } else { -half },
                if c & 4 == 4 { 0.0 } else { -2.0 * half },
            );
            (centre + r * local).as_vec3()
        })
        .collect();
    let tris = vec![
        [0, 2, 1],
        [1, 2, 3],
        [4, 5, 6],
        [5, 7, 6],
        [0, 1, 4],
        [1, 5, 4],
        [2, 6, 3],
        [3, 6, 7],
        [0, 4, 2],
        [2, 4, 6],
        [1, 3, 5],
        [3, 7, 5],
    ];
    let mut mesh = TriangleMesh::new(corners, tris);
    if mesh.signed_volume() < 0.0 {
        mesh.flip_orientation();
    }
    mesh
}

#[test]
fn mesh_half_space_matches_equation_5() {
    let centre = DVec3::new(0.21, 0.13, -0.08);
    for filter in [Filter::Hypercone, Filter::GAUSSIAN] {
        for n in orientations() {
            let mesh = slab_mesh(n, centre, 1.0);
            let solid = MeshSolid::new(&mesh).unwrap();
            assert!(solid.is_exact());
            let offset = n.dot(centre);
            for (resolution, radius_voxels) in [(24usize, 1.0), (40, 1.0)] {
                let plane = Plane {
                    normal: n,
                    offset,
                    centre,
                };
                let err = worst_error(&solid, &plane, filter, resolution, radius_voxels);
                assert!(
                    err <= 0.01,
                    "{} mesh normal {n:?} resolution {resolution}: error {err}",
                    filter.name()
                );
            }
        }
    }
}
