//! Times the shared route (surface nets over all labels, smoothing that keeps volume, every
//! label's mesh taken out) on a generated map, and writes the map as raw bytes for
//! `scripts/shared-nets-vtk.py` to run VTK's `vtkSurfaceNets3D` on the same voxels:
//!
//! ```sh
//! cargo run --release -p voxlod-labels --example shared_nets -- ellipsoids 256 50 /tmp/e.u32
//! cargo run --release -p voxlod-labels --example shared_nets -- voronoi 512 1000 /tmp/v.u32
//! ```
//!
//! `raw N Z10 FILE` reads such a file back (an N³ cube, z spacing Z10 / 10) instead of making
//! a map. Maps: `ellipsoids` (N³, L random ellipsoids drawn in order over a background, spacing
//! 1 × 1 × 1.5) and `voronoi` (N³, every voxel labelled by the nearest of L random sites,
//! spacing 1). The raw file is little-endian uint32, x fastest; the dimensions and spacing are
//! printed. `SHARED_NETS_KEEP_VOLUME=0` skips the volume restoring (VTK keeps no volumes), to
//! time the rest alone.

use std::io::Write;
use std::time::Instant;

use rayon::prelude::*;
use voxlod_core::{Grid, LabelVolume};
use voxlod_labels::smoothing::{smooth, SmoothingOptions};
use voxlod_labels::surface_nets::{surface_nets, SurfaceNetsOptions};

/// splitmix64 as a uniform in [0, 1).
fn uniform(state: &mut u64) -> f64 {
    *state = state.wrapping_add(0x9e3779b97f4a7c15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58476d1ce4e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d049bb133111eb);
    ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
}

fn ellipsoids(n: usize, count: u32) -> LabelVolume {
    let mut seed = 1u64;
    let shapes: Vec<([f64; 3], [f64; 3])> = (0..count)
        .map(|_| {
            let c = std::array::from_fn(|_| (0.15 + 0.7 * uniform(&mut seed)) * n as f64);
            let r = std::array::from_fn(|_| (0.03 + 0.09 * uniform(&mut seed)) * n as f64);
            (c, r)
        })
        .collect();
    let mut values = vec![0u32; n * n * n];
    values
        .par_chunks_mut(n * n)
        .enumerate()
        .for_each(|(k, plane)| {
            for (label, (c, r)) in shapes.iter().enumerate() {
                let dz = (k as f64 + 0.5 - c[2]) / r[2];
                if dz.abs() > 1.0 {
                    continue;
                }
                for (v, value) in plane.iter_mut().enumerate() {
                    let (dx, dy) = (
                        ((v % n) as f64 + 0.5 - c[0]) / r[0],
                        ((v / n) as f64 + 0.5 - c[1]) / r[1],
                    );
                    if dx * dx + dy * dy + dz * dz <= 1.0 {
                        *value = label as u32 + 1;
                    }
                }
            }
        });
    let grid = Grid::new([n; 3], [1.0, 1.0, 1.5], [0.0; 3]).unwrap();
    LabelVolume::from_vec(grid, values).unwrap()
}

fn voronoi(n: usize, count: u32) -> LabelVolume {
    let mut seed = 2u64;
    let sites: Vec<[f64; 3]> = (0..count)
        .map(|_| std::array::from_fn(|_| uniform(&mut seed) * n as f64))
        .collect();
    let b = ((count as f64).cbrt().round() as usize).max(1);
    let cell = n as f64 / b as f64;
    let mut buckets = vec![Vec::new(); b * b * b];
    for (s, p) in sites.iter().enumerate() {
        let at = p.map(|v| ((v / cell) as usize).min(b - 1));
        buckets[(at[2] * b + at[1]) * b + at[0]].push(s);
    }
    let nearest = |p: [f64; 3]| -> u32 {
        let at = p.map(|c| ((c / cell) as isize).min(b as isize - 1));
        let mut best = (f64::INFINITY, 0usize);
        for reach in 1..=b as isize {
            for q in shell(at, reach - 1, b as isize) {
                for &s in &buckets[q] {
                    let d: f64 = (0..3).map(|a| (p[a] - sites[s][a]).powi(2)).sum();
                    if d < best.0 {
                        best = (d, s);
                    }
                }
            }
            if best.0.sqrt() <= (reach - 1) as f64 * cell {
                break;
            }
        }
        best.1 as u32 + 1
    };
    let mut values = vec![0u32; n * n * n];
    values.par_chunks_mut(n).enumerate().for_each(|(row, out)| {
        let (j, k) = (row % n, row / n);
        for (i, value) in out.iter_mut().enumerate() {
            *value = nearest([i as f64 + 0.5, j as f64 + 0.5, k as f64 + 0.5]);
        }
    });
    LabelVolume::from_vec(Grid::new([n; 3], [1.0; 3], [0.0; 3]).unwrap(), values).unwrap()
}

/// The buckets at Chebyshev distance exactly `r` from `at`, inside `0..b`.
fn shell(at: [isize; 3], r: isize, b: isize) -> Vec<usize> {
    let mut out = Vec::new();
    for z in at[2] - r..=at[2] + r {
        for y in at[1] - r..=at[1] + r {
            for x in at[0] - r..=at[0] + r {
                let edge = (x - at[0])
                    .abs()
                    .max((y - at[1]).abs())
                    .max((z - at[2]).abs());
                if edge == r && [x, y, z].iter().all(|&c| (0..b).contains(&c)) {
                    out.push(((z * b + y) * b + x) as usize);
                }
            }
        }
    }
    out
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let kind = args.first().map_or("ellipsoids", |s| s.as_str());
    let n: usize = args.get(1).map_or(256, |s| s.parse().expect("N"));
    let count: u32 = args.get(2).map_or(50, |s| s.parse().expect("L"));
    let t = Instant::now();
    let map = if kind == "raw" {
        // raw FILE N SPACING_Z: a cube written by an earlier run.
        let path = args.get(3).expect("raw FILE");
        let bytes = std::fs::read(path).expect("raw file");
        let values = bytes
            .chunks_exact(4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
        let spacing = [1.0, 1.0, count as f64 / 10.0];
        let grid = Grid::new([n; 3], spacing, [0.0; 3]).unwrap();
        let values: Vec<u32> = values.collect();
        drop(bytes);
        run(&LabelVolume::from_vec(grid, values).unwrap());
        return;
    } else if kind == "voronoi" {
        voronoi(n, count)
    } else {
        ellipsoids(n, count)
    };
    eprintln!("made the {kind} map in {:.2} s", t.elapsed().as_secs_f64());
    if let Some(path) = args.get(3) {
        let mut file = std::io::BufWriter::new(std::fs::File::create(path).expect("raw file"));
        for v in &map.values {
            file.write_all(&v.to_le_bytes()).expect("write");
        }
        println!(
            "wrote {path}: dims {:?} spacing {:?}",
            map.grid.dims, map.grid.spacing
        );
    }
    run(&map);
}

/// CPU seconds of this process so far (all threads), from /proc (0 elsewhere).
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let fields: Vec<&str> = stat
        .rsplit(')')
        .next()
        .unwrap_or("")
        .split_whitespace()
        .collect();
    let tick = |n: usize| {
        fields
            .get(n)
            .and_then(|f| f.parse::<f64>().ok())
            .unwrap_or(0.0)
    };
    (tick(11) + tick(12)) / 100.0
}

fn run(map: &LabelVolume) {
    let (t, c) = (Instant::now(), cpu_seconds());
    let mut surface = surface_nets(map, &SurfaceNetsOptions::default()).unwrap();
    let (nets, nets_cpu) = (t.elapsed().as_secs_f64(), cpu_seconds() - c);
    let options = SmoothingOptions {
        keep_volume: std::env::var("SHARED_NETS_KEEP_VOLUME").map_or(true, |v| v != "0"),
        ..SmoothingOptions::default()
    };
    let report = smooth(&mut surface, &options).unwrap();
    let (smoothed, smoothed_cpu) = (t.elapsed().as_secs_f64(), cpu_seconds() - c);
    let labels = surface.labels();
    let meshes = surface.label_meshes(&labels).unwrap();
    let (total, total_cpu) = (t.elapsed().as_secs_f64(), cpu_seconds() - c);
    let label_triangles: usize = meshes.iter().map(|m| m.triangles.len()).sum();
    println!(
        "{} labels; shared surface {} vertices, {} triangles; label meshes {} triangles",
        labels.len(),
        surface.positions.len(),
        surface.triangles.len(),
        label_triangles
    );
    println!(
        "surface nets {nets:.3} s, + smoothing {smoothed:.3} s, + every label's mesh {total:.3} s \
         ({} threads; CPU time {nets_cpu:.2}, {smoothed_cpu:.2}, {total_cpu:.2} s)",
        rayon::current_num_threads()
    );
    let voxel: f64 = map.grid.spacing.iter().product();
    let mut counts = std::collections::HashMap::new();
    for &v in &map.values {
        *counts.entry(v).or_insert(0usize) += 1;
    }
    let mut errors: Vec<(f64, usize)> = report
        .volumes
        .iter()
        .map(|v| (v.relative().abs(), counts[&v.label]))
        .collect();
    errors.sort_by(|a, b| a.0.total_cmp(&b.0));
    let big = errors
        .iter()
        .filter(|e| e.1 >= 1000)
        .map(|e| e.0)
        .fold(0.0, f64::max);
    println!(
        "volume vs voxels after smoothing: median |error| {:.4} %, worst {:.4} %, worst of \
         labels >= 1000 voxels {:.4} % ({} restoring rounds, {} vertices on their box, {} \
         diagonals turned; voxel volume {voxel})",
        100.0 * errors[errors.len() / 2].0,
        100.0 * errors.last().unwrap().0,
        100.0 * big,
        report.restore_rounds,
        report.constrained_vertices,
        report.turned_diagonals
    );
}
