//! The silhouette difference ([`voxlod_render::silhouette`]): zero for the reference itself,
//! growing as a copy shrinks, and counting dangling edges.

use glam::Vec3;
use voxlod_core::PolyMesh;
use voxlod_render::SilhouetteReference;
use voxlod_testkit::shapes::torus;

#[test]
fn silhouette_difference_is_zero_for_the_input_and_grows_as_a_copy_shrinks() {
    let ring = torus(48, 24, 2.0, 0.7);
    let reference = SilhouetteReference::new(&ring, 6, 128).unwrap();
    let same = reference.difference(&PolyMesh::from(ring.clone())).unwrap();
    assert_eq!(same.differing_pixels, 0);
    assert_eq!(same.fraction, 0.0);
    assert_eq!(same.views, 6);
    assert!(same.covered_pixels > 6 * 1000, "{same:?}");
    let mut last = 0.0;
    for scale in [0.95f32, 0.8, 0.5] {
        let mut smaller = ring.clone();
        for p in &mut smaller.positions {
            *p *= scale;
        }
        let d = reference.difference(&PolyMesh::from(smaller)).unwrap();
        assert!(d.fraction > last, "scale {scale}: {d:?}");
        last = d.fraction;
    }
    // A copy shrunk to half is inside the input's box and covers about a quarter of the area:
    // most of the union differs.
    assert!(last > 0.5 && last < 1.0, "{last}");
    // Dangling edges count: a single edge through the ring's hole adds differing pixels.
    let mut with_edge = PolyMesh::from(ring.clone());
    with_edge.mesh.positions.push(Vec3::new(-1.0, 0.0, 0.0));
    with_edge.mesh.positions.push(Vec3::new(1.0, 0.0, 0.0));
    let n = with_edge.mesh.positions.len() as u32;
    with_edge.lines.push([n - 2, n - 1]);
    let d = reference.difference(&with_edge).unwrap();
    assert!(d.differing_pixels > 0, "{d:?}");
}

#[test]
fn the_triangles_alone_differ_by_the_same_pixels_as_a_level_without_wires() {
    let ring = torus(40, 20, 2.0, 0.7);
    let reference = SilhouetteReference::new(&ring, 14, 96).unwrap();
    let mut thinner = torus(40, 20, 2.0, 0.5);
    thinner.normals.clear();
    let a = reference.mesh_difference(&thinner).unwrap();
    let b = reference.difference(&PolyMesh::from(thinner)).unwrap();
    assert_eq!(a, b);
    assert_eq!(a.views, 14);
    // The thinner tube covers less from every view: some pixels differ, but not most.
    assert!(a.fraction > 0.05 && a.fraction < 0.5, "{a:?}");
}
