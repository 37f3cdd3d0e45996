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

/// The first defect of `mesh` against `required`, if any.
pub fn find_defect(mesh: &TriangleMesh, required: &Requirements) -> Option<MeshDefect> {
    if required.triangles && mesh.triangles.is_empty() {
        return Some(MeshDefect::NoTriangles);
    }
    if let Some(vertex) = mesh.positions.par_iter().position_first(|p| !p.is_finite()) {
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
    if let Some(triangle) = mesh.triangles.par_iter().position_first(out_of_range) {
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
        let bad = mesh.normals.par_iter().position_first(|n| !n.is_finite());
        if let Some(vertex) = bad {
            return Some(MeshDefect::NonFiniteNormal { vertex });
        }
    }
    None
}
