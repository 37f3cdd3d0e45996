//! Visibility from a sphere of views ([`voxlod_render::visibility`]) on boxes whose hidden and
//! seen triangles are known by hand. Boxes are [`unit_cube`]s scaled and moved, so their
//! triangles come in its order: z = 0 face (0, 1), z = 1 (2, 3), y = 0 (4, 5), y = 1 (6, 7),
//! x = 0 (8, 9), x = 1 (10, 11).

use glam::Vec3;
use voxlod_core::TriangleMesh;
use voxlod_render::{
    sphere_directions, visible_sample_counts, visible_triangles, RenderError, VisibilityOptions,
};
use voxlod_testkit::shapes::{append, unit_cube};

/// The box `min + size · [0, 1]³`, in [`unit_cube`]'s triangle order.
fn cuboid(min: Vec3, size: Vec3) -> TriangleMesh {
    let mut cube = unit_cube();
    for p in &mut cube.positions {
        *p = min + *p * size;
    }
    cube
}

/// The triangles, among `first..first + count`, that are seen.
fn seen(visible: &[bool], first: usize, count: usize) -> Vec<usize> {
    (first..first + count).filter(|&t| visible[t]).collect()
}

#[test]
fn a_cube_inside_a_closed_cube_is_hidden() {
    let mut scene = unit_cube();
    append(&mut scene, &cuboid(Vec3::splat(0.4), Vec3::splat(0.2)));
    let visible = visible_triangles(&scene, &VisibilityOptions::default()).unwrap();
    assert_eq!(visible.len(), 24);
    assert_eq!(seen(&visible, 0, 12), (0..12).collect::<Vec<_>>());
    assert_eq!(seen(&visible, 12, 12), Vec::<usize>::new());
}

#[test]
fn faces_where_two_cubes_touch_are_hidden() {
    // [0, 1]³ and [1, 2] × [0, 1]²: the first cube's x = 1 face (10, 11) lies on the second's
    // x = 0 face (12 + 8, 12 + 9); everything else is on the outside of the pair.
    let mut scene = unit_cube();
    append(&mut scene, &cuboid(Vec3::X, Vec3::ONE));
    let visible = visible_triangles(&scene, &VisibilityOptions::default()).unwrap();
    let hidden: Vec<usize> = (0..24).filter(|&t| !visible[t]).collect();
    assert_eq!(hidden, vec![10, 11, 20, 21]);
}

#[test]
fn an_open_quad_is_seen_from_either_side() {
    // One view, along +x from the −x side (sphere_directions(1) is +x); the quad lies in
    // the plane x = 0, facing −x (towards the eye) or +x (away). The camera frames the box's
    // sphere, radius √2/2, with a 5 % margin at 100 pixels: the quad's edges, 0.5 from the
    // centre, land at 50 ± 0.5 / (0.7071 · 1.05) · 50 = 50 ± 33.67 pixels, so the pixel centres
    // of columns and rows 16 to 83 are inside: 68² = 4624 samples. The diagonal runs through
    // the 68 centres with column + row = 99, on the edge of both triangles and credited to
    // neither; each triangle wins the (4624 − 68) / 2 = 2278 on its side.
    assert_eq!(sphere_directions(1), vec![glam::DVec3::X]);
    let corners = vec![
        Vec3::ZERO,
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(0.0, 1.0, 1.0),
        Vec3::new(0.0, 0.0, 1.0),
    ];
    let options = VisibilityOptions {
        views: 1,
        resolution: 100,
        min_samples: 1,
    };
    for triangles in [vec![[0, 1, 2], [0, 2, 3]], vec![[0, 2, 1], [0, 3, 2]]] {
        let quad = TriangleMesh::new(corners.clone(), triangles);
        let counts = visible_sample_counts(&quad, &options).unwrap();
        assert_eq!(counts, vec![2278, 2278]);
        assert_eq!(
            visible_triangles(&quad, &options).unwrap(),
            vec![true, true]
        );
        // A triangle is seen when it wins at least min_samples samples, not one more.
        let exactly = VisibilityOptions {
            min_samples: counts[0] as u32,
            ..options
        };
        assert!(visible_triangles(&quad, &exactly).unwrap()[0]);
        let more = VisibilityOptions {
            min_samples: counts[0] as u32 + 1,
            ..exactly
        };
        assert!(!visible_triangles(&quad, &more).unwrap()[0]);
    }
    // A double-sided card, each triangle doubled with the opposite orientation: the coincident
    // copies tie at every sample and are both credited.
    let card = TriangleMesh::new(
        corners.clone(),
        vec![[0, 1, 2], [0, 2, 3], [0, 2, 1], [0, 3, 2]],
    );
    let counts = visible_sample_counts(&card, &options).unwrap();
    assert_eq!(counts, vec![2278; 4]);
    // Over the whole sphere of views, both triangles are seen too.
    let quad = TriangleMesh::new(corners, vec![[0, 1, 2], [0, 2, 3]]);
    let visible = visible_triangles(&quad, &VisibilityOptions::default()).unwrap();
    assert_eq!(visible, vec![true, true]);
}

#[test]
fn a_cube_in_an_open_box_is_seen_through_the_opening() {
    // The box [0, 4]³ without its top (z = 4, triangles 2 and 3), and the cube [1.5, 2.5]³ inside
    // at triangles 10 to 21. Rays from the cube's top climb 1.5 to the opening, which reaches 1.5
    // or more beyond the cube on every side: the top is seen from the views within 45° of +z.
    // Its sides are seen through the opening from views tilted towards them; its bottom (10, 11)
    // faces the floor 1.5 below and reaches no opening. The box's ten triangles are seen from outside.
    let mut scene = cuboid(Vec3::ZERO, Vec3::splat(4.0));
    scene.triangles.drain(2..4);
    append(&mut scene, &cuboid(Vec3::splat(1.5), Vec3::ONE));
    let visible = visible_triangles(&scene, &VisibilityOptions::default()).unwrap();
    assert_eq!(seen(&visible, 0, 10), (0..10).collect::<Vec<_>>());
    let hidden: Vec<usize> = (10..22).filter(|&t| !visible[t]).collect();
    assert_eq!(hidden, vec![10, 11]);
    // Closed, the box hides the whole cube.
    let mut closed = cuboid(Vec3::ZERO, Vec3::splat(4.0));
    append(&mut closed, &cuboid(Vec3::splat(1.5), Vec3::ONE));
    let visible = visible_triangles(&closed, &VisibilityOptions::default()).unwrap();
    assert_eq!(seen(&visible, 12, 12), Vec::<usize>::new());
}

#[test]
fn sphere_directions_are_unit_and_balanced() {
    for count in [1, 2, 7, 64] {
        let d = sphere_directions(count);
        assert_eq!(d.len(), count);
        assert!(d.iter().all(|v| (v.length() - 1.0).abs() < 1e-12));
        // Heights 1 − (2i + 1)/n are symmetric about 0.
        let mean_height = d.iter().map(|v| v.y).sum::<f64>() / count as f64;
        assert!(mean_height.abs() < 1e-12, "{count}: {mean_height}");
    }
    // 64 points leave no cap of half-angle 20° empty (4π/64 sr each, about 25° apart): every
    // axis and octant diagonal has a direction within 20°.
    let d = sphere_directions(64);
    for axis in voxlod_render::view_directions(14) {
        let axis = axis.normalize();
        let best = d.iter().map(|v| v.dot(axis)).fold(-1.0, f64::max);
        assert!(best > 20f64.to_radians().cos(), "{axis}: {best}");
    }
}

#[test]
fn empty_meshes_and_zero_settings_are_refused() {
    let cube = unit_cube();
    let ok = VisibilityOptions::default();
    let refusal = |mesh: &TriangleMesh, options: VisibilityOptions| {
        visible_triangles(mesh, &options).unwrap_err()
    };
    let empty = TriangleMesh::new(vec![Vec3::ZERO], vec![]);
    assert!(matches!(refusal(&empty, ok), RenderError::EmptyScene));
    let bad_index = TriangleMesh::new(vec![Vec3::ZERO], vec![[0, 0, 5]]);
    assert!(matches!(refusal(&bad_index, ok), RenderError::Invalid(_)));
    let no_views = VisibilityOptions { views: 0, ..ok };
    assert!(matches!(refusal(&cube, no_views), RenderError::Invalid(_)));
    let no_pixels = VisibilityOptions {
        resolution: 0,
        ..ok
    };
    assert!(matches!(
        refusal(&cube, no_pixels),
        RenderError::BadSize(0, 0)
    ));
    let no_samples = VisibilityOptions {
        min_samples: 0,
        ..ok
    };
    assert!(matches!(
        refusal(&cube, no_samples),
        RenderError::Invalid(_)
    ));
}
