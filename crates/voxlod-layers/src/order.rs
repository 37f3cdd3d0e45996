//! Back-to-front order of the triangles of marching-cubes meshes by traversing their volume's
//! cells (paper §3: "sorting can be accomplished by traversing only the surface-intersected
//! voxels in a slice-by-slice fashion").
//!
//! **Why cell order works.** Cells are boxes of a regular grid. If a point of cell A lies in front
//! of a point of cell B along a view direction d (`a = b − t d`, t > 0), then along every axis
//! with `dᵢ > 0` A's index is at most B's, and with `dᵢ < 0` at least B's. So visiting the cells
//! slice by slice, row by row and cell by cell, each axis from its far side to its near side, draws
//! every cell before any cell in front of it. The traversal depends only on the signs of d — its
//! octant — so the eight orthographic orders can be computed once and stored. For a perspective
//! view from an eye E the same argument holds per axis with "far" meaning far from E's cell: each
//! axis is walked from both ends towards the eye's cell (the traversal is split at the eye's cell).
//!
//! **Placed meshes** (beyond the paper). The layers of an oblique or flipped scan lie in the
//! world, an affine image `L x + t` of the grid's space ([`CellTriangles::placement`]). An affine
//! map keeps rays, and the order of points along them, so the order of the placed triangles along
//! a world direction d is the order of the grid-space triangles along `L⁻¹ d`: the traversal
//! walks the grid by the signs of `L⁻¹ d` (an eye is taken to grid space likewise), while the
//! pair tests inside a cell compare the placed triangles along d itself. A world octant's stored
//! order is walked by the signs of `L⁻¹` of its diagonal, so between cells it is right for every
//! direction of the octant whose image has those signs (all of them when `L` only permutes or
//! flips axes; near the diagonal when `L` is oblique), inside cells for the diagonal.
//!
//! **Inside a cell** (the paper says nothing about it). A cell holds the triangles of several
//! layers, and a layer may hold several in one cell. They are put in depth order exactly: every
//! pair whose projections overlap is compared by depth at an interior point of the overlap
//! ([`crate::geometry::behind`]) and the cell's triangles are sorted topologically, ties and
//! (rare) cycles between crossing triangles broken by centroid depth. For the stored octant orders
//! the in-cell sort uses the octant's diagonal direction: the order between cells is right for
//! every direction of the octant, the order inside a cell for the diagonal (and, since the layers
//! in a cell are nearly parallel, for most directions near it); [`view_order`] sorts inside cells
//! for the exact direction.
//!
//! **Cost.** Indexing the triangles by cell is one sort of T keys. A traversal visits the
//! occupied cells, rows and slices only, O(T) whatever size the grid claims; in-cell sorting
//! costs O(k²) pair tests for k triangles in a cell, a few on average (at most
//! [`MAX_EXACT_CELL`]). Slices are ordered in parallel; the eight octants too.

use glam::{DVec3, Vec3};
use rayon::prelude::*;
use voxlod_core::{Grid, Placement};

use crate::geometry::{behind_fast, second_is_behind, Projected, Projector};
use crate::LayersError;

/// Names of the eight stored orders, by [`Octant::index`]: the signs of the view direction (eye
/// to scene) along x, y and z (the accessor names of a layered `.glb`).
pub use voxlod_gltf::ORDER_NAMES;

/// The most triangles in one cell that are sorted exactly (pair tests, O(k²)); a fuller cell is
/// sorted by centroid depth. Marching cubes puts at most 5 triangles per layer in a cell, so
/// only a file whose stated grid does not match its mesh (every triangle in one cell) gets
/// here, and it must not cost hours.
pub const MAX_EXACT_CELL: usize = 1024;

/// Overlaps smaller than this fraction of the smaller triangle's projected area are ignored.
pub const OVERLAP_TOLERANCE: f64 = 1e-7;

/// One of the eight sign patterns of a view direction. Index bits: 4 for x < 0, 2 for y < 0,
/// 1 for z < 0 (a zero component counts as positive).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Octant(u8);

impl Octant {
    /// The eight octants, by index.
    pub const ALL: [Octant; 8] = [
        Octant(0),
        Octant(1),
        Octant(2),
        Octant(3),
        Octant(4),
        Octant(5),
        Octant(6),
        Octant(7),
    ];

    /// The octant of a view direction; refuses zero and non-finite directions.
    pub fn of(direction: DVec3) -> Result<Octant, LayersError> {
        check_direction(direction)?;
        Ok(Octant(
            ((direction.x < 0.0) as u8) << 2
                | ((direction.y < 0.0) as u8) << 1
                | (direction.z < 0.0) as u8,
        ))
    }

    /// The octant of index `index` (0 to 7; panics beyond).
    pub fn from_index(index: usize) -> Octant {
        assert!(index < 8);
        Octant(index as u8)
    }

    /// 0 to 7: bit 4 for x < 0, 2 for y < 0, 1 for z < 0.
    pub fn index(self) -> usize {
        self.0 as usize
    }

    /// ±1 per axis.
    pub fn signs(self) -> DVec3 {
        let s = |bit: u8| if self.0 & bit != 0 { -1.0 } else { 1.0 };
        DVec3::new(s(4), s(2), s(1))
    }

    /// The unit diagonal of the octant: the direction the stored order is sorted for in cells.
    pub fn diagonal(self) -> DVec3 {
        self.signs() / 3f64.sqrt()
    }

    /// `order+x+y+z` … `order-x-y-z`.
    pub fn name(self) -> &'static str {
        ORDER_NAMES[self.index()]
    }

    /// The octant of a stored order's name (see [`ORDER_NAMES`]).
    pub fn from_name(name: &str) -> Option<Octant> {
        ORDER_NAMES
            .iter()
            .position(|n| *n == name)
            .map(|i| Octant(i as u8))
    }
}

/// Refuses a zero or non-finite view direction.
pub fn check_direction(direction: DVec3) -> Result<(), LayersError> {
    if !direction.is_finite() {
        return Err(LayersError::NonFiniteView(format!(
            "view direction {direction}"
        )));
    }
    if direction.length_squared() == 0.0 {
        return Err(LayersError::ZeroViewDirection);
    }
    Ok(())
}

/// How the scene is looked at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum View {
    /// Parallel rays.
    Orthographic {
        /// The view direction, eye to scene (need not be normalised).
        direction: DVec3,
    },
    /// Rays from an eye.
    Perspective {
        /// Where the eye is, in the mesh's coordinates.
        eye: DVec3,
    },
}

/// A direction of the vertices' space in the grid's space: by the inverse of `placement`'s
/// linear part.
fn grid_direction(placement: &Placement, d: DVec3) -> DVec3 {
    if placement.is_identity() {
        d
    } else {
        placement.linear.inverse() * d
    }
}

/// A point of the vertices' space in the grid's space: by the inverse of `placement`.
fn grid_point(placement: &Placement, p: DVec3) -> DVec3 {
    grid_direction(placement, p - placement.translation)
}

impl View {
    /// Refuses a zero or non-finite direction, or a non-finite eye.
    pub fn check(&self) -> Result<(), LayersError> {
        match *self {
            View::Orthographic { direction } => check_direction(direction),
            View::Perspective { eye } => {
                if eye.is_finite() {
                    Ok(())
                } else {
                    Err(LayersError::NonFiniteView(format!("eye {eye}")))
                }
            }
        }
    }
}

/// Triangles that know the cell of their volume they came from.
#[derive(Clone, Copy, Debug)]
pub struct CellTriangles<'a> {
    /// The volume's sample grid, in its axis-aligned grid space: cells are `dims − 1` per axis.
    pub grid: Grid,
    /// The map from the grid's space to the vertices' ([`crate::LayeredMesh::placement`]): the
    /// identity when the vertices lie in grid space.
    pub placement: Placement,
    /// The vertices (placed).
    pub positions: &'a [Vec3],
    /// The triangles, as indices into `positions`.
    pub triangles: &'a [[u32; 3]],
    /// Linear cell index `i + cx (j + cy k)` per triangle.
    pub cells: &'a [u32],
}

impl CellTriangles<'_> {
    /// Cells per axis.
    pub fn cell_dims(&self) -> [usize; 3] {
        self.grid.dims.map(|d| d.saturating_sub(1).max(1))
    }

    fn corners(&self, t: u32) -> [DVec3; 3] {
        self.triangles[t as usize].map(|v| self.positions[v as usize].as_dvec3())
    }
}

/// The cell of each marching-cubes triangle of `grid`, recovered from its corners placed by
/// `placement` (for meshes read back from a file, which keep the grid and its placement but not
/// the cells): the corners are taken back to grid space first. A triangle's corners lie on the
/// edges of its cell, and never all on the cell's upper face along an axis, so along each axis
/// the smallest corner coordinate, in samples, lies in `[i, i + 1 − 10⁻⁴]` for cell i (marching
/// cubes keeps vertices 10⁻⁴ of an edge from its ends); a slack of 5·10⁻⁵ absorbs the rounding
/// of stored coordinates.
pub fn recover_cells(
    grid: &Grid,
    placement: &Placement,
    positions: &[Vec3],
    triangles: &[[u32; 3]],
) -> Vec<u32> {
    let dims = grid.dims.map(|d| d.saturating_sub(1).max(1));
    let origin = grid.origin_vec();
    let spacing = grid.spacing_vec();
    let inverse = placement.linear.inverse();
    let identity = placement.is_identity();
    let to_grid = |p: Vec3| {
        let p = p.as_dvec3();
        if identity {
            p
        } else {
            inverse * (p - placement.translation)
        }
    };
    triangles
        .par_iter()
        .map(|t| {
            let mut lo = DVec3::splat(f64::INFINITY);
            for &v in t {
                lo = lo.min((to_grid(positions[v as usize]) - origin) / spacing);
            }
            let ijk = [0, 1, 2].map(|a| {
                let c = (lo[a] + 5e-5).floor();
                if c.is_finite() {
                    (c.max(0.0) as usize).min(dims[a] - 1)
                } else {
                    0
                }
            });
            (ijk[0] + dims[0] * (ijk[1] + dims[1] * ijk[2])) as u32
        })
        .collect()
}

/// The triangles grouped by occupied cell, cells in storage order. Only occupied cells, rows
/// and slices are listed, so its size and the traversal's time depend on the triangles, never on
/// the grid's dimensions (which a file may state as anything).
#[derive(Clone, Debug, Default)]
pub struct CellIndex {
    dims: [usize; 3],
    /// Occupied cells, ascending.
    cells: Vec<u32>,
    /// Triangles of `cells[c]` are `tris[start[c]..start[c + 1]]`.
    start: Vec<u32>,
    tris: Vec<u32>,
    /// Occupied rows `j + cy k`, ascending.
    rows: Vec<u32>,
    /// Cells of `rows[r]` are `cells[row_start[r]..row_start[r + 1]]`.
    row_start: Vec<u32>,
    /// Occupied slices `k`, ascending.
    slices: Vec<u32>,
    /// Rows of `slices[s]` are `rows[slice_start[s]..slice_start[s + 1]]`.
    slice_start: Vec<u32>,
}

impl CellIndex {
    /// How many cells hold a triangle.
    pub fn occupied_cells(&self) -> usize {
        self.cells.len()
    }

    /// The most triangles in one cell.
    pub fn largest_cell(&self) -> usize {
        self.start
            .windows(2)
            .map(|w| (w[1] - w[0]) as usize)
            .max()
            .unwrap_or(0)
    }
}

/// Groups the triangles by cell: one parallel sort of (cell, triangle) keys. Refuses a grid with
/// more cells than a `u32` cell number can name (a grid read from a file may claim any size).
pub fn index_cells(obj: &CellTriangles) -> Result<CellIndex, LayersError> {
    let dims = obj.cell_dims();
    let total = dims.iter().map(|&d| d as u64).product::<u64>();
    if total > u32::MAX as u64 {
        return Err(LayersError::Invalid(format!(
            "the volume grid has {}x{}x{} cells, more than 32-bit cell numbers can name",
            dims[0], dims[1], dims[2]
        )));
    }
    if obj.cells.len() != obj.triangles.len() {
        return Err(LayersError::Invalid(format!(
            "{} cells for {} triangles",
            obj.cells.len(),
            obj.triangles.len()
        )));
    }
    if let Some(c) = obj.cells.iter().find(|&&c| c as u64 >= total) {
        return Err(LayersError::Invalid(format!(
            "cell {c} is outside the grid's {total} cells"
        )));
    }
    let mut keys: Vec<u64> = obj
        .cells
        .par_iter()
        .enumerate()
        .map(|(t, &c)| (c as u64) << 32 | t as u64)
        .collect();
    keys.par_sort_unstable();
    let mut index = CellIndex {
        dims,
        tris: keys.iter().map(|k| *k as u32).collect(),
        ..Default::default()
    };
    let mut last = u32::MAX;
    for (i, k) in keys.iter().enumerate() {
        let c = (k >> 32) as u32;
        if c != last {
            index.cells.push(c);
            index.start.push(i as u32);
            last = c;
        }
    }
    index.start.push(keys.len() as u32);
    (index.rows, index.row_start) = runs(&index.cells, |c| c / dims[0] as u32);
    (index.slices, index.slice_start) = runs(&index.rows, |r| r / dims[1] as u32);
    Ok(index)
}

/// The distinct values of `key` over the ascending `items` (ascending too), and where each
/// value's run starts in `items` (with `items.len()` at the end).
fn runs(items: &[u32], key: impl Fn(u32) -> u32) -> (Vec<u32>, Vec<u32>) {
    let (mut values, mut start) = (Vec::new(), Vec::new());
    for (i, &item) in items.iter().enumerate() {
        let k = key(item);
        if values.last() != Some(&k) {
            values.push(k);
            start.push(i as u32);
        }
    }
    start.push(items.len() as u32);
    (values, start)
}

/// How the cells are walked.
#[derive(Clone, Copy, Debug)]
enum Sweep {
    /// Each axis from the far side of a grid-space direction (only its signs matter).
    Octant(DVec3),
    /// Each axis from both ends towards the eye's cell (which may lie outside the grid).
    Eye([i64; 3]),
}

/// How triangles inside one cell are compared.
#[derive(Clone, Copy, Debug)]
enum InCell {
    Direction(DVec3),
    Eye(DVec3),
}

/// The order in which to visit `n` occupied positions along one axis, given their ascending
/// coordinates `coord(0) < coord(1) < …`: appends `first + i` for each position i to `out`.
/// An octant sweep walks from the far side; an eye sweep from both ends towards the eye's
/// coordinate (the farther end first, the upper one on a tie).
fn axis_order(
    n: usize,
    coord: impl Fn(usize) -> i64,
    sweep: Sweep,
    axis: usize,
    first: usize,
    out: &mut Vec<usize>,
) {
    match sweep {
        Sweep::Octant(signs) => {
            if signs[axis] >= 0.0 {
                out.extend((0..n).rev().map(|i| first + i));
            } else {
                out.extend((0..n).map(|i| first + i));
            }
        }
        Sweep::Eye(e) => {
            let e = e[axis];
            let (mut lo, mut hi) = (0i64, n as i64 - 1);
            while lo <= hi {
                if (coord(hi as usize) - e).abs() >= (coord(lo as usize) - e).abs() {
                    out.push(first + hi as usize);
                    hi -= 1;
                } else {
                    out.push(first + lo as usize);
                    lo += 1;
                }
            }
        }
    }
}

/// The order of one triangle mesh for a view, with the cell index built on the way.
pub fn view_order(obj: &CellTriangles, view: &View) -> Result<Vec<u32>, LayersError> {
    let index = index_cells(obj)?;
    view_order_indexed(obj, &index, view)
}

/// [`view_order`] with a prebuilt index.
pub fn view_order_indexed(
    obj: &CellTriangles,
    index: &CellIndex,
    view: &View,
) -> Result<Vec<u32>, LayersError> {
    view.check()?;
    Ok(match *view {
        View::Orthographic { direction } => {
            let along = grid_direction(&obj.placement, direction);
            check_direction(along)?;
            let in_cell = InCell::Direction(direction.normalize());
            traverse(obj, index, Sweep::Octant(along), in_cell)
        }
        View::Perspective { eye } => {
            let (g, at) = (&obj.grid, grid_point(&obj.placement, eye));
            let cell = [0, 1, 2].map(|a| ((at[a] - g.origin[a]) / g.spacing[a]).floor() as i64);
            traverse(obj, index, Sweep::Eye(cell), InCell::Eye(eye))
        }
    })
}

/// The stored order of one octant of view directions in the space of the vertices: the grid
/// walked by the signs of the octant's diagonal taken to grid space, in-cell sorting along the
/// diagonal (see the module documentation).
pub fn octant_order(obj: &CellTriangles, index: &CellIndex, octant: Octant) -> Vec<u32> {
    let diagonal = octant.diagonal();
    let along = grid_direction(&obj.placement, diagonal);
    traverse(
        obj,
        index,
        Sweep::Octant(along),
        InCell::Direction(diagonal),
    )
}

/// All eight octant orders, by [`Octant::index`], octants of view directions in the space of the
/// vertices. Opposite octants have reversed orders (the traversal reverses, and so does "behind"
/// inside a cell, the diagonals being opposite), so four are computed and reversed for the other
/// four.
pub fn octant_orders(obj: &CellTriangles) -> Result<Vec<Vec<u32>>, LayersError> {
    let index = index_cells(obj)?;
    let mut half: Vec<Vec<u32>> = Octant::ALL[..4]
        .par_iter()
        .map(|&o| octant_order(obj, &index, o))
        .collect();
    let mut opposite: Vec<Vec<u32>> = half
        .par_iter()
        .map(|o| o.iter().rev().copied().collect())
        .collect();
    // Octant 7 − i is the opposite of octant i.
    opposite.reverse();
    half.append(&mut opposite);
    Ok(half)
}

fn traverse(obj: &CellTriangles, index: &CellIndex, sweep: Sweep, in_cell: InCell) -> Vec<u32> {
    let [cx, cy, _] = index.dims.map(|d| d as u32);
    let mut slice_seq = Vec::with_capacity(index.slices.len());
    let slice = |s: usize| index.slices[s] as i64;
    axis_order(index.slices.len(), slice, sweep, 2, 0, &mut slice_seq);
    let slices: Vec<Vec<u32>> = slice_seq
        .par_iter()
        .map(|&s| {
            let mut out = Vec::new();
            let mut scratch = Scratch::default();
            let (mut row_seq, mut row_cells) = (Vec::new(), Vec::new());
            let first_row = index.slice_start[s] as usize;
            let rows = &index.rows[first_row..index.slice_start[s + 1] as usize];
            let y = |i: usize| (rows[i] % cy) as i64;
            axis_order(rows.len(), y, sweep, 1, first_row, &mut row_seq);
            for &r in &row_seq {
                let first = index.row_start[r] as usize;
                let row = &index.cells[first..index.row_start[r + 1] as usize];
                row_cells.clear();
                let x = |i: usize| (row[i] % cx) as i64;
                axis_order(row.len(), x, sweep, 0, first, &mut row_cells);
                for &c in &row_cells {
                    let tris = &index.tris[index.start[c] as usize..index.start[c + 1] as usize];
                    if tris.len() == 1 {
                        out.push(tris[0]);
                    } else {
                        sort_cell(obj, tris, in_cell, &mut scratch, &mut out);
                    }
                }
            }
            out
        })
        .collect();
    let mut order = Vec::with_capacity(obj.triangles.len());
    for s in slices {
        order.extend_from_slice(&s);
    }
    debug_assert_eq!(order.len(), obj.triangles.len());
    order
}

#[derive(Default)]
struct Scratch {
    projected: Vec<Projected>,
    key: Vec<f64>,
    by_depth: Vec<usize>,
    indegree: Vec<u32>,
    edges: Vec<(u16, u16)>,
    succ_start: Vec<u32>,
    succ: Vec<u16>,
    fill: Vec<u32>,
    done: Vec<bool>,
}

/// Appends the triangles of one cell to `out`, back to front (see the module documentation).
fn sort_cell(
    obj: &CellTriangles,
    tris: &[u32],
    in_cell: InCell,
    s: &mut Scratch,
    out: &mut Vec<u32>,
) {
    let projector = cell_projector(obj, tris, in_cell);
    let projected = projector
        .as_ref()
        .is_some_and(|p| project_cell(obj, tris, p, &mut s.projected));
    if !projected || tris.len() > MAX_EXACT_CELL {
        // The eye is in the cell, or the cell is too full for pair tests.
        push_farthest_centroid_first(obj, tris, in_cell, s, out);
        return;
    }
    let projector = projector.expect("checked");
    first_guess(&projector, s);
    // Most cells are already in order by the first guess: check that no later triangle lies
    // behind an earlier one (cheap when it does not), and only sort topologically if one does.
    if !has_conflict(&projector, s) {
        out.extend(s.by_depth.iter().map(|&i| tris[i]));
        return;
    }
    overlap_constraints(&projector, s);
    if s.edges.is_empty() {
        out.extend(s.by_depth.iter().map(|&i| tris[i]));
        return;
    }
    topological_order(tris, s, out);
}

/// The projection the cell's triangles are compared in: along the direction, or from the eye
/// towards the cell's centroid (`None` when the eye is at the centroid).
#[inline]
fn cell_projector(obj: &CellTriangles, tris: &[u32], in_cell: InCell) -> Option<Projector> {
    match in_cell {
        InCell::Direction(d) => Some(Projector::orthographic(d)),
        InCell::Eye(eye) => {
            let centre: DVec3 = tris
                .iter()
                .map(|&t| obj.corners(t).iter().sum::<DVec3>() / 3.0)
                .sum::<DVec3>()
                / tris.len() as f64;
            let d = centre - eye;
            (d.length_squared() > 0.0).then(|| Projector::perspective(eye, d))
        }
    }
}

/// Projects every triangle of the cell into `projected`; `false` when one cannot be (it reaches
/// behind the eye).
#[inline]
fn project_cell(
    obj: &CellTriangles,
    tris: &[u32],
    projector: &Projector,
    projected: &mut Vec<Projected>,
) -> bool {
    projected.clear();
    for &t in tris {
        match Projected::new(projector, obj.corners(t)) {
            Some(x) => projected.push(x),
            None => return false,
        }
    }
    true
}

/// Appends the cell's triangles farthest centroid first (from the eye, or from far back along
/// the direction), ties by position in the cell.
fn push_farthest_centroid_first(
    obj: &CellTriangles,
    tris: &[u32],
    in_cell: InCell,
    s: &mut Scratch,
    out: &mut Vec<u32>,
) {
    let eye = match in_cell {
        InCell::Eye(e) => e,
        InCell::Direction(d) => -d * 1e30,
    };
    s.by_depth.clear();
    s.by_depth.extend(0..tris.len());
    let dist: Vec<f64> = tris
        .iter()
        .map(|&t| (obj.corners(t).iter().sum::<DVec3>() / 3.0 - eye).length())
        .collect();
    s.by_depth
        .sort_by(|&a, &b| dist[b].total_cmp(&dist[a]).then(a.cmp(&b)));
    out.extend(s.by_depth.iter().map(|&i| tris[i]));
}

/// A first guess of the order, farthest first, into `s.by_depth`. The layers in a cell are
/// nearly parallel offsets of one surface, so where the cell's surface faces the eye the inner
/// layers (smaller offset along the mean outward normal) are behind, and where it faces away
/// the outer ones: the offset along the normal, signed by the facing, orders nested layers
/// where centroid depth along the view would be fooled by their sideways shifts. Near
/// silhouettes, view depth.
#[inline]
fn first_guess(projector: &Projector, s: &mut Scratch) {
    let proj = &s.projected;
    let normal: DVec3 = proj.iter().map(|p| p.normal).sum();
    let view = projector.direction;
    let facing = normal.normalize_or_zero().dot(view);
    s.key.clear();
    if facing.abs() > 0.25 {
        let sign = facing.signum();
        s.key.extend(
            proj.iter()
                .map(|p| sign * normal.dot(p.world.iter().sum::<DVec3>())),
        );
    } else {
        s.key.extend(proj.iter().map(|p| p.depth));
    }
    s.by_depth.clear();
    s.by_depth.extend(0..proj.len());
    let key = &s.key;
    s.by_depth
        .sort_by(|&a, &b| key[b].total_cmp(&key[a]).then(a.cmp(&b)));
}

/// Whether some triangle of `s.by_depth` lies behind one before it.
#[inline]
fn has_conflict(projector: &Projector, s: &Scratch) -> bool {
    let proj = &s.projected;
    for x in 0..s.by_depth.len() {
        let a = &proj[s.by_depth[x]];
        for &y in &s.by_depth[x + 1..] {
            if second_is_behind(projector, a, &proj[y], OVERLAP_TOLERANCE) {
                return true;
            }
        }
    }
    false
}

/// The constraints "i before j" for every overlapping pair of the cell, into `s.edges`.
fn overlap_constraints(projector: &Projector, s: &mut Scratch) {
    let proj = &s.projected;
    let n = proj.len();
    s.edges.clear();
    for i in 0..n {
        for j in i + 1..n {
            match behind_fast(projector, &proj[i], &proj[j], OVERLAP_TOLERANCE) {
                Some(true) => s.edges.push((i as u16, j as u16)),
                Some(false) => s.edges.push((j as u16, i as u16)),
                None => {}
            }
        }
    }
}

/// Appends the cell's triangles in an order that keeps every constraint of `s.edges` (Kahn's
/// algorithm, choosing the farthest ready triangle of `s.by_depth` each time; a cycle between
/// crossing triangles is broken at the farthest remaining).
fn topological_order(tris: &[u32], s: &mut Scratch, out: &mut Vec<u32>) {
    let n = tris.len();
    s.indegree.clear();
    s.indegree.resize(n, 0);
    s.succ_start.clear();
    s.succ_start.resize(n + 1, 0);
    for &(a, b) in &s.edges {
        s.indegree[b as usize] += 1;
        s.succ_start[a as usize + 1] += 1;
    }
    for i in 0..n {
        s.succ_start[i + 1] += s.succ_start[i];
    }
    s.succ.clear();
    s.succ.resize(s.edges.len(), 0);
    s.fill.clear();
    s.fill.extend_from_slice(&s.succ_start);
    for &(a, b) in &s.edges {
        s.succ[s.fill[a as usize] as usize] = b;
        s.fill[a as usize] += 1;
    }
    s.done.clear();
    s.done.resize(n, false);
    for _ in 0..n {
        let pick = s
            .by_depth
            .iter()
            .copied()
            .find(|&i| !s.done[i] && s.indegree[i] == 0)
            // A cycle (crossing triangles): break it at the farthest remaining.
            .or_else(|| s.by_depth.iter().copied().find(|&i| !s.done[i]))
            .expect("a triangle remains");
        s.done[pick] = true;
        out.push(tris[pick]);
        for e in s.succ_start[pick]..s.succ_start[pick + 1] {
            let b = s.succ[e as usize] as usize;
            s.indegree[b] = s.indegree[b].saturating_sub(1);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn octants_and_names_agree() {
        for o in Octant::ALL {
            assert_eq!(Octant::of(o.signs()).unwrap(), o);
            assert_eq!(Octant::from_name(o.name()), Some(o));
            let s = o.signs();
            let expect = format!(
                "order{}x{}y{}z",
                if s.x > 0.0 { '+' } else { '-' },
                if s.y > 0.0 { '+' } else { '-' },
                if s.z > 0.0 { '+' } else { '-' }
            );
            assert_eq!(o.name(), expect);
        }
        assert!(Octant::of(DVec3::ZERO).is_err());
        assert!(Octant::of(DVec3::new(f64::NAN, 0.0, 1.0)).is_err());
    }

    #[test]
    fn opposite_octants_are_opposite_indices() {
        for o in Octant::ALL {
            assert_eq!(Octant::from_index(7 - o.index()).signs(), -o.signs());
        }
    }

    fn sequence(coords: &[i64], sweep: Sweep) -> Vec<i64> {
        let mut out = Vec::new();
        axis_order(coords.len(), |i| coords[i], sweep, 0, 0, &mut out);
        out.into_iter().map(|i| coords[i]).collect()
    }

    #[test]
    fn eye_sequences_walk_towards_the_eye() {
        let seq = sequence(&[0, 1, 2, 3, 4, 5, 6], Sweep::Eye([3, 0, 0]));
        let keys: Vec<i64> = seq.iter().map(|&i| (i - 3).abs()).collect();
        assert!(keys.windows(2).all(|w| w[0] >= w[1]), "{seq:?}");
        assert_eq!(seq.len(), 7);
        // Eye outside the grid: a plain sweep.
        assert_eq!(
            sequence(&[0, 1, 2, 3], Sweep::Eye([-2, 0, 0])),
            vec![3, 2, 1, 0]
        );
        assert_eq!(
            sequence(&[0, 1, 2, 3], Sweep::Eye([9, 0, 0])),
            vec![0, 1, 2, 3]
        );
        // Occupied positions only: the same order as the full sweep restricted to them.
        assert_eq!(
            sequence(&[1, 2, 7, 8], Sweep::Eye([3, 0, 0])),
            vec![8, 7, 1, 2]
        );
        let octant = Sweep::Octant(DVec3::new(1.0, -1.0, 1.0));
        assert_eq!(sequence(&[2, 5, 9], octant), vec![9, 5, 2]);
    }

    #[test]
    fn huge_stated_grids_cost_nothing_or_are_refused() {
        // Two triangles in far corners of a grid with 60000² rows: the index lists two rows.
        let positions = [[0.1, 0.1, 0.1], [0.9, 0.1, 0.1], [0.1, 0.9, 0.1]]
            .into_iter()
            .chain([
                [0.1, 0.1, 59990.1],
                [0.9, 0.1, 59990.1],
                [0.1, 0.9, 59990.1],
            ])
            .map(Vec3::from)
            .collect::<Vec<_>>();
        let triangles = [[0, 1, 2], [3, 4, 5]];
        let grid = Grid::new([2, 60_000, 60_000], [1.0; 3], [0.0; 3]).unwrap();
        let cells = recover_cells(&grid, &Placement::IDENTITY, &positions, &triangles);
        let obj = CellTriangles {
            grid,
            placement: Placement::IDENTITY,
            positions: &positions,
            triangles: &triangles,
            cells: &cells,
        };
        let index = index_cells(&obj).unwrap();
        assert_eq!((index.rows.len(), index.slices.len()), (2, 2));
        let up = View::Orthographic {
            direction: DVec3::Z,
        };
        assert_eq!(view_order(&obj, &up).unwrap(), vec![1, 0]);
        let eye = View::Perspective {
            eye: DVec3::new(0.5, 0.5, -10.0),
        };
        assert_eq!(view_order(&obj, &eye).unwrap(), vec![1, 0]);
        // More cells than a u32 names: refused, not wrapped around.
        let grid = Grid::new([100_000; 3], [1.0; 3], [0.0; 3]).unwrap();
        let err = index_cells(&CellTriangles { grid, ..obj }).unwrap_err();
        assert!(err.to_string().contains("99999x99999x99999 cells"), "{err}");
    }
}
