//! The vertex-clustering baselines in one call: Rossignac–Borrel (1993: grading, a uniform grid,
//! mean or max-weight synthesis, §3.5 elimination, a series by octree merging, §4) or Low–Tan
//! (floating cells around the heaviest vertices, thick edges with widths and view-facing
//! normals). Triangles that collapse become dangling edges and isolated points, which the
//! levels keep. Cost: O(V + T) per level after an O(V log V) sort.

use voxlod_clustering::{
    low_tan, rossignac_borrel, thick_edges, ClusterOptions, FloatingCellOptions, Level, Method,
    Synthesis,
};
use voxlod_core::TriangleMesh;
use voxlod_gltf::{chain_glb_bytes, ChainLevel, ChainOptions};

use crate::error::Error;

/// Options of [`cluster`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClusteringOptions {
    /// Rossignac–Borrel or Low–Tan.
    pub method: Method,
    /// Cells along the longest side of the object's box at the finest level.
    pub cells: u32,
    /// Levels, each with cells twice as large.
    pub levels: u32,
    /// Rossignac–Borrel's synthesis: weighted centre (smoothing) or heaviest vertex.
    pub synthesis: Synthesis,
    /// Thick edges (widths and normals on the dangling edges); `None`: on for Low–Tan, off
    /// for Rossignac–Borrel.
    pub thick_edges: Option<bool>,
}

impl Default for ClusteringOptions {
    /// One level of Rossignac–Borrel on 64 cells, weighted centres.
    fn default() -> Self {
        ClusteringOptions::rossignac_borrel(64)
    }
}

impl ClusteringOptions {
    /// Rossignac–Borrel on `cells` cells, one level, weighted centres.
    pub fn rossignac_borrel(cells: u32) -> Self {
        ClusteringOptions {
            method: Method::RossignacBorrel,
            cells,
            levels: 1,
            synthesis: Synthesis::Mean,
            thick_edges: None,
        }
    }

    /// Low–Tan floating cells of 1/`cells` of the box's longest side, one level, thick edges.
    pub fn low_tan(cells: u32) -> Self {
        ClusteringOptions {
            method: Method::LowTan,
            ..ClusteringOptions::rossignac_borrel(cells)
        }
    }

    /// These options with `levels` levels.
    pub fn with_levels(self, levels: u32) -> Self {
        ClusteringOptions { levels, ..self }
    }
}

/// The levels of `mesh` simplified by vertex clustering, finest first.
///
/// ```
/// # fn main() -> Result<(), voxlod::Error> {
/// use voxlod::core::glam::Vec3;
/// // A unit square of two triangles, clustered on one cell: one vertex, one isolated point.
/// let p = vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
/// let square = voxlod::core::TriangleMesh::new(p, vec![[0, 1, 2], [0, 2, 3]]);
/// let levels = voxlod::cluster(&square, &voxlod::ClusteringOptions::rossignac_borrel(1))?;
/// let r = &levels[0].report;
/// assert_eq!((r.clusters, r.triangles, r.dangling_edges, r.isolated_points), (1, 0, 0, 1));
/// # Ok(())
/// # }
/// ```
pub fn cluster(mesh: &TriangleMesh, options: &ClusteringOptions) -> Result<Vec<Level>, Error> {
    Ok(match options.method {
        Method::RossignacBorrel => rossignac_borrel(
            mesh,
            &ClusterOptions {
                cells: options.cells,
                levels: options.levels,
                synthesis: options.synthesis,
                thick_edges: options.thick_edges.unwrap_or(false),
                ..Default::default()
            },
        )?,
        Method::LowTan => low_tan(
            mesh,
            &FloatingCellOptions {
                cells: options.cells,
                levels: options.levels,
                thick_edges: options.thick_edges.unwrap_or(true),
                ..Default::default()
            },
        )?,
    })
}

/// The levels of [`cluster`] in one binary glTF file: a mesh per level with a `TRIANGLES`, a
/// `LINES` (the dangling edges, their thick-edge widths as a `_WIDTH` attribute) and a `POINTS`
/// primitive, chained with `MSFT_lod` finest first and switched by the pixel-size rule of
/// [`crate::select()`] on the levels' cell sizes (`MSFT_screencoverage`). Cost: linear in the
/// levels' size.
///
/// ```
/// # fn main() -> Result<(), voxlod::Error> {
/// use voxlod::core::glam::Vec3;
/// let p = vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
/// let square = voxlod::core::TriangleMesh::new(p, vec![[0, 1, 2], [0, 2, 3]]);
/// let levels = voxlod::cluster(&square, &voxlod::ClusteringOptions::low_tan(4).with_levels(2))?;
/// let bytes = voxlod::cluster_glb(&levels)?;
/// assert_eq!(&bytes[..4], b"glTF");
/// # Ok(())
/// # }
/// ```
pub fn cluster_glb(levels: &[Level]) -> Result<Vec<u8>, Error> {
    let widths: Vec<&[f32]> = levels
        .iter()
        .map(|l| {
            l.mesh
                .line_attributes
                .iter()
                .find(|a| a.name == thick_edges::WIDTH)
                .map_or(&[][..], |a| &a.values[..])
        })
        .collect();
    let chain: Vec<ChainLevel> = levels
        .iter()
        .zip(&widths)
        .map(|(l, w)| {
            ChainLevel::new(l.report.level, &l.mesh.mesh, l.report.cell_size)
                .with_lines(&l.mesh.lines, w)
                .with_points(&l.mesh.points)
        })
        .collect();
    let options = ChainOptions {
        name: "voxlod clustering".into(),
        ..Default::default()
    };
    Ok(chain_glb_bytes(&chain, &options)?)
}
