//! Where marching cubes puts a vertex on a crossed grid edge, and its normal: linear
//! interpolation of the iso value between the edge's two samples (Lorensen and Cline 1987, as
//! the voxel paper's §2 uses it) and the density gradient by central differences, one formula
//! for the dense and the sparse (brick) extraction so that both give bit-identical vertices.
//!
//! Interpolation parameters are clamped to `[c, 1 - c]` along their edge
//! ([`crate::ContourOptions::clamp`]). Plain marching cubes takes `c` = 1e-4, so that a sample
//! exactly at the iso value does not collapse triangles to zero area; triangles of area 1e-12
//! to 1e-6 cell² remain where the surface passes near a sample. The snapping clamp
//! ([`crate::marching_cubes::snap_clamp`]; `c` = 0.0721 for cleaning's defaults) leaves none. Every edge of a triangle joins vertices on two edges of one cell; if
//! those share a corner, the vertices lie at least `c` from it along perpendicular axes, so at
//! least `√2 · c` = 0.102 cell apart; if not, they are a whole cell apart along some axis.
//! Three points inside three distinct edges of a cube are never collinear (a line meets a
//! convex solid's boundary in two points unless it lies in a face, and a line in a face meets
//! the interiors of at most two of its edges), so a triangle's area has a positive minimum
//! over the box of allowed parameters: `(√3 / 2) · c²` (4.5e-3 cell² for 0.0721), reached by
//! the triangle that cuts a corner with its three vertices `c` from it (a search over all 220
//! triples of cube edges finds no smaller one; the tests check every cell case). Clamping
//! moves a vertex along its edge only, and never past a sample, so every sample's side and
//! every triangle of the mesh stay those of plain marching cubes.
//!
//! [`VertexPlacer::corner_range`] gives scikit-image's per-vertex `values`: the largest range of
//! the samples of a cell around the vertex's edge.
//!
//! Cost: two sample reads for the position, twelve more for the normal, eighteen for the
//! corner range. Dense samples away from the grid's border are read by flat offsets (the same
//! arithmetic on the same samples, so bit-identical results), skipping the index triples and
//! border tests that the general path needs for bricks and borders.

use glam::{DVec3, Vec3};
use voxlod_core::{BrickVolume, Grid, TriangleMesh};

/// Read access to the samples of a grid, dense or bricked.
pub(crate) trait Samples: Sync {
    fn at(&self, i: usize, j: usize, k: usize) -> f32;

    /// All samples, x fastest, when they are stored densely: the placer then reads interior
    /// neighbourhoods by flat offsets instead of index triples.
    #[inline]
    fn dense(&self) -> Option<&[f32]> {
        None
    }
}

/// The samples of a dense volume, x fastest.
pub(crate) struct DenseSamples<'a> {
    pub data: &'a [f32],
    pub dims: [usize; 3],
}

impl Samples for DenseSamples<'_> {
    #[inline]
    fn at(&self, i: usize, j: usize, k: usize) -> f32 {
        self.data[i + self.dims[0] * (j + self.dims[1] * k)]
    }

    #[inline]
    fn dense(&self) -> Option<&[f32]> {
        Some(self.data)
    }
}

impl Samples for BrickVolume {
    #[inline]
    fn at(&self, i: usize, j: usize, k: usize) -> f32 {
        self.get(i, j, k)
    }
}

/// The sampled field with its geometry, for vertex placement.
pub(crate) struct VertexPlacer<'a, S: Samples> {
    samples: &'a S,
    dims: [usize; 3],
    /// Flat offsets of one step along x, y, z in dense samples.
    strides: [usize; 3],
    spacing: DVec3,
    origin: DVec3,
    iso: f32,
    /// Interpolation parameters are clamped to `[clamp, 1 - clamp]`.
    clamp: f32,
}

impl<'a, S: Samples> VertexPlacer<'a, S> {
    pub fn new(samples: &'a S, grid: &Grid, iso: f32, clamp: f32) -> Self {
        VertexPlacer {
            samples,
            dims: grid.dims,
            strides: [1, grid.dims[0], grid.dims[0] * grid.dims[1]],
            spacing: grid.spacing_vec(),
            origin: grid.origin_vec(),
            iso,
            clamp,
        }
    }

    #[inline]
    fn at(&self, p: [usize; 3]) -> f32 {
        self.samples.at(p[0], p[1], p[2])
    }

    /// The flat index of `p` in dense samples.
    #[inline]
    fn flat(&self, p: [usize; 3]) -> usize {
        p[0] + self.strides[1] * p[1] + self.strides[2] * p[2]
    }

    /// Whether `p` has a neighbour on both sides along `axis`.
    #[inline]
    fn interior(&self, p: [usize; 3], axis: usize) -> bool {
        p[axis] > 0 && p[axis] + 1 < self.dims[axis]
    }

    /// Density gradient at a sample, in index units (central differences, one-sided at borders).
    fn gradient(&self, p: [usize; 3]) -> Vec3 {
        if let Some(data) = self.samples.dense() {
            if (0..3).all(|axis| self.interior(p, axis)) {
                // The general formula's arithmetic with a span of 2, by flat offsets.
                let f = self.flat(p);
                let [sx, sy, sz] = self.strides;
                return Vec3::new(
                    (data[f + sx] - data[f - sx]) / 2.0,
                    (data[f + sy] - data[f - sy]) / 2.0,
                    (data[f + sz] - data[f - sz]) / 2.0,
                );
            }
        }
        let mut g = [0.0f32; 3];
        for (axis, slot) in g.iter_mut().enumerate() {
            let n = self.dims[axis];
            let (mut lo, mut hi) = (p, p);
            if p[axis] > 0 {
                lo[axis] -= 1;
            }
            if p[axis] + 1 < n {
                hi[axis] += 1;
            }
            let span = (hi[axis] - lo[axis]) as f32;
            if span > 0.0 {
                *slot = (self.at(hi) - self.at(lo)) / span;
            }
        }
        Vec3::from(g)
    }

    /// Position and outward normal of the vertex on the edge from sample `p` along `axis`.
    pub fn edge_vertex(&self, p: [usize; 3], axis: usize, with_normal: bool) -> (Vec3, Vec3) {
        let mut q = p;
        q[axis] += 1;
        let (a, b) = (self.at(p), self.at(q));
        let t = (self.iso - a) / (b - a);
        let t = if t.is_finite() {
            t.clamp(self.clamp, 1.0 - self.clamp)
        } else {
            0.5
        };
        let mut index = DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
        index[axis] += t as f64;
        let position = (self.origin + index * self.spacing).as_vec3();
        let normal = if with_normal {
            let g = self.gradient(p).lerp(self.gradient(q), t);
            // World-space gradient divides by the spacing; the normal points down the gradient.
            let world = -(g.as_dvec3() / self.spacing);
            world.normalize_or_zero().as_vec3()
        } else {
            Vec3::ZERO
        };
        (position, normal)
    }
}

impl<S: Samples> VertexPlacer<'_, S> {
    /// The largest corner range (max − min of its eight samples) of the cells of the grid
    /// around the edge from sample `p` along `axis`: up to four cells, those at `p` and one
    /// below it along each of the other two axes. The 3 × 3 columns of two samples along
    /// `axis` around the edge are reduced once, then each cell takes its 2 × 2 of them.
    pub fn corner_range(&self, p: [usize; 3], axis: usize) -> f32 {
        let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
        if let Some(data) = self.samples.dense() {
            if self.interior(p, b) && self.interior(p, c) {
                return self.interior_corner_range(data, p, [axis, b, c]);
            }
        }
        // Columns at offsets -1, 0, 1 along b and c (those inside the grid).
        let mut columns = [[None::<(f32, f32)>; 3]; 3];
        for (db, row) in columns.iter_mut().enumerate() {
            for (dc, column) in row.iter_mut().enumerate() {
                let (Some(qb), Some(qc)) = ((p[b] + db).checked_sub(1), (p[c] + dc).checked_sub(1))
                else {
                    continue;
                };
                if qb >= self.dims[b] || qc >= self.dims[c] {
                    continue;
                }
                let mut q = p;
                (q[b], q[c]) = (qb, qc);
                let low = self.at(q);
                q[axis] += 1;
                let high = self.at(q);
                *column = Some((low.min(high), low.max(high)));
            }
        }
        let mut largest = f32::NEG_INFINITY;
        for ob in 0..2 {
            for oc in 0..2 {
                let corners = [
                    columns[ob][oc],
                    columns[ob + 1][oc],
                    columns[ob][oc + 1],
                    columns[ob + 1][oc + 1],
                ];
                // A cell exists when all four of its columns are inside the grid.
                if let [Some(a), Some(b), Some(c), Some(d)] = corners {
                    let lo = a.0.min(b.0).min(c.0).min(d.0);
                    let hi = a.1.max(b.1).max(c.1).max(d.1);
                    largest = largest.max(hi - lo);
                }
            }
        }
        largest
    }

    /// [`Self::corner_range`] of an edge with all four cells inside dense samples: the same
    /// minima and maxima in the same order, read by flat offsets.
    #[inline]
    fn interior_corner_range(&self, data: &[f32], p: [usize; 3], [a, b, c]: [usize; 3]) -> f32 {
        let (sa, sb, sc) = (self.strides[a], self.strides[b], self.strides[c]);
        let corner = self.flat(p) - sb - sc;
        let mut columns = [[(0.0f32, 0.0f32); 3]; 3];
        for (db, row) in columns.iter_mut().enumerate() {
            for (dc, column) in row.iter_mut().enumerate() {
                let q = corner + db * sb + dc * sc;
                let (low, high) = (data[q], data[q + sa]);
                *column = (low.min(high), low.max(high));
            }
        }
        let mut largest = f32::NEG_INFINITY;
        for ob in 0..2 {
            for oc in 0..2 {
                let (w, x) = (columns[ob][oc], columns[ob + 1][oc]);
                let (y, z) = (columns[ob][oc + 1], columns[ob + 1][oc + 1]);
                let lo = w.0.min(x.0).min(y.0).min(z.0);
                let hi = w.1.max(x.1).max(y.1).max(z.1);
                largest = largest.max(hi - lo);
            }
        }
        largest
    }
}

/// Vertices whose interpolated gradient vanished get the area-weighted normal of their triangles.
pub(crate) fn repair_zero_normals(mesh: &mut TriangleMesh) {
    if !mesh.normals.contains(&Vec3::ZERO) {
        return;
    }
    let mut acc = vec![Vec3::ZERO; mesh.positions.len()];
    for &[a, b, c] in &mesh.triangles {
        let (pa, pb, pc) = (
            mesh.positions[a as usize],
            mesh.positions[b as usize],
            mesh.positions[c as usize],
        );
        let n = (pb - pa).cross(pc - pa);
        for v in [a, b, c] {
            acc[v as usize] += n;
        }
    }
    for (n, a) in mesh.normals.iter_mut().zip(acc) {
        if *n == Vec3::ZERO {
            *n = a.normalize_or_zero();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The same samples without the dense view: every read goes through `at`.
    struct IndexedOnly<'a>(DenseSamples<'a>);

    impl Samples for IndexedOnly<'_> {
        fn at(&self, i: usize, j: usize, k: usize) -> f32 {
            self.0.at(i, j, k)
        }
    }

    /// Pseudo-random samples in [-1, 1) with repeats, so that ties between corners occur.
    fn scrambled(len: usize) -> Vec<f32> {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        (0..len)
            .map(|_| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                ((state >> 40) % 64) as f32 / 32.0 - 1.0
            })
            .collect()
    }

    #[test]
    fn flat_offset_reads_give_the_indexed_results_bit_for_bit() {
        let dims = [7, 5, 6];
        let data = scrambled(dims.iter().product());
        let grid = Grid::new(dims, [0.5, 1.0, 2.0], [1.0, -2.0, 0.25]).unwrap();
        let dense = DenseSamples { data: &data, dims };
        let indexed = IndexedOnly(DenseSamples { data: &data, dims });
        let fast = VertexPlacer::new(&dense, &grid, 0.1, 1e-4);
        let slow = VertexPlacer::new(&indexed, &grid, 0.1, 1e-4);
        let mut interior = 0;
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    let p = [i, j, k];
                    assert_eq!(fast.gradient(p), slow.gradient(p), "gradient at {p:?}");
                    for axis in 0..3 {
                        if p[axis] + 1 >= dims[axis] {
                            continue;
                        }
                        let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
                        interior += usize::from(fast.interior(p, b) && fast.interior(p, c));
                        let (x, y) = (fast.corner_range(p, axis), slow.corner_range(p, axis));
                        assert_eq!(x.to_bits(), y.to_bits(), "range at {p:?} along {axis}");
                        assert_eq!(
                            fast.edge_vertex(p, axis, true),
                            slow.edge_vertex(p, axis, true),
                            "vertex at {p:?} along {axis}"
                        );
                    }
                }
            }
        }
        // Both paths were exercised: interior edges and border edges.
        assert!(interior > 100, "{interior} interior edges");
    }
}
