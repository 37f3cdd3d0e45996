//! The shared surface smoothed block by block (the route of `voxlod.dask.labels` with
//! `shared`): each block meshed with a margin, the restoring's sums of the blocks added and its
//! pressures solved once for the whole map, then each block smoothed with those pressures. Its
//! inner vertices must land where the whole map puts them, bit for bit.

use std::collections::HashMap;

use voxlod_core::glam::Vec3;
use voxlod_core::{Grid, LabelVolume};
use voxlod_labels::smoothing::{
    restoring_pressure, restoring_sums, smooth, Owned, PairSums, Pressure, RestoringSums,
    SmoothingOptions,
};
use voxlod_labels::surface_nets::{surface_nets, SharedSurface, SurfaceNetsOptions};

const DIMS: [usize; 3] = [34, 30, 26];
const SPACING: [f64; 3] = [1.0, 0.8, 1.3];
const ORIGIN: [f64; 3] = [2.0, -3.0, 0.5];

/// Twelve labels: a Voronoi partition of scattered sites, cut to a ball (background outside), so
/// that labels meet each other, the background and the map's border.
fn map() -> LabelVolume {
    // Sites scattered by the multiples of irrational steps, modulo 1, per axis.
    let sites: Vec<[f64; 3]> = (1..=12)
        .map(|n| {
            let u = |a: usize| (n as f64 * [0.618_034, 0.754_878, 0.569_840][a]).fract();
            [0, 1, 2].map(|a| u(a) * DIMS[a] as f64)
        })
        .collect();
    let mut values = Vec::new();
    for k in 0..DIMS[2] {
        for j in 0..DIMS[1] {
            for i in 0..DIMS[0] {
                let p = [i, j, k].map(|c| c as f64 + 0.5);
                let centre: f64 = (0..3).map(|a| (p[a] - DIMS[a] as f64 / 2.0).powi(2)).sum();
                if centre > (0.62 * DIMS[0] as f64).powi(2) {
                    values.push(0);
                    continue;
                }
                let d = |s: &[f64; 3]| (0..3).map(|a| (p[a] - s[a]).powi(2)).sum::<f64>();
                let nearest = (0..sites.len())
                    .min_by(|&a, &b| d(&sites[a]).total_cmp(&d(&sites[b])))
                    .unwrap();
                values.push(nearest as u32 + 1);
            }
        }
    }
    LabelVolume::from_vec(Grid::new(DIMS, SPACING, ORIGIN).unwrap(), values).unwrap()
}

/// The samples `lo..hi` of `whole` as a map of their own, with the whole map's origin (its
/// place given by the nets' offset).
fn cut(whole: &LabelVolume, lo: [usize; 3], hi: [usize; 3]) -> LabelVolume {
    let dims = [0, 1, 2].map(|a| hi[a] - lo[a]);
    let mut values = Vec::new();
    for k in lo[2]..hi[2] {
        for j in lo[1]..hi[1] {
            let row = (k * DIMS[1] + j) * DIMS[0];
            values.extend_from_slice(&whole.values[row + lo[0]..row + hi[0]]);
        }
    }
    LabelVolume::from_vec(Grid::new(dims, SPACING, ORIGIN).unwrap(), values).unwrap()
}

/// Blocks of `side` voxels: per block the corners it owns and its samples grown by `margin`.
fn blocks(side: usize, margin: usize) -> Vec<(Owned, [usize; 3], [usize; 3])> {
    let starts = |a: usize| (0..DIMS[a]).step_by(side).collect::<Vec<_>>();
    let mut out = Vec::new();
    for &z in &starts(2) {
        for &y in &starts(1) {
            for &x in &starts(0) {
                let start = [x, y, z];
                let end = [0, 1, 2].map(|a| (start[a] + side).min(DIMS[a]));
                // The last block along an axis owns the last corner plane too.
                let own_hi = [0, 1, 2].map(|a| end[a] as u32 + (end[a] == DIMS[a]) as u32);
                let owned = Owned {
                    lo: start.map(|s| s as u32),
                    hi: own_hi,
                };
                let lo = start.map(|s| s.saturating_sub(margin));
                let hi = [0, 1, 2].map(|a| (end[a] + margin).min(DIMS[a]));
                out.push((owned, lo, hi));
            }
        }
    }
    out
}

fn nets_of(map: &LabelVolume, lo: [usize; 3]) -> SharedSurface {
    let options = SurfaceNetsOptions {
        offset: lo.map(|c| c as u32),
        ..SurfaceNetsOptions::default()
    };
    surface_nets(map, &options).unwrap()
}

/// The pressures solved from the blocks' sums, round after round, as the whole map would.
fn blockwise_pressures(
    whole: &LabelVolume,
    options: &SmoothingOptions,
    margin: usize,
) -> Vec<Pressure> {
    let mut pressures = Vec::new();
    for _ in 0..options.restore_rounds {
        let given = SmoothingOptions {
            pressures: Some(pressures.clone()),
            ..options.clone()
        };
        let sums: Vec<RestoringSums> = blocks(11, margin)
            .into_iter()
            .map(|(owned, lo, hi)| {
                let mut surface = nets_of(&cut(whole, lo, hi), lo);
                restoring_sums(&mut surface, &given, owned).unwrap()
            })
            .collect();
        let merged = RestoringSums {
            before: PairSums::merged(sums.iter().map(|s| s.before.clone())),
            volumes: PairSums::merged(sums.iter().map(|s| s.volumes.clone())),
            weights: PairSums::merged(sums.iter().map(|s| s.weights.clone())),
        };
        match restoring_pressure(&merged, options) {
            Some(p) => pressures.push(p),
            None => break,
        }
    }
    pressures
}

/// The whole map's smoothed positions by corner.
fn whole_positions(
    whole: &LabelVolume,
    options: &SmoothingOptions,
) -> (HashMap<[u32; 3], Vec3>, usize) {
    let mut surface = nets_of(whole, [0; 3]);
    let report = smooth(&mut surface, options).unwrap();
    let at = surface
        .corners
        .iter()
        .copied()
        .zip(surface.positions.iter().copied());
    (at.collect(), report.restore_rounds)
}

#[test]
fn blocks_with_the_whole_maps_pressures_smooth_as_the_whole_map() {
    let whole = map();
    let options = SmoothingOptions {
        iterations: 3,
        ..SmoothingOptions::default()
    };
    let margin = 2 * options.iterations + 3 + options.restore_rounds;
    let (positions, rounds) = whole_positions(&whole, &options);
    let pressures = blockwise_pressures(&whole, &options, margin);
    assert!(rounds >= 1, "the map's volumes need restoring");
    assert_eq!(pressures.len(), rounds);
    let given = SmoothingOptions {
        pressures: Some(pressures),
        ..options.clone()
    };
    let mut checked = 0;
    for (owned, lo, hi) in blocks(11, margin) {
        let mut surface = nets_of(&cut(&whole, lo, hi), lo);
        smooth(&mut surface, &given).unwrap();
        for (c, p) in surface.corners.iter().zip(&surface.positions) {
            let global = [0, 1, 2].map(|a| c[a] + lo[a] as u32);
            if (0..3).all(|a| (owned.lo[a]..owned.hi[a]).contains(&global[a])) {
                assert_eq!(*p, positions[&global], "corner {global:?}");
                checked += 1;
            }
        }
    }
    assert_eq!(checked, positions.len());
}

#[test]
fn a_block_without_its_margin_does_not() {
    // The margin matters: with one voxel, inner vertices are moved by the block's own border.
    let whole = map();
    let options = SmoothingOptions {
        iterations: 3,
        keep_volume: false,
        ..SmoothingOptions::default()
    };
    let (positions, _) = whole_positions(&whole, &options);
    let mut differ = 0;
    for (owned, lo, hi) in blocks(11, 1) {
        let mut surface = nets_of(&cut(&whole, lo, hi), lo);
        smooth(&mut surface, &options).unwrap();
        for (c, p) in surface.corners.iter().zip(&surface.positions) {
            let global = [0, 1, 2].map(|a| c[a] + lo[a] as u32);
            let inside = (0..3).all(|a| (owned.lo[a]..owned.hi[a]).contains(&global[a]));
            differ += (inside && *p != positions[&global]) as usize;
        }
    }
    assert!(differ > 100, "{differ} vertices moved otherwise");
}
