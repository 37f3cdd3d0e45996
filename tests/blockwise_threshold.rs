//! A scan read window by window (`Source::BlockwiseThreshold`, the blockwise threshold route) gives
//! the levels of the same scan held whole (`Source::Threshold`) with the default chain: the
//! genus step included, since a blockwise level small enough for the dense route is made dense
//! for it. On a generated closed gyroid, whose genus the step lowers along the chain.

use voxlod::blockwise::BlockwiseScan;
use voxlod::core::{Grid, Volume};
use voxlod::io::IoError;
use voxlod::sampling::Filter;
use voxlod::{LodOptions, Source};
use voxlod_testkit::volumes::window;

/// A scan held in memory, read window by window.
struct InMemory(Volume);

impl BlockwiseScan for InMemory {
    fn grid(&self) -> Grid {
        self.0.grid
    }

    fn read_window(&self, start: [usize; 3], extent: [usize; 3]) -> Result<Volume, IoError> {
        Ok(window(&self.0, start, extent))
    }
}

/// A gyroid of two periods cut by a ball, as values around 0, on an `n`³ grid.
fn closed_gyroid(n: usize) -> Volume {
    let grid = Grid::new([n; 3], [0.8, 1.0, 1.25], [-2.0, 0.5, 3.0]).unwrap();
    let k = 4.0 * std::f64::consts::PI / (n - 1) as f64;
    let c = (n - 1) as f64 / 2.0;
    let mut values = Vec::with_capacity(grid.len());
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                let (a, b, e) = (x as f64 * k, y as f64 * k, z as f64 * k);
                let g = a.sin() * b.cos() + b.sin() * e.cos() + e.sin() * a.cos();
                let r = [x, y, z]
                    .map(|i| (i as f64 - c).powi(2))
                    .iter()
                    .sum::<f64>();
                let ball = (0.45 * n as f64 - r.sqrt()) / (0.1 * n as f64);
                values.push((1000.0 * g.min(ball)).round() as f32);
            }
        }
    }
    Volume::from_vec(grid, values).unwrap()
}

#[test]
fn a_blockwise_scan_gives_the_levels_of_the_scan_held_whole() {
    let scan = closed_gyroid(150);
    let options = LodOptions::halving(64, 3, Filter::Hypercone);
    let whole = Source::Threshold {
        volume: &scan,
        threshold: 0.0,
    };
    let reader = InMemory(scan.clone());
    let blockwise = Source::BlockwiseThreshold {
        scan: &reader,
        threshold: 0.0,
    };
    let (a, b) = (
        voxlod::lod(&whole, &options).unwrap(),
        voxlod::lod(&blockwise, &options).unwrap(),
    );
    // Both routes keep the genus from rising on every level, and neither says otherwise.
    assert_eq!(a.warnings, b.warnings);
    assert!(
        b.warnings.iter().all(|w| !w.contains("narrow band")),
        "{:?}",
        b.warnings
    );
    let genera: Vec<_> = a.levels.iter().map(|l| l.topology.genus).collect();
    assert!(
        genera[0] > genera[2],
        "the genus step should act: {genera:?}"
    );
    for (x, y) in a.levels.iter().zip(&b.levels) {
        assert_eq!(
            x.mesh.triangle_count(),
            y.mesh.triangle_count(),
            "{}",
            x.resolution
        );
        assert_eq!(x.topology.genus, y.topology.genus, "{}", x.resolution);
        assert_eq!(
            x.monotone.is_some(),
            y.monotone.is_some(),
            "{}",
            x.resolution
        );
        let sorted = |m: &voxlod::core::TriangleMesh| {
            let mut p: Vec<[u32; 3]> = m
                .positions
                .iter()
                .map(|v| v.to_array().map(f32::to_bits))
                .collect();
            p.sort_unstable();
            p
        };
        assert_eq!(sorted(&x.mesh), sorted(&y.mesh), "{}", x.resolution);
    }
}
