//! Where marching cubes puts a vertex on a crossed grid edge, and its normal: linear
//! interpolation of the iso value between the edge's two samples (Lorensen and Cline 1987, as
//! the voxel paper's §2 uses it) and the density gradient by central differences, one formula
//! for the dense and the sparse (brick) extraction so that both give bit-identical vertices.
//!
//! Interpolation parameters are clamped to `[1e-4, 1 - 1e-4]` along their edge so that a sample
//! exactly at the iso value does not collapse triangles to zero area.
//!
//! [`VertexPlacer::corner_range`] gives scikit-image's per-vertex `values`: the largest range of
//! the samples of a cell around the vertex's edge.
//!
//! Cost: two sample reads for the position, twelve more for the normal, eighteen for the
//! corner range.

use glam::{DVec3, Vec3};
use voxlod_core::{BrickVolume, Grid, TriangleMesh};

const CLAMP: f32 = 1e-4;

/// Read access to the samples of a grid, dense or bricked.
pub(crate) trait Samples: Sync {
    fn at(&self, i: usize, j: usize, k: usize) -> f32;
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
    spacing: DVec3,
    origin: DVec3,
    iso: f32,
}

impl<'a, S: Samples> VertexPlacer<'a, S> {
    pub fn new(samples: &'a S, grid: &Grid, iso: f32) -> Self {
        VertexPlacer {
            samples,
            dims: grid.dims,
            spacing: grid.spacing_vec(),
            origin: grid.origin_vec(),
            iso,
        }
    }

    #[inline]
    fn at(&self, p: [usize; 3]) -> f32 {
        self.samples.at(p[0], p[1], p[2])
    }

    /// Density gradient at a sample, in index units (central differences, one-sided at borders).
    fn gradient(&self, p: [usize; 3]) -> Vec3 {
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
            t.clamp(CLAMP, 1.0 - CLAMP)
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
