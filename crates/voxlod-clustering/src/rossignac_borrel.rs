//! Rossignac–Borrel vertex clustering (Rossignac and Borrel 1993, §3 and §4).
//!
//! The steps of the paper's Fig. 2, in order:
//! 1. **Grading** (§3.1): a weight per vertex, see [`crate::grading`].
//! 2. **Triangulation** (§3.2): faces are cut into triangles on their own vertices. Our input,
//!    a [`TriangleMesh`], is already triangles (the readers triangulate polygons), so this step
//!    has nothing left to do.
//! 3. **Clustering** (§3.3): the vertices falling in one cell of a uniform grid over the object's
//!    box, or over a box shared by a whole scene ([`ClusterOptions::bounds`]), form a cluster;
//!    clusters are numbered in the order they are created, scanning the vertices in order.
//!    See [`crate::grid`] for the cells.
//! 4. **Synthesis** (§3.4): one representative per cluster, the weighted centre of mass of its
//!    vertices ([`Synthesis::Mean`], smoothing) or its heaviest vertex ([`Synthesis::MaxWeight`],
//!    removing details without moving the kept faces; ties go to the lowest vertex index). If all
//!    the weights of a cluster are 0 its mean is unweighted.
//! 5. **Elimination** (§3.5): see [`crate::elimination`].
//! 6. **Normals** (§3.6): recomputed from the simplified triangles (area-weighted vertex normals).
//!
//! **Series** (§4): the finest level is simplified as above; each coarser level merges the eight
//! cells of an octree node: cell `c` of level `l` becomes cell `c >> 1` of level `l + 1`, and the
//! clusters of a node become one. The octree is implicit (a linear octree: a node is its level and
//! integer cell coordinates), so only the occupied nodes exist. A merged cluster's
//! representative comes from its children's sums and heaviest vertices, and elimination runs on
//! the finer level's simplified model, never again on the original triangles. The result equals
//! a fresh run on the coarser grid (same clusters, numbering, triangles, edges and points; means
//! equal to rounding) whenever the cell count halves exactly.
//!
//! The output is generally not a manifold: triangles from different sheets meet at one edge or
//! vertex, dangling edges hang off surfaces. That is what the method does (MeshLab's users meet
//! it too); downstream code must accept it.
//!
//! Beyond the paper, optionally ([`ClusterOptions::thick_edges`]): Low–Tan thick edges for the
//! dangling edges, see [`crate::thick_edges`].
//!
//! Cost: O(V + T) for the finest level (grading O(Σ valence²), one pass over the vertices, one
//! parallel pass over the triangles, radix sorts of the survivors), then O(clusters + S) per
//! coarser level for S simplices of the finer level. Memory: 4 bytes per corner for grading,
//! a cell table (a flat array up to 2²⁴ cells, a hash map beyond), O(clusters) accumulators.

use std::str::FromStr;
use std::time::Instant;

use glam::{DVec3, Vec3};
use serde::Serialize;
use voxlod_core::{Bounds, PolyMesh, TriangleMesh};

use crate::elimination::{self, Simplices};
use crate::grading::{grade_prepared, Grading};
use crate::grid::{self, CellTable, ClusterGrid};
use crate::input::{self, Prepared};
use crate::level::{Level, LevelReport, Method};
use crate::thick_edges;
use crate::ClusteringError;

/// How a cluster's representative vertex is made (§3.4).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Synthesis {
    /// Centre of mass of the cluster's vertices weighted by their grades: smoothing.
    #[default]
    Mean,
    /// The cluster's vertex of greatest weight: detail removal that keeps large faces in place.
    MaxWeight,
}

impl FromStr for Synthesis {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "mean" => Ok(Synthesis::Mean),
            "max-weight" => Ok(Synthesis::MaxWeight),
            _ => Err(format!(
                "unknown synthesis '{s}' (expected mean or max-weight)"
            )),
        }
    }
}

/// Options of [`rossignac_borrel`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClusterOptions {
    /// Cells along the longest side of the clustering box, at the finest level.
    pub cells: u32,
    /// Number of levels: the finest, then each with cells twice as large (§4).
    pub levels: u32,
    /// How a cluster's representative is made (§3.4).
    pub synthesis: Synthesis,
    /// The clustering box; `None` for the box of the mesh's (used) vertices. Give the box of the
    /// whole scene to cluster all its objects on one grid.
    pub bounds: Option<Bounds>,
    /// Also estimate Low–Tan thick-edge widths and normals for the dangling edges.
    pub thick_edges: bool,
}

impl Default for ClusterOptions {
    /// One level of 64 cells, weighted centres of mass, on the mesh's own box, no thick edges.
    fn default() -> Self {
        ClusterOptions {
            cells: 64,
            levels: 1,
            synthesis: Synthesis::Mean,
            bounds: None,
            thick_edges: false,
        }
    }
}

impl ClusterOptions {
    /// One level of `cells` cells, weighted centres of mass (the paper's smoothing).
    pub fn smoothing(cells: u32) -> Self {
        ClusterOptions {
            cells,
            ..Default::default()
        }
    }

    /// One level of `cells` cells, heaviest vertices (the paper's detail removal).
    pub fn detail_removal(cells: u32) -> Self {
        ClusterOptions {
            cells,
            synthesis: Synthesis::MaxWeight,
            ..Default::default()
        }
    }

    /// `levels` levels from `cells` cells, each with cells twice as large.
    pub fn series(cells: u32, levels: u32) -> Self {
        ClusterOptions {
            cells,
            levels,
            ..Default::default()
        }
    }

    /// The longest series from `cells` cells down to a single cell.
    pub fn full_series(cells: u32) -> Self {
        Self::series(cells, grid::max_levels(cells))
    }

    /// The same with another synthesis.
    pub fn with_synthesis(self, synthesis: Synthesis) -> Self {
        ClusterOptions { synthesis, ..self }
    }

    /// The same on the grid over `bounds` (a whole scene's box, say).
    pub fn with_bounds(self, bounds: Bounds) -> Self {
        ClusterOptions {
            bounds: Some(bounds),
            ..self
        }
    }

    /// The same with thick edges on or off.
    pub fn with_thick_edges(self, thick_edges: bool) -> Self {
        ClusterOptions {
            thick_edges,
            ..self
        }
    }

    fn check(&self) -> Result<(), ClusteringError> {
        grid::check_cells(self.cells)?;
        grid::check_levels(self.levels, self.cells)?;
        if let Some(b) = &self.bounds {
            grid::check_bounds(b)?;
        }
        Ok(())
    }
}

/// Simplifies `mesh` into `options.levels` levels, finest first.
///
/// # Errors
///
/// [`ClusteringError`] for zero cells or levels, more levels than the cells allow, a bad box,
/// and a mesh without triangles, with an index out of range or a non-finite coordinate.
///
/// # Example
///
/// A unit cube on 2 × 2 × 2 cells keeps each corner in a cell of its own, so it comes back
/// unchanged; the octree's next level (§4) merges all eight cells and the cube collapses to
/// one isolated point.
///
/// ```
/// use glam::Vec3;
/// use voxlod_clustering::{rossignac_borrel, ClusterOptions};
/// use voxlod_core::TriangleMesh;
///
/// // Corner k is at (k & 1, (k >> 1) & 1, k >> 2).
/// let corner = |k: u32| Vec3::new((k & 1) as f32, ((k >> 1) & 1) as f32, (k >> 2) as f32);
/// let cube = TriangleMesh::new(
///     (0..8).map(corner).collect(),
///     vec![
///         [0, 2, 3], [0, 3, 1], [4, 5, 7], [4, 7, 6], [0, 1, 5], [0, 5, 4],
///         [2, 6, 7], [2, 7, 3], [0, 4, 6], [0, 6, 2], [1, 3, 7], [1, 7, 5],
///     ],
/// );
/// let levels = rossignac_borrel(&cube, &ClusterOptions::series(2, 2))?;
/// let counts = |l: usize| {
///     let m = &levels[l].mesh;
///     (m.mesh.triangles.len(), m.lines.len(), m.points.len())
/// };
/// assert_eq!(counts(0), (12, 0, 0));
/// assert_eq!(levels[0].mesh.mesh.positions, cube.positions);
/// assert_eq!(counts(1), (0, 0, 1));
/// assert_eq!(levels[1].cluster_of, vec![0; 8]);
/// # Ok::<(), voxlod_clustering::ClusteringError>(())
/// ```
pub fn rossignac_borrel(
    mesh: &TriangleMesh,
    options: &ClusterOptions,
) -> Result<Vec<Level>, ClusteringError> {
    options.check()?;
    let start = Instant::now();
    let prepared = input::prepare(mesh)?;
    let grid = ClusterGrid::new(&options.bounds.unwrap_or(prepared.bounds), options.cells)?;

    // Grading and clustering are independent, and so are elimination and synthesis: each pair
    // runs side by side (the idle worker steals from the parallel one).
    let (weights, clusters) = rayon::join(
        || grade_prepared(&prepared, mesh, Grading::RossignacBorrel),
        || cluster_on_grid(mesh, &prepared, &grid),
    );
    let (simplices, sums) = rayon::join(
        || {
            elimination::eliminate_covering(
                &mesh.triangles,
                &clusters.cluster_of,
                clusters.cells.len(),
            )
        },
        || synthesis_sums(mesh, &weights, &clusters),
    );
    drop(weights);

    let mut levels = Vec::with_capacity(options.levels as usize);
    let mut state = State {
        grid,
        cells: clusters.cells,
        sums,
        simplices,
        cluster_of: clusters.cluster_of,
    };
    levels.push(make_level(mesh, &state, 0, options, start));

    for level in 1..options.levels as usize {
        let start = Instant::now();
        state = coarsen(&state);
        levels.push(make_level(mesh, &state, level, options, start));
    }
    Ok(levels)
}

/// The clusters of one grid level.
struct GridClusters {
    /// Vertex → cluster (`u32::MAX` for vertices no triangle uses).
    cluster_of: Vec<u32>,
    /// Cluster → its cell.
    cells: Vec<[u32; 3]>,
}

/// What a level carries to the next.
struct State {
    grid: ClusterGrid,
    cells: Vec<[u32; 3]>,
    sums: Vec<Sums>,
    simplices: Simplices,
    cluster_of: Vec<u32>,
}

/// Per cluster, what both syntheses need and what merges across octree levels.
#[derive(Clone, Copy, Debug)]
struct Sums {
    weighted: DVec3,
    weight: f64,
    plain: DVec3,
    count: u32,
    heaviest: u32,
    heaviest_weight: f32,
}

impl Sums {
    const EMPTY: Sums = Sums {
        weighted: DVec3::ZERO,
        weight: 0.0,
        plain: DVec3::ZERO,
        count: 0,
        heaviest: u32::MAX,
        heaviest_weight: f32::NEG_INFINITY,
    };

    #[inline]
    fn merge(&mut self, o: &Sums) {
        self.weighted += o.weighted;
        self.weight += o.weight;
        self.plain += o.plain;
        self.count += o.count;
        if o.heaviest_weight > self.heaviest_weight
            || (o.heaviest_weight == self.heaviest_weight && o.heaviest < self.heaviest)
        {
            self.heaviest = o.heaviest;
            self.heaviest_weight = o.heaviest_weight;
        }
    }

    fn representative(&self, synthesis: Synthesis, positions: &[Vec3]) -> Vec3 {
        debug_assert!(self.count > 0);
        match synthesis {
            Synthesis::Mean if self.weight > 0.0 => (self.weighted / self.weight).as_vec3(),
            Synthesis::Mean => (self.plain / self.count as f64).as_vec3(),
            Synthesis::MaxWeight => positions[self.heaviest as usize],
        }
    }
}

/// §3.3: scan the used vertices in order, numbering clusters as their cells are first met.
fn cluster_on_grid(mesh: &TriangleMesh, prepared: &Prepared, grid: &ClusterGrid) -> GridClusters {
    let mut table = CellTable::new(grid.cell_count(), prepared.referenced);
    let mut cluster_of = vec![u32::MAX; mesh.positions.len()];
    let mut cells = Vec::new();
    for (v, &p) in mesh.positions.iter().enumerate() {
        if !prepared.is_referenced(v) {
            continue;
        }
        let cell = grid.cell_of(p);
        let (id, new) = table.get_or_insert(grid.key(cell), cells.len() as u32);
        if new {
            cells.push(cell);
        }
        cluster_of[v] = id;
    }
    GridClusters { cluster_of, cells }
}

/// §3.4: per-cluster sums of the weighted and plain positions, and the heaviest vertex.
fn synthesis_sums(mesh: &TriangleMesh, weights: &[f32], clusters: &GridClusters) -> Vec<Sums> {
    let mut sums = vec![Sums::EMPTY; clusters.cells.len()];
    for (v, (&c, &p)) in clusters.cluster_of.iter().zip(&mesh.positions).enumerate() {
        if c == u32::MAX {
            continue;
        }
        let s = &mut sums[c as usize];
        let w = weights[v];
        let p = p.as_dvec3();
        s.weighted += w as f64 * p;
        s.weight += w as f64;
        s.plain += p;
        s.count += 1;
        if w > s.heaviest_weight {
            s.heaviest = v as u32;
            s.heaviest_weight = w;
        }
    }
    sums
}

/// §4: the next octree level, merging the clusters of each node.
fn coarsen(fine: &State) -> State {
    let grid = fine.grid.coarsened(1);
    let mut table = CellTable::new(grid.cell_count(), fine.cells.len());
    let mut merge = Vec::with_capacity(fine.cells.len());
    let mut cells = Vec::new();
    let mut sums: Vec<Sums> = Vec::new();
    for (c, cell) in fine.cells.iter().enumerate() {
        let parent = cell.map(|x| x >> 1);
        let (id, new) = table.get_or_insert(grid.key(parent), cells.len() as u32);
        if new {
            cells.push(parent);
            sums.push(Sums::EMPTY);
        }
        sums[id as usize].merge(&fine.sums[c]);
        merge.push(id);
    }
    let simplices = elimination::eliminate_merged(&fine.simplices, &merge, cells.len());
    let cluster_of = fine
        .cluster_of
        .iter()
        .map(|&c| if c == u32::MAX { c } else { merge[c as usize] })
        .collect();
    State {
        grid,
        cells,
        sums,
        simplices,
        cluster_of,
    }
}

fn make_level(
    mesh: &TriangleMesh,
    state: &State,
    level: usize,
    options: &ClusterOptions,
    start: Instant,
) -> Level {
    let positions: Vec<Vec3> = state
        .sums
        .iter()
        .map(|s| s.representative(options.synthesis, &mesh.positions))
        .collect();
    let poly = build_poly_mesh(
        mesh,
        positions,
        &state.simplices,
        &state.cluster_of,
        options.thick_edges,
    );
    let report = LevelReport {
        method: Method::RossignacBorrel,
        level,
        cells: state.grid.cells(),
        cell_size: state.grid.cell_size,
        clusters: state.sums.len(),
        triangles: poly.mesh.triangles.len(),
        dangling_edges: poly.lines.len(),
        isolated_points: poly.points.len(),
        cluster_seconds: start.elapsed().as_secs_f64(),
    };
    Level {
        report,
        mesh: poly,
        cluster_of: state.cluster_of.clone(),
    }
}

/// The output model of a level: representatives as vertices, §3.6 normals, optional thick edges.
pub(crate) fn build_poly_mesh(
    original: &TriangleMesh,
    positions: Vec<Vec3>,
    simplices: &Simplices,
    cluster_of: &[u32],
    thick: bool,
) -> PolyMesh {
    let mut tm = TriangleMesh::new(positions, simplices.triangles.clone());
    tm.compute_vertex_normals();
    let mut poly = PolyMesh {
        mesh: tm,
        lines: simplices.edges.clone(),
        points: simplices.points.clone(),
        ..Default::default()
    };
    if thick {
        let edges =
            thick_edges::thick_edges(original, cluster_of, &poly.mesh.positions, &poly.lines);
        thick_edges::attach(&mut poly, &edges);
    }
    debug_assert!(poly.validate().is_ok());
    poly
}
