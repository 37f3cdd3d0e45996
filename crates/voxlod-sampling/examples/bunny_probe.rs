//! Times the bunny's finest level at 256 piece by piece (crossings per family, then the whole
//! filtered density) and prints a checksum of the density's bits, so that a change to the
//! sampler can be timed and checked bit for bit without the whole command. Usage:
//! `cargo run --release -p voxlod-sampling --example bunny_probe -- MESH [RES] [REPEATS]`.

use std::time::Instant;

use voxlod_core::Axis;
use voxlod_sampling::lattice::LineFamily;
use voxlod_sampling::{filtered_density, plan_levels, Filter, MeshSolid, PyramidOptions, Solid};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = std::path::Path::new(&args[1]);
    let res: usize = args.get(2).map_or(256, |s| s.parse().unwrap());
    let repeats: usize = args.get(3).map_or(5, |s| s.parse().unwrap());
    let mesh = voxlod_testkit::readers::read_obj(path);
    let solid = MeshSolid::new(&mesh).unwrap();
    let pyramid = PyramidOptions::halving(res, 6, Filter::Hypercone);
    let plans = plan_levels(&solid.bounds(), &pyramid).unwrap();
    for plan in plans.iter().take(2) {
        let options = plan.density_options(&pyramid);
        let q = options.lines_per_voxel(plan.voxel_size);
        for axis in [Axis::X, Axis::Y, Axis::Z] {
            let family = LineFamily::new(axis, plan.grid, q);
            let mut times = Vec::new();
            let mut n = 0;
            for _ in 0..repeats {
                let t = Instant::now();
                let c = solid.crossings(&family).unwrap();
                times.push(t.elapsed().as_secs_f64());
                n = c.len();
            }
            times.sort_by(f64::total_cmp);
            println!(
                "res {} {axis:?}: {n} crossings, median {:.4} s",
                plan.resolution,
                times[repeats / 2]
            );
        }
        let mut times = Vec::new();
        let mut sum = 0u64;
        for _ in 0..repeats {
            let t = Instant::now();
            let (v, _) = filtered_density(&solid, &plan.grid, &options).unwrap();
            times.push(t.elapsed().as_secs_f64());
            sum = v.as_slice().iter().fold(0u64, |h, x| {
                h.rotate_left(5) ^ (x.to_bits() as u64).wrapping_mul(0x9E3779B97F4A7C15)
            });
        }
        times.sort_by(f64::total_cmp);
        println!(
            "res {}: density median {:.4} s, bits {sum:016x}",
            plan.resolution,
            times[repeats / 2]
        );
    }
}
