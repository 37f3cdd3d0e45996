//! The targets of levels by budget on every shared mesh and every generated case, each budget
//! measured beside meshoptimizer's `simplify` and `simplifySloppy` on the same input (module
//! `targets_common`): Hausdorff at most 1.1 times the better peer that reaches the budget within
//! 10 % with a manifold result, mean at most 1.25 times `simplify`'s, every level within its
//! budget, a manifold, oriented, and closed where the input is. Ignored for time (about two
//! minutes); `scripts/real-data.sh` runs it. Time targets are measured by
//! `examples/portfolio.rs` (BENCHMARKS.md), never here.

mod targets_common;

use targets_common::{measured, target_budgets, verdict};
use voxlod_budget::{levels, PortfolioOptions};
use voxlod_core::{mesh_topology, TriangleMesh};
use voxlod_quadric::{simplify_sloppy, simplify_unchecked};

/// The failures of `mesh`'s levels, one line each.
fn failures(name: &str, mesh: &TriangleMesh) -> Vec<String> {
    let budgets = target_budgets(mesh.triangle_count());
    let run = levels(mesh, &PortfolioOptions::for_triangles(&budgets)).unwrap();
    let closed_input = run.input.closed;
    let mut out = Vec::new();
    for (level, &b) in run.levels.iter().zip(&budgets) {
        let t = mesh_topology(&level.mesh);
        let shape_ok = t.is_manifold() && t.is_consistently_oriented();
        if !shape_ok || (closed_input && !t.is_closed_manifold()) {
            out.push(format!("{name} {b}: {t:?}"));
        }
        let simplify = simplify_unchecked(mesh, b, false).ok().map(|m| m.0);
        let sloppy = simplify_sloppy(mesh, b).ok();
        let ours = measured(mesh, &level.mesh).expect("a level with area");
        let s = simplify.as_ref().and_then(|m| measured(mesh, m));
        let sl = sloppy.as_ref().and_then(|m| measured(mesh, m));
        let v = verdict(b, &ours, s.as_ref(), sl.as_ref());
        if !v.met() {
            out.push(format!(
                "{name} {b}: {v:?}, ours {ours:?}, simplify {s:?}, sloppy {sl:?}"
            ));
        }
    }
    out
}

#[test]
#[ignore = "about two minutes: scripts/real-data.sh runs it"]
fn every_budget_of_every_shared_mesh_and_generated_case_meets_the_targets() {
    let mut inputs: Vec<(String, TriangleMesh)> = voxlod_testkit::corpus::corpus()
        .into_iter()
        .map(|(n, m)| (n.to_string(), m))
        .collect();
    for f in voxlod_testkit::data::shared_meshes("budget targets") {
        let mesh = voxlod_io::read_mesh(&f).unwrap().mesh;
        inputs.push((f.file_name().unwrap().to_string_lossy().into_owned(), mesh));
    }
    let failed: Vec<String> = inputs.iter().flat_map(|(n, m)| failures(n, m)).collect();
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}
