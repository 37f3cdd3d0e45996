//! How many triangles marching cubes will make of a surface at a given resolution, from the
//! input mesh alone, so that a pipeline can pick the finest level before sampling anything
//! (for example, a chain that starts at or below the input's triangle count).
//!
//! Beyond the paper (He et al. 1995 report the counts of Tables 1–3 after the fact). A surface
//! element of area `A` and unit normal `n` crosses the grid edges along axis `a` (spacing `h`)
//! `A |n_a| / h²` times on average over its position, and marching cubes puts one vertex on
//! every crossed edge, so a surface has `V ≈ Σ A (|n_x| + |n_y| + |n_z|) / h²` vertices; a
//! closed triangle mesh has `F = 2V − 2χ ≈ 2V` triangles. Averaged over orientations the factor
//! `|n|₁` is 3/2, so a sphere gets `3A/h²` and an axis-aligned box `2A/h²`; taking each
//! triangle's own normal gets both right. The filtered level is smoother than the input, so
//! detail smaller than the filter (and a scan's noise) makes the estimate high, never low by
//! much: the tests hold it within 15 % on smooth shapes.
//!
//! Cost: O(F) over the input's triangles.

use voxlod_core::TriangleMesh;

/// `Σ A |n|₁` over the triangles: the surface's area as the grid sees it.
fn projected_area(mesh: &TriangleMesh) -> f64 {
    (0..mesh.triangles.len())
        .map(|t| {
            let [a, b, c] = mesh.corners(t);
            // Half the cross product: its components are the projected areas.
            let n = (b - a).cross(c - a) * 0.5;
            if n.is_finite() {
                n.x.abs() + n.y.abs() + n.z.abs()
            } else {
                0.0
            }
        })
        .sum()
}

/// Triangles marching cubes is expected to make of `mesh`'s surface on a grid of spacing
/// `cell` (in the mesh's units). Zero for a mesh without area or a non-positive `cell`.
pub fn estimated_triangles(mesh: &TriangleMesh, cell: f64) -> f64 {
    if !(cell.is_finite() && cell > 0.0) {
        return 0.0;
    }
    2.0 * projected_area(mesh) / (cell * cell)
}

/// Triangles expected at `resolution` samples across the longest side of `mesh`'s box (the
/// pyramid's convention, `voxlod_sampling::pyramid`).
pub fn estimated_triangles_at(mesh: &TriangleMesh, resolution: usize) -> f64 {
    let extent = mesh.bounds().longest_extent();
    if resolution == 0 || !(extent.is_finite() && extent > 0.0) {
        return 0.0;
    }
    estimated_triangles(mesh, extent / resolution as f64)
}

/// The largest resolution (samples across the longest side, at least 1) whose estimated
/// triangle count does not exceed `triangles`; `None` for a mesh without area.
pub fn resolution_for_triangles(mesh: &TriangleMesh, triangles: usize) -> Option<usize> {
    let extent = mesh.bounds().longest_extent();
    let area = projected_area(mesh);
    if !(extent.is_finite() && extent > 0.0 && area > 0.0) {
        return None;
    }
    // F(N) = 2 · area · N² / extent², so N = extent · sqrt(F / (2 area)).
    let n = extent * (triangles as f64 / (2.0 * area)).sqrt();
    let mut n = (n.floor() as usize).max(1);
    while n > 1 && estimated_triangles_at(mesh, n) > triangles as f64 {
        n -= 1;
    }
    Some(n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn a_unit_square_pair_gives_the_axis_aligned_count() {
        // Two triangles of a unit square in the xy plane: projected area 1, so 2/h².
        let square = TriangleMesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
            vec![[0, 1, 2], [0, 2, 3]],
        );
        assert!((estimated_triangles(&square, 0.1) - 200.0).abs() < 1e-9);
        assert_eq!(estimated_triangles(&square, 0.0), 0.0);
        assert!((estimated_triangles_at(&square, 10) - 200.0).abs() < 1e-9);
        assert_eq!(resolution_for_triangles(&square, 200), Some(10));
        assert_eq!(resolution_for_triangles(&square, 199), Some(9));
        assert_eq!(resolution_for_triangles(&TriangleMesh::default(), 10), None);
    }
}
