//! The bolt of the paper's Figure 7 ("five layers of meshes on a bolt"), as a CSG part: a
//! hexagonal head with a chamfer and a slot, a washer, a shank and ten thread ridges. The
//! antialiasing comparison (`voxlod-eval`), `voxlod demo`, and the layers tests, benchmark and
//! examples use it.
//!
//! Cost: building the shape is O(1); sampling it is the CSG solid's (voxlod-sampling).

use glam::DVec3;
use voxlod_core::Axis;
use voxlod_sampling::Shape;

/// A bolt-like part, about 1.6 units long along z: a hexagonal head 1 across the flats, a shank
/// of radius 0.25 and ten thread ridges of radius 0.31.
pub fn bolt() -> Shape {
    let mut head_faces = Vec::new();
    for k in 0..3 {
        let a = (k as f64) * std::f64::consts::PI / 3.0;
        let n = DVec3::new(a.cos(), a.sin(), 0.0);
        head_faces.push(Shape::HalfSpace {
            normal: n,
            offset: 0.5,
        });
        head_faces.push(Shape::HalfSpace {
            normal: -n,
            offset: 0.5,
        });
    }
    head_faces.push(Shape::cuboid(
        DVec3::new(-0.6, -0.6, 1.2),
        DVec3::new(0.6, 0.6, 1.55),
    ));
    // A chamfer on the top of the head: a sphere trimming its corners.
    head_faces.push(Shape::sphere(DVec3::new(0.0, 0.0, 1.05), 0.72));
    let head = Shape::Intersection(head_faces);
    let washer = Shape::cylinder(DVec3::new(0.0, 0.0, 1.17), Axis::Z, 0.45, 0.04);
    let shank = Shape::cylinder(DVec3::new(0.0, 0.0, 0.6), Axis::Z, 0.25, 0.6);
    let mut parts = vec![head, washer, shank];
    for i in 0..10 {
        let z = 0.08 + 0.085 * i as f64;
        parts.push(Shape::cylinder(
            DVec3::new(0.0, 0.0, z),
            Axis::Z,
            0.31,
            0.022,
        ));
    }
    // A slot across the head.
    Shape::Union(parts).minus(Shape::cuboid(
        DVec3::new(-0.7, -0.06, 1.42),
        DVec3::new(0.7, 0.06, 1.6),
    ))
}
