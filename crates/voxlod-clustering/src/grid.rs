//! The uniform clustering grid of Rossignac–Borrel §3.3: a box cut into cubic cells.
//!
//! "A box, or other bound, containing the object is uniformly subdivided into cells"; the
//! procedure takes "the box in which the clustering should occur and the maximum number of cells
//! along each dimension". We read that maximum as the count along the box's longest side and
//! make the cells cubes (as Open3D, VTK and meshoptimizer do), so one length, the cell size,
//! describes a level: what the model selection of Low–Tan compares with the size of a pixel.
//! The shorter sides get as many cells as they need to be covered, at least one.
//!
//! Cells are found by truncating coordinates, `floor((p − origin) / size)`, clamped into the
//! grid: a vertex on the box's far faces belongs to the last cell, and a vertex outside a box
//! given by the caller (a scene box that does not contain it) to the nearest border cell.
//!
//! Coarser grids for the octree of §4 double the cell size from the same origin. Their cells are
//! exactly the parents `c >> 1` of the finer cells, and the same as a fresh grid of `cells / 2`
//! cells over the same box when `cells` is even: doubling a float is exact, so both routes
//! truncate the same products.
//!
//! Cost: O(1) per vertex to find its cell. The cell table of a level is a flat array when the
//! grid has few cells for its occupied ones (at most 8 per occupied cell, or 2¹⁶, and never
//! beyond 2²⁴) and a hash map otherwise, so memory follows the occupied cells, not the grid.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

use glam::{DVec3, Vec3};
use serde::Serialize;
use voxlod_core::Bounds;

use crate::ClusteringError;

/// Largest number of cells along an axis (cell keys then fit 60 bits).
pub const MAX_CELLS: u32 = 1 << 20;

/// A grid of cubic cells: `dims` cells per axis of side `cell_size`, the first at `origin`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ClusterGrid {
    /// The lower corner of the first cell, in the mesh's units.
    pub origin: [f64; 3],
    /// Side of a cell, in the mesh's units.
    pub cell_size: f64,
    /// Cells per axis.
    pub dims: [u32; 3],
}

impl ClusterGrid {
    /// `cells` cubic cells along the longest side of `bounds`.
    pub fn new(bounds: &Bounds, cells: u32) -> Result<ClusterGrid, ClusteringError> {
        check_cells(cells)?;
        check_bounds(bounds)?;
        let size = bounds.size();
        let extent = size.max_element();
        let cell_size = if extent > 0.0 {
            extent / cells as f64
        } else {
            1.0
        };
        let longest = size.max_position();
        let mut dims = [1u32; 3];
        for (axis, d) in dims.iter_mut().enumerate() {
            *d = if extent == 0.0 {
                1
            } else if axis == longest {
                cells
            } else {
                ((size[axis] / cell_size).ceil() as u32).clamp(1, cells)
            };
        }
        Ok(ClusterGrid {
            origin: bounds.min.to_array(),
            cell_size,
            dims,
        })
    }

    /// The grid whose cells are `2^steps` times larger, from the same origin: level `steps` of
    /// the octree over this grid.
    pub fn coarsened(&self, steps: u32) -> ClusterGrid {
        let scale = (1u64 << steps) as f64;
        ClusterGrid {
            origin: self.origin,
            cell_size: self.cell_size * scale,
            dims: self.dims.map(|d| d.div_ceil(1 << steps).max(1)),
        }
    }

    /// Cells per axis along the longest side.
    pub fn cells(&self) -> u32 {
        self.dims.into_iter().max().unwrap_or(1)
    }

    /// Cells in the whole grid.
    pub fn cell_count(&self) -> u64 {
        self.dims.iter().map(|&d| d as u64).product()
    }

    /// The cell holding `p`, clamped into the grid.
    #[inline]
    pub fn cell_of(&self, p: Vec3) -> [u32; 3] {
        let inv = 1.0 / self.cell_size;
        let rel = (p.as_dvec3() - DVec3::from_array(self.origin)) * inv;
        let mut c = [0u32; 3];
        for axis in 0..3 {
            let f = rel[axis].floor();
            let top = (self.dims[axis] - 1) as f64;
            c[axis] = f.clamp(0.0, top) as u32;
        }
        c
    }

    /// A unique integer per cell, x fastest.
    #[inline]
    pub fn key(&self, c: [u32; 3]) -> u64 {
        c[0] as u64 + self.dims[0] as u64 * (c[1] as u64 + self.dims[1] as u64 * c[2] as u64)
    }

    /// The box covered by the grid's cells (it may reach past the clustering box).
    pub fn bounds(&self) -> Bounds {
        let min = DVec3::from_array(self.origin);
        let dims = DVec3::new(
            self.dims[0] as f64,
            self.dims[1] as f64,
            self.dims[2] as f64,
        );
        Bounds::new(min, min + dims * self.cell_size)
    }
}

/// Cluster ids of occupied cells: a flat array over the whole grid when it is small (a 64³ grid
/// is 1 MiB), a hash map of the occupied cells otherwise.
pub(crate) enum CellTable {
    Dense(Vec<u32>),
    Sparse(HashMap<u64, u32, BuildHasherDefault<KeyHasher>>),
}

impl CellTable {
    /// A table for a grid of `cell_count` cells of which at most `occupied` are used.
    pub fn new(cell_count: u64, occupied: usize) -> CellTable {
        let dense_limit = (8 * occupied as u64).clamp(1 << 16, 1 << 24);
        if cell_count <= dense_limit {
            CellTable::Dense(vec![u32::MAX; cell_count as usize])
        } else {
            CellTable::Sparse(HashMap::with_capacity_and_hasher(
                occupied.min(1 << 20),
                Default::default(),
            ))
        }
    }

    /// The id stored for `key`, if any.
    #[inline]
    pub fn get(&self, key: u64) -> Option<u32> {
        match self {
            CellTable::Dense(v) => Some(v[key as usize]).filter(|&id| id != u32::MAX),
            CellTable::Sparse(m) => m.get(&key).copied(),
        }
    }

    /// The id stored for `key`, or `next` after storing it; the flag says whether it is new.
    #[inline]
    pub fn get_or_insert(&mut self, key: u64, next: u32) -> (u32, bool) {
        match self {
            CellTable::Dense(v) => {
                let slot = &mut v[key as usize];
                if *slot == u32::MAX {
                    *slot = next;
                    (next, true)
                } else {
                    (*slot, false)
                }
            }
            CellTable::Sparse(m) => {
                let id = *m.entry(key).or_insert(next);
                (id, id == next)
            }
        }
    }
}

/// A multiplicative hash for integer cell keys (the standard SipHash is needlessly slow here).
#[derive(Default)]
pub(crate) struct KeyHasher(u64);

impl Hasher for KeyHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(b as u64);
        }
    }
    #[inline]
    fn write_u64(&mut self, k: u64) {
        let h = (self.0 ^ k).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        self.0 = h ^ (h >> 29);
    }
}

pub(crate) fn check_cells(cells: u32) -> Result<(), ClusteringError> {
    if cells == 0 {
        return Err(ClusteringError::ZeroCells);
    }
    if cells > MAX_CELLS {
        return Err(ClusteringError::TooManyCells {
            cells,
            max: MAX_CELLS,
        });
    }
    Ok(())
}

/// How many levels a series starting at `cells` cells can have before the longest axis holds a
/// single cell: `1 + ceil(log2(cells))`.
pub fn max_levels(cells: u32) -> u32 {
    1 + (32 - (cells.max(1) - 1).leading_zeros())
}

pub(crate) fn check_levels(levels: u32, cells: u32) -> Result<(), ClusteringError> {
    if levels == 0 {
        return Err(ClusteringError::ZeroLevels);
    }
    let max = max_levels(cells);
    if levels > max {
        return Err(ClusteringError::TooManyLevels { levels, cells, max });
    }
    Ok(())
}

pub(crate) fn check_bounds(b: &Bounds) -> Result<(), ClusteringError> {
    if b.is_empty() || !b.min.is_finite() || !b.max.is_finite() {
        return Err(ClusteringError::InvalidBounds {
            min: b.min.to_array(),
            max: b.max.to_array(),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cubic_cells_along_the_longest_side() {
        let b = Bounds::new(DVec3::ZERO, DVec3::new(4.0, 1.0, 2.5));
        let g = ClusterGrid::new(&b, 8).unwrap();
        assert_eq!(g.cell_size, 0.5);
        assert_eq!(g.dims, [8, 2, 5]);
        assert_eq!(g.cell_of(Vec3::new(4.0, 1.0, 2.5)), [7, 1, 4]);
        assert_eq!(g.cell_of(Vec3::new(-3.0, 0.49, 0.5)), [0, 0, 1]);
        assert_eq!(g.cell_of(Vec3::new(99.0, 0.5, 0.0)), [7, 1, 0]);
        let c = g.coarsened(1);
        assert_eq!((c.cell_size, c.dims), (1.0, [4, 1, 3]));
        assert_eq!(c, ClusterGrid::new(&b, 4).unwrap());
    }

    #[test]
    fn coarsening_is_the_parent_cell() {
        let b = Bounds::new(DVec3::new(-1.3, 0.2, 5.0), DVec3::new(2.9, 1.7, 6.1));
        let fine = ClusterGrid::new(&b, 64).unwrap();
        let coarse = ClusterGrid::new(&b, 16).unwrap();
        assert_eq!(coarse.cell_size, fine.coarsened(2).cell_size);
        let mut x = 0.123456f32;
        for _ in 0..10_000 {
            // A cheap deterministic scatter over the box.
            x = (x * 997.0 + 0.2718).fract();
            let y = (x * 131.0).fract();
            let z = (y * 71.0).fract();
            let p = b.min.as_vec3() + Vec3::new(x, y, z) * b.size().as_vec3();
            let f = fine.cell_of(p);
            assert_eq!(coarse.cell_of(p), f.map(|c| c >> 2), "{p}");
            assert_eq!(fine.coarsened(2).cell_of(p), f.map(|c| c >> 2), "{p}");
        }
    }

    #[test]
    fn level_limits() {
        assert_eq!(max_levels(1), 1);
        assert_eq!(max_levels(2), 2);
        assert_eq!(max_levels(64), 7);
        assert_eq!(max_levels(65), 8);
        assert!(check_levels(7, 64).is_ok());
        assert!(check_levels(8, 64).is_err());
        assert!(check_levels(0, 64).is_err());
    }

    #[test]
    fn a_single_point_is_one_cell() {
        let b = Bounds::new(DVec3::ONE, DVec3::ONE);
        let g = ClusterGrid::new(&b, 16).unwrap();
        assert_eq!(g.dims, [1, 1, 1]);
        assert_eq!(g.cell_of(Vec3::ONE), [0, 0, 0]);
    }
}
