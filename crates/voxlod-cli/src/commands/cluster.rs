//! `voxlod cluster`: the vertex-clustering baselines, Rossignac–Borrel and Low–Tan.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use serde::Serialize;
use voxlod::clustering::{LevelReport, Method, Synthesis};
use voxlod::ClusteringOptions;

use super::common::say;
use super::common::{
    in_file, level_path, print_json, progress, read_mesh_input, thousands, CliError,
};
use super::values::number;

/// Simplify a mesh by vertex clustering: the baselines voxlod is compared with.
///
/// rossignac-borrel (1993): vertices are graded, clustered on a uniform grid of N cells along the
/// object's longest side, replaced by their weighted centre (--synthesis mean) or heaviest
/// vertex (max-weight), and the triangles that collapse become dangling edges or isolated
/// points (§3.5). More levels merge the clusters of an octree (§4).
///
/// low-tan (patent): the heaviest unclustered vertex becomes the centre of a floating cell of the
/// grid's cell size; degenerate triangles become thick edges with a width and a normal the
/// renderer turns towards the viewer.
///
/// Triangles, dangling edges (with their widths) and isolated points all reach the file: PLY
/// with `edge` and `point` elements, or VTK PolyData with polys, lines and verts. With several
/// levels, OUT's name gets the level: out.ply -> out-0.ply, out-1.ply, ...
///
/// OUT.glb is one glTF file with every level: a mesh per level with a TRIANGLES, a LINES
/// (the edges' widths as a _WIDTH attribute) and a POINTS primitive, chained with MSFT_lod
/// finest first and switched by the pixel-size rule of `voxlod select` on the cell sizes
/// (MSFT_screencoverage); `voxlod view` draws it.
///
/// Examples:
///   voxlod cluster bunny.obj -o bunny-rb.ply --method rossignac-borrel --cells 64
///   voxlod cluster bunny.obj -o bunny-lt.vtp --method low-tan --cells 32 --levels 4 --json
///   voxlod cluster bunny.obj -o bunny-lt.glb --method low-tan --cells 64 --levels 4
#[derive(Args, Debug)]
#[command(verbatim_doc_comment)]
pub struct ClusterArgs {
    /// The input mesh
    pub input: PathBuf,
    /// Output (.ply, .vtp or .vtk: formats that hold edges and points; .glb: every level in one
    /// MSFT_lod chain)
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    /// rossignac-borrel or low-tan
    #[arg(long, default_value = "rossignac-borrel")]
    pub method: Method,
    /// Cells along the longest side of the object's box at the finest level
    #[arg(long, value_name = "N", value_parser = number::<u32>, allow_hyphen_values = true)]
    pub cells: u32,
    /// Levels, each with cells twice as large
    #[arg(long, value_name = "L", default_value_t = 1,
        value_parser = number::<u32>, allow_hyphen_values = true)]
    pub levels: u32,
    /// Rossignac–Borrel synthesis: mean (weighted centre, smoothing) or max-weight (the
    /// heaviest vertex, detail removal)
    #[arg(long, default_value = "mean")]
    pub synthesis: Synthesis,
    /// Thick edges (widths and normals on the dangling edges): on for low-tan, off for
    /// rossignac-borrel unless given
    #[arg(long)]
    pub thick_edges: Option<bool>,
    /// Print the report as JSON on standard output
    #[arg(long)]
    pub json: bool,
}

#[derive(Serialize)]
struct ClusterLevel {
    #[serde(flatten)]
    report: LevelReport,
    file: String,
    write_seconds: f64,
}

#[derive(Serialize)]
struct ClusterReport {
    input: String,
    method: Method,
    input_triangles: usize,
    levels: Vec<ClusterLevel>,
    /// Every warning printed without --json.
    warnings: Vec<String>,
}

pub fn run(args: ClusterArgs) -> Result<(), CliError> {
    let ext = args
        .output
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    if !["ply", "vtp", "vtk", "glb"].contains(&ext.as_str()) {
        return Err(CliError::usage(format!(
            "{}: clustering output has dangling edges and points; write .ply, .vtp, .vtk or .glb",
            args.output.display()
        )));
    }
    let glb = ext == "glb";
    let mut out = voxlod::io::OutputSet::protecting([&args.input]);
    if glb {
        out.check(&args.output)?;
    } else {
        for level in 0..args.levels as usize {
            out.check(&level_path(&args.output, level, args.levels as usize))?;
        }
    }
    let loaded = read_mesh_input(&args.input)?;
    let mesh = &loaded.mesh;
    let options = ClusteringOptions {
        method: args.method,
        cells: args.cells,
        levels: args.levels,
        synthesis: args.synthesis,
        thick_edges: args.thick_edges,
    };
    let bar = progress(1, "clustering", args.json);
    let start = Instant::now();
    let levels = voxlod::cluster(mesh, &options).map_err(|e| in_file(&args.input, e))?;
    let total = start.elapsed().as_secs_f64();
    bar.finish_and_clear();
    let mut report = ClusterReport {
        input: args.input.display().to_string(),
        method: args.method,
        input_triangles: mesh.triangles.len(),
        levels: Vec::new(),
        warnings: Vec::new(),
    };
    if glb {
        let start = Instant::now();
        let bytes = voxlod::cluster_glb(&levels).map_err(|e| in_file(&args.output, e))?;
        out.bytes(&args.output, &bytes)?;
        let seconds = start.elapsed().as_secs_f64();
        for level in &levels {
            report.levels.push(ClusterLevel {
                report: level.report.clone(),
                file: args.output.display().to_string(),
                write_seconds: seconds,
            });
        }
    }
    for level in levels.iter().filter(|_| !glb) {
        let path = level_path(&args.output, level.report.level, args.levels as usize);
        let start = Instant::now();
        out.poly_mesh(&path, &level.mesh)?;
        report.levels.push(ClusterLevel {
            report: level.report.clone(),
            file: path.display().to_string(),
            write_seconds: start.elapsed().as_secs_f64(),
        });
    }
    out.commit()?;
    if args.json {
        return print_json(&report);
    }
    print_levels(&report, mesh.triangles.len(), total);
    Ok(())
}

/// One line per level and a summary, without --json.
fn print_levels(report: &ClusterReport, input_triangles: usize, total: f64) {
    for l in &report.levels {
        say(format_args!(
            "level {}: {} cells of {:.4}: {} triangles, {} dangling edges, {} isolated points in {:.3} s -> {}",
            l.report.level,
            l.report.cells,
            l.report.cell_size,
            thousands(l.report.triangles),
            thousands(l.report.dangling_edges),
            thousands(l.report.isolated_points),
            l.report.cluster_seconds,
            l.file
        ));
    }
    say(format_args!(
        "{} triangles in, {} levels in {total:.3} s",
        thousands(input_triangles),
        report.levels.len()
    ));
}
