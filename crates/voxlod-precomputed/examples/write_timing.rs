//! Times [`write_layer`] on a generated Voronoi label map meshed by marching cubes, the path of
//! `voxlod labels SEG --format precomputed`:
//! `cargo run --release -p voxlod-precomputed --example write_timing -- [N LABELS LODS
//! plain|sharded|both BITS FRAGMENT_VOXELS]` (defaults 256, 1000, 3, both, 16, 32). Prints
//! the meshing time, then per layout the write time (wall and CPU), the triangles per level,
//! the fragments and their bytes.

use std::time::Instant;

use voxlod_core::{Grid, LabelVolume, TriangleMesh};
use voxlod_labels::{label_surfaces, SurfaceOptions};
use voxlod_precomputed::{write_layer, PrecomputedOptions, Sharding};

/// A linear congruential generator's next value in [0, 1).
fn next(seed: &mut u64) -> f64 {
    *seed = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*seed >> 11) as f64 / (1u64 << 53) as f64
}

/// An `n`³ map of unit voxels where each voxel holds the label (1 ..= count) of its nearest
/// site, the sites uniform in the cube; the nearest site is searched in rings of buckets.
fn voronoi(n: usize, count: u32) -> LabelVolume {
    let mut seed = 7u64;
    let sites: Vec<[f64; 3]> = (0..count)
        .map(|_| std::array::from_fn(|_| next(&mut seed) * n as f64))
        .collect();
    let b = ((count as f64).cbrt().ceil() as usize).max(1);
    let cell = n as f64 / b as f64;
    let bucket_of = |p: [f64; 3]| p.map(|v| ((v / cell) as usize).min(b - 1));
    let mut buckets = vec![Vec::new(); b * b * b];
    for (s, &p) in sites.iter().enumerate() {
        let q = bucket_of(p);
        buckets[(q[2] * b + q[1]) * b + q[0]].push(s);
    }
    let nearest = |p: [f64; 3]| -> u32 {
        let q = bucket_of(p).map(|v| v as isize);
        let mut best = (f64::INFINITY, 0usize);
        for r in 0..b as isize {
            for z in (q[2] - r).max(0)..=(q[2] + r).min(b as isize - 1) {
                for y in (q[1] - r).max(0)..=(q[1] + r).min(b as isize - 1) {
                    for x in (q[0] - r).max(0)..=(q[0] + r).min(b as isize - 1) {
                        let ring = [x - q[0], y - q[1], z - q[2]].map(isize::abs);
                        if ring.into_iter().max() != Some(r) {
                            continue;
                        }
                        for &s in &buckets[((z as usize) * b + y as usize) * b + x as usize] {
                            let d: f64 = (0..3).map(|a| (p[a] - sites[s][a]).powi(2)).sum();
                            if d < best.0 {
                                best = (d, s);
                            }
                        }
                    }
                }
            }
            // Every site beyond ring r is at least r · cell away.
            if best.0.sqrt() <= r as f64 * cell {
                break;
            }
        }
        best.1 as u32 + 1
    };
    let values = (0..n * n * n)
        .map(|v| nearest([v % n, v / n % n, v / (n * n)].map(|c| c as f64 + 0.5)))
        .collect();
    LabelVolume::from_vec(Grid::new([n; 3], [1.0; 3], [0.0; 3]).unwrap(), values).unwrap()
}

/// CPU seconds this process has used (user and system, all threads), from `/proc/self/stat`;
/// zero where that file is missing.
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // The fields after the command name, which is in parentheses: utime and stime are the
    // 12th and 13th of them, in clock ticks (100 per second on Linux).
    let after = stat.rsplit_once(')').map_or("", |(_, rest)| rest);
    let fields: Vec<f64> = after
        .split_whitespace()
        .map(|f| f.parse().unwrap_or(0.0))
        .collect();
    fields
        .get(11)
        .zip(fields.get(12))
        .map_or(0.0, |(u, s)| (u + s) / 100.0)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let number = |i: usize, default: usize| args.get(i).map_or(default, |s| s.parse().unwrap());
    let (n, count, lods) = (number(0, 256), number(1, 1000) as u32, number(2, 3));
    let layouts = args.get(3).map_or("both", |s| s.as_str());
    let bits = number(4, 16) as u32;
    let fragment_voxels = number(5, 32);
    let t = Instant::now();
    let map = voronoi(n, count);
    eprintln!(
        "map {n}^3, {count} sites: {:.2} s",
        t.elapsed().as_secs_f64()
    );
    let t = Instant::now();
    let surfaces = label_surfaces(&map, &SurfaceOptions::default()).unwrap();
    let meshes: Vec<(u32, TriangleMesh)> = surfaces
        .labels
        .into_iter()
        .map(|l| (l.label.value, l.mesh))
        .collect();
    let triangles: usize = meshes.iter().map(|(_, m)| m.triangles.len()).sum();
    println!(
        "meshed {} labels, {triangles} triangles: {:.2} s",
        meshes.len(),
        t.elapsed().as_secs_f64()
    );
    let dir = tempfile::tempdir().unwrap();
    for (name, sharding) in [("sharded", Sharding::Always), ("plain", Sharding::Never)] {
        if layouts != "both" && layouts != name {
            continue;
        }
        let options = PrecomputedOptions {
            lods,
            sharding,
            quantization_bits: bits,
            fragment_voxels,
            ..PrecomputedOptions::default()
        };
        let (t, cpu) = (Instant::now(), cpu_seconds());
        let report = write_layer(&dir.path().join(name), &map, &meshes, &options).unwrap();
        let seconds = t.elapsed().as_secs_f64();
        let cpu = cpu_seconds() - cpu;
        let per_lod: Vec<usize> = (0..lods)
            .map(|k| {
                report
                    .labels
                    .iter()
                    .map(|l| l.lods.get(k).map_or(0, |r| r.triangles))
                    .sum()
            })
            .collect();
        let fragments: usize = report
            .labels
            .iter()
            .flat_map(|l| l.lods.iter().map(|r| r.fragments))
            .sum();
        let bytes: u64 = report
            .labels
            .iter()
            .flat_map(|l| l.lods.iter().map(|r| r.bytes))
            .sum();
        println!("{name}: write_layer {seconds:.2} s ({cpu:.2} s CPU); triangles per lod {per_lod:?}; {fragments} fragments, {bytes} bytes");
    }
}
