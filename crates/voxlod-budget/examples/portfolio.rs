//! The budget portfolio beside meshoptimizer's `simplify` and `simplifySloppy` on the same
//! input, in the same run: per budget (1/8, 1/32, 1/128 of the input's triangles, and 1 000
//! and 300 where below 1/8) the two-sided Hausdorff and mean distance of each (one independent
//! measure, 50 000 samples a side, none of the portfolio's own samples), whether the peers'
//! results are manifold, and the run's time against `simplify`'s for the same counts.
//!
//! Usage: `cargo run --release -p voxlod-budget --example portfolio -- [FILES…] [--shared]
//! [--corpus] [--sphereflake N] [--json OUT]`. The targets (issue text in BENCHMARKS.md):
//! Hausdorff at most 1.1 times the better peer that reaches the budget within 10 % with a
//! manifold result, mean at most 1.25 times `simplify`'s, every level within 10 %, and the
//! run within 5 times `simplify`'s time plus 0.5 s.

use std::path::{Path, PathBuf};
use std::time::Instant;

use voxlod_budget::{levels, BudgetOptions};
use voxlod_core::{mesh_topology, TriangleMesh};
use voxlod_metrics::{mesh_distance, DistanceOptions};
use voxlod_quadric::{simplify_sloppy, simplify_unchecked};

/// Samples a side of the independent measure.
const SAMPLES: usize = 50_000;

fn main() {
    let mut inputs: Vec<(String, TriangleMesh)> = Vec::new();
    let mut json_out: Option<PathBuf> = None;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--shared" => {
                for f in voxlod_testkit::data::shared_meshes("portfolio example") {
                    inputs.push(load(&f));
                }
            }
            "--corpus" => {
                for (name, mesh) in voxlod_testkit::corpus::corpus() {
                    inputs.push((name.to_string(), mesh));
                }
            }
            "--case" => {
                let wanted = args.next().expect("--case NAME");
                for (name, mesh) in voxlod_testkit::corpus::corpus() {
                    if name == wanted {
                        inputs.push((name.to_string(), mesh));
                    }
                }
            }
            "--sphereflake" => {
                let n: usize = args
                    .next()
                    .and_then(|s| s.parse().ok())
                    .expect("--sphereflake N");
                inputs.push((format!("sphereflake-{n}"), sphereflake(n)));
            }
            "--json" => json_out = args.next().map(PathBuf::from),
            file => inputs.push(load(&PathBuf::from(file))),
        }
    }
    let mut rows = Vec::new();
    let mut tally = Tally::default();
    for (name, mesh) in &inputs {
        rows.extend(run(name, mesh, &mut tally));
    }
    println!(
        "\nsummary: hausdorff target met {}/{} (eligible), mean {}/{}, in budget {}/{}, time {}/{}",
        tally.h_ok,
        tally.h_n,
        tally.mean_ok,
        tally.mean_n,
        tally.budget_ok,
        tally.levels,
        tally.time_ok,
        tally.runs
    );
    if let Some(out) = json_out {
        std::fs::write(out, serde_json::to_string_pretty(&rows).unwrap()).unwrap();
    }
}

#[derive(Default)]
struct Tally {
    h_ok: usize,
    h_n: usize,
    mean_ok: usize,
    mean_n: usize,
    budget_ok: usize,
    levels: usize,
    time_ok: usize,
    runs: usize,
}

fn load(path: &Path) -> (String, TriangleMesh) {
    let mesh = voxlod_io::read_mesh(path).expect("readable mesh").mesh;
    let name = path.file_stem().unwrap().to_string_lossy().to_string();
    (name, mesh)
}

fn sphereflake(n: usize) -> TriangleMesh {
    let field = voxlod_testkit::fields::sphereflake_field(n).expect("field");
    voxlod_contouring::marching_cubes(
        &field,
        &voxlod_contouring::ContourOptions::geometry_only(0.0),
    )
    .expect("contour")
}

/// The budgets of the targets for an input of `f` triangles.
fn budgets(f: usize) -> Vec<usize> {
    if let Ok(list) = std::env::var("BUDGETS") {
        return list
            .split(',')
            .map(|b| b.parse().expect("BUDGETS=a,b,c"))
            .collect();
    }
    let mut b = vec![f / 8, f / 32, f / 128];
    for fixed in [1000, 300] {
        if fixed < f / 8 && !b.contains(&fixed) {
            b.push(fixed);
        }
    }
    b.retain(|&x| x >= 4);
    b.sort_unstable_by(|a, b| b.cmp(a));
    b.dedup();
    b
}

/// A method's level measured.
#[derive(serde::Serialize, Clone, Copy)]
struct Measured {
    triangles: usize,
    hausdorff: f64,
    mean: f64,
    manifold: bool,
}

fn measured(input: &TriangleMesh, mesh: &TriangleMesh, diagonal: f64) -> Option<Measured> {
    let d = mesh_distance(input, mesh, &DistanceOptions::with_samples(SAMPLES)).ok()?;
    let mut m = mesh.clone();
    m.remove_unreferenced_vertices();
    let t = mesh_topology(&m);
    Some(Measured {
        triangles: mesh.triangle_count(),
        hausdorff: d.hausdorff / diagonal,
        mean: d.mean / diagonal,
        manifold: t.is_manifold() && t.degenerate_triangles == 0,
    })
}

#[derive(serde::Serialize)]
struct Row {
    input: String,
    budget: usize,
    ours: Option<Measured>,
    method: String,
    simplify: Option<Measured>,
    sloppy: Option<Measured>,
    seconds: f64,
    simplify_seconds: f64,
}

fn run(name: &str, mesh: &TriangleMesh, tally: &mut Tally) -> Vec<Row> {
    let budgets = budgets(mesh.triangle_count());
    let diagonal = mesh.bounds().diagonal();
    // The peers first: simplify from the input for each count, timed on one thread as
    // meshoptimizer runs.
    let mut simplify_seconds = 0.0;
    let mut peers = Vec::new();
    for &b in &budgets {
        let t = Instant::now();
        let s = simplify_unchecked(mesh, b, false).map(|r| r.0);
        simplify_seconds += t.elapsed().as_secs_f64();
        let sl = simplify_sloppy(mesh, b);
        peers.push((s.ok(), sl.ok()));
    }
    let t = Instant::now();
    let ours = levels(mesh, &BudgetOptions::for_triangles(&budgets));
    let seconds = t.elapsed().as_secs_f64();
    let target_time = 5.0 * simplify_seconds + 0.5;
    tally.runs += 1;
    tally.time_ok += usize::from(seconds <= target_time);
    println!(
        "\n{name}: {} triangles, ours {seconds:.2} s, simplify {simplify_seconds:.3} s (target {target_time:.2} s){}",
        mesh.triangle_count(),
        if seconds <= target_time { "" } else { "  TIME MISSED" }
    );
    let ours = match ours {
        Ok(o) => o,
        Err(e) => {
            println!("  FAILED: {e}");
            return Vec::new();
        }
    };
    let t = ours.timings;
    println!(
        "  phases: prepare {:.2} s, collapses {:.2} s, voxels {:.2} s, choice {:.2} s",
        t.prepare, t.collapses, t.voxels, t.choice
    );
    for w in &ours.warnings {
        println!("  warning: {w}");
    }
    let mut rows = Vec::new();
    for ((&b, level), (s, sl)) in budgets.iter().zip(&ours.levels).zip(peers) {
        let o = measured(mesh, &level.mesh, diagonal);
        let s = s.and_then(|m| measured(mesh, &m, diagonal));
        let sl = sl.and_then(|m| measured(mesh, &m, diagonal));
        let within =
            |m: &Measured| (m.triangles as f64 - b as f64).abs() <= (0.1 * b as f64).max(1.0);
        let eligible = |m: &Option<Measured>| m.filter(|m| within(m) && m.manifold);
        let best_peer = [eligible(&s), eligible(&sl)]
            .into_iter()
            .flatten()
            .map(|m| m.hausdorff)
            .fold(f64::INFINITY, f64::min);
        tally.levels += 1;
        let mut flags = String::new();
        if let Some(o) = &o {
            if within(o) {
                tally.budget_ok += 1;
            } else {
                flags += " OFF-BUDGET";
            }
            if best_peer.is_finite() {
                tally.h_n += 1;
                if o.hausdorff <= 1.1 * best_peer {
                    tally.h_ok += 1;
                } else {
                    flags += &format!(" H×{:.2}", o.hausdorff / best_peer);
                }
            }
            if let Some(s) = eligible(&s) {
                tally.mean_n += 1;
                if o.mean <= 1.25 * s.mean {
                    tally.mean_ok += 1;
                } else {
                    flags += &format!(" MEAN×{:.2}", o.mean / s.mean);
                }
            }
        }
        let cell = |m: &Option<Measured>| match m {
            Some(m) => format!(
                "{:7.3}%/{:6.3}% ({:6}{})",
                100.0 * m.hausdorff,
                100.0 * m.mean,
                m.triangles,
                if m.manifold { "" } else { "!" }
            ),
            None => "      failed      ".into(),
        };
        let label = level.report.method.name().to_string()
            + &level
                .report
                .resolution
                .map(|r| format!("@{r}"))
                .unwrap_or_default()
            + if level.report.fitted_to_input {
                "f"
            } else {
                ""
            };
        println!(
            "  {b:7}  ours {} {label:14} simplify {}  sloppy {} {flags}",
            cell(&o),
            cell(&s),
            cell(&sl)
        );
        if std::env::var_os("VERBOSE").is_some() {
            println!("           ({:.2} s)", level.report.seconds);
            for c in &level.report.candidates {
                println!(
                    "           {:28} {:7} quick {:>10} careful {:>10} broken {:?}",
                    c.candidate,
                    c.triangles,
                    c.shape
                        .map_or("-".into(), |h| format!("{:.3}%", 100.0 * h / diagonal)),
                    c.careful_hausdorff
                        .map_or("-".into(), |h| format!("{:.3}%", 100.0 * h / diagonal)),
                    c.broken
                );
            }
        }
        rows.push(Row {
            input: name.to_string(),
            budget: b,
            ours: o,
            method: label,
            simplify: s,
            sloppy: sl,
            seconds,
            simplify_seconds,
        });
    }
    rows
}
