//! Times the one-pass label meshing on generated maps: `cargo run --release -p voxlod-labels
//! --example labels_timing -- [ellipsoids N L | voronoi N L]`.

use std::time::Instant;

use voxlod_core::{Grid, LabelVolume};
use voxlod_labels::{find_labels, marching_cubes_of, select_labels};

fn lcg(seed: &mut u64) -> f64 {
    *seed = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*seed >> 11) as f64 / (1u64 << 53) as f64
}

fn ellipsoids(n: usize, count: u32) -> LabelVolume {
    let mut seed = 1u64;
    let mut values = vec![0u32; n * n * n];
    for label in 1..=count {
        let c: [f64; 3] = std::array::from_fn(|_| 0.15 + 0.7 * lcg(&mut seed));
        let r: [f64; 3] = std::array::from_fn(|_| 0.03 + 0.09 * lcg(&mut seed));
        let lo: [usize; 3] =
            std::array::from_fn(|a| ((c[a] - r[a]) * n as f64).floor().max(0.0) as usize);
        let hi: [usize; 3] =
            std::array::from_fn(|a| (((c[a] + r[a]) * n as f64).ceil() as usize).min(n - 1));
        for k in lo[2]..=hi[2] {
            for j in lo[1]..=hi[1] {
                for i in lo[0]..=hi[0] {
                    let p = [i, j, k].map(|v| v as f64 / n as f64);
                    let d: f64 = (0..3).map(|a| ((p[a] - c[a]) / r[a]).powi(2)).sum();
                    if d <= 1.0 {
                        values[(k * n + j) * n + i] = label;
                    }
                }
            }
        }
    }
    LabelVolume::from_vec(
        Grid::new([n; 3], [1.0, 1.0, 1.5], [0.0; 3]).unwrap(),
        values,
    )
    .unwrap()
}

fn voronoi(n: usize, count: u32) -> LabelVolume {
    let mut seed = 2u64;
    let sites: Vec<[f64; 3]> = (0..count)
        .map(|_| std::array::from_fn(|_| lcg(&mut seed) * n as f64))
        .collect();
    // Sites bucketed on a coarse grid for a quick nearest search.
    let b = ((count as f64).cbrt().ceil() as usize).max(1);
    let cell = n as f64 / b as f64;
    let mut buckets = vec![Vec::new(); b * b * b];
    for (s, p) in sites.iter().enumerate() {
        let at = p.map(|v| ((v / cell) as usize).min(b - 1));
        buckets[(at[2] * b + at[1]) * b + at[0]].push(s);
    }
    let values: Vec<u32> = (0..n * n * n)
        .map(|v| {
            let p = [v % n, v / n % n, v / (n * n)].map(|c| c as f64 + 0.5);
            let at = p.map(|c| ((c / cell) as isize).min(b as isize - 1));
            let mut best = (f64::INFINITY, 0usize);
            for r in 1..=b as isize {
                for dz in -r..=r {
                    for dy in -r..=r {
                        for dx in -r..=r {
                            let q = [at[0] + dx, at[1] + dy, at[2] + dz];
                            if q.iter().any(|&c| c < 0 || c >= b as isize) {
                                continue;
                            }
                            for &s in
                                &buckets[((q[2] as usize) * b + q[1] as usize) * b + q[0] as usize]
                            {
                                let d: f64 = (0..3).map(|a| (p[a] - sites[s][a]).powi(2)).sum();
                                if d < best.0 {
                                    best = (d, s);
                                }
                            }
                        }
                    }
                }
                if best.0.sqrt() <= (r as f64 - 1.0) * cell {
                    break;
                }
            }
            best.1 as u32 + 1
        })
        .collect();
    LabelVolume::from_vec(Grid::new([n; 3], [1.0; 3], [0.0; 3]).unwrap(), values).unwrap()
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let kind = args.first().map_or("ellipsoids", |s| s.as_str());
    let n: usize = args.get(1).map_or(256, |s| s.parse().unwrap());
    let count: u32 = args.get(2).map_or(50, |s| s.parse().unwrap());
    let t = Instant::now();
    let map = if kind == "voronoi" {
        voronoi(n, count)
    } else {
        ellipsoids(n, count)
    };
    eprintln!("made the map in {:.2} s", t.elapsed().as_secs_f64());
    let t = Instant::now();
    let labels = select_labels(find_labels(&map), None).unwrap();
    let found = t.elapsed().as_secs_f64();
    let meshes = marching_cubes_of(&map, &labels).unwrap();
    let total = t.elapsed().as_secs_f64();
    let triangles: usize = meshes.iter().map(|m| m.triangles.len()).sum();
    println!(
        "{} labels, {} triangles: find {:.3} s, find + mesh {:.3} s",
        labels.len(),
        triangles,
        found,
        total
    );
}
