//! `voxlod lod --triangles A,B,… | --error E`: levels by triangle budget or error target, the
//! library's budget pipeline (`voxlod::budget`: the voxel resolution that filters away what the
//! budget cannot afford, then a geometric stage, paper §5). Writes `DIR/level-N.EXT` (with
//! `--format glb`, `DIR/lod.glb` chaining the levels, and the level files as PLY with `--split`)
//! and `DIR/report.json` with, per level, the budget, the chosen resolution, the stage and its error
//! bound, the measured two-sided distance to the input, genus, components and handles removed,
//! and every warning (with `--json` too).

use std::time::Instant;

use serde::Serialize;
use voxlod::budget::BudgetLevel;
use voxlod::io::OutputSet;
use voxlod::{BudgetOptions, Lod};

use super::common::say;
use super::common::Input;
use super::common::{add_report, describe_mesh, in_dir, print_json, CliError};
use super::lod::{lod_error, print_repairs, LodArgs};
use super::lod_glb::{add_chain, GlbReport, LodFormat, CHAIN_FILE};
use super::source::MeshSummary;

/// The report of a budget run.
#[derive(Serialize)]
struct BudgetReport {
    input: String,
    /// For a mesh: what was read and what preparing it repaired.
    #[serde(skip_serializing_if = "Option::is_none")]
    mesh: Option<MeshSummary>,
    route: &'static str,
    then: voxlod::budget::Then,
    closed: bool,
    time_cap_seconds: f64,
    levels: Vec<BudgetLevelReport>,
    /// The MSFT_lod chain file, with --format glb.
    #[serde(skip_serializing_if = "Option::is_none")]
    glb: Option<GlbReport>,
    total_seconds: f64,
    /// Every warning, also printed on standard error without --json.
    warnings: Vec<String>,
}

#[derive(Serialize)]
struct BudgetLevelReport {
    level: usize,
    file: Option<String>,
    vertices: usize,
    closed_manifold: bool,
    #[serde(flatten)]
    budget: BudgetLevel,
}

/// Runs the budget pipeline as `args` ask (`--triangles` or `--error` was given).
pub fn run(args: &LodArgs) -> Result<(), CliError> {
    let start = Instant::now();
    let format = args.format();
    args.glb.check(format)?;
    let options = options(args);
    let input = args.route.read(&args.input)?;
    let source = args.route.source(&input);
    let lod = voxlod::lod_by_budget(&source, &options).map_err(|e| lod_error(args, e))?;
    let level_name = |level: usize| super::lod::level_name(args, level);
    let chain = format == LodFormat::Glb;
    let level_files = !chain || args.glb.split;
    let mut out = OutputSet::protecting([&args.input]);
    for i in 0..lod.levels.len() {
        if level_files {
            out.check(&in_dir(&args.output, &level_name(i)))?;
        }
    }
    if chain {
        out.check(&in_dir(&args.output, CHAIN_FILE))?;
    }
    out.create_dir(&args.output)?;
    let mut levels = Vec::new();
    for (i, (level, budget)) in lod.levels.iter().zip(&lod.budgets).enumerate() {
        let file = match (level.mesh.is_empty(), level_files) {
            (true, _) => None,
            (false, true) => Some(level_name(i)),
            (false, false) => Some(CHAIN_FILE.to_string()),
        };
        if let (Some(name), true) = (&file, level_files) {
            out.mesh(&in_dir(&args.output, name), &level.mesh)?;
        }
        let t = &level.topology;
        levels.push(BudgetLevelReport {
            level: i,
            file,
            vertices: level.mesh.positions.len(),
            closed_manifold: t.is_closed_manifold() && t.is_consistently_oriented(),
            budget: budget.clone(),
        });
    }
    let mut report = report(args, &options, &lod, levels, start);
    report.mesh = match (&input, lod.preparation) {
        (Input::Mesh(m), Some(preparation)) => Some(MeshSummary::of(m, preparation)),
        _ => None,
    };
    if chain {
        report.glb = Some(add_chain(&mut out, &args.output, &lod, &args.glb)?);
    }
    add_report(&mut out, &args.output, &report)?;
    out.commit()?;
    if args.json {
        return print_json(&report);
    }
    if let Some(m) = &report.mesh {
        print_repairs(args, &m.preparation);
    }
    for w in &report.warnings {
        eprintln!("warning: {w}");
    }
    for (l, level) in report.levels.iter().zip(&lod.levels) {
        say(format_args!("{}", describe_level(l, &level.mesh)));
    }
    say(format_args!(
        "{} levels in {:.2} s; report in {}",
        report.levels.len(),
        report.total_seconds,
        in_dir(&args.output, "report.json").display()
    ));
    Ok(())
}

/// The library options of `args`.
pub(super) fn options(args: &LodArgs) -> BudgetOptions {
    BudgetOptions {
        triangles: args.triangles.clone().unwrap_or_default(),
        error: args.error,
        then: args.then,
        filter: args.filter,
        radius_voxels: args.radius,
        lines_per_radius: args.lines_per_radius,
        iso: args.iso,
        normals: true,
        monotone: !args.no_monotone,
        closed: args.closed,
        fit: (!args.no_fit).then(voxlod::FitOptions::quick),
        time_cap: args.time_cap,
        frame: args.frame.target(),
    }
}

fn report(
    args: &LodArgs,
    options: &BudgetOptions,
    lod: &Lod,
    levels: Vec<BudgetLevelReport>,
    start: Instant,
) -> BudgetReport {
    BudgetReport {
        input: args.input.display().to_string(),
        mesh: None,
        route: lod.route.name(),
        then: options.then,
        closed: options.closed,
        time_cap_seconds: options.time_cap,
        levels,
        glb: None,
        total_seconds: start.elapsed().as_secs_f64(),
        warnings: lod.warnings.clone(),
    }
}

/// One line per level: budget, resolution, stage, what came out, the distance measured.
fn describe_level(l: &BudgetLevelReport, mesh: &voxlod::core::TriangleMesh) -> String {
    let b = &l.budget;
    let aim = match (b.budget, b.error_target) {
        (Some(n), _) => format!("budget {n}"),
        (None, Some(e)) => format!("error {e:.4}"),
        (None, None) => String::new(),
    };
    let distance = b
        .hausdorff
        .map(|h| format!(", Hausdorff {h:.4}"))
        .unwrap_or_default()
        + &b.silhouette_difference
            .map(|s| format!(", silhouette difference {s:.3}"))
            .unwrap_or_default();
    let how = match b.method {
        Some(m) if b.resolution > 0 => format!("{} at resolution {}", m.name(), b.resolution),
        Some(m) => m.name().to_string(),
        None => format!("resolution {}, then {:?}", b.resolution, b.stage),
    };
    format!(
        "level {}: {aim}: {how}: {}{distance} -> {}",
        l.level,
        describe_mesh(mesh),
        l.file.as_deref().unwrap_or("(empty, not written)")
    )
}
