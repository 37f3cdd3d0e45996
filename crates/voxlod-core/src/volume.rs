//! [`Volume`]: a scalar field on a [`Grid`], the input (a scan) and output (a filtered density,
//! paper §2 equation 1) of sampling, and the input of marching cubes. Memory: 4 bytes per
//! sample, checked against the budget before allocating; trilinear lookups cost O(1).

use ndarray::Array3;

use crate::{memory, CoreError, Grid, Orientation, WorldTransform};

/// A scalar field sampled on a [`Grid`]: one `f32` per sample, stored in an ndarray of shape
/// `(nz, ny, nx)` so that x varies fastest in memory, as in NRRD, VTK and raw CT files.
/// `orientation` turns the axis-aligned grid into the patient's world (`world.rs`); the
/// default, identity in an unknown frame, is what formats without orientation give.
#[derive(Clone, Debug, PartialEq)]
pub struct Volume {
    /// Where the samples sit.
    pub grid: Grid,
    /// The samples, indexed `[k, j, i]` (z, y, x).
    pub values: Array3<f32>,
    /// Direction cosines and anatomical frame (`world.rs`).
    pub orientation: Orientation,
}

impl Volume {
    /// A volume of `value` everywhere, after checking that it fits in memory.
    pub fn filled(grid: Grid, value: f32, what: &str) -> Result<Volume, CoreError> {
        memory::check_allocation(what, memory::bytes_of::<f32>(grid.len()))?;
        let mut values: Vec<f32> = memory::zeroed_vec(grid.len());
        if value != 0.0 {
            values.fill(value);
        }
        Volume::from_vec(grid, values)
    }

    /// Wraps samples given x fastest; fails if their number does not match the grid.
    pub fn from_vec(grid: Grid, values: Vec<f32>) -> Result<Volume, CoreError> {
        let [nx, ny, nz] = grid.dims;
        if values.len() != grid.len() {
            return Err(CoreError::InvalidGrid(format!(
                "{} samples given for a {}x{}x{} grid ({} samples)",
                values.len(),
                nx,
                ny,
                nz,
                grid.len()
            )));
        }
        let values = Array3::from_shape_vec((nz, ny, nx), values)
            .map_err(|e| CoreError::InvalidGrid(e.to_string()))?;
        Ok(Volume {
            grid,
            values,
            orientation: Orientation::default(),
        })
    }

    /// The volume placed by `orientation` (direction and frame).
    pub fn oriented(self, orientation: Orientation) -> Volume {
        Volume {
            orientation,
            ..self
        }
    }

    /// The full index-to-world transform.
    pub fn world(&self) -> WorldTransform {
        WorldTransform::of(&self.grid, &self.orientation)
    }

    /// The samples as one slice, x fastest.
    pub fn as_slice(&self) -> &[f32] {
        self.values
            .as_slice()
            .expect("volumes are always stored in standard layout")
    }

    /// The samples as one mutable slice, x fastest.
    pub fn as_slice_mut(&mut self) -> &mut [f32] {
        self.values
            .as_slice_mut()
            .expect("volumes are always stored in standard layout")
    }

    /// The sample at (i, j, k); panics outside the grid.
    #[inline]
    pub fn get(&self, i: usize, j: usize, k: usize) -> f32 {
        self.values[[k, j, i]]
    }

    /// Smallest and largest finite sample, or `None` if there is none.
    pub fn range(&self) -> Option<(f32, f32)> {
        let (lo, hi) = self
            .as_slice()
            .iter()
            .filter(|v| v.is_finite())
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &v| {
                (lo.min(v), hi.max(v))
            });
        (lo <= hi).then_some((lo, hi))
    }

    /// Trilinear interpolation at fractional sample coordinates, clamped to the grid.
    pub fn sample_trilinear(&self, x: f64, y: f64, z: f64) -> f32 {
        let [nx, ny, nz] = self.grid.dims;
        let split = |c: f64, n: usize| -> (usize, usize, f32) {
            let c = c.clamp(0.0, (n - 1) as f64);
            let i0 = (c.floor() as usize).min(n - 1);
            let i1 = (i0 + 1).min(n - 1);
            (i0, i1, (c - i0 as f64) as f32)
        };
        let (x0, x1, fx) = split(x, nx);
        let (y0, y1, fy) = split(y, ny);
        let (z0, z1, fz) = split(z, nz);
        let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
        let v = |i, j, k| self.get(i, j, k);
        let c00 = lerp(v(x0, y0, z0), v(x1, y0, z0), fx);
        let c10 = lerp(v(x0, y1, z0), v(x1, y1, z0), fx);
        let c01 = lerp(v(x0, y0, z1), v(x1, y0, z1), fx);
        let c11 = lerp(v(x0, y1, z1), v(x1, y1, z1), fx);
        lerp(lerp(c00, c10, fy), lerp(c01, c11, fy), fz)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stores_x_fastest() {
        let g = Grid::unit([3, 2, 2]).unwrap();
        let v = Volume::from_vec(g, (0..12).map(|i| i as f32).collect()).unwrap();
        assert_eq!(v.get(1, 0, 0), 1.0);
        assert_eq!(v.get(0, 1, 0), 3.0);
        assert_eq!(v.get(2, 1, 1), 11.0);
        assert_eq!(v.range(), Some((0.0, 11.0)));
        assert!(Volume::from_vec(g, vec![0.0; 11]).is_err());
    }

    #[test]
    fn trilinear_is_exact_for_linear_fields() {
        let g = Grid::unit([4, 4, 4]).unwrap();
        let mut data = Vec::new();
        for k in 0..4 {
            for j in 0..4 {
                for i in 0..4 {
                    data.push((i + 2 * j + 3 * k) as f32);
                }
            }
        }
        let v = Volume::from_vec(g, data).unwrap();
        let got = v.sample_trilinear(1.25, 2.5, 0.75);
        assert!((got - (1.25 + 5.0 + 2.25)).abs() < 1e-5);
        // clamped outside
        assert_eq!(v.sample_trilinear(-3.0, 0.0, 0.0), 0.0);
    }
}
