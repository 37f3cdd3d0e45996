//! Checking a triangle mesh once and building what every baseline needs from it: for each
//! vertex the list of triangle corners that use it (a compressed sparse row table built by a
//! counting sort), and the box of the vertices that triangles use.
//!
//! Cost: two passes over the 3T corners and one over the V vertices, O(V + T), with 4 bytes per
//! corner and per vertex. Vertices that no triangle uses are left out of everything downstream
//! (they are not part of the object's boundary): they join no cluster and weigh nothing.

use glam::Vec3;
use rayon::prelude::*;
use voxlod_core::{memory, Bounds, TriangleMesh};

use crate::BaselineError;

/// A checked mesh's vertex-to-corner table and bounds. Corner `c` is corner `c % 3` of
/// triangle `c / 3`.
#[derive(Debug)]
pub(crate) struct Prepared {
    /// `offsets[v]..offsets[v + 1]` indexes `corners` for vertex `v` (length V + 1).
    pub offsets: Vec<u32>,
    /// Corner ids grouped by vertex, in increasing order within each vertex.
    pub corners: Vec<u32>,
    /// Box of the vertices that at least one triangle uses.
    pub bounds: Bounds,
    /// How many vertices at least one triangle uses.
    pub referenced: usize,
}

impl Prepared {
    #[inline]
    pub fn is_referenced(&self, v: usize) -> bool {
        self.offsets[v + 1] > self.offsets[v]
    }

    #[inline]
    pub fn corners_of(&self, v: usize) -> &[u32] {
        &self.corners[self.offsets[v] as usize..self.offsets[v + 1] as usize]
    }
}

/// Refuses what no baseline can work on: no triangles, a non-finite coordinate (any vertex),
/// an index out of range, or more corners than 32-bit ids can name.
pub(crate) fn check(mesh: &TriangleMesh) -> Result<(), BaselineError> {
    if mesh.triangles.is_empty() {
        return Err(BaselineError::EmptyMesh);
    }
    if mesh.positions.len() >= u32::MAX as usize {
        return Err(BaselineError::TooLarge {
            what: format!(
                "{} vertices (at most {})",
                mesh.positions.len(),
                u32::MAX - 1
            ),
        });
    }
    // Triangle ids carry an orientation bit in their top bit during elimination.
    if mesh.triangles.len() > (u32::MAX / 3) as usize {
        return Err(BaselineError::TooLarge {
            what: format!(
                "{} triangles (at most {})",
                mesh.triangles.len(),
                u32::MAX / 3
            ),
        });
    }
    if let Some(v) = mesh.positions.par_iter().position_first(|p| !p.is_finite()) {
        let p = mesh.positions[v];
        return Err(BaselineError::NonFiniteCoordinate {
            vertex: v,
            x: p.x,
            y: p.y,
            z: p.z,
        });
    }
    let n = mesh.positions.len();
    if let Some(t) = mesh
        .triangles
        .par_iter()
        .position_first(|tri| tri.iter().any(|&v| v as usize >= n))
    {
        let vertex = *mesh.triangles[t]
            .iter()
            .find(|&&v| v as usize >= n)
            .expect("an index is out of range");
        return Err(BaselineError::IndexOutOfRange {
            triangle: t,
            vertex,
            vertices: n,
        });
    }
    Ok(())
}

/// Checks the mesh (see [`check`]) and builds the vertex-to-corner table and bounds.
pub(crate) fn prepare(mesh: &TriangleMesh) -> Result<Prepared, BaselineError> {
    check(mesh)?;
    let n = mesh.positions.len();
    let corner_count = mesh.triangles.len() * 3;
    memory::check_allocation(
        "the vertex-to-corner table",
        memory::bytes_of::<u32>(corner_count + 2 * (n + 1)),
    )?;

    // Counting sort of the corners by vertex.
    let mut offsets = vec![0u32; n + 1];
    for tri in &mesh.triangles {
        for &v in tri {
            offsets[v as usize + 1] += 1;
        }
    }
    for i in 0..n {
        offsets[i + 1] += offsets[i];
    }
    let mut cursor: Vec<u32> = offsets[..n].to_vec();
    let mut corners = vec![0u32; corner_count];
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for (k, &v) in tri.iter().enumerate() {
            let slot = &mut cursor[v as usize];
            corners[*slot as usize] = (3 * t + k) as u32;
            *slot += 1;
        }
    }
    drop(cursor);

    let (lo, hi, referenced) = mesh
        .positions
        .par_iter()
        .enumerate()
        .with_min_len(4096)
        .filter(|(v, _)| offsets[v + 1] > offsets[*v])
        .fold(
            || {
                (
                    Vec3::splat(f32::INFINITY),
                    Vec3::splat(f32::NEG_INFINITY),
                    0usize,
                )
            },
            |(lo, hi, k), (_, &p)| (lo.min(p), hi.max(p), k + 1),
        )
        .reduce(
            || {
                (
                    Vec3::splat(f32::INFINITY),
                    Vec3::splat(f32::NEG_INFINITY),
                    0usize,
                )
            },
            |a, b| (a.0.min(b.0), a.1.max(b.1), a.2 + b.2),
        );
    let bounds = Bounds::new(lo.as_dvec3(), hi.as_dvec3());
    debug_assert!(referenced > 0 && !bounds.is_empty());
    Ok(Prepared {
        offsets,
        corners,
        bounds,
        referenced,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn corners_are_grouped_by_vertex() {
        let mesh = TriangleMesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z, Vec3::splat(9.0)],
            vec![[0, 1, 2], [0, 2, 3]],
        );
        let p = prepare(&mesh).unwrap();
        assert_eq!(p.corners_of(0), &[0, 3]);
        assert_eq!(p.corners_of(2), &[2, 4]);
        assert_eq!(p.corners_of(3), &[5]);
        assert!(p.corners_of(4).is_empty());
        assert_eq!(p.referenced, 4);
        // The unreferenced vertex at (9, 9, 9) does not count in the box.
        assert_eq!(p.bounds.max, glam::DVec3::ONE);
    }
}
