//! The label maps the filtered levels read: a [`LabelVolume`] of `u32` labels (every label
//! exact), or a [`Volume`] of `f32` samples holding whole numbers (labels up to 2²⁴, where
//! `f32` stops being exact, as a scan reader gives a map).

use voxlod_core::{Grid, LabelVolume, Orientation, Volume, WorldTransform};

use super::LabelError;

/// A label map: its grid and placement, and the label of each voxel.
pub trait LabelSource: Sync {
    /// The map's grid.
    fn grid(&self) -> &Grid;
    /// Its direction and frame.
    fn orientation(&self) -> Orientation;
    /// Its index-to-world transform.
    fn world(&self) -> WorldTransform {
        WorldTransform::of(self.grid(), &self.orientation())
    }
    /// The label of voxel (i, j, k), 0 for background; fails on a sample that is no label.
    /// Panics outside the grid.
    fn label(&self, i: usize, j: usize, k: usize) -> Result<i64, LabelError>;
    /// Whether voxel (i, j, k) holds `label` (a value [`LabelSource::label`] gave). Panics
    /// outside the grid.
    fn holds(&self, i: usize, j: usize, k: usize, label: i64) -> bool;
}

impl LabelSource for LabelVolume {
    fn grid(&self) -> &Grid {
        &self.grid
    }

    fn orientation(&self) -> Orientation {
        self.orientation
    }

    #[inline]
    fn label(&self, i: usize, j: usize, k: usize) -> Result<i64, LabelError> {
        Ok(i64::from(self.get(i, j, k)))
    }

    #[inline]
    fn holds(&self, i: usize, j: usize, k: usize, label: i64) -> bool {
        i64::from(self.get(i, j, k)) == label
    }
}

/// Whole `f32` numbers are exact up to this magnitude.
const EXACT: f32 = 16_777_216.0;

impl LabelSource for Volume {
    fn grid(&self) -> &Grid {
        &self.grid
    }

    fn orientation(&self) -> Orientation {
        self.orientation
    }

    #[inline]
    fn label(&self, i: usize, j: usize, k: usize) -> Result<i64, LabelError> {
        let v = self.get(i, j, k);
        if !v.is_finite() || v.fract() != 0.0 || v.abs() > EXACT {
            return Err(LabelError::NotALabel(i, j, k, v));
        }
        Ok(v as i64)
    }

    #[inline]
    fn holds(&self, i: usize, j: usize, k: usize, label: i64) -> bool {
        self.get(i, j, k) == label as f32
    }
}
