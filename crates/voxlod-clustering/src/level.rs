//! What a baseline returns: one [`Level`] per simplification level, finest first, each with the
//! simplified [`PolyMesh`] and a [`LevelReport`] the command line prints as JSON.
//!
//! Cost: a level holds its mesh and one cluster id (4 bytes) per input vertex.

use serde::Serialize;
use voxlod_core::PolyMesh;

/// The clustering method that made a level.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Uniform-grid clustering with an octree series (Rossignac and Borrel 1993).
    RossignacBorrel,
    /// Weight-controlled floating-cell clustering with thick edges (Low and Tan's patent).
    LowTan,
}

impl Method {
    /// The name the command line and the JSON reports use: `rossignac-borrel` or `low-tan`.
    pub fn name(self) -> &'static str {
        match self {
            Method::RossignacBorrel => "rossignac-borrel",
            Method::LowTan => "low-tan",
        }
    }
}

impl std::str::FromStr for Method {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "rossignac-borrel" => Ok(Method::RossignacBorrel),
            "low-tan" => Ok(Method::LowTan),
            _ => Err(format!(
                "unknown clustering method '{s}' (expected rossignac-borrel or low-tan)"
            )),
        }
    }
}

/// The figures of one level, as the command line reports them.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LevelReport {
    /// The method that made the level.
    pub method: Method,
    /// 0 for the finest level.
    pub level: usize,
    /// Cells along the longest side of the clustering box at this level (for floating cells, the
    /// box's longest side divided by the cell size).
    pub cells: u32,
    /// Side of a clustering cell, in the mesh's units: what the level selection
    /// (`voxlod::select`) compares with the size of a pixel.
    pub cell_size: f64,
    /// Clusters, that is vertices of the simplified model.
    pub clusters: usize,
    /// Triangles of the simplified model.
    pub triangles: usize,
    /// Edges left from collapsed triangles that bound no triangle (§3.5).
    pub dangling_edges: usize,
    /// Points left from collapsed triangles that bound no edge or triangle (§3.5).
    pub isolated_points: usize,
    /// Wall time of the algorithm for this level, without reading or writing files. The finest
    /// level includes checking the input and grading; a coarser level of a Rossignac–Borrel series
    /// only its own merging and elimination (it starts from the finer level's result).
    pub cluster_seconds: f64,
}

/// One simplification level.
#[derive(Clone, Debug)]
pub struct Level {
    /// The level's figures.
    pub report: LevelReport,
    /// Triangles, dangling edges (`lines`, with `width` and `normal_x/y/z` line attributes when
    /// thick edges were computed) and isolated points. Vertex `i` is cluster `i`; vertex normals
    /// are recomputed from the simplified triangles (zero on vertices that only edges or points
    /// use).
    pub mesh: PolyMesh,
    /// For each input vertex, its cluster (vertex of `mesh`); `u32::MAX` for vertices that no
    /// triangle uses. This is the paper's `R` table.
    pub cluster_of: Vec<u32>,
}

/// The reports of `levels`, in order.
pub fn reports(levels: &[Level]) -> Vec<LevelReport> {
    levels.iter().map(|l| l.report.clone()).collect()
}
