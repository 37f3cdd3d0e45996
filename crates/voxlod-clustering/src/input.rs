//! Checking a triangle mesh once and building what every baseline needs from it: for each
//! vertex, the two other vertices of every triangle that uses it (a compressed sparse row table
//! built by a parallel counting sort), and the box of the vertices that triangles use.
//!
//! Cost: two parallel passes over the 3T corners (count, then fill) and one over the V vertices,
//! O(V + T), 8 bytes per corner plus 4 bytes per vertex and worker. Vertices that no triangle
//! uses are left out of everything downstream (they are not part of the object's boundary):
//! they join no cluster and weigh nothing.

use glam::Vec3;
use rayon::prelude::*;
use voxlod_core::{memory, Bounds, TriangleMesh};

use crate::ClusteringError;

/// A checked mesh's vertex-to-neighbour table and bounds.
#[derive(Debug)]
pub(crate) struct Prepared {
    /// `offsets[v]..offsets[v + 1]` indexes `neighbours` for vertex `v` (length V + 1).
    pub offsets: Vec<u32>,
    /// For each corner of each triangle at vertex `v`, grouped by `v` in triangle order: the
    /// next and the previous vertex of that triangle (counter-clockwise).
    pub neighbours: Vec<[u32; 2]>,
    /// Box of the vertices that at least one triangle uses.
    pub bounds: Bounds,
    /// How many vertices at least one triangle uses.
    pub referenced: usize,
}

impl Prepared {
    /// Whether some triangle uses vertex `v`.
    #[inline]
    pub fn is_referenced(&self, v: usize) -> bool {
        self.offsets[v + 1] > self.offsets[v]
    }

    /// The (next, previous) vertices of every triangle corner at `v`, in triangle order.
    #[inline]
    pub fn neighbours_of(&self, v: usize) -> &[[u32; 2]] {
        &self.neighbours[self.offsets[v] as usize..self.offsets[v + 1] as usize]
    }
}

/// A raw pointer that workers may share because each writes only its own slots.
#[derive(Clone, Copy)]
struct SharedSlots(*mut [u32; 2]);
// SAFETY: used only in `fill_neighbours`, where the slots written by different workers are disjoint
// (each worker owns the range of cursors it computed for its chunk of triangles).
unsafe impl Send for SharedSlots {}
unsafe impl Sync for SharedSlots {}

impl SharedSlots {
    /// # Safety
    /// `i` must be inside the table, and no other worker may write slot `i`.
    #[inline]
    unsafe fn write(&self, i: usize, value: [u32; 2]) {
        // SAFETY: as the caller promises.
        unsafe { self.0.add(i).write(value) }
    }
}

/// Checks the mesh and builds the table: refuses no triangles, more corners than 32-bit ids can
/// name, an index out of range (the first such triangle is named) and a non-finite coordinate
/// (on any vertex, used or not; the first is named).
pub(crate) fn prepare(mesh: &TriangleMesh) -> Result<Prepared, ClusteringError> {
    voxlod_core::validate::validate_mesh(mesh, &Default::default())?;
    let n = mesh.positions.len();
    if n >= u32::MAX as usize {
        return Err(ClusteringError::TooLarge {
            what: format!("{n} vertices (at most {})", u32::MAX - 1),
        });
    }
    // Triangle ids carry an orientation bit in their top bit during elimination.
    let max_triangles = (u32::MAX / 3) as usize;
    if mesh.triangles.len() > max_triangles {
        return Err(ClusteringError::TooLarge {
            what: format!(
                "{} triangles (at most {max_triangles})",
                mesh.triangles.len()
            ),
        });
    }
    let corner_count = mesh.triangles.len() * 3;
    let workers = rayon::current_num_threads().clamp(1, 8);
    let chunk = mesh.triangles.len().div_ceil(workers).max(1 << 14);
    let chunks = mesh.triangles.len().div_ceil(chunk);
    memory::check_allocation(
        "the vertex-to-neighbour table",
        memory::bytes_of::<[u32; 2]>(corner_count)
            + memory::bytes_of::<u32>((chunks + 1) * (n + 1)),
    )?;
    let mut counts = count_corners(mesh, chunk);
    let offsets = offsets_and_cursors(&mut counts, n);
    debug_assert_eq!(offsets[n] as usize, corner_count);
    let neighbours = fill_neighbours(mesh, chunk, counts, corner_count);
    let (bounds, referenced) = used_bounds(mesh, &offsets)?;
    Ok(Prepared {
        offsets,
        neighbours,
        bounds,
        referenced,
    })
}

/// Pass 1: per chunk of `chunk` triangles, how many corners each vertex has in it (indices
/// are in range: validated by the caller).
fn count_corners(mesh: &TriangleMesh, chunk: usize) -> Vec<Vec<u32>> {
    let n = mesh.positions.len();
    mesh.triangles
        .par_chunks(chunk)
        .map(|tris| {
            let mut count = vec![0u32; n];
            for &v in tris.iter().flatten() {
                count[v as usize] += 1;
            }
            count
        })
        .collect()
}

/// The table's offsets (length `n + 1`), and each chunk's first slot per vertex: the counts
/// become cursors in place.
fn offsets_and_cursors(counts: &mut [Vec<u32>], n: usize) -> Vec<u32> {
    let mut offsets = vec![0u32; n + 1];
    let mut sum = 0u32;
    for v in 0..n {
        offsets[v] = sum;
        for count in counts.iter_mut() {
            let k = count[v];
            count[v] = sum;
            sum += k;
        }
    }
    offsets[n] = sum;
    offsets
}

/// Pass 2: the table, each chunk writing through its own cursors, in parallel.
fn fill_neighbours(
    mesh: &TriangleMesh,
    chunk: usize,
    mut cursors: Vec<Vec<u32>>,
    corner_count: usize,
) -> Vec<[u32; 2]> {
    let mut neighbours = vec![[0u32; 2]; corner_count];
    let slots = SharedSlots(neighbours.as_mut_ptr());
    mesh.triangles
        .par_chunks(chunk)
        .zip(cursors.par_iter_mut())
        .for_each(|(tris, cursor)| {
            for &[a, b, c] in tris {
                for (v, next, prev) in [(a, b, c), (b, c, a), (c, a, b)] {
                    let slot = &mut cursor[v as usize];
                    // SAFETY: `*slot` lies in this chunk's own range for `v`, inside the table:
                    // the ranges of all chunks and vertices partition 0..corner_count.
                    unsafe { slots.write(*slot as usize, [next, prev]) };
                    *slot += 1;
                }
            }
        });
    neighbours
}

/// Pass 3: the box and number of the used vertices (those with a corner in `offsets`;
/// coordinates are finite: validated by the caller).
fn used_bounds(mesh: &TriangleMesh, offsets: &[u32]) -> Result<(Bounds, usize), ClusteringError> {
    const BLOCK: usize = 1 << 14;
    let parts: Vec<([f32; 3], [f32; 3], usize)> = mesh
        .positions
        .par_chunks(BLOCK)
        .enumerate()
        .map(|(c, ps)| {
            let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
            let mut k = 0usize;
            let base = c * BLOCK;
            for (i, p) in ps.iter().enumerate() {
                let v = base + i;
                if offsets[v + 1] > offsets[v] {
                    for (axis, x) in p.to_array().into_iter().enumerate() {
                        lo[axis] = if x < lo[axis] { x } else { lo[axis] };
                        hi[axis] = if x > hi[axis] { x } else { hi[axis] };
                    }
                    k += 1;
                }
            }
            (lo, hi, k)
        })
        .collect();
    let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    let mut referenced = 0;
    for (l, h, k) in parts {
        lo = lo.min(Vec3::from(l));
        hi = hi.max(Vec3::from(h));
        referenced += k;
    }
    let bounds = Bounds::new(lo.as_dvec3(), hi.as_dvec3());
    debug_assert!(referenced > 0 && !bounds.is_empty());
    Ok((bounds, referenced))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neighbours_are_grouped_by_vertex() {
        let mesh = TriangleMesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z, Vec3::splat(9.0)],
            vec![[0, 1, 2], [0, 2, 3]],
        );
        let p = prepare(&mesh).unwrap();
        assert_eq!(p.neighbours_of(0), &[[1, 2], [2, 3]]);
        assert_eq!(p.neighbours_of(2), &[[0, 1], [3, 0]]);
        assert_eq!(p.neighbours_of(3), &[[0, 2]]);
        assert!(p.neighbours_of(4).is_empty());
        assert_eq!(p.referenced, 4);
        // The unreferenced vertex at (9, 9, 9) does not count in the box.
        assert_eq!(p.bounds.max, glam::DVec3::ONE);
    }

    #[test]
    fn many_chunks_fill_in_triangle_order() {
        // More triangles than one chunk holds, all sharing vertex 0.
        let count = 100_000u32;
        let positions = (0..count + 2)
            .map(|i| Vec3::new(i as f32, (i % 7) as f32, 0.0))
            .collect();
        let triangles: Vec<[u32; 3]> = (0..count).map(|i| [0, i + 1, i + 2]).collect();
        let p = prepare(&TriangleMesh::new(positions, triangles)).unwrap();
        let at0 = p.neighbours_of(0);
        assert_eq!(at0.len(), count as usize);
        assert!(at0
            .iter()
            .enumerate()
            .all(|(i, &[a, b])| a == i as u32 + 1 && b == i as u32 + 2));
        assert_eq!(p.neighbours_of(1), &[[2, 0]]);
    }

    #[test]
    fn the_first_bad_index_and_coordinate_are_named() {
        let mut mesh =
            TriangleMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]; 40_000]);
        mesh.triangles[35_000] = [0, 7, 2];
        mesh.triangles[39_000] = [9, 1, 2];
        let e = prepare(&mesh).unwrap_err().to_string();
        assert_eq!(
            e,
            "triangle 35000 refers to vertex 7 but there are only 3 vertices"
        );
        let mut mesh = TriangleMesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::ONE],
            vec![[0, 1, 2]],
        );
        mesh.positions[3].y = f32::NAN;
        mesh.positions[1].x = f32::NEG_INFINITY;
        let e = prepare(&mesh).unwrap_err().to_string();
        assert_eq!(e, "vertex 1 has a non-finite coordinate (-inf, 0, 0)");
    }
}
