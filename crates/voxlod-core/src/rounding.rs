//! Whether a mesh lies so far from the origin, for its size, that its `f32` coordinates have
//! rounded away detail that matters: a scan or a CAD export placed at map coordinates (10⁵ to
//! 10⁷ units out) keeps a step of up to `2⁻²³` times its largest coordinate, half a unit at
//! 5·10⁶.
//! Beyond the paper. Readers of such files cannot give back what the `f32` mesh lost (glTF
//! scenes are read relative to an origin near them, crate `voxlod-gltf`), so the jobs say so.
//!
//! Cost: one pass over the positions.

use crate::TriangleMesh;

/// Coordinates whose `f32` step exceeds this fraction of the mesh's diagonal are warned of:
/// a ten-thousandth, well below a voxel of the finest grids (a 256th) yet far above what a
/// mesh near the origin ever has (`2⁻²³` of its extent).
pub const ROUNDING_WARNED: f64 = 1e-4;

/// A warning where `mesh`'s coordinates reach so far from the origin that `f32` holds them to
/// more than [`ROUNDING_WARNED`] of its diagonal; `None` otherwise (or for a mesh without
/// extent or with non-finite coordinates, which the readers refuse).
///
/// ```
/// use voxlod_core::glam::Vec3;
/// use voxlod_core::rounding::rounding_warning;
/// use voxlod_core::TriangleMesh;
///
/// let triangle = |at: Vec3| {
///     let corners = [Vec3::ZERO, Vec3::X, Vec3::Y].map(|c| c + at).to_vec();
///     TriangleMesh::new(corners, vec![[0, 1, 2]])
/// };
/// assert!(rounding_warning(&triangle(Vec3::new(1000.0, 0.0, 0.0))).is_none());
/// // At 5·10⁶, f32 steps by half a unit: a third of a unit triangle's size.
/// let far = rounding_warning(&triangle(Vec3::new(5.0e6, 0.0, 0.0))).unwrap();
/// assert!(far.contains("0.5"), "{far}");
/// ```
pub fn rounding_warning(mesh: &TriangleMesh) -> Option<String> {
    // Over every position (a triangle's out-of-range index, refused elsewhere, is not read).
    let far = (mesh.positions.iter())
        .map(|p| p.abs().max_element())
        .fold(0.0f32, f32::max);
    let diagonal = crate::Bounds::from_points(&mesh.positions).diagonal();
    if !far.is_finite() || diagonal.is_nan() || diagonal <= 0.0 {
        return None;
    }
    let step = f64::from(far.next_up() - far);
    (step > ROUNDING_WARNED * diagonal).then(|| {
        format!(
            "the coordinates reach {far:.4e} from the origin, where f32 holds them only to \
             {step} ({:.3} % of the mesh's size): finer detail was rounded away on reading; \
             moved nearer the origin, the mesh keeps it",
            100.0 * step / diagonal
        )
    })
}

#[cfg(test)]
mod tests {
    //! A unit octahedron at 2·10⁵ (an `f32` step of 2⁻⁶) is warned of with that step; the same
    //! near the origin, and one a million units across at 4·10⁶ (whose half-unit step is a
    //! tiny part of its size), are not.

    use super::rounding_warning;
    use crate::glam::Vec3;
    use crate::test_shapes;
    use crate::TriangleMesh;

    /// The octahedron of `radius` about `centre`.
    fn octahedron(centre: Vec3, radius: f32) -> TriangleMesh {
        let mut mesh = test_shapes::octahedron();
        for p in &mut mesh.positions {
            *p = centre + radius * *p;
        }
        mesh
    }

    #[test]
    fn a_small_mesh_far_out_is_warned_of_with_its_step() {
        let far = octahedron(Vec3::new(1.0e5, -2.0e5, 5.0e4), 1.0);
        let warning = rounding_warning(&far).expect("a warning");
        // Between 2¹⁷ and 2¹⁸, f32 steps by 2⁻⁶; the octahedron's diagonal is 2√3.
        assert!(warning.contains("0.015625"), "{warning}");
        assert!(warning.contains("0.451 %"), "{warning}");
    }

    #[test]
    fn a_mesh_near_the_origin_or_large_for_its_place_is_not() {
        assert!(rounding_warning(&octahedron(Vec3::new(3.0, -2.0, 1.0), 1.0)).is_none());
        assert!(rounding_warning(&octahedron(Vec3::new(4.0e6, 0.0, 0.0), 5.0e5)).is_none());
    }
}
