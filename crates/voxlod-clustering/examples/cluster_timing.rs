//! Times the clustering baselines on one mesh, stage by stage (best of several runs).
//!
//!     cargo run --release -p voxlod-clustering --example cluster_timing -- MESH [CELLS] [RUNS]
//!
//! Without MESH (or if it cannot be read) a torus of about a million triangles is generated.
//! `ONLY=grade`, `ONLY=rb`, `ONLY=lt` or `ONLY=load` runs just grading, one method or nothing
//! after loading, for `perf stat` (CPU time) on a busy machine.

use std::time::Instant;

use voxlod_clustering::{
    eliminate, grade, low_tan, rossignac_borrel, ClusterGrid, ClusterOptions, FloatingCellOptions,
    Grading,
};
use voxlod_testkit::shapes::torus;

/// The minimum over `runs` runs (on a shared machine the least disturbed run is the best
/// estimate of the algorithm's own cost); the median is printed too, as the peers report it.
fn best<T>(runs: usize, mut f: impl FnMut() -> T) -> f64 {
    let mut t: Vec<f64> = (0..runs)
        .map(|_| {
            let s = Instant::now();
            std::hint::black_box(f());
            s.elapsed().as_secs_f64()
        })
        .collect();
    t.sort_by(f64::total_cmp);
    eprint!("[median {:.4} s] ", t[t.len() / 2]);
    t[0]
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mesh = args
        .get(1)
        .and_then(|p| voxlod_io::read_mesh(std::path::Path::new(p)).ok())
        .map(|l| l.mesh)
        .unwrap_or_else(|| torus(1000, 500, 1.0, 0.3));
    let cells: u32 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(64);
    let runs: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(7);
    println!(
        "{} vertices, {} triangles, {cells} cells, {} threads",
        mesh.positions.len(),
        mesh.triangles.len(),
        rayon::current_num_threads()
    );
    // ONLY=grade or ONLY=rb: run just that stage (for `perf stat` on a busy machine).
    match std::env::var("ONLY").as_deref() {
        Ok("load") => return,
        Ok("grade") => {
            best(runs, || grade(&mesh, Grading::RossignacBorrel).unwrap());
            return;
        }
        Ok("lt") => {
            best(runs, || {
                low_tan(&mesh, &FloatingCellOptions::single(cells)).unwrap()
            });
            return;
        }
        Ok("rb") => {
            best(runs, || {
                rossignac_borrel(&mesh, &ClusterOptions::smoothing(cells)).unwrap()
            });
            return;
        }
        _ => {}
    }
    let t = best(runs, || grade(&mesh, Grading::RossignacBorrel).unwrap());
    println!("grading (prepare + R–B weights)   {:.4} s", t);
    let grid = ClusterGrid::new(&mesh.bounds(), cells).unwrap();
    let cluster_of: Vec<u32> = {
        let mut ids = std::collections::HashMap::new();
        mesh.positions
            .iter()
            .map(|&p| {
                let n = ids.len() as u32;
                *ids.entry(grid.key(grid.cell_of(p))).or_insert(n)
            })
            .collect()
    };
    let clusters = *cluster_of.iter().max().unwrap() as usize + 1;
    let t = best(runs, || eliminate(&mesh.triangles, &cluster_of, clusters));
    println!("elimination alone                 {:.4} s", t);
    for (name, options) in [
        ("rossignac-borrel mean", ClusterOptions::smoothing(cells)),
        (
            "rossignac-borrel max-weight",
            ClusterOptions::detail_removal(cells),
        ),
        (
            "rossignac-borrel 4 levels",
            ClusterOptions::series(cells, 4),
        ),
    ] {
        let mut report = None;
        let t = best(runs, || {
            let levels = rossignac_borrel(&mesh, &options).unwrap();
            report = Some(voxlod_clustering::reports(&levels));
        });
        let r = report.unwrap();
        println!(
            "{name:32}  {t:.4} s  ({} triangles, {} edges, {} points at level 0; per level {:?})",
            r[0].triangles,
            r[0].dangling_edges,
            r[0].isolated_points,
            r.iter()
                .map(|r| format!("{:.4}", r.cluster_seconds))
                .collect::<Vec<_>>()
        );
    }
    let mut report = None;
    let t = best(runs.min(3), || {
        report = Some(voxlod_clustering::reports(
            &low_tan(&mesh, &FloatingCellOptions::single(cells)).unwrap(),
        ));
    });
    let r = &report.unwrap()[0];
    println!(
        "low-tan                           {t:.4} s  ({} triangles, {} edges, {} points)",
        r.triangles, r.dangling_edges, r.isolated_points
    );
}
