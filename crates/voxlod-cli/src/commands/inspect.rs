//! `voxlod inspect`: the topology and health report of a mesh file.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use serde::Serialize;
use voxlod::metrics::MeshReport;
use voxlod::InspectOptions;

use super::common::say;
use super::common::{count, print_json, CliError};

/// Report a mesh's topology and health: counts, components, boundary loops, manifoldness,
/// orientation, duplicate and zero-area triangles, Euler characteristic, genus, area, volume.
///
/// A .glb file (the layered shells of `voxlod layers`, or any binary glTF) is reported mesh by
/// mesh (layer by layer, innermost first) and as a whole.
///
/// Counts are of the mesh after coincident vertices (identical coordinates) are welded, so that
/// a triangle soup such as an STL file is judged by the surface it describes; the report says
/// how many vertices the file held and how many welding left (--as-indexed counts the file's
/// own indexing instead). Triangles are what the reader makes of the file: polygons are split
/// by ear clipping. A mesh without area is reported, with a note.
///
/// Examples:
///   voxlod inspect bunny.obj
///   voxlod inspect part.stl --json
///   voxlod inspect scan.ply --as-indexed
///   voxlod inspect bunny.glb
#[derive(Args, Debug)]
#[command(verbatim_doc_comment)]
pub struct InspectArgs {
    /// The mesh (.obj .ply .stl .off .vtp .vtu .vtk .glb .gltf)
    pub mesh: PathBuf,
    /// Count vertices as the file indexes them, without welding coincident ones
    #[arg(long)]
    pub as_indexed: bool,
    /// Print the report as JSON on standard output
    #[arg(long)]
    pub json: bool,
}

/// The JSON report: the file, then the metrics crate's report at the top level.
#[derive(Serialize)]
struct InspectReport {
    input: String,
    format: String,
    /// Vertices and triangles as the file holds them (an STL's corners before its welding).
    file_vertices: usize,
    file_triangles: usize,
    polygons_triangulated: usize,
    /// Whether coincident vertices were welded before counting.
    welded: bool,
    #[serde(flatten)]
    report: MeshReport,
    /// The meshes of a `.glb` file (the layers of `voxlod layers`, innermost first), each
    /// reported on its own; the report above is of all of them together.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    parts: Vec<PartReport>,
    notes: Vec<String>,
    seconds: f64,
    /// Every warning printed without --json.
    warnings: Vec<String>,
}

/// One mesh of a `.glb` file.
#[derive(Serialize)]
struct PartReport {
    index: usize,
    name: String,
    /// The material's alpha: the layer's opacity.
    alpha: f32,
    #[serde(flatten)]
    report: MeshReport,
}

pub fn run(args: InspectArgs) -> Result<(), CliError> {
    let start = Instant::now();
    let options = if args.as_indexed {
        InspectOptions::as_indexed()
    } else {
        InspectOptions::welded()
    };
    let file = voxlod::inspect_file(&args.mesh, &options)?;
    let output = InspectReport {
        input: args.mesh.display().to_string(),
        format: file.format,
        file_vertices: file.file_vertices,
        file_triangles: file.file_triangles,
        polygons_triangulated: file.polygons_triangulated,
        welded: options.welded,
        report: file.whole.report,
        parts: file
            .parts
            .into_iter()
            .map(|p| PartReport {
                index: p.index,
                name: p.name,
                alpha: p.alpha,
                report: p.report,
            })
            .collect(),
        notes: file.whole.notes,
        seconds: start.elapsed().as_secs_f64(),
        warnings: Vec::new(),
    };
    if args.json {
        return print_json(&output);
    }
    print_text(&output);
    Ok(())
}

fn print_text(output: &InspectReport) {
    say(format_args!(
        "{} ({}): {} vertices and {} triangles in the file{}",
        output.input,
        output.format,
        output.file_vertices,
        output.file_triangles,
        if output.polygons_triangulated > 0 {
            format!(
                " ({} polygons split into triangles)",
                output.polygons_triangulated
            )
        } else {
            String::new()
        }
    ));
    for p in &output.parts {
        let t = &p.report.topology;
        say(format_args!(
            "mesh {} '{}' (alpha {:.3}): {} vertices, {} triangles, {}, {}, {}, genus {}",
            p.index,
            p.name,
            p.alpha,
            t.vertices,
            t.triangles,
            count(t.components, "component", "components"),
            count(t.boundary_loops, "boundary loop", "boundary loops"),
            if p.report.closed_manifold && p.report.consistently_oriented {
                "closed and consistently oriented"
            } else {
                "not a closed, consistently oriented manifold"
            },
            t.genus.map_or("undefined".to_string(), |g| g.to_string())
        ));
    }
    // The report's own text, without its notes: ours follow, with the additions above.
    let text = output.report.to_string();
    for line in text.lines().filter(|l| !l.starts_with("note: ")) {
        say(format_args!("{line}"));
    }
    for note in &output.notes {
        say(format_args!("note: {note}"));
    }
}
