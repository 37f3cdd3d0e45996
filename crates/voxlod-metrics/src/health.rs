//! Mesh health: what shape a mesh is in, in one serialisable report.
//!
//! The combinatorial part (edges, boundary loops, manifoldness, orientation, duplicates,
//! components, Euler characteristic, genus) is [`voxlod_core::mesh_topology`], flattened into
//! the report unchanged. This module adds the geometry: surface area, signed enclosed volume
//! (divergence theorem; negative when a closed shell is inside out), bounding box and its
//! diagonal, and the triangles of zero geometric area whose three vertex indices differ
//! (collinear or coincident corners), which the index-based topology cannot see.
//!
//! Cost: the topology's O(F log F) edge sort, plus one linear pass over the triangles.
//! [`welded_mesh_report`] also copies the mesh and welds it, O(V) expected.

use std::fmt;

use rayon::prelude::*;
use serde::Serialize;
use voxlod_core::weld::weld_vertices;
use voxlod_core::{mesh_topology, Topology, TriangleMesh};

use crate::error::{check_mesh, MetricsError};

/// Topology and geometry of a mesh (see the module documentation).
///
/// In JSON the topology's fields (`vertices`, `components`, `boundary_loops`, `genus`, …) sit
/// at the top level beside `area`, `volume` and the rest; `genus` is `null` where undefined.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MeshReport {
    /// Counts, manifoldness, orientation, components and genus from the vertex indices.
    #[serde(flatten)]
    pub topology: Topology,
    /// Triangles with three distinct vertex indices but no area: the height over the longest
    /// edge is below `f32` precision of that edge (`|ab × ac| ≤ ε·L²`). Triangles with a
    /// repeated index are counted in `degenerate_triangles` instead.
    pub zero_area_triangles: usize,
    /// Total surface area.
    pub area: f64,
    /// Signed volume by the divergence theorem. It is the enclosed volume when
    /// `volume_is_enclosed`; negative then means the shell is inside out.
    pub volume: f64,
    /// The mesh is a closed, consistently oriented 2-manifold, so `volume` is what it encloses.
    pub volume_is_enclosed: bool,
    /// A closed, consistently oriented shell whose triangles wind clockwise seen from outside
    /// (negative volume).
    pub inside_out: bool,
    /// [`Topology::is_closed_manifold`]: no boundary, every edge shared by two triangles, every
    /// vertex a single fan.
    pub closed_manifold: bool,
    /// [`Topology::is_consistently_oriented`]: neighbouring triangles agree across every edge.
    pub consistently_oriented: bool,
    /// Bounds of the vertices that triangles use.
    pub bounds: BoxReport,
    /// Length of the diagonal of `bounds`.
    pub diagonal: f64,
    /// Set by [`welded_mesh_report`]: the counts above are of the welded mesh.
    pub welding: Option<WeldSummary>,
}

/// An axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct BoxReport {
    /// The smallest x, y and z.
    pub min: [f64; 3],
    /// The largest x, y and z.
    pub max: [f64; 3],
}

/// How many vertices welding coincident ones left.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct WeldSummary {
    /// Vertices in the mesh as given.
    pub vertices_before: usize,
    /// Vertices once coincident ones are merged.
    pub vertices_after: usize,
}

/// The health report of `mesh` as it is indexed (coincident vertices with different indices
/// count as different vertices: see [`welded_mesh_report`] for triangle soups).
///
/// Fails on an empty mesh, an out-of-range index or a non-finite coordinate. A mesh with no
/// area is reported, not refused.
///
/// A triangle soup (every triangle with its own corners, as in STL) is twelve separate pieces
/// until its coincident corners are welded:
///
/// ```
/// use voxlod_core::{glam::Vec3, TriangleMesh};
/// use voxlod_metrics::{mesh_report, welded_mesh_report, WeldSummary};
///
/// let corners = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
/// let faces = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
/// let soup = TriangleMesh::new(
///     faces.iter().flat_map(|f| f.map(|v| corners[v])).collect(),
///     (0..4).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect(),
/// );
/// let as_stored = mesh_report(&soup)?;
/// assert_eq!((as_stored.topology.components, as_stored.topology.boundary_loops), (4, 4));
/// assert!(!as_stored.closed_manifold);
///
/// let welded = welded_mesh_report(&soup)?;
/// assert!(welded.closed_manifold && welded.volume_is_enclosed);
/// let summary = WeldSummary { vertices_before: 12, vertices_after: 4 };
/// assert_eq!(welded.welding, Some(summary));
/// # Ok::<(), voxlod_metrics::MetricsError>(())
/// ```
pub fn mesh_report(mesh: &TriangleMesh) -> Result<MeshReport, MetricsError> {
    check_mesh(mesh)?;
    let topology = mesh_topology(mesh);
    let bounds = mesh.bounds();
    let volume = mesh.signed_volume();
    let closed_manifold = topology.is_closed_manifold();
    let consistently_oriented = topology.is_consistently_oriented();
    let volume_is_enclosed = closed_manifold && consistently_oriented;
    Ok(MeshReport {
        zero_area_triangles: count_zero_area_triangles(mesh),
        area: mesh.area(),
        volume,
        volume_is_enclosed,
        inside_out: volume_is_enclosed && volume < 0.0,
        closed_manifold,
        consistently_oriented,
        bounds: BoxReport {
            min: bounds.min.to_array(),
            max: bounds.max.to_array(),
        },
        diagonal: bounds.diagonal(),
        welding: None,
        topology,
    })
}

/// The health report of `mesh` after welding vertices with identical coordinates (on a copy),
/// as triangle soups such as STL files need; `welding` records the vertex counts.
pub fn welded_mesh_report(mesh: &TriangleMesh) -> Result<MeshReport, MetricsError> {
    check_mesh(mesh)?;
    let mut welded = mesh.clone();
    let weld = weld_vertices(&mut welded);
    let mut report = mesh_report(&welded)?;
    report.welding = Some(WeldSummary {
        vertices_before: weld.vertices_before,
        vertices_after: weld.vertices_after,
    });
    Ok(report)
}

/// Triangles with distinct indices and zero geometric area (see [`MeshReport::zero_area_triangles`]).
pub fn count_zero_area_triangles(mesh: &TriangleMesh) -> usize {
    let tolerance = f32::EPSILON as f64;
    (0..mesh.triangles.len())
        .into_par_iter()
        .filter(|&t| {
            let [i, j, k] = mesh.triangles[t];
            if i == j || j == k || i == k {
                return false;
            }
            let [a, b, c] = mesh.corners(t);
            let longest_squared = (b - a)
                .length_squared()
                .max((c - b).length_squared())
                .max((a - c).length_squared());
            (b - a).cross(c - a).length() <= tolerance * longest_squared
        })
        .count()
}

impl MeshReport {
    /// One sentence for each thing a reader should know about the mesh's shape.
    pub fn notes(&self) -> Vec<String> {
        let t = &self.topology;
        let mut notes = Vec::new();
        if let Some(w) = self.welding {
            notes.push(format!(
                "counted after welding coincident vertices: {} vertices became {}",
                w.vertices_before, w.vertices_after
            ));
        }
        if self.inside_out {
            notes.push(format!(
                "the shell is inside out: its triangles wind clockwise seen from outside (volume {:.6e})",
                self.volume
            ));
        }
        if t.boundary_edges > 0 {
            let through = if t.non_manifold_edges > 0 {
                " (a loop closes through the edges shared by three or more triangles that its \
                 rim meets)"
            } else {
                ""
            };
            notes.push(format!(
                "the surface is open: {} in {}{through}, so the volume is not an enclosed volume",
                count(t.boundary_edges, "boundary edge", "boundary edges"),
                count(t.boundary_loops, "loop", "loops"),
            ));
        }
        if t.non_manifold_edges > 0 || t.non_manifold_vertices > 0 {
            notes.push(format!(
                "not a manifold: {} shared by three or more triangles, {}",
                count(t.non_manifold_edges, "edge", "edges"),
                count(
                    t.non_manifold_vertices,
                    "pinched vertex",
                    "pinched vertices"
                ),
            ));
        }
        if t.inconsistent_edges > 0 {
            notes.push(format!(
                "inconsistent orientation: {} used twice in the same direction",
                count(t.inconsistent_edges, "edge", "edges")
            ));
        }
        if t.degenerate_triangles > 0 || self.zero_area_triangles > 0 || t.duplicate_triangles > 0 {
            notes.push(format!(
                "{} a vertex, {} zero area, {} {}",
                count(
                    t.degenerate_triangles,
                    "triangle repeats",
                    "triangles repeat"
                ),
                count(self.zero_area_triangles, "other has", "others have"),
                t.duplicate_triangles,
                if t.duplicate_triangles == 1 {
                    "is a duplicate"
                } else {
                    "are duplicates"
                }
            ));
        }
        if t.genus.is_none() {
            notes.push(
                "genus undefined: the mesh is not a consistently oriented manifold".to_string(),
            );
        }
        notes
    }
}

impl fmt::Display for MeshReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let t = &self.topology;
        writeln!(
            f,
            "vertices {} ({} unreferenced), triangles {}, edges {}",
            t.vertices, t.unreferenced_vertices, t.triangles, t.edges
        )?;
        writeln!(
            f,
            "components {}, boundary loops {}, Euler characteristic {}, genus {}",
            t.components,
            t.boundary_loops,
            t.euler_characteristic,
            t.genus.map_or("undefined".to_string(), |g| g.to_string())
        )?;
        writeln!(
            f,
            "closed manifold {}, consistently oriented {}",
            yes_no(self.closed_manifold),
            yes_no(self.consistently_oriented)
        )?;
        writeln!(
            f,
            "area {:.6e}, volume {:.6e}{}",
            self.area,
            self.volume,
            if self.volume_is_enclosed {
                ""
            } else {
                " (not enclosed)"
            }
        )?;
        let [x0, y0, z0] = self.bounds.min;
        let [x1, y1, z1] = self.bounds.max;
        write!(
            f,
            "bounds ({x0}, {y0}, {z0}) to ({x1}, {y1}, {z1}), diagonal {:.6e}",
            self.diagonal
        )?;
        for note in self.notes() {
            write!(f, "\nnote: {note}")?;
        }
        Ok(())
    }
}

/// `n thing` or `n things` (`one` and `many` may carry a verb: "triangle repeats").
fn count(n: usize, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

fn yes_no(b: bool) -> &'static str {
    if b {
        "yes"
    } else {
        "no"
    }
}
