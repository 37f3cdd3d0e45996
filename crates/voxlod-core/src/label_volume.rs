//! A segmentation (label map) as unsigned 32-bit labels, one per voxel, 0 the background.
//!
//! [`crate::Volume`] holds `f32` samples, which are exact integers only up to 2²⁴; label maps of
//! connectomics hold ids up to 2³²−1, so they get a type of their own. The samples are stored x
//! fastest, as the volumes are, and placed by the same [`Grid`] and [`Orientation`].

use crate::error::CoreError;
use crate::memory;
use crate::world::{Orientation, WorldTransform};
use crate::{Grid, Volume};

/// One unsigned 32-bit label per voxel, x fastest; 0 is the background.
#[derive(Clone, Debug, PartialEq)]
pub struct LabelVolume {
    /// Where the voxels sit (their centres are the grid's samples).
    pub grid: Grid,
    /// The labels, x fastest, then y, then z.
    pub values: Vec<u32>,
    /// Direction cosines and anatomical frame (`world.rs`).
    pub orientation: Orientation,
}

impl LabelVolume {
    /// Wraps labels given x fastest; fails if their number does not match the grid.
    pub fn from_vec(grid: Grid, values: Vec<u32>) -> Result<LabelVolume, CoreError> {
        if values.len() != grid.len() {
            let [nx, ny, nz] = grid.dims;
            return Err(CoreError::InvalidGrid(format!(
                "{} labels given for a {nx}x{ny}x{nz} grid ({} voxels)",
                values.len(),
                grid.len()
            )));
        }
        Ok(LabelVolume {
            grid,
            values,
            orientation: Orientation::default(),
        })
    }

    /// The labels of a volume whose samples are all whole numbers in 0..=2³²−1 (the samples
    /// of `f32` are exact up to 2²⁴). Fails naming the first sample that is not: a fraction, a
    /// negative value, NaN or infinity. Asks the memory limit for the copy.
    pub fn from_volume(volume: &Volume) -> Result<LabelVolume, CoreError> {
        memory::check_allocation("the label map", memory::bytes_of::<u32>(volume.grid.len()))?;
        let [nx, ny, _] = volume.grid.dims;
        let mut values = Vec::with_capacity(volume.grid.len());
        for (n, &v) in volume.as_slice().iter().enumerate() {
            if !(v.is_finite() && v.fract() == 0.0 && (0.0..=u32::MAX as f32).contains(&v)) {
                let (i, j, k) = (n % nx, n / nx % ny, n / (nx * ny));
                return Err(CoreError::InvalidGrid(format!(
                    "sample ({i}, {j}, {k}) holds {v}, which is not a label \
                     (a whole number from 0 to 4294967295)"
                )));
            }
            values.push(v as u32);
        }
        Ok(LabelVolume {
            grid: volume.grid,
            values,
            orientation: volume.orientation,
        })
    }

    /// The map placed by `orientation` (direction and frame).
    pub fn oriented(self, orientation: Orientation) -> LabelVolume {
        LabelVolume {
            orientation,
            ..self
        }
    }

    /// The full index-to-world transform.
    pub fn world(&self) -> WorldTransform {
        WorldTransform::of(&self.grid, &self.orientation)
    }

    /// The label at (i, j, k); panics outside the grid.
    #[inline]
    pub fn get(&self, i: usize, j: usize, k: usize) -> u32 {
        let [nx, ny, _] = self.grid.dims;
        self.values[(k * ny + j) * nx + i]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid() -> Grid {
        Grid::new([3, 2, 2], [1.0; 3], [0.0; 3]).unwrap()
    }

    #[test]
    fn labels_are_indexed_x_fastest() {
        let map = LabelVolume::from_vec(grid(), (0..12).collect()).unwrap();
        assert_eq!(map.get(2, 0, 0), 2);
        assert_eq!(map.get(0, 1, 0), 3);
        assert_eq!(map.get(1, 1, 1), 10);
    }

    #[test]
    fn a_count_that_does_not_match_the_grid_is_refused() {
        let error = LabelVolume::from_vec(grid(), vec![0; 11]).unwrap_err();
        assert!(error
            .to_string()
            .contains("11 labels given for a 3x2x2 grid"));
    }

    #[test]
    fn samples_that_are_not_labels_are_named() {
        for (bad, shown) in [(-1.0, "-1"), (2.5, "2.5"), (f32::NAN, "NaN")] {
            let mut values = vec![1.0; 12];
            values[4] = bad;
            let volume = Volume::from_vec(grid(), values).unwrap();
            let error = LabelVolume::from_volume(&volume).unwrap_err().to_string();
            assert!(
                error.contains(&format!("sample (1, 1, 0) holds {shown}")),
                "{error}"
            );
        }
    }
}
