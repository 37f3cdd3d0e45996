//! The regular lattice every volume lives on: [`Grid`] (dimensions, spacing and origin in world
//! units, millimetres for a CT) and [`Axis`]. The voxel paper (§2) samples each level of detail
//! on such a grid, its spacing set by the level's resolution. Cost: O(1) per operation.

use glam::DVec3;
use serde::Serialize;

use crate::{Bounds, CoreError};

/// One of the three coordinate axes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
pub enum Axis {
    /// The x axis; samples along it are adjacent in memory.
    X = 0,
    /// The y axis.
    Y = 1,
    /// The z axis (slices of a scan).
    Z = 2,
}

impl Axis {
    /// The three axes in order x, y, z.
    pub const ALL: [Axis; 3] = [Axis::X, Axis::Y, Axis::Z];

    /// 0, 1 or 2: the axis as an index into `[x, y, z]` arrays.
    pub fn index(self) -> usize {
        self as usize
    }

    /// The two other axes, in cyclic order: for X that is (Y, Z), for Y (Z, X), for Z (X, Y).
    pub fn others(self) -> (Axis, Axis) {
        match self {
            Axis::X => (Axis::Y, Axis::Z),
            Axis::Y => (Axis::Z, Axis::X),
            Axis::Z => (Axis::X, Axis::Y),
        }
    }
}

/// A regular lattice of sample points: `dims` samples per axis (x varies fastest in storage),
/// `spacing` between neighbours and `origin`, the world position of sample (0, 0, 0).
///
/// Samples sit at `origin + (i, j, k) * spacing`; the grid's cells are the boxes between
/// eight neighbouring samples, so there are `dims - 1` cells per axis.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Grid {
    /// Samples along x, y and z (at least 1 each).
    pub dims: [usize; 3],
    /// Distance between neighbouring samples along x, y and z, in world units.
    pub spacing: [f64; 3],
    /// World position of sample (0, 0, 0).
    pub origin: [f64; 3],
}

impl Grid {
    /// A grid, checked: every dimension at least 1, spacing finite and positive, origin finite.
    pub fn new(dims: [usize; 3], spacing: [f64; 3], origin: [f64; 3]) -> Result<Grid, CoreError> {
        if dims.contains(&0) {
            return Err(CoreError::InvalidGrid(format!(
                "dimensions {}x{}x{} include a zero",
                dims[0], dims[1], dims[2]
            )));
        }
        if spacing.iter().any(|s| !s.is_finite() || *s <= 0.0) {
            return Err(CoreError::InvalidGrid(format!(
                "spacing {:?} must be finite and positive",
                spacing
            )));
        }
        if origin.iter().any(|o| !o.is_finite()) {
            return Err(CoreError::InvalidGrid(format!(
                "origin {:?} must be finite",
                origin
            )));
        }
        dims.iter()
            .try_fold(1usize, |acc, &d| acc.checked_mul(d))
            .ok_or_else(|| {
                CoreError::InvalidGrid(format!(
                    "dimensions {}x{}x{} overflow the address space",
                    dims[0], dims[1], dims[2]
                ))
            })?;
        Ok(Grid {
            dims,
            spacing,
            origin,
        })
    }

    /// A grid with unit spacing at the origin (no checks beyond `new`'s).
    pub fn unit(dims: [usize; 3]) -> Result<Grid, CoreError> {
        Grid::new(dims, [1.0; 3], [0.0; 3])
    }

    /// Number of samples, `nx × ny × nz`.
    pub fn len(&self) -> usize {
        self.dims[0] * self.dims[1] * self.dims[2]
    }

    /// No samples (never true of a grid made by [`Grid::new`]).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Linear index of sample (i, j, k), x fastest.
    #[inline]
    pub fn index(&self, i: usize, j: usize, k: usize) -> usize {
        debug_assert!(i < self.dims[0] && j < self.dims[1] && k < self.dims[2]);
        i + self.dims[0] * (j + self.dims[1] * k)
    }

    /// World position of sample (i, j, k); fractional indices are allowed.
    #[inline]
    pub fn position(&self, i: f64, j: f64, k: f64) -> DVec3 {
        DVec3::new(
            self.origin[0] + i * self.spacing[0],
            self.origin[1] + j * self.spacing[1],
            self.origin[2] + k * self.spacing[2],
        )
    }

    /// The box spanned by the samples.
    pub fn bounds(&self) -> Bounds {
        let max = self.position(
            (self.dims[0] - 1) as f64,
            (self.dims[1] - 1) as f64,
            (self.dims[2] - 1) as f64,
        );
        Bounds::new(DVec3::from(self.origin), max)
    }

    /// [`Grid::spacing`] as a vector.
    pub fn spacing_vec(&self) -> DVec3 {
        DVec3::from(self.spacing)
    }

    /// [`Grid::origin`] as a vector.
    pub fn origin_vec(&self) -> DVec3 {
        DVec3::from(self.origin)
    }

    /// Number of cells (boxes between samples).
    pub fn cell_count(&self) -> usize {
        self.dims.iter().map(|d| d.saturating_sub(1)).product()
    }
}

/// The offsets of a sample's six face neighbours on a grid, `[di, dj, dk]`.
pub const FACE_OFFSETS: [[i64; 3]; 6] = [
    [1, 0, 0],
    [-1, 0, 0],
    [0, 1, 0],
    [0, -1, 0],
    [0, 0, 1],
    [0, 0, -1],
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_bad_grids() {
        assert!(Grid::new([0, 2, 2], [1.0; 3], [0.0; 3]).is_err());
        assert!(Grid::new([2, 2, 2], [1.0, 0.0, 1.0], [0.0; 3]).is_err());
        assert!(Grid::new([2, 2, 2], [1.0, f64::NAN, 1.0], [0.0; 3]).is_err());
        assert!(Grid::new([2, 2, 2], [1.0; 3], [f64::INFINITY, 0.0, 0.0]).is_err());
        assert!(Grid::new([usize::MAX, 2, 2], [1.0; 3], [0.0; 3]).is_err());
    }

    #[test]
    fn indexes_x_fastest_and_positions_samples() {
        let g = Grid::new([4, 3, 2], [0.5, 1.0, 2.0], [1.0, 0.0, -1.0]).unwrap();
        assert_eq!(g.len(), 24);
        assert_eq!(g.index(1, 0, 0), 1);
        assert_eq!(g.index(0, 1, 0), 4);
        assert_eq!(g.index(0, 0, 1), 12);
        assert_eq!(g.position(2.0, 1.0, 1.0), DVec3::new(2.0, 1.0, 1.0));
        assert_eq!(g.bounds().max, DVec3::new(2.5, 2.0, 1.0));
        assert_eq!(g.cell_count(), 3 * 2);
        assert_eq!(Axis::Y.others(), (Axis::Z, Axis::X));
    }
}
