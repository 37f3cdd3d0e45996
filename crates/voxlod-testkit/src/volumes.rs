//! Small volumes made in code.

use voxlod_core::{Grid, Volume};

/// A 5×4×3 volume with distinct values, uneven spacing and an offset origin.
pub fn small_volume() -> Volume {
    let grid = Grid::new([5, 4, 3], [0.5, 1.40625, 2.5], [-90.0, 12.25, 3.5]).unwrap();
    let values = (0..60).map(|i| i as f32 * 1.5 - 7.0).collect();
    Volume::from_vec(grid, values).unwrap()
}

/// The CT head of the shared data (256 × 256 × 113, big-endian `u16`, spacing 1, 1, 2), or
/// `None` with a printed reason when it is absent.
pub fn shared_ct_head(test: &str) -> Option<Volume> {
    let relative = "volumes/CThead_256x256x113_uint16be.raw";
    let path = crate::data::shared_data_or_skip(relative, test)?;
    let bytes = std::fs::read(path).expect("the CT head is readable");
    let values = bytes
        .chunks_exact(2)
        .map(|b| u16::from_be_bytes([b[0], b[1]]) as f32)
        .collect();
    let grid = voxlod_core::Grid::new([256, 256, 113], [1.0, 1.0, 2.0], [0.0; 3]).ok()?;
    Volume::from_vec(grid, values).ok()
}

/// The samples `start .. start + extent` (x, y, z indices) of `scan` as a volume of their own,
/// placed where they sit in `scan`: what a blockwise reader returns for that window.
pub fn window(scan: &Volume, start: [usize; 3], extent: [usize; 3]) -> Volume {
    let s = &scan.grid;
    let origin = [0, 1, 2].map(|a| s.origin[a] + start[a] as f64 * s.spacing[a]);
    let grid = Grid::new(extent, s.spacing, origin).unwrap();
    let mut values = Vec::with_capacity(grid.len());
    for k in 0..extent[2] {
        for j in 0..extent[1] {
            values
                .extend((0..extent[0]).map(|i| scan.get(start[0] + i, start[1] + j, start[2] + k)));
        }
    }
    Volume::from_vec(grid, values).unwrap()
}
