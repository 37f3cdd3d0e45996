//! A canonical order of a mesh's vertices and triangles, so that a layer's bytes depend on the
//! set of triangles a label has and not on the order they were given in.
//!
//! Vertices are ordered by position (x, then y, then z, as exact doubles) and vertices at the
//! same position are one vertex; a triangle is rotated to start at its least vertex (its
//! orientation kept) and triangles are sorted, a triangle given twice kept once. The same
//! triangles given in any order, with their corners rotated, with a vertex repeated or a
//! triangle given twice (as blockwise meshing yields on block faces) come out as the same
//! arrays. Cost: a sort of the vertices and one of the triangles.

use voxlod_core::glam::DVec3;

/// A key whose order is the lexicographic order of the positions (−0 just below +0).
#[inline]
pub fn position_key(p: DVec3) -> [u64; 3] {
    p.to_array().map(|c| {
        let bits = c.to_bits();
        if bits >> 63 == 1 {
            !bits
        } else {
            bits | 1 << 63
        }
    })
}

/// `t` rotated to start at its least index, with the same orientation.
#[inline]
pub fn rotate(t: [u32; 3]) -> [u32; 3] {
    if t[0] <= t[1] && t[0] <= t[2] {
        t
    } else if t[1] <= t[2] {
        [t[1], t[2], t[0]]
    } else {
        [t[2], t[0], t[1]]
    }
}

/// Whether a triangle repeats an index.
#[inline]
pub fn degenerate(t: &[u32; 3]) -> bool {
    t[0] == t[1] || t[1] == t[2] || t[2] == t[0]
}

/// The vertices used by `triangles`, one per position, in position order, and the triangles on
/// them rotated and sorted; triangles that repeat a vertex once merged are dropped, and a
/// triangle given twice (same corners, same orientation, as two blocks may both emit one on
/// their common face) is kept once. Unused vertices do not count. Indices must be in range
/// (`TriangleMesh::validate`).
pub fn weld(positions: &[DVec3], triangles: &[[u32; 3]]) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut used = vec![false; positions.len()];
    triangles
        .iter()
        .flatten()
        .for_each(|&v| used[v as usize] = true);
    let mut keys: Vec<([u64; 3], u32)> = (0..positions.len() as u32)
        .filter(|&v| used[v as usize])
        .map(|v| (position_key(positions[v as usize]), v))
        .collect();
    keys.sort_unstable();
    let mut remap = vec![u32::MAX; positions.len()];
    let mut welded: Vec<DVec3> = Vec::with_capacity(keys.len());
    for (i, (key, v)) in keys.iter().enumerate() {
        if i == 0 || keys[i - 1].0 != *key {
            welded.push(positions[*v as usize]);
        }
        remap[*v as usize] = welded.len() as u32 - 1;
    }
    let mut out: Vec<[u32; 3]> = triangles
        .iter()
        .map(|t| t.map(|v| remap[v as usize]))
        .filter(|t| !degenerate(t))
        .map(rotate)
        .collect();
    out.sort_unstable();
    out.dedup();
    (welded, out)
}

/// Renumbers the vertices in position order (vertices at the same position keep their relative
/// order) and the triangles' indices with them, each triangle rotated again. The first `sorted`
/// vertices must already be in increasing position order (as [`weld`] leaves them, before a
/// cut appends its new vertices): only the others are sorted, then merged with them.
pub fn renumber_by_position(positions: &mut Vec<DVec3>, sorted: usize, triangles: &mut [[u32; 3]]) {
    let sorted = sorted.min(positions.len());
    let mut tail: Vec<([u64; 3], u32)> = (sorted..positions.len())
        .map(|i| (position_key(positions[i]), i as u32))
        .collect();
    tail.sort_unstable();
    let mut order: Vec<u32> = Vec::with_capacity(positions.len());
    let mut tail = tail.into_iter().peekable();
    for (head, p) in positions[..sorted].iter().enumerate() {
        let key = position_key(*p);
        while let Some(&(_, v)) = tail.peek().filter(|(k, _)| *k < key) {
            order.push(v);
            tail.next();
        }
        order.push(head as u32);
    }
    order.extend(tail.map(|(_, v)| v));
    let mut remap = vec![0u32; positions.len()];
    for (new, &old) in order.iter().enumerate() {
        remap[old as usize] = new as u32;
    }
    *positions = order.iter().map(|&old| positions[old as usize]).collect();
    for t in triangles.iter_mut() {
        *t = rotate(t.map(|v| remap[v as usize]));
    }
}

/// A piece of a mesh on its own vertices: `vertices` are the indices it uses, increasing, and
/// `triangles` index into `vertices`.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Compact {
    /// The indices used, increasing.
    pub vertices: Vec<u32>,
    /// The triangles on `vertices`, in the order given.
    pub triangles: Vec<[u32; 3]>,
}

impl Compact {
    /// The piece `triangles` on its own vertices, in increasing order of the indices (so in
    /// position order when the indices are, as after [`renumber_by_position`]). Cost: a sort
    /// of its corners; [`Compactor`] does better for many pieces of one mesh.
    pub fn of(triangles: &[[u32; 3]]) -> Compact {
        let vertices = triangles
            .iter()
            .flatten()
            .max()
            .map_or(0, |&v| v as usize + 1);
        Compactor::new(vertices).compact(triangles)
    }
}

/// Puts pieces of one mesh on their own vertices, as [`Compact::of`] does, with one mark per
/// vertex of the mesh kept from piece to piece. Cost: linear in the piece, plus a sort of its
/// vertices.
#[derive(Clone, Debug)]
pub struct Compactor {
    /// Per vertex of the mesh, its index in the piece being made; `u32::MAX` outside it.
    local: Vec<u32>,
}

impl Compactor {
    /// A compactor for pieces of a mesh of `vertices` vertices.
    pub fn new(vertices: usize) -> Compactor {
        Compactor {
            local: vec![u32::MAX; vertices],
        }
    }

    /// The piece `triangles` on its own vertices (indices below the `vertices` given to
    /// [`Compactor::new`]).
    pub fn compact(&mut self, triangles: &[[u32; 3]]) -> Compact {
        let mut vertices = Vec::with_capacity(triangles.len());
        for &v in triangles.iter().flatten() {
            if self.local[v as usize] == u32::MAX {
                self.local[v as usize] = 0;
                vertices.push(v);
            }
        }
        vertices.sort_unstable();
        for (i, &v) in vertices.iter().enumerate() {
            self.local[v as usize] = i as u32;
        }
        let triangles = triangles
            .iter()
            .map(|t| t.map(|v| self.local[v as usize]))
            .collect();
        for &v in &vertices {
            self.local[v as usize] = u32::MAX;
        }
        Compact {
            vertices,
            triangles,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_order_positions_as_numbers() {
        let values = [-3.5, -1.0, -0.0, 0.0, 1e-300, 2.0, 7.25];
        for w in values.windows(2) {
            let k = |x: f64| position_key(DVec3::new(x, 0.0, 0.0));
            assert!(k(w[0]) < k(w[1]), "{} !< {}", w[0], w[1]);
        }
        let a = position_key(DVec3::new(1.0, 5.0, -2.0));
        let b = position_key(DVec3::new(1.0, 5.0, 3.0));
        assert!(a < b);
    }

    #[test]
    fn the_same_triangles_in_another_order_weld_to_the_same_arrays() {
        // A square in two triangles, then the same with a vertex given twice, the triangles
        // swapped and their corners rotated, and an unused vertex.
        let square = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
        ];
        let (p, t) = weld(&square, &[[0, 1, 2], [0, 2, 3]]);
        let shuffled = [
            square[2],
            square[3],
            square[0],
            square[1],
            square[2],
            DVec3::splat(9.0),
        ];
        let (q, u) = weld(&shuffled, &[[3, 4, 2], [1, 2, 0]]);
        assert_eq!(p, q);
        assert_eq!(t, u);
        assert_eq!(p.len(), 4);
        // Sorted by x then y: (0,0), (0,1), (1,0), (1,1).
        assert_eq!(t, vec![[0, 2, 3], [0, 3, 1]]);
    }

    #[test]
    fn renumbering_merges_the_appended_vertices_in_position_order() {
        let x = |v: f64| DVec3::new(v, 0.0, 0.0);
        // A sorted head, then appended vertices, one at the same place as a head vertex.
        let mut positions = vec![x(1.0), x(3.0), x(5.0), x(4.0), x(0.5), x(3.0), x(9.0)];
        let mut triangles = vec![[3, 4, 5], [6, 0, 2]];
        renumber_by_position(&mut positions, 3, &mut triangles);
        let values: Vec<f64> = positions.iter().map(|p| p.x).collect();
        assert_eq!(values, vec![0.5, 1.0, 3.0, 3.0, 4.0, 5.0, 9.0]);
        // Old 1 (head) stays before old 5 at the same place: old 5 is new 3.
        assert_eq!(triangles, vec![[0, 3, 4], [1, 5, 6]]);
    }

    #[test]
    fn rotation_keeps_the_orientation() {
        for t in [[4, 1, 9], [1, 9, 4], [9, 4, 1]] {
            assert_eq!(rotate(t), [1, 9, 4]);
        }
    }

    #[test]
    fn a_piece_on_its_own_vertices() {
        let c = Compact::of(&[[7, 3, 9], [9, 3, 12]]);
        assert_eq!(c.vertices, vec![3, 7, 9, 12]);
        assert_eq!(c.triangles, vec![[1, 0, 2], [2, 0, 3]]);
        let mut compactor = Compactor::new(20);
        assert_eq!(compactor.compact(&[[7, 3, 9], [9, 3, 12]]), c);
        let d = compactor.compact(&[[12, 4, 3]]);
        assert_eq!((d.vertices, d.triangles), (vec![3, 4, 12], vec![[2, 1, 0]]));
    }
}
