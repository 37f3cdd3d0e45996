//! The meshes voxlod reads, builds and writes: [`TriangleMesh`] (what marching cubes makes from
//! each level, paper §2) and [`PolyMesh`] (a triangle mesh with the dangling edges and isolated
//! points of vertex clustering, and the per-vertex opacity of the multi-layer shells of §3).
//! Coordinates are in world units, `f32`; sums (area, volume) are taken in `f64`. Cost: every
//! operation here is one linear pass over the vertices or triangles.

use glam::{DVec3, Vec3};

use crate::{Bounds, CoreError};

/// An indexed triangle mesh: shared vertices, counter-clockwise triangles seen from outside, and
/// optionally one normal per vertex (`normals` is either empty or as long as `positions`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleMesh {
    /// Vertex positions, in world units.
    pub positions: Vec<Vec3>,
    /// Unit normals, one per vertex, or none at all.
    pub normals: Vec<Vec3>,
    /// Three indices into `positions` per triangle, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}

impl TriangleMesh {
    /// A mesh of these vertices and triangles, without normals (not checked: see
    /// [`TriangleMesh::validate`]).
    pub fn new(positions: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> TriangleMesh {
        TriangleMesh {
            positions,
            normals: Vec::new(),
            triangles,
        }
    }

    /// Number of vertices, used by a triangle or not.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// No triangles (vertices alone do not count).
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// Checks what every algorithm assumes: finite coordinates, indices in range, normals either
    /// absent or one per vertex. The message names the first offending vertex or triangle.
    pub fn validate(&self) -> Result<(), CoreError> {
        crate::validate::validate_mesh(self, &crate::validate::Requirements::well_formed())
    }

    /// Bounds of the vertices that triangles use (unreferenced vertices do not count).
    pub fn bounds(&self) -> Bounds {
        let mut b = Bounds::EMPTY;
        for tri in &self.triangles {
            for &v in tri {
                b.grow(self.positions[v as usize].as_dvec3());
            }
        }
        b
    }

    /// The three corners of triangle `t`, in double precision.
    #[inline]
    pub fn corners(&self, t: usize) -> [DVec3; 3] {
        let [a, b, c] = self.triangles[t];
        [
            self.positions[a as usize].as_dvec3(),
            self.positions[b as usize].as_dvec3(),
            self.positions[c as usize].as_dvec3(),
        ]
    }

    /// Sum of the triangle areas.
    pub fn area(&self) -> f64 {
        (0..self.triangles.len())
            .map(|t| {
                let [a, b, c] = self.corners(t);
                0.5 * (b - a).cross(c - a).length()
            })
            .sum()
    }

    /// Signed enclosed volume by the divergence theorem: positive for a closed mesh whose
    /// triangles wind counter-clockwise seen from outside, negative for an inside-out one.
    pub fn signed_volume(&self) -> f64 {
        (0..self.triangles.len())
            .map(|t| {
                let [a, b, c] = self.corners(t);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    /// Reverses the winding of every triangle (and the normals), turning the mesh inside out.
    pub fn flip_orientation(&mut self) {
        for tri in &mut self.triangles {
            tri.swap(1, 2);
        }
        for n in &mut self.normals {
            *n = -*n;
        }
    }

    /// Area-weighted vertex normals from the triangles' geometric normals.
    pub fn compute_vertex_normals(&mut self) {
        let mut acc = vec![DVec3::ZERO; self.positions.len()];
        for t in 0..self.triangles.len() {
            let [a, b, c] = self.corners(t);
            let n = (b - a).cross(c - a);
            for &v in &self.triangles[t] {
                acc[v as usize] += n;
            }
        }
        self.normals = acc
            .into_iter()
            .map(|n| n.normalize_or_zero().as_vec3())
            .collect();
    }

    /// Drops vertices that no triangle uses and renumbers the rest, keeping their order.
    pub fn remove_unreferenced_vertices(&mut self) {
        let mut remap = vec![u32::MAX; self.positions.len()];
        for tri in &self.triangles {
            for &v in tri {
                remap[v as usize] = 0;
            }
        }
        let mut next = 0u32;
        for slot in remap.iter_mut() {
            if *slot == 0 {
                *slot = next;
                next += 1;
            }
        }
        let keep = |i: usize| remap[i] != u32::MAX;
        let positions = (0..self.positions.len())
            .filter(|&i| keep(i))
            .map(|i| self.positions[i])
            .collect();
        if !self.normals.is_empty() {
            self.normals = (0..self.normals.len())
                .filter(|&i| keep(i))
                .map(|i| self.normals[i])
                .collect();
        }
        self.positions = positions;
        for tri in &mut self.triangles {
            for v in tri.iter_mut() {
                *v = remap[*v as usize];
            }
        }
    }
}

/// A named scalar per element (per vertex, or per line), such as a layer's opacity.
#[derive(Clone, Debug, PartialEq)]
pub struct Attribute {
    /// The name written to the file (a PLY property, a VTK array), e.g. `opacity`.
    pub name: String,
    /// One value per vertex (or per line), in element order.
    pub values: Vec<f32>,
}

/// A triangle mesh with what clustering and layering add to it: dangling edges (lines),
/// isolated points, and named per-vertex and per-line scalars.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PolyMesh {
    /// The vertices (shared by triangles, lines and points) and the triangles.
    pub mesh: TriangleMesh,
    /// Dangling edges: two vertex indices each.
    pub lines: Vec<[u32; 2]>,
    /// Isolated points: one vertex index each.
    pub points: Vec<u32>,
    /// Scalars with one value per vertex of `mesh`.
    pub vertex_attributes: Vec<Attribute>,
    /// Scalars with one value per line.
    pub line_attributes: Vec<Attribute>,
}

impl From<TriangleMesh> for PolyMesh {
    fn from(mesh: TriangleMesh) -> Self {
        PolyMesh {
            mesh,
            ..Default::default()
        }
    }
}

impl PolyMesh {
    /// The box of the triangles' vertices, the lines' and the points.
    pub fn bounds(&self) -> Bounds {
        let mut b = self.mesh.bounds();
        for &v in self.lines.iter().flatten().chain(&self.points) {
            b.grow(self.mesh.positions[v as usize].as_dvec3());
        }
        b
    }

    /// Checks the triangle mesh and that lines, points and attributes are in range and sized.
    pub fn validate(&self) -> Result<(), CoreError> {
        self.mesh.validate()?;
        let n = self.mesh.positions.len() as u64;
        if self
            .lines
            .iter()
            .flatten()
            .chain(self.points.iter())
            .any(|&v| v as u64 >= n)
        {
            return Err(CoreError::InvalidMesh(format!(
                "a line or point refers to a vertex beyond the {n} vertices"
            )));
        }
        for a in &self.vertex_attributes {
            if a.values.len() != self.mesh.positions.len() {
                return Err(CoreError::InvalidMesh(format!(
                    "vertex attribute '{}' has {} values for {} vertices",
                    a.name,
                    a.values.len(),
                    n
                )));
            }
        }
        for a in &self.line_attributes {
            if a.values.len() != self.lines.len() {
                return Err(CoreError::InvalidMesh(format!(
                    "line attribute '{}' has {} values for {} lines",
                    a.name,
                    a.values.len(),
                    self.lines.len()
                )));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_shapes::unit_cube;

    #[test]
    fn cube_measures() {
        let mut cube = unit_cube();
        assert!((cube.area() - 6.0).abs() < 1e-12);
        assert!((cube.signed_volume() - 1.0).abs() < 1e-12);
        cube.flip_orientation();
        assert!((cube.signed_volume() + 1.0).abs() < 1e-12);
        cube.flip_orientation();
        cube.compute_vertex_normals();
        let n0 = cube.normals[0];
        assert!(n0.x < 0.0 && n0.y < 0.0 && n0.z < 0.0);
    }

    #[test]
    fn validate_names_the_problem() {
        let mut cube = unit_cube();
        cube.positions[3].y = f32::NAN;
        assert!(cube
            .validate()
            .unwrap_err()
            .to_string()
            .contains("vertex 3"));
        let mut cube = unit_cube();
        cube.triangles[5][1] = 99;
        assert!(cube
            .validate()
            .unwrap_err()
            .to_string()
            .contains("triangle 5"));
    }

    #[test]
    fn removes_unreferenced_vertices() {
        let mut cube = unit_cube();
        cube.positions.insert(0, Vec3::splat(9.0));
        for t in &mut cube.triangles {
            for v in t.iter_mut() {
                *v += 1;
            }
        }
        cube.remove_unreferenced_vertices();
        assert_eq!(cube, unit_cube());
    }
}
