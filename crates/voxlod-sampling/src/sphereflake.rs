//! The sphereflake: the recursive fractal of spheres the voxel paper simplifies in Table 1
//! (820 spheres: 1 + 9 + 81 + 729). Each sphere carries nine children of a third of its radius,
//! six around its equator and three above it, each child's "up" pointing away from its parent.
//! The construction matches the field of `../shared/peers/peers.py` so that benchmarks against
//! the peers run on the same shape. Cost: O(9^levels) spheres (820 for the paper's three
//! generations), built once.

use glam::DVec3;

use crate::csg::Shape;

/// Centres and radii of the sphereflake with `levels` generations below the root sphere of
/// radius 0.5 at the origin (`levels = 3` gives the paper's 820 spheres).
pub fn sphereflake_spheres(levels: usize) -> Vec<(DVec3, f64)> {
    let mut spheres = vec![(DVec3::ZERO, 0.5)];
    let mut frontier = vec![(DVec3::ZERO, 0.5, DVec3::Z)];
    for _ in 0..levels {
        let mut next = Vec::with_capacity(frontier.len() * 9);
        for (centre, radius, up) in frontier {
            let mut t = up.cross(DVec3::X);
            if t.length() < 1e-6 {
                t = up.cross(DVec3::Y);
            }
            let t = t.normalize();
            let s = up.cross(t);
            let third = std::f64::consts::PI / 3.0;
            let mut dirs: Vec<DVec3> = (0..6)
                .map(|k| (k as f64 * third).cos() * t + (k as f64 * third).sin() * s)
                .collect();
            dirs.extend((0..3).map(|k| {
                let a = k as f64 * 2.0 * third + third / 2.0;
                0.5 * (a.cos() * t + a.sin() * s) + 0.866 * up
            }));
            for d in dirs {
                let d = d.normalize();
                let child = centre + d * (radius + radius / 3.0);
                spheres.push((child, radius / 3.0));
                next.push((child, radius / 3.0, d));
            }
        }
        frontier = next;
    }
    spheres
}

/// The sphereflake as a CSG union of spheres.
pub fn sphereflake(levels: usize) -> Shape {
    Shape::Union(
        sphereflake_spheres(levels)
            .into_iter()
            .map(|(c, r)| Shape::sphere(c, r))
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn has_820_spheres_that_touch_their_parents() {
        let spheres = sphereflake_spheres(3);
        assert_eq!(spheres.len(), 820);
        // The first child touches the root: distance = 0.5 + 1/6.
        let (c, r) = spheres[1];
        assert!((c.length() - (0.5 + r)).abs() < 1e-12);
        assert!((r - 0.5 / 3.0).abs() < 1e-12);
        let b = sphereflake(3).bounds();
        assert!(b.size().max_element() < 2.5 && b.size().min_element() > 1.0);
    }
}
