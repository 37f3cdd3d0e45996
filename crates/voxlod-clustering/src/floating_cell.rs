//! Low–Tan weight-controlled vertex clustering with floating cells (the patent's steps 1–9).
//!
//! 1. **Grading**: weights from the angles between incident edges and their lengths, see
//!    [`crate::grading`] (`L · cos(θ/2)`).
//! 2. **Sorting**: the used vertices in non-increasing weight (ties: lower index first).
//! 3. **Triangulation**: the input is already triangles (see [`crate::rossignac_borrel`](mod@crate::rossignac_borrel)).
//! 4. **Clustering**: the heaviest vertex not yet clustered becomes the centre of a cell of the
//!    given size, an axis-aligned cube of side `cell_size` centred on it (boundary included), and
//!    every vertex not yet clustered inside that cube joins its cluster. Repeat until every vertex
//!    is clustered. Cells "float": they sit where the important vertices are, not on a grid.
//! 5. **Thick edges**: see [`crate::thick_edges`].
//! 6. **Synthesis**: a cluster's representative is its centre vertex, the heaviest.
//! 7. **Normals**: recomputed from the simplified triangles.
//! 8. **Elimination**: as Rossignac–Borrel §3.5, see [`crate::elimination`].
//! 9. **Storing**: each level is returned; the caller writes it.
//!
//! Further levels repeat steps 4–9 from the graded, sorted original with a larger cell, as the
//! patent says; the cells double from level to level like the Rossignac–Borrel octree series, so
//! the level selection (`voxlod::select`) treats both alike. The patent names the cell size; we
//! take it, as for the grid, as the clustering box's longest side divided by `cells`.
//!
//! Our choices: the cell is a cube (the patent says "cell" and gives no shape) so that its size
//! means the same as a grid cell's. Finding the vertices in a cube uses a bucket grid of cells of
//! the same size, with clustered vertices swapped out of their buckets, so each query looks at
//! most at 8 buckets of vertices still unclustered.
//!
//! Cost: O(V log V) for the sort (parallel), then per level O(V + T) expected: each vertex is
//! bucketed once and removed once, each query scans at most 8 buckets, plus the elimination.

use std::time::Instant;

use glam::{DVec3, Vec3};
use rayon::prelude::*;
use voxlod_core::{Bounds, TriangleMesh};

use crate::elimination;
use crate::grading::{grade_prepared, Grading};
use crate::grid::{self, CellTable, ClusterGrid};
use crate::input;
use crate::level::{Level, LevelReport, Method};
use crate::rossignac_borrel::build_poly_mesh;
use crate::sort::radix_sort_by_key;
use crate::ClusteringError;

/// Options of [`low_tan`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FloatingCellOptions {
    /// The finest cell size is the clustering box's longest side divided by `cells`.
    pub cells: u32,
    /// Number of levels, each with cells twice as large as the previous.
    pub levels: u32,
    /// The box whose longest side sets the cell size; `None` for the mesh's own box.
    pub bounds: Option<Bounds>,
    /// Estimate thick-edge widths and normals (step 5).
    pub thick_edges: bool,
}

impl Default for FloatingCellOptions {
    /// One level of 64 cells, with thick edges, on the mesh's own box.
    fn default() -> Self {
        FloatingCellOptions {
            cells: 64,
            levels: 1,
            bounds: None,
            thick_edges: true,
        }
    }
}

impl FloatingCellOptions {
    /// One level with cells of 1/`cells` of the box's longest side, with thick edges.
    pub fn single(cells: u32) -> Self {
        FloatingCellOptions {
            cells,
            ..Default::default()
        }
    }

    /// `levels` levels from `cells`, each with cells twice as large.
    pub fn series(cells: u32, levels: u32) -> Self {
        FloatingCellOptions {
            cells,
            levels,
            ..Default::default()
        }
    }

    /// The same with the cell size taken from `bounds` (a whole scene's box, say).
    pub fn with_bounds(self, bounds: Bounds) -> Self {
        FloatingCellOptions {
            bounds: Some(bounds),
            ..self
        }
    }

    /// The same with thick edges on or off.
    pub fn with_thick_edges(self, thick_edges: bool) -> Self {
        FloatingCellOptions {
            thick_edges,
            ..self
        }
    }

    fn check(&self) -> Result<(), ClusteringError> {
        grid::check_cells(self.cells)?;
        grid::check_levels(self.levels, self.cells)?;
        if let Some(b) = &self.bounds {
            grid::check_bounds(b)?;
        }
        Ok(())
    }
}

/// Simplifies `mesh` into `options.levels` levels, finest first.
///
/// # Errors
///
/// [`ClusteringError`] for zero cells or levels, more levels than the cells allow, a bad box,
/// and a mesh without triangles, with an index out of range or a non-finite coordinate.
///
/// # Example
///
/// A 16 × 16 grid of quads on the unit square in floating cells of 1/4: every representative
/// is an input vertex (the heaviest of its cluster), and every input vertex lies in the cube of
/// side 1/4 centred on its representative.
///
/// ```
/// use glam::Vec3;
/// use voxlod_clustering::{low_tan, FloatingCellOptions};
/// use voxlod_core::TriangleMesh;
///
/// let n = 16u32;
/// let positions = (0..=n)
///     .flat_map(|j| (0..=n).map(move |i| Vec3::new(i as f32, j as f32, 0.0) / n as f32))
///     .collect();
/// let id = |i: u32, j: u32| j * (n + 1) + i;
/// let mut triangles = Vec::new();
/// for j in 0..n {
///     for i in 0..n {
///         let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
///         triangles.extend([[a, b, c], [a, c, d]]);
///     }
/// }
/// let plane = TriangleMesh::new(positions, triangles);
///
/// let level = &low_tan(&plane, &FloatingCellOptions::single(4))?[0];
/// assert_eq!(level.report.cell_size, 0.25);
/// assert!(level.mesh.mesh.triangles.len() < plane.triangles.len());
/// let representatives = &level.mesh.mesh.positions;
/// assert!(representatives.iter().all(|r| plane.positions.contains(r)));
/// for (p, &c) in plane.positions.iter().zip(&level.cluster_of) {
///     let off = (*p - representatives[c as usize]).abs().max_element();
///     assert!(off <= 0.125, "{p} is {off} from its representative");
/// }
/// # Ok::<(), voxlod_clustering::ClusteringError>(())
/// ```
pub fn low_tan(
    mesh: &TriangleMesh,
    options: &FloatingCellOptions,
) -> Result<Vec<Level>, ClusteringError> {
    options.check()?;
    let mut start = Instant::now();
    let prepared = input::prepare(mesh)?;
    let box_ = options.bounds.unwrap_or(prepared.bounds);
    let base = ClusterGrid::new(&box_, options.cells)?;
    let weights = grade_prepared(&prepared, mesh, Grading::LowTan);
    let order = heaviest_first(&weights, |v| prepared.is_referenced(v));
    drop(weights);

    let mut levels = Vec::with_capacity(options.levels as usize);
    for level in 0..options.levels as usize {
        if level > 0 {
            start = Instant::now();
        }
        let grid = base.coarsened(level as u32);
        let clusters = floating_cells(&mesh.positions, &order, grid.cell_size);
        let simplices = elimination::eliminate_covering(
            &mesh.triangles,
            &clusters.cluster_of,
            clusters.centres.len(),
        );
        let positions = clusters
            .centres
            .iter()
            .map(|&v| mesh.positions[v as usize])
            .collect();
        let poly = build_poly_mesh(
            mesh,
            positions,
            &simplices,
            &clusters.cluster_of,
            options.thick_edges,
        );
        levels.push(Level {
            report: LevelReport {
                method: Method::LowTan,
                level,
                cells: grid.cells(),
                cell_size: grid.cell_size,
                clusters: clusters.centres.len(),
                triangles: poly.mesh.triangles.len(),
                dangling_edges: poly.lines.len(),
                isolated_points: poly.points.len(),
                cluster_seconds: start.elapsed().as_secs_f64(),
            },
            mesh: poly,
            cluster_of: clusters.cluster_of,
        });
    }
    Ok(levels)
}

/// The vertices for which `keep` holds, by non-increasing weight, ties by increasing index.
pub fn heaviest_first(weights: &[f32], keep: impl Fn(usize) -> bool + Sync) -> Vec<u32> {
    // Sort keys: the weight's bits turned so that integer order is descending `total_cmp`
    // order, then the index; one radix sort of 64-bit keys.
    let mut keys: Vec<u64> = (0..weights.len() as u32)
        .into_par_iter()
        .filter(|&v| keep(v as usize))
        .map(|v| ((descending(weights[v as usize]) as u64) << 32) | v as u64)
        .collect();
    radix_sort_by_key(&mut keys, 64, |&k| k);
    keys.into_iter().map(|k| k as u32).collect()
}

/// A key whose unsigned order is the reverse of `f32::total_cmp`.
fn descending(w: f32) -> u32 {
    let b = w.to_bits();
    let ascending = if b & 0x8000_0000 != 0 {
        !b
    } else {
        b | 0x8000_0000
    };
    !ascending
}

/// Floating-cell clusters.
#[derive(Clone, Debug, PartialEq)]
pub struct FloatingClusters {
    /// Vertex → cluster, `u32::MAX` for vertices not in the order.
    pub cluster_of: Vec<u32>,
    /// Cluster → its centre vertex, in order of creation.
    pub centres: Vec<u32>,
}

/// Step 4: clusters the vertices listed in `order` (heaviest first), each cluster a cube of side
/// `cell_size` centred on the heaviest vertex not yet clustered.
pub fn floating_cells(positions: &[Vec3], order: &[u32], cell_size: f64) -> FloatingClusters {
    debug_assert!(cell_size > 0.0 && cell_size.is_finite());
    let mut cluster_of = vec![u32::MAX; positions.len()];
    let mut centres = Vec::new();
    if order.is_empty() {
        return FloatingClusters {
            cluster_of,
            centres,
        };
    }
    let bounds = Bounds::from_points(order.iter().map(|&v| &positions[v as usize]));
    // Buckets of the cell's size: a cube of that side overlaps at most 2 per axis.
    let mut dims = [1u32; 3];
    for (axis, d) in dims.iter_mut().enumerate() {
        *d = ((bounds.size()[axis] / cell_size).floor() as u64 + 1).min(grid::MAX_CELLS as u64)
            as u32;
    }
    let buckets = ClusterGrid {
        origin: bounds.min.to_array(),
        cell_size,
        dims,
    };
    let mut items: Vec<(u64, u32)> = order
        .iter()
        .map(|&v| (buckets.key(buckets.cell_of(positions[v as usize])), v))
        .collect();
    let key_bits = 64 - buckets.cell_count().saturating_sub(1).leading_zeros();
    radix_sort_by_key(&mut items, key_bits.max(1), |it| it.0);
    // Buckets: runs of equal keys, found through a table from key to run.
    let mut table = CellTable::new(buckets.cell_count(), items.len());
    let mut start = Vec::new();
    let mut live_end = Vec::new();
    for (i, it) in items.iter().enumerate() {
        if i == 0 || items[i - 1].0 != it.0 {
            table.get_or_insert(it.0, start.len() as u32);
            start.push(i);
            live_end.push(i);
        }
        *live_end.last_mut().expect("a run is open") = i + 1;
    }
    let mut slots: Vec<u32> = items.iter().map(|it| it.1).collect();
    drop(items);

    let half = 0.5 * cell_size;
    let inv = 1.0 / cell_size;
    let origin = DVec3::from_array(buckets.origin);
    for &v in order {
        if cluster_of[v as usize] != u32::MAX {
            continue;
        }
        let id = centres.len() as u32;
        centres.push(v);
        let c = positions[v as usize].as_dvec3();
        // The buckets the cube [c − half, c + half] overlaps, with a hair of margin for rounding.
        let rel = (c - origin) * inv;
        let lo = (rel - DVec3::splat(0.5 + 1e-9)).floor();
        let hi = (rel + DVec3::splat(0.5 + 1e-9)).floor();
        let clamp = |x: f64, axis: usize| x.clamp(0.0, (dims[axis] - 1) as f64) as u32;
        for z in clamp(lo.z, 2)..=clamp(hi.z, 2) {
            for y in clamp(lo.y, 1)..=clamp(hi.y, 1) {
                for x in clamp(lo.x, 0)..=clamp(hi.x, 0) {
                    let Some(b) = table.get(buckets.key([x, y, z])) else {
                        continue;
                    };
                    let b = b as usize;
                    let mut i = start[b];
                    while i < live_end[b] {
                        let w = slots[i];
                        let d = (positions[w as usize].as_dvec3() - c).abs();
                        if d.max_element() <= half {
                            cluster_of[w as usize] = id;
                            live_end[b] -= 1;
                            slots.swap(i, live_end[b]);
                        } else {
                            i += 1;
                        }
                    }
                }
            }
        }
        debug_assert_eq!(cluster_of[v as usize], id);
    }
    FloatingClusters {
        cluster_of,
        centres,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn heaviest_vertex_takes_its_neighbourhood() {
        // Points on a line 0.3 apart; vertex 3 is heaviest, then 0.
        let positions: Vec<Vec3> = (0..8)
            .map(|i| Vec3::new(0.3 * i as f32, 0.0, 0.0))
            .collect();
        let weights = [5.0, 1.0, 1.0, 9.0, 1.0, 1.0, 1.0, 1.0];
        let order = heaviest_first(&weights, |_| true);
        assert_eq!(order, vec![3, 0, 1, 2, 4, 5, 6, 7]);
        // Descending total order, ties by index, whatever the signs.
        let w = [0.0, -1.0, 2.5, f32::INFINITY, -0.0, 2.5, 1e-30];
        assert_eq!(heaviest_first(&w, |_| true), vec![3, 2, 5, 6, 0, 4, 1]);
        assert_eq!(heaviest_first(&w, |v| v % 2 == 0), vec![2, 6, 0, 4]);
        let c = floating_cells(&positions, &order, 1.0);
        // The cube of side 1 around x = 0.9 takes 0.6, 0.9 and 1.2 (vertices 2, 3, 4); then
        // vertex 0 takes 0 and 0.3; vertex 5 takes 1.5 and 1.8; 2.1 is 0.6 from 1.5: alone.
        assert_eq!(c.centres, vec![3, 0, 5, 7]);
        assert_eq!(c.cluster_of, vec![1, 1, 0, 0, 0, 2, 2, 3]);
    }
}
