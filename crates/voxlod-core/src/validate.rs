//! One check of a triangle mesh for every stage: at least one triangle (when asked), finite
//! coordinates, vertex indices in range, normals one per vertex (and finite, when asked).
//!
//! Every reader, writer and algorithm that refuses a broken mesh calls [`validate_mesh`], so the
//! same defect gets the same [`MeshDefect`] (and message) wherever it is found, naming the first
//! offending vertex or triangle. Cost: one pass over the vertices and one over the triangles,
//! in parallel; O(V + T).

use rayon::prelude::*;

use crate::{CoreError, TriangleMesh};

/// What is wrong with a mesh. Each message is one line naming the first offending element.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum MeshDefect {
    /// The mesh has no triangles (where at least one is required).
    #[error("the mesh has no triangles")]
    NoTriangles,
    /// A vertex has a NaN or infinite coordinate.
    #[error("vertex {vertex} has a non-finite coordinate ({x}, {y}, {z})")]
    NonFiniteCoordinate {
        /// The first such vertex.
        vertex: usize,
        /// Its coordinates.
        x: f32,
        /// Its coordinates.
        y: f32,
        /// Its coordinates.
        z: f32,
    },
    /// A triangle names a vertex the mesh does not have.
    #[error(
        "triangle {triangle} refers to vertex {vertex} but there are only {vertices} vertices"
    )]
    IndexOutOfRange {
        /// The first such triangle.
        triangle: usize,
        /// The index it holds.
        vertex: u32,
        /// The vertices the mesh has.
        vertices: usize,
    },
    /// The normals are present but not one per vertex.
    #[error("{normals} normals for {vertices} vertices")]
    NormalCount {
        /// Normals stored.
        normals: usize,
        /// Vertices stored.
        vertices: usize,
    },
    /// A vertex normal is NaN or infinite (checked when [`Requirements::finite_normals`]).
    #[error("the normal of vertex {vertex} is not finite")]
    NonFiniteNormal {
        /// The first such vertex.
        vertex: usize,
    },
}

impl MeshDefect {
    /// Whether the defect is a NaN or infinite number (rather than a structural one).
    pub fn is_non_finite(&self) -> bool {
        matches!(
            self,
            MeshDefect::NonFiniteCoordinate { .. } | MeshDefect::NonFiniteNormal { .. }
        )
    }
}

/// What [`validate_mesh`] requires beyond finite coordinates and indices in range.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Requirements {
    /// At least one triangle.
    pub triangles: bool,
    /// Finite normals (their count is always checked).
    pub finite_normals: bool,
}

impl Default for Requirements {
    /// What the algorithms need: at least one triangle; normals are not used.
    fn default() -> Self {
        Requirements {
            triangles: true,
            finite_normals: false,
        }
    }
}

impl Requirements {
    /// Any well-formed mesh, the empty one included (what a mesh type must hold).
    pub fn well_formed() -> Self {
        Requirements {
            triangles: false,
            finite_normals: false,
        }
    }

    /// What a file must hold: finite normals too, triangles or not (a file may hold only lines
    /// or points).
    pub fn files() -> Self {
        Requirements {
            triangles: false,
            finite_normals: true,
        }
    }

    /// What a computed surface must be to be written: triangles or not, finite normals.
    pub fn computed() -> Self {
        Self::files()
    }
}

/// Checks `mesh` against `required`, in this order: triangles, coordinates, indices, normals.
///
/// ```
/// use voxlod_core::glam::Vec3;
/// use voxlod_core::validate::{validate_mesh, MeshDefect, Requirements};
/// use voxlod_core::{CoreError, TriangleMesh};
///
/// let p = vec![Vec3::ZERO, Vec3::X, Vec3::new(0.0, f32::NAN, 0.0)];
/// let mesh = TriangleMesh::new(p, vec![[0, 1, 2]]);
/// let e = validate_mesh(&mesh, &Requirements::default()).unwrap_err();
/// assert!(matches!(e, CoreError::Mesh(MeshDefect::NonFiniteCoordinate { vertex: 2, .. })));
/// assert_eq!(e.to_string(), "vertex 2 has a non-finite coordinate (0, NaN, 0)");
/// let empty = TriangleMesh::default();
/// assert!(validate_mesh(&empty, &Requirements::well_formed()).is_ok());
/// assert_eq!(
///     validate_mesh(&empty, &Requirements::default()).unwrap_err().to_string(),
///     "the mesh has no triangles"
/// );
/// ```
pub fn validate_mesh(mesh: &TriangleMesh, required: &Requirements) -> Result<(), CoreError> {
    find_defect(mesh, required).map_or(Ok(()), |d| Err(CoreError::Mesh(d)))
}

/// Elements per block of the whole-mesh checks.
const BLOCK: usize = 1 << 14;

/// The first defect of `mesh` against `required`, if any.
pub fn find_defect(mesh: &TriangleMesh, required: &Requirements) -> Option<MeshDefect> {
    if required.triangles && mesh.triangles.is_empty() {
        return Some(MeshDefect::NoTriangles);
    }
    // Each check first asks, in blocks that vectorise, whether any element fails, and looks
    // for the first one only then (a per-element search is several times the cost).
    if let Some(vertex) = first_non_finite(&mesh.positions) {
        let p = mesh.positions[vertex];
        return Some(MeshDefect::NonFiniteCoordinate {
            vertex,
            x: p.x,
            y: p.y,
            z: p.z,
        });
    }
    let vertices = mesh.positions.len();
    let out_of_range = |t: &[u32; 3]| t.iter().any(|&v| v as usize >= vertices);
    let any_out_of_range = mesh.triangles.par_chunks(BLOCK).any(|b| {
        let largest = b.iter().flatten().fold(0u32, |m, &v| m.max(v));
        largest as usize >= vertices
    });
    let first_out_of_range = || mesh.triangles.par_iter().position_first(out_of_range);
    if let Some(triangle) = any_out_of_range.then(first_out_of_range).flatten() {
        let t = mesh.triangles[triangle];
        let vertex = *t.iter().find(|&&v| v as usize >= vertices)?;
        return Some(MeshDefect::IndexOutOfRange {
            triangle,
            vertex,
            vertices,
        });
    }
    if !mesh.normals.is_empty() && mesh.normals.len() != vertices {
        return Some(MeshDefect::NormalCount {
            normals: mesh.normals.len(),
            vertices,
        });
    }
    if required.finite_normals {
        if let Some(vertex) = first_non_finite(&mesh.normals) {
            return Some(MeshDefect::NonFiniteNormal { vertex });
        }
    }
    None
}

/// The first vector with a NaN or infinite coordinate: blocks that vectorise ask whether there
/// is one, and the search runs only then.
fn first_non_finite(vectors: &[glam::Vec3]) -> Option<usize> {
    let any =
        (vectors.par_chunks(BLOCK)).any(|b| b.iter().fold(false, |bad, v| bad | !v.is_finite()));
    any.then(|| vectors.par_iter().position_first(|v| !v.is_finite()))
        .flatten()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// The defect found element by element, in order: what the blocked checks must give.
    fn first_defect_in_order(mesh: &TriangleMesh) -> Option<MeshDefect> {
        let n = mesh.positions.len();
        if let Some(vertex) = mesh.positions.iter().position(|p| !p.is_finite()) {
            let p = mesh.positions[vertex];
            let (x, y, z) = (p.x, p.y, p.z);
            return Some(MeshDefect::NonFiniteCoordinate { vertex, x, y, z });
        }
        let bad = |t: &[u32; 3]| t.iter().find(|&&v| v as usize >= n).copied();
        if let Some(triangle) = mesh.triangles.iter().position(|t| bad(t).is_some()) {
            let vertex = bad(&mesh.triangles[triangle]).unwrap();
            return Some(MeshDefect::IndexOutOfRange {
                triangle,
                vertex,
                vertices: n,
            });
        }
        let vertex = mesh.normals.iter().position(|m| !m.is_finite())?;
        Some(MeshDefect::NonFiniteNormal { vertex })
    }

    /// Meshes of several blocks with defects planted in the first, a middle and the last
    /// block (two at once: the first is named), and none.
    #[test]
    fn blocked_checks_name_the_first_defect() {
        let n = 3 * BLOCK + 17;
        let clean = TriangleMesh {
            positions: (0..n).map(|i| Vec3::splat(i as f32)).collect(),
            normals: vec![Vec3::Z; n],
            triangles: (0..n as u32).map(|i| [i, (i + 1) % n as u32, 0]).collect(),
        };
        let required = Requirements {
            triangles: true,
            finite_normals: true,
        };
        assert_eq!(find_defect(&clean, &required), None);
        let places = [[5, n - 1], [BLOCK + 3, 2 * BLOCK], [n - 2, n - 1], [0, 1]];
        for [a, b] in places {
            let mut m = clean.clone();
            m.positions[b] = Vec3::new(1.0, f32::NAN, 0.0);
            m.positions[a] = Vec3::new(f32::INFINITY, 2.0, 3.0);
            let found = find_defect(&m, &required);
            assert!(
                matches!(found, Some(MeshDefect::NonFiniteCoordinate { vertex, .. }) if vertex == a)
            );
            let mut m = clean.clone();
            m.triangles[b][2] = n as u32 + 9;
            m.triangles[a][1] = n as u32;
            assert_eq!(find_defect(&m, &required), first_defect_in_order(&m));
            assert!(
                matches!(find_defect(&m, &required), Some(MeshDefect::IndexOutOfRange { triangle, vertex, .. }) if triangle == a && vertex == n as u32)
            );
            let mut m = clean.clone();
            m.normals[b] = Vec3::NAN;
            m.normals[a] = Vec3::NEG_INFINITY;
            assert_eq!(
                find_defect(&m, &required),
                Some(MeshDefect::NonFiniteNormal { vertex: a })
            );
            assert_eq!(find_defect(&m, &required), first_defect_in_order(&m));
        }
    }
}
