//! `voxlod demo`: the paper's Table 1 on a generated sphereflake, no input needed.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use serde::Serialize;
use voxlod::io::OutputSet;
use voxlod::sampling::{sphereflake, CsgSolid};
use voxlod::{Control, Event, LodOptions, Progress, Source};

use super::common::say;
use super::common::{add_report, in_dir, print_json, progress, thousands, CliError};
use voxlod_eval::paper_tables::PAPER_TABLE1;

/// Run the paper's Table 1 on a generated 820-sphere sphereflake (no input needed).
///
/// Builds the sphereflake of He et al. (1995, §4) as an exact union of 820 spheres, filters it
/// with the Gaussian at resolutions 200, 100, 50, 30, 15 and 5 (radius one voxel of each level),
/// extracts each level at isodensity 0.5 and prints our triangle counts beside the paper's.
/// The level meshes and report.json go to DIR.
#[derive(Args, Debug)]
pub struct DemoArgs {
    /// Folder for the level meshes and report.json (created if missing)
    #[arg(short, long, value_name = "DIR", default_value = "voxlod-demo")]
    pub output: PathBuf,
    /// Print the report as JSON on standard output
    #[arg(long)]
    pub json: bool,
}

#[derive(Serialize)]
struct Row {
    index: &'static str,
    resolution: usize,
    radius_in_finest_voxels: f64,
    paper_triangles: usize,
    triangles: usize,
    vertices: usize,
    genus: Option<i64>,
    closed_manifold: bool,
    seconds: f64,
    file: String,
}

#[derive(Serialize)]
struct DemoReport {
    object: &'static str,
    spheres: usize,
    filter: &'static str,
    iso: f32,
    table1: Vec<Row>,
    total_seconds: f64,
    /// Every warning printed without --json.
    warnings: Vec<String>,
}

pub fn run(args: DemoArgs) -> Result<(), CliError> {
    let start = Instant::now();
    let solid = CsgSolid::new(sphereflake(3)).map_err(voxlod::Error::from)?;
    let options = LodOptions::paper_table1();
    let bar = progress(PAPER_TABLE1.len() as u64, "table 1", args.json);
    let level_made = |p: Progress| {
        if let Event::LodLevel(_) = p.event {
            bar.inc(1);
        }
        Control::Continue
    };
    let lod = voxlod::lod_with(&Source::Solid(&solid), &options, &level_made)?;
    bar.finish_and_clear();
    let mut out = OutputSet::new();
    out.create_dir(&args.output)?;
    let mut rows = Vec::new();
    for (level, &(index, resolution, paper_radius, paper_triangles)) in
        lod.levels.iter().zip(&PAPER_TABLE1)
    {
        debug_assert_eq!(level.resolution, resolution);
        let file = format!("level-{}.ply", level.plan.level);
        out.mesh(&in_dir(&args.output, &file), &level.mesh)?;
        let t = &level.topology;
        rows.push(Row {
            index,
            resolution,
            radius_in_finest_voxels: paper_radius,
            paper_triangles,
            triangles: level.mesh.triangles.len(),
            vertices: level.mesh.positions.len(),
            genus: t.genus,
            closed_manifold: t.is_closed_manifold() && t.is_consistently_oriented(),
            seconds: level.sample_seconds + level.contour_seconds,
            file,
        });
    }
    let report = DemoReport {
        object: "sphereflake (He et al. 1995, Table 1)",
        spheres: voxlod::sampling::sphereflake_spheres(3).len(),
        filter: "gaussian, sigma = R/3",
        iso: lod.iso,
        table1: rows,
        total_seconds: start.elapsed().as_secs_f64(),
        warnings: Vec::new(),
    };
    add_report(&mut out, &args.output, &report)?;
    // Paper §3, Figure 7: single surface, layered shells and the 16x16 reference, side by side.
    let antialias = voxlod_eval::antialias::demo_comparison(&mut out, &args.output)
        .map_err(voxlod::Error::from)?;
    out.commit()?;
    if args.json {
        return print_json(&report);
    }
    say(format_args!(
        "Table 1 of He, Hong, Kaufman, Varshney, Wang (1995): the {}-sphere sphereflake,",
        report.spheres
    ));
    say(format_args!(
        "Gaussian filter of radius one voxel per level, isodensity 0.5.\n"
    ));
    say(format_args!(
        "{:<6}{:>12}{:>8}{:>18}{:>18}{:>8}{:>7}{:>9}",
        "index",
        "resolution",
        "radius",
        "paper triangles",
        "voxlod triangles",
        "ratio",
        "genus",
        "seconds"
    ));
    for r in &report.table1 {
        say(format_args!(
            "{:<6}{:>12}{:>8}{:>18}{:>18}{:>8.2}{:>7}{:>9.3}",
            r.index,
            format!("{0}x{0}x{0}", r.resolution),
            r.radius_in_finest_voxels,
            thousands(r.paper_triangles),
            thousands(r.triangles),
            r.triangles as f64 / r.paper_triangles as f64,
            r.genus.map_or("-".into(), |g| g.to_string()),
            r.seconds
        ));
    }
    say(format_args!(
        "\nAll {} levels are closed manifolds: {}. Meshes and report.json in {} ({:.2} s).",
        report.table1.len(),
        report.table1.iter().all(|r| r.closed_manifold),
        args.output.display(),
        report.total_seconds
    ));
    say(format_args!("{antialias}"));
    Ok(())
}
