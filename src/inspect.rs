//! A mesh's topology and health in one call: components, boundary loops, non-manifold edges and
//! vertices, orientation, degenerate, duplicate and zero-area triangles, Euler characteristic,
//! genus, area and volume ([`voxlod_metrics::health`]), counted after welding coincident
//! vertices by default, so a triangle soup is judged by the surface it describes; and the same
//! for each mesh of a glTF scene (the layers of a layered file). Cost: O(V + T) after an
//! O(V log V) weld.

use std::path::Path;

use voxlod_core::TriangleMesh;
use voxlod_gltf::{GlbPart, GlbScene};
use voxlod_io::{FileKind, IoError, IoErrorKind};
use voxlod_layers::LayersError;
use voxlod_metrics::{mesh_report, welded_mesh_report, MeshReport};

use crate::error::Error;
use crate::files::{is_glb, is_gltf, read_glb};

/// Options of [`inspect`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct InspectOptions {
    /// Weld coincident vertices (identical coordinates) before counting.
    pub welded: bool,
}

impl Default for InspectOptions {
    /// Welded.
    fn default() -> Self {
        InspectOptions::welded()
    }
}

impl InspectOptions {
    /// Count after welding coincident vertices (the default).
    pub fn welded() -> Self {
        InspectOptions { welded: true }
    }

    /// Count vertices as the mesh indexes them.
    pub fn as_indexed() -> Self {
        InspectOptions { welded: false }
    }
}

/// A mesh's report and notes in words.
#[derive(Clone, Debug)]
pub struct Inspection {
    /// The figures.
    pub report: MeshReport,
    /// What the figures mean where they are unusual (open, non-manifold, no area, …).
    pub notes: Vec<String>,
}

/// One mesh of a scene.
#[derive(Clone, Debug)]
pub struct PartInspection {
    /// Its index in the scene.
    pub index: usize,
    /// Its name in the file.
    pub name: String,
    /// Its material's alpha: the layer's opacity.
    pub alpha: f32,
    /// Its figures.
    pub report: MeshReport,
}

/// A scene: every mesh on its own, and all together.
#[derive(Clone, Debug)]
pub struct SceneInspection {
    /// All meshes together.
    pub whole: Inspection,
    /// Each mesh, in file order (a layered file's layers, innermost first).
    pub parts: Vec<PartInspection>,
    /// Whether the file is layered (it holds the eight back-to-front orders).
    pub layered: bool,
}

/// The report of `mesh`.
///
/// ```
/// # fn main() -> Result<(), voxlod::Error> {
/// use voxlod::core::glam::Vec3;
/// // A tetrahedron: closed, genus 0, four faces.
/// let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
/// let t = vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
/// let tetra = voxlod::core::TriangleMesh::new(p, t);
/// let inspection = voxlod::inspect(&tetra, &voxlod::InspectOptions::default())?;
/// assert!(inspection.report.closed_manifold && inspection.report.consistently_oriented);
/// assert_eq!(inspection.report.topology.genus, Some(0));
/// assert!((inspection.report.volume - 1.0 / 6.0).abs() < 1e-9);
/// # Ok(())
/// # }
/// ```
pub fn inspect(mesh: &TriangleMesh, options: &InspectOptions) -> Result<Inspection, Error> {
    Ok(with_notes(measure(mesh, options)?))
}

/// `report` with its notes, and one more for a mesh without area.
fn with_notes(report: MeshReport) -> Inspection {
    let mut notes = report.notes();
    if report.area <= 0.0 {
        notes.push(
            "the mesh has no area: every triangle is degenerate, so it cannot be compared, \
             sampled or simplified"
                .into(),
        );
    }
    Inspection { report, notes }
}

fn measure(mesh: &TriangleMesh, options: &InspectOptions) -> Result<MeshReport, Error> {
    Ok(if options.welded {
        welded_mesh_report(mesh)?
    } else {
        mesh_report(mesh)?
    })
}

/// The report of every mesh of `scene` on its own and of all together; an error names the
/// mesh.
pub fn inspect_scene(scene: &GlbScene, options: &InspectOptions) -> Result<SceneInspection, Error> {
    let mut parts = Vec::new();
    for (index, p) in scene.parts.iter().enumerate() {
        let what = format!("mesh {index} ('{}')", p.name);
        let mesh = part_mesh(&scene.mesh, p).ok_or_else(|| {
            let problem = "a triangle uses a vertex of another mesh".to_string();
            Error::from(LayersError::Gltf(problem)).context(what.clone())
        })?;
        parts.push(PartInspection {
            index,
            name: p.name.clone(),
            alpha: p.color[3],
            report: measure(&mesh, options).map_err(|e| e.context(what))?,
        });
    }
    let mut whole = inspect(&scene.mesh, options)?;
    let layered = scene.is_layered();
    if layered {
        whole.notes.insert(
            0,
            format!(
                "a layered file of {} {}: each layer is reported on its own, innermost first, \
                 and the counts above are of all layers together",
                parts.len(),
                if parts.len() == 1 { "layer" } else { "layers" }
            ),
        );
    }
    Ok(SceneInspection {
        whole,
        parts,
        layered,
    })
}

/// A mesh file's inspection: what the file holds as read, and the figures.
#[derive(Clone, Debug)]
pub struct FileInspection {
    /// The format in words (`OBJ`, `binary PLY`, `glTF binary, layered`, …).
    pub format: String,
    /// Vertices as the file holds them (an STL's corners, before the reader welds them).
    pub file_vertices: usize,
    /// Triangles as read.
    pub file_triangles: usize,
    /// Polygons the reader split into triangles (by ear clipping).
    pub polygons_triangulated: usize,
    /// All meshes of the file together, with the notes (first, how the file was counted).
    pub whole: Inspection,
    /// Each mesh of a glTF file on its own, in file order; empty for other formats.
    pub parts: Vec<PartInspection>,
}

/// The report of the mesh file at `path`, by its extension: a `.glb` mesh by mesh and as a
/// whole ([`inspect_scene`]), any other mesh format as one mesh ([`inspect`]), an STL's
/// welding counted from the soup's corners. A volume is refused. Errors name the file.
///
/// ```
/// # fn main() -> Result<(), voxlod::Error> {
/// let dir = std::env::temp_dir().join(format!("voxlod-doc-inspect-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// let path = dir.join("square.obj");
/// std::fs::write(&path, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n").unwrap();
/// let i = voxlod::inspect_file(&path, &voxlod::InspectOptions::default())?;
/// assert_eq!((i.file_vertices, i.file_triangles, i.polygons_triangulated), (4, 2, 1));
/// assert_eq!(i.whole.report.topology.boundary_loops, 1);
/// # std::fs::remove_dir_all(&dir).unwrap();
/// # Ok(())
/// # }
/// ```
pub fn inspect_file(
    path: impl AsRef<Path>,
    options: &InspectOptions,
) -> Result<FileInspection, Error> {
    let path = path.as_ref();
    let inspection = if is_gltf(path) {
        inspect_gltf_file(path, options)
    } else {
        inspect_mesh_file(path, options)
    };
    inspection.map_err(|e| e.in_file(path))
}

/// [`inspect_file`] of a mesh format the readers know.
fn inspect_mesh_file(path: &Path, options: &InspectOptions) -> Result<FileInspection, Error> {
    if let FileKind::Volume(_) = voxlod_io::file_kind(path)? {
        let problem = "this is a volume; inspecting takes a mesh";
        return Err(IoError::new(path, IoErrorKind::Unsupported, problem).into());
    }
    let loaded = voxlod_io::read_mesh(path)?;
    let mut report = measure(&loaded.mesh, options)?;
    // The STL reader welds the soup: count from its corners.
    if let (Some(read_weld), Some(weld)) = (loaded.welded, report.welding.as_mut()) {
        weld.vertices_before = read_weld.vertices_before;
    }
    let mut whole = with_notes(report);
    if !options.welded {
        let note = match loaded.welded {
            Some(w) => format!(
                "counted as read: the STL reader welds a soup's {} corners into {} vertices",
                w.vertices_before, w.vertices_after
            ),
            None => {
                "counted as the file indexes its vertices (coincident vertices not welded)".into()
            }
        };
        whole.notes.insert(0, note);
    }
    // What reading changed (an unstructured grid's volume cells read as their boundary).
    whole.notes.extend(loaded.notes.iter().cloned());
    Ok(FileInspection {
        format: loaded.format.to_string(),
        file_vertices: loaded
            .welded
            .map_or(loaded.mesh.positions.len(), |w| w.vertices_before),
        file_triangles: loaded.mesh.triangles.len(),
        polygons_triangulated: loaded.polygons_triangulated,
        whole,
        parts: Vec::new(),
    })
}

/// [`inspect_file`] of a glTF file (`.glb`, or `.gltf` with its buffers beside it).
fn inspect_gltf_file(path: &Path, options: &InspectOptions) -> Result<FileInspection, Error> {
    let scene = read_glb(path)?;
    let inspection = inspect_scene(&scene, options)?;
    let format = match (is_glb(path), inspection.layered) {
        (true, true) => "glTF binary, layered",
        (true, false) => "glTF binary",
        (false, _) => "glTF",
    };
    Ok(FileInspection {
        format: format.into(),
        file_vertices: scene.mesh.positions.len(),
        file_triangles: scene.mesh.triangles.len(),
        polygons_triangulated: 0,
        whole: inspection.whole,
        parts: inspection.parts,
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
