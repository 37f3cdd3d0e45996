//! `voxlod inspect`: the topology and health report of a mesh file.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use serde::Serialize;
use voxlod::core::TriangleMesh;
use voxlod::metrics::{mesh_report, welded_mesh_report, MeshReport};
use voxlod_gltf::{read_glb, GlbPart};

use super::common::say;
use super::common::{count, is_glb, print_json, read_mesh_input, CliError};

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
    /// The mesh (.obj .ply .stl .off .vtp .vtk .glb)
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

/// The report of `mesh`, welded unless `as_indexed`; errors name the file.
fn measure(mesh: &TriangleMesh, as_indexed: bool, name: &str) -> Result<MeshReport, CliError> {
    let measured = if as_indexed {
        mesh_report(mesh)
    } else {
        welded_mesh_report(mesh)
    };
    measured.map_err(|e| CliError::msg(format!("{name}: {e}")))
}

pub fn run(args: InspectArgs) -> Result<(), CliError> {
    let start = Instant::now();
    let output = if is_glb(&args.mesh) {
        inspect_glb(&args)?
    } else {
        inspect_mesh(&args)?
    };
    let output = InspectReport {
        seconds: start.elapsed().as_secs_f64(),
        ..output
    };
    if args.json {
        return print_json(&output);
    }
    print_text(&output);
    Ok(())
}

/// A mesh file of any format the readers know.
fn inspect_mesh(args: &InspectArgs) -> Result<InspectReport, CliError> {
    let loaded = read_mesh_input(&args.mesh)?;
    let name = args.mesh.display().to_string();
    let mut report = measure(&loaded.mesh, args.as_indexed, &name)?;
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
    no_area_note(&report, &mut notes);
    let file_vertices = loaded
        .welded
        .map_or(loaded.mesh.positions.len(), |w| w.vertices_before);
    Ok(InspectReport {
        input: name,
        format: loaded.format.to_string(),
        file_vertices,
        file_triangles: loaded.mesh.triangles.len(),
        polygons_triangulated: loaded.polygons_triangulated,
        welded: !args.as_indexed,
        report,
        parts: Vec::new(),
        notes,
        seconds: 0.0,
        warnings: Vec::new(),
    })
}

/// A binary glTF file, as `voxlod render` reads it: every mesh on its own (the shells of a
/// layered file), and all together.
fn inspect_glb(args: &InspectArgs) -> Result<InspectReport, CliError> {
    let name = args.mesh.display().to_string();
    let scene = read_glb(&args.mesh).map_err(|e| CliError::msg(e.to_string()))?;
    let mut parts = Vec::new();
    for (index, p) in scene.parts.iter().enumerate() {
        let what = format!("{name}: mesh {index} ('{}')", p.name);
        let mesh = part_mesh(&scene.mesh, p).ok_or_else(|| {
            CliError::msg(format!("{what}: a triangle uses a vertex of another mesh"))
        })?;
        parts.push(PartReport {
            index,
            name: p.name.clone(),
            alpha: p.color[3],
            report: measure(&mesh, args.as_indexed, &what)?,
        });
    }
    let report = measure(&scene.mesh, args.as_indexed, &name)?;
    let mut notes = report.notes();
    let layered = scene.is_layered();
    if layered {
        notes.insert(
            0,
            format!(
                "a layered file of {}: each layer is reported on its own, innermost first, and \
                 the counts above are of all layers together",
                count(parts.len(), "layer", "layers")
            ),
        );
    }
    no_area_note(&report, &mut notes);
    Ok(InspectReport {
        input: name,
        format: if layered {
            "glTF binary, layered".into()
        } else {
            "glTF binary".into()
        },
        file_vertices: scene.mesh.positions.len(),
        file_triangles: scene.mesh.triangles.len(),
        polygons_triangulated: 0,
        welded: !args.as_indexed,
        report,
        parts,
        notes,
        seconds: 0.0,
        warnings: Vec::new(),
    })
}

/// One part of a glTF scene as a mesh of its own vertices, or `None` when a triangle of the
/// part names a vertex outside it.
fn part_mesh(all: &TriangleMesh, part: &GlbPart) -> Option<TriangleMesh> {
    let (v0, nv) = (part.first_vertex as usize, part.vertex_count as usize);
    let (t0, nt) = (part.first_triangle as usize, part.triangle_count as usize);
    let positions = all.positions.get(v0..v0 + nv)?.to_vec();
    let triangles = all
        .triangles
        .get(t0..t0 + nt)?
        .iter()
        .map(|t| {
            let local = t.map(|v| (v as usize).checked_sub(v0).filter(|&l| l < nv));
            match local {
                [Some(a), Some(b), Some(c)] => Some([a as u32, b as u32, c as u32]),
                _ => None,
            }
        })
        .collect::<Option<Vec<_>>>()?;
    Some(TriangleMesh::new(positions, triangles))
}

fn no_area_note(report: &MeshReport, notes: &mut Vec<String>) {
    if report.area <= 0.0 {
        notes.push(
            "the mesh has no area: every triangle is degenerate, so it cannot be compared, \
             sampled or simplified"
                .into(),
        );
    }
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
