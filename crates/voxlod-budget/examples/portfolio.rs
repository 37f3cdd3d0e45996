//! The budget portfolio beside meshoptimizer's `simplify` and `simplifySloppy` on the same
//! input, in the same run: per budget (1/8, 1/32, 1/128 of the input's triangles, and 1 000
//! and 300 where below 1/8) the two-sided Hausdorff and mean distance of each (one independent
//! measure, 50 000 samples a side, none of the portfolio's own samples), whether the peers'
//! results are manifold, and the run's time against `simplify`'s for the same counts.
//!
//! Usage: `cargo run --release -p voxlod-budget --example portfolio -- [FILES…] [--shared]
//! [--corpus] [--known-misses] [--case NAME] [--sphereflake N] [--json OUT]`. The targets (as
//! BENCHMARKS.md states them):
//! Hausdorff at most 1.1 times the better peer that reaches the budget within 10 % with a
//! manifold result, mean at most 1.25 times `simplify`'s, every level within 10 %, and the
//! run within 5 times `simplify`'s time plus 0.5 s. With `VERBOSE` set, every candidate of
//! every budget is listed; with `CHAIN_ONLY` set, only the chain runs and is timed, with its
//! phases (nothing is measured afterwards: for profiling).

use std::path::{Path, PathBuf};
use std::time::Instant;

use voxlod_budget::{levels, PortfolioOptions};

#[path = "../tests/targets_common/mod.rs"]
mod targets_common;
use targets_common::{measured, target_budgets, verdict, Measured};
use voxlod_core::TriangleMesh;
use voxlod_quadric::{simplify_sloppy, simplify_unchecked};

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
            "--known-misses" => {
                for (name, mesh) in voxlod_testkit::corpus::known_misses() {
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
        "\nsummary: levels meeting every target {}/{}; hausdorff target met {}/{} (eligible), mean {}/{}, in budget {}/{}, time {}/{}",
        tally.met,
        tally.levels,
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
    met: usize,
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

/// The targets' budgets, or those of the environment's `BUDGETS=a,b,c`.
fn budgets(f: usize) -> Vec<usize> {
    match std::env::var("BUDGETS") {
        Ok(list) => (list.split(','))
            .map(|b| b.parse().expect("BUDGETS=a,b,c"))
            .collect(),
        Err(_) => target_budgets(f),
    }
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

impl Tally {
    /// Counts one level's verdict; the flags to print beside it.
    fn count(
        &mut self,
        budget: usize,
        ours: Option<&Measured>,
        simplify: Option<&Measured>,
        sloppy: Option<&Measured>,
    ) -> String {
        self.levels += 1;
        let mut flags = String::new();
        let Some(o) = ours else {
            return flags;
        };
        let v = verdict(budget, o, simplify, sloppy);
        self.met += usize::from(v.met());
        if v.within_budget {
            self.budget_ok += 1;
        } else {
            flags += " OFF-BUDGET";
        }
        if let Some(r) = v.hausdorff_ratio {
            self.h_n += 1;
            if r <= 1.1 {
                self.h_ok += 1;
            } else {
                flags += &format!(" H×{r:.2}");
            }
        }
        if let Some(r) = v.mean_ratio {
            self.mean_n += 1;
            if r <= 1.25 {
                self.mean_ok += 1;
            } else {
                flags += &format!(" MEAN×{r:.2}");
            }
        }
        flags
    }
}

/// Every candidate of a level, with its distances in % of `diagonal`.
fn print_candidates(report: &voxlod_budget::BudgetLevel, diagonal: f64) {
    println!("           ({:.2} s)", report.seconds);
    let percent =
        |h: Option<f64>| h.map_or("-".into(), |h| format!("{:.3}%", 100.0 * h / diagonal));
    for c in &report.candidates {
        println!(
            "           {:28} {:7} quick {:>10} careful {:>10} broken {:?}",
            c.candidate,
            c.triangles,
            percent(c.shape),
            percent(c.careful_hausdorff),
            c.broken
        );
    }
}

/// Per budget, the peers' levels: simplify's and sloppy's.
type PeerLevels = Vec<(Option<TriangleMesh>, Option<TriangleMesh>)>;

/// The peers' levels for each of `budgets` and simplify's time in all, timed on one thread as
/// meshoptimizer runs.
fn peers(mesh: &TriangleMesh, budgets: &[usize]) -> (f64, PeerLevels) {
    let mut simplify_seconds = 0.0;
    let mut peers = Vec::new();
    for &b in budgets {
        let t = Instant::now();
        let s = simplify_unchecked(mesh, b, false).map(|r| r.0);
        simplify_seconds += t.elapsed().as_secs_f64();
        let sl = simplify_sloppy(mesh, b);
        peers.push((s.ok(), sl.ok()));
    }
    (simplify_seconds, peers)
}

fn run(name: &str, mesh: &TriangleMesh, tally: &mut Tally) -> Vec<Row> {
    let budgets = budgets(mesh.triangle_count());
    let diagonal = mesh.bounds().diagonal();
    let (simplify_seconds, peers) = peers(mesh, &budgets);
    let t = Instant::now();
    let ours = levels(mesh, &PortfolioOptions::for_triangles(&budgets));
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
    if std::env::var_os("CHAIN_ONLY").is_some() {
        return Vec::new();
    }
    let mut rows = Vec::new();
    for ((&b, level), (s, sl)) in budgets.iter().zip(&ours.levels).zip(peers) {
        let o = measured(mesh, &level.mesh);
        let s = s.and_then(|m| measured(mesh, &m));
        let sl = sl.and_then(|m| measured(mesh, &m));
        // A budget above the input's triangles asks for the input's count (its level is the
        // input's own, as the peers' are).
        let asked = b.min(mesh.triangle_count());
        let flags = tally.count(asked, o.as_ref(), s.as_ref(), sl.as_ref());
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
            + if level.report.staged { "s" } else { "" }
            + if level.report.fitted_to_input {
                "f"
            } else {
                ""
            }
            + match level.report.fill {
                voxlod_budget::Fill::None => "",
                voxlod_budget::Fill::Cavities => " cavities",
                voxlod_budget::Fill::Hollows => " hollows",
                voxlod_budget::Fill::HollowLining => " lined",
                voxlod_budget::Fill::OpenShells => " shells",
            };
        println!(
            "  {b:7}  ours {} {label:14} simplify {}  sloppy {} {flags}",
            cell(&o),
            cell(&s),
            cell(&sl)
        );
        if std::env::var_os("VERBOSE").is_some() {
            print_candidates(&level.report, diagonal);
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
