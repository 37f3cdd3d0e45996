//! Which points on a scene's surface are seen from outside: the point-wise form of
//! [`super::visible_triangles`]. A triangle counts as seen where any sample of it shows, so a
//! large face of which a sliver shows between other parts counts whole; its points tell the
//! sliver from the buried rest.
//!
//! Each view of the [`VisibilityOptions`] draws the mesh's nearest depth at every sample, as
//! [`super::visible_triangles`] does. A point is seen in a view when its depth is at most
//! `reach` pixels (in depth, world units of a pixel) beyond the farthest of the four samples
//! around it: a point between samples on a face tilted away from the view lies behind the
//! nearer of them by the tilt, and a point at a silhouette has a sample with no surface
//! beside it. It is seen when some view sees it. The test is lenient by design: a buried
//! point counts as seen only within `reach` pixels of a face that shows.
//!
//! Cost: per view, the drawing (O(V + T + rows spanned + samples covered)) and O(1) per point
//! not seen yet; views in parallel, one depth buffer and one flag per point per worker.

use glam::DVec3;
use voxlod_core::TriangleMesh;

use super::{check_request, over_views, View, VisibilityOptions};
use crate::{Camera, RenderError};

/// Whether each of `points` is seen from outside `mesh` (module docs), in order.
///
/// # Errors
///
/// As [`super::visible_sample_counts`], and [`RenderError::Invalid`] for a `reach` that is
/// negative or not finite.
///
/// # Example
///
/// A unit cube and a second box below it, touching along the face z = 0: a point of that face
/// is buried, a point of the cube's top is seen.
///
/// ```
/// use glam::{DVec3, Vec3};
/// use voxlod_render::{seen_points, VisibilityOptions};
/// use voxlod_testkit::shapes::{append, unit_cube};
///
/// let mut scene = unit_cube();
/// let mut below = unit_cube();
/// below.positions.iter_mut().for_each(|p| *p -= Vec3::Z);
/// append(&mut scene, &below);
/// let points = [DVec3::new(0.5, 0.5, 0.0), DVec3::new(0.5, 0.5, 1.0)];
/// let seen = seen_points(&scene, &points, &VisibilityOptions::default(), 2.0)?;
/// assert_eq!(seen, [false, true]);
/// # Ok::<(), voxlod_render::RenderError>(())
/// ```
pub fn seen_points(
    mesh: &TriangleMesh,
    points: &[DVec3],
    options: &VisibilityOptions,
    reach: f64,
) -> Result<Vec<bool>, RenderError> {
    let bounds = check_request(mesh, options)?;
    if !(reach.is_finite() && reach >= 0.0) {
        return Err(RenderError::Invalid(format!(
            "reach {reach}: a depth slack must be zero or more pixels"
        )));
    }
    let what = "point-visibility buffers";
    let partial = over_views(
        mesh,
        &bounds,
        options,
        points.len(),
        what,
        |view, camera, seen| {
            view.draw(mesh, camera);
            mark_seen(view, camera, points, reach, seen);
        },
    )?;
    let mut all = vec![false; points.len()];
    for seen in partial {
        all.iter_mut().zip(seen).for_each(|(a, s)| *a |= s);
    }
    Ok(all)
}

/// Sets `seen[k]` for the points `view` (drawn from `camera`) sees (module docs).
fn mark_seen(view: &View, camera: &Camera, points: &[DVec3], reach: f64, seen: &mut [bool]) {
    let side = view.side as i64;
    let slack = reach * camera.pixel_size_at(camera.eye);
    let depth_at = |x: i64, y: i64| match (0..side).contains(&x) && (0..side).contains(&y) {
        true => view.depth[(y * side + x) as usize],
        false => f64::INFINITY,
    };
    for (p, s) in points.iter().zip(seen.iter_mut()) {
        if *s {
            continue;
        }
        let Some(q) = camera.project(*p) else {
            continue;
        };
        // Sample centres lie at half-integers: the four around q.
        let (x, y) = ((q.x - 0.5).floor() as i64, (q.y - 0.5).floor() as i64);
        let farthest = [(0, 0), (1, 0), (0, 1), (1, 1)]
            .iter()
            .map(|&(dx, dy)| depth_at(x + dx, y + dy))
            .fold(f64::NEG_INFINITY, f64::max);
        *s = q.depth_key <= farthest + slack;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use voxlod_testkit::shapes::{append, unit_cube};

    /// A cube with a second cube inside it, and a point on each.
    fn nested() -> (TriangleMesh, [DVec3; 2]) {
        let mut scene = unit_cube();
        let mut inner = unit_cube();
        inner
            .positions
            .iter_mut()
            .for_each(|p| *p = Vec3::splat(0.4) + *p * 0.2);
        append(&mut scene, &inner);
        (
            scene,
            [DVec3::new(0.5, 0.5, 0.6), DVec3::new(0.3, 0.7, 1.0)],
        )
    }

    #[test]
    fn seen_points_sees_the_outer_surface_and_not_what_it_encloses() {
        let (scene, points) = nested();
        let seen = seen_points(&scene, &points, &VisibilityOptions::default(), 2.0).unwrap();
        assert_eq!(seen, [false, true]);
    }

    #[test]
    fn seen_points_shows_a_buried_face_only_where_a_sliver_of_it_is_open() {
        // A 1 × 1 slab on z = 0 and a box on it covering x < 0.9: the slab's top is seen at
        // x = 0.95 and buried at x = 0.5, though it is one face.
        let mut scene = unit_cube();
        scene.positions.iter_mut().for_each(|p| p.z *= 0.1);
        let mut block = unit_cube();
        block.positions.iter_mut().for_each(|p| {
            p.x *= 0.9;
            p.z += 0.1;
        });
        append(&mut scene, &block);
        let points = [DVec3::new(0.5, 0.5, 0.1), DVec3::new(0.95, 0.5, 0.1)];
        let seen = seen_points(&scene, &points, &VisibilityOptions::default(), 2.0).unwrap();
        assert_eq!(seen, [false, true]);
    }

    #[test]
    fn seen_points_refuses_a_reach_that_is_not_a_distance() {
        let (scene, points) = nested();
        for reach in [-1.0, f64::NAN, f64::INFINITY] {
            let err = seen_points(&scene, &points, &VisibilityOptions::default(), reach);
            assert!(matches!(err, Err(RenderError::Invalid(_))), "{reach}");
        }
    }
}
