//! `voxlod inspect`: the topology and health report of a mesh file.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use serde::Serialize;
use voxlod_metrics::{mesh_report, welded_mesh_report, MeshReport};

use super::common::{print_json, read_mesh_input, CliError};

/// Report a mesh's topology and health: counts, components, boundary loops, manifoldness,
/// orientation, duplicate and zero-area triangles, Euler characteristic, genus, area, volume.
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
#[derive(Args, Debug)]
#[command(verbatim_doc_comment)]
pub struct InspectArgs {
    /// The mesh (.obj .ply .stl .off .vtp .vtk)
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
    notes: Vec<String>,
    seconds: f64,
}

pub fn run(args: InspectArgs) -> Result<(), CliError> {
    let start = Instant::now();
    let loaded = read_mesh_input(&args.mesh)?;
    let name = args.mesh.display();
    let measured = if args.as_indexed {
        mesh_report(&loaded.mesh)
    } else {
        welded_mesh_report(&loaded.mesh)
    };
    let mut report = measured.map_err(|e| CliError::msg(format!("{name}: {e}")))?;
    // STL files are welded by the reader: count from the soup's corners.
    if let (Some(read_weld), Some(weld)) = (loaded.welded, report.welding.as_mut()) {
        weld.vertices_before = read_weld.vertices_before;
    }
    let mut notes = report.notes();
    if args.as_indexed {
        notes.insert(
            0,
            match loaded.welded {
                Some(w) => format!(
                    "counted as read: the STL reader welds a soup's {} corners into {} vertices",
                    w.vertices_before, w.vertices_after
                ),
                None => "counted as the file indexes its vertices (coincident vertices not welded)"
                    .into(),
            },
        );
    }
    if report.area <= 0.0 {
        notes.push(
            "the mesh has no area: every triangle is degenerate, so it cannot be compared, \
             sampled or simplified"
                .into(),
        );
    }
    let file_vertices = loaded
        .welded
        .map_or(loaded.mesh.positions.len(), |w| w.vertices_before);
    let output = InspectReport {
        input: name.to_string(),
        format: loaded.format.to_string(),
        file_vertices,
        file_triangles: loaded.mesh.triangles.len(),
        polygons_triangulated: loaded.polygons_triangulated,
        welded: !args.as_indexed,
        report,
        notes,
        seconds: start.elapsed().as_secs_f64(),
    };
    if args.json {
        return print_json(&output);
    }
    println!(
        "{name} ({}): {} vertices and {} triangles in the file{}",
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
    );
    // The report's own text, without its notes: ours follow, with the additions above.
    let text = output.report.to_string();
    for line in text.lines().filter(|l| !l.starts_with("note: ")) {
        println!("{line}");
    }
    for note in &output.notes {
        println!("note: {note}");
    }
    Ok(())
}
