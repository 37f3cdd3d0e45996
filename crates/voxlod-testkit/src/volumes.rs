//! Small volumes made in code.

use voxlod_core::{Grid, Volume};

/// A 5×4×3 volume with distinct values, uneven spacing and an offset origin.
pub fn small_volume() -> Volume {
    let grid = Grid::new([5, 4, 3], [0.5, 1.40625, 2.5], [-90.0, 12.25, 3.5]).unwrap();
    let values = (0..60).map(|i| i as f32 * 1.5 - 7.0).collect();
    Volume::from_vec(grid, values).unwrap()
}
