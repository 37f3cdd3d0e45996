//! The blockwise threshold route gives the dense route's samples (to the f64 residue of the
//! dense rows' running sums, ~1e-16, far from any iso value): a generated gyroid
//! scan, thresholded, sampled block by block from windows of it, against `filtered_density` of
//! the whole scan's `ThresholdSolid`, at several resolutions (level spacing unlike the scan's),
//! both filters and both brick sides, with blocks small enough that every sample's filter
//! reaches across block faces.

use std::convert::Infallible;

use voxlod_core::{Grid, Volume};
use voxlod_sampling::narrow_band::NarrowBandOptions;
use voxlod_sampling::{
    blockwise_threshold_density, filtered_density, level_grid, BlockwiseThreshold, DensityOptions,
    Filter, ThresholdSolid,
};
use voxlod_testkit::volumes::window;

/// A gyroid of period `period` samples as u8-like values 48..208, on an `n`³ grid of spacing
/// `spacing` (so that the level grids never align with the scan's samples).
fn gyroid_scan(n: usize, period: f64, spacing: f64) -> Volume {
    let grid = Grid::new([n, n, n - 3], [spacing; 3], [-1.5, 2.0, 0.25]).unwrap();
    let k = 2.0 * std::f64::consts::PI / period;
    let mut values = Vec::with_capacity(grid.len());
    for z in 0..grid.dims[2] {
        for y in 0..n {
            for x in 0..n {
                let (x, y, z) = (x as f64 * k, y as f64 * k, z as f64 * k);
                let g = x.sin() * y.cos() + y.sin() * z.cos() + z.sin() * x.cos();
                values.push((128.0 + 80.0 * g).round() as f32);
            }
        }
    }
    Volume::from_vec(grid, values).unwrap()
}

/// Samples one level both ways and compares every sample's bits; returns the band's leaves.
fn compare(
    scan: &Volume,
    threshold: f32,
    resolution: usize,
    filter: Filter,
    brick: usize,
    block: usize,
) -> usize {
    let solid = ThresholdSolid::new(scan, threshold).unwrap();
    let voxel = scan.grid.bounds().longest_extent() / resolution as f64;
    let radius = voxel
        * if filter == Filter::Hypercone {
            1.0
        } else {
            1.5
        };
    let grid = level_grid(&scan.grid.bounds(), resolution, radius).unwrap();
    let options = DensityOptions::new(filter, radius);
    let (dense, _) = filtered_density(&solid, &grid, &options).unwrap();
    let band = NarrowBandOptions { brick_size: brick };
    let mut level = BlockwiseThreshold::new(scan.grid, threshold, &grid, &options, &band).unwrap();
    level.block_side = block;
    let read = |start, extent| Ok::<_, Infallible>(window(scan, start, extent));
    // Block by block from windows, and from the whole scan read once: the same bits.
    level.whole_scan_above = f64::INFINITY;
    let (bricks, report, band) = blockwise_threshold_density(&level, &read).unwrap();
    level.whole_scan_above = 0.0;
    let (whole, whole_report, whole_band) = blockwise_threshold_density(&level, &read).unwrap();
    assert_eq!(whole_band, band);
    assert!(whole_report.crossings > 0);
    assert_eq!(whole.to_volume().unwrap().as_slice().len(), grid.len());
    for (x, y) in whole
        .to_volume()
        .unwrap()
        .as_slice()
        .iter()
        .zip(bricks.to_volume().unwrap().as_slice())
    {
        assert_eq!(x.to_bits(), y.to_bits(), "whole scan against windows");
    }
    let blocks: usize = level.block_dims().iter().product();
    assert!(
        blocks >= 8,
        "{blocks} blocks: the test must cross block faces"
    );
    let [nx, ny, nz] = grid.dims;
    let mut differing = 0;
    let mut worst = 0.0f32;
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let (x, y) = (bricks.get(i, j, k), dense.get(i, j, k));
                if x.to_bits() != y.to_bits() {
                    differing += 1;
                    worst = worst.max((x - y).abs());
                }
            }
        }
    }
    // Per block, the difference array of a row starts at the block's first sample rather than
    // the grid's, so a span that ended before the block leaves no f64 residue (`full - full`
    // interleaved with other lines' terms) as it does in the dense row: values that are 0 in
    // one route can be ~1e-16 in the other. Nothing else may differ.
    assert!(
        worst <= 1e-12,
        "resolution {resolution}, {filter:?}, bricks {brick}, blocks {block}: {differing} samples differ, by up to {worst:e}"
    );
    assert!(report.crossings > 0);
    assert!(band.band_bricks > 0, "{band:?}");
    band.band_bricks
}

#[test]
fn blockwise_threshold_matches_the_dense_route() {
    let scan = gyroid_scan(40, 23.0, 0.7);
    // The level about as fine as the scan, and coarser; hyper-cone and Gaussian.
    compare(&scan, 128.0, 40, Filter::Hypercone, 8, 8);
    compare(&scan, 140.5, 40, Filter::GAUSSIAN, 16, 16);
    compare(&scan, 128.0, 24, Filter::Hypercone, 8, 8);
}

#[test]
fn blockwise_threshold_matches_the_dense_route_on_a_level_finer_than_the_scan() {
    let scan = gyroid_scan(40, 23.0, 0.7);
    compare(&scan, 128.0, 56, Filter::Hypercone, 8, 16);
}

#[test]
fn far_from_the_surface_bricks_are_single_values() {
    // A slab that is inside for z below the middle: most bricks are all 0 or all 1.
    let grid = Grid::new([48, 48, 48], [1.0; 3], [0.0; 3]).unwrap();
    let values = (0..grid.len())
        .map(|n| if n / (48 * 48) < 24 { 200.0 } else { 0.0 })
        .collect();
    let scan = Volume::from_vec(grid, values).unwrap();
    let leaves = compare(&scan, 100.0, 48, Filter::Hypercone, 8, 16);
    // The surface (z = 23.5) crosses one layer of bricks, and the box's faces a shell of them.
    let bricks_per_layer = 7 * 7;
    assert!(
        leaves >= bricks_per_layer && leaves < 7 * 7 * 7 / 2,
        "{leaves} leaves"
    );
}

#[test]
fn blocks_answered_without_the_density_pass_hold_what_the_pass_gives() {
    // Inside (200) for x below 24, outside (0) above: blocks far on either side have windows
    // without a crossing.
    let grid = Grid::new([48, 48, 48], [1.0; 3], [0.0; 3]).unwrap();
    let values = (0..grid.len())
        .map(|n| if n % 48 < 24 { 200.0 } else { 0.0 })
        .collect();
    let scan = Volume::from_vec(grid, values).unwrap();
    let level_grid = level_grid(&scan.grid.bounds(), 48, 1.0).unwrap();
    let options = DensityOptions::new(Filter::Hypercone, 1.0);
    let band = NarrowBandOptions { brick_size: 8 };
    let mut level =
        BlockwiseThreshold::new(scan.grid, 100.0, &level_grid, &options, &band).unwrap();
    level.block_side = 8;
    let [bx, by, bz] = level.block_dims();
    let (mut answered, mut refused_inside, mut below_one) = ([0, 0], 0, 0);
    for block in (0..bx * by * bz).map(|i| [i % bx, (i / bx) % by, i / (bx * by)]) {
        let (start, extent) = level.scan_window(block);
        let window = window(&scan, start, extent);
        let (low, high) = window.range().unwrap();
        let (filled, _) = level.fill_block(block, &window);
        match level.uniform_value(block, low, high) {
            Some(value) => {
                assert_eq!(
                    level
                        .uniform_block(block, value)
                        .iter()
                        .map(|b| (b.index, b.value.to_bits()))
                        .collect::<Vec<_>>(),
                    filled
                        .iter()
                        .map(|b| (b.index, b.value.to_bits()))
                        .collect::<Vec<_>>(),
                    "block {block:?}"
                );
                assert!(filled.iter().all(|b| b.leaf.is_none()), "block {block:?}");
                answered[(value == 1.0) as usize] += 1;
            }
            // A window inside everywhere but cut by the scan's edge: the filter may reach beyond
            // the scan, where the solid is outside, and the pass find values below 1.
            None if low >= 100.0 => {
                refused_inside += 1;
                below_one += filled.iter().any(|b| b.leaf.is_some() || b.value != 1.0) as usize;
            }
            None => assert!(low < 100.0 && high >= 100.0),
        }
    }
    assert!(
        answered[0] > 0 && answered[1] > 0 && below_one > 0,
        "{answered:?} {refused_inside} {below_one}"
    );
}
