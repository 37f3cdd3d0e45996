//! Light repairs that make a mesh safe for the algorithms without changing the shape it shows:
//! dropping triangles with a repeated vertex or zero area, and exact duplicates (same three
//! vertices in any order; of a pair with opposite windings, the first is kept).
//!
//! Duplicates matter to the inside test: two copies of a face cross every ray twice at the same
//! point, so a parity count would see no surface there at all.

use std::collections::HashSet;

use crate::TriangleMesh;

/// What [`remove_degenerate_and_duplicate_triangles`] removed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RepairReport {
    pub degenerate_triangles: usize,
    pub duplicate_triangles: usize,
}

impl RepairReport {
    pub fn is_clean(&self) -> bool {
        self.degenerate_triangles == 0 && self.duplicate_triangles == 0
    }
}

/// Removes degenerate triangles (a repeated vertex index or zero area) and exact duplicates.
pub fn remove_degenerate_and_duplicate_triangles(mesh: &mut TriangleMesh) -> RepairReport {
    let mut report = RepairReport::default();
    let mut seen = HashSet::with_capacity(mesh.triangles.len());
    let positions = &mesh.positions;
    mesh.triangles.retain(|&[a, b, c]| {
        let (pa, pb, pc) = (
            positions[a as usize].as_dvec3(),
            positions[b as usize].as_dvec3(),
            positions[c as usize].as_dvec3(),
        );
        if a == b || b == c || a == c || (pb - pa).cross(pc - pa).length_squared() == 0.0 {
            report.degenerate_triangles += 1;
            return false;
        }
        let mut key = [a, b, c];
        key.sort_unstable();
        if !seen.insert(key) {
            report.duplicate_triangles += 1;
            return false;
        }
        true
    });
    report
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::tests::unit_cube;
    use glam::Vec3;

    #[test]
    fn drops_degenerate_and_duplicate_triangles() {
        let mut cube = unit_cube();
        cube.triangles.push([2, 1, 0]); // duplicate of [0, 2, 1] reversed
        cube.triangles.push([0, 0, 3]); // repeated index
        cube.positions.push(Vec3::new(2.0, 0.0, 0.0));
        cube.triangles.push([0, 1, 8]); // collinear: zero area
        let report = remove_degenerate_and_duplicate_triangles(&mut cube);
        assert_eq!(report.duplicate_triangles, 1);
        assert_eq!(report.degenerate_triangles, 2);
        assert_eq!(cube.triangles, unit_cube().triangles);
    }
}
