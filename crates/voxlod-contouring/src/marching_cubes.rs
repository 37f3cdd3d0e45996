//! Table-driven marching cubes (Lorensen and Cline 1987), as the voxel paper's §2 uses it to turn
//! each filtered volume of the pyramid into a triangle mesh.
//!
//! **Rule.** A sample is inside when `value >= iso`, everywhere, once. Each grid edge whose two
//! samples disagree carries exactly one vertex, shared by every triangle that uses it; the
//! cells' triangles come from [`crate::tables`]. A surface that does not touch the grid boundary
//! therefore comes out closed, 2-manifold and consistently oriented, with triangles winding
//! counter-clockwise seen from outside (from lower density) and normals from the density
//! gradient pointing outwards.
//!
//! **Passes.** Beyond the paper (which describes the classic cell-by-cell loop), the extraction
//! is organised like Schroeder et al.'s Flying Edges so that the output can be written in
//! parallel into arrays sized in advance, and the float volume is read in full only once:
//! 1. classify every sample into one bit (`value >= iso`), 64 samples per word;
//! 2. per row of the grid, count the crossed edges each row owns (its +x, +y and +z edges: XOR
//!    and popcount of bit rows) and the triangles of each row of cells, visiting only the cells
//!    whose eight corner bits are mixed;
//! 3. prefix sums give every row its first vertex and first triangle; then each z-slice writes
//!    its vertices (interpolated positions, gradient normals) and triangles into its own part of
//!    the output, finding a vertex's index by counting the crossed edges before it in its row.
//!    A vertex's gradient and corner range read the samples one row and one slice around its
//!    edge, sparsely along x; the sample rows two rows ahead are prefetched into the cache, since
//!    the hardware prefetcher does not follow such reads (a sixth less time on the 256³ gyroid
//!    with normals and corner ranges).
//!
//! The output is deterministic (independent of the number of threads): vertices are ordered by
//! z, y, x and then edge axis, triangles by cell.
//!
//! **Cells and several surfaces** (for the multi-layer shells of paper §3).
//! [`marching_cubes_with_cells`] also returns the cell each triangle came from, which the
//! slice-by-slice back-to-front traversal needs; [`marching_cubes_multi`] classifies the samples
//! against several iso values in one read of the volume (pass 1 for all of them), then runs
//! passes 2 and 3 per surface. Both give exactly the mesh [`marching_cubes`] gives.
//!
//! **Cost.** One streaming read of the volume (pass 1), then O(N³/64) word operations, then work
//! proportional to the surface: O(N³/64 + V + T) beyond the first read, and `N³/8` bytes of bits.
//!
//! Vertex interpolation parameters are clamped to `[c, 1 - c]` along their edge,
//! [`ContourOptions::clamp`]: by default `c` = [`PLAIN_CLAMP`] = 1e-4, so that a sample exactly
//! at the iso value does not collapse triangles to zero area (what scikit-image and VTK do, up to
//! that clamp); with [`snap_clamp`]`(0.1, 1e-3)` (the lod pipeline's levels that are cleaned)
//! no edge is shorter than a tenth of a cell and no triangle smaller than 4.5e-3 cell² (see
//! `edge_vertex.rs`), while every sample's side, hence the triangles, stay those of plain
//! marching cubes.

use glam::Vec3;
use rayon::prelude::*;
use thiserror::Error;
use voxlod_core::{memory, CoreError, Grid, TriangleMesh, Volume};

use crate::edge_vertex::{repair_zero_normals, DenseSamples, VertexPlacer};
use crate::tables::{tables, Tables};

/// Options of [`marching_cubes`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContourOptions {
    /// The iso value. Samples `>= iso` are inside.
    pub iso: f32,
    /// Compute per-vertex normals from the density gradient (central differences).
    pub normals: bool,
    /// Each vertex's interpolation parameter along its grid edge is clamped to
    /// `[clamp, 1 - clamp]`, a number in `[0, 0.5]`: [`PLAIN_CLAMP`] (the default) for plain
    /// marching cubes, a [`snap_clamp`] for a surface with no sliver, needle or tiny triangle.
    pub clamp: f32,
}

/// The interpolation clamp of plain marching cubes: a sample at the iso value does not make a
/// zero-area triangle, and vertices match scikit-image's and VTK's to about 1e-4 cell.
pub const PLAIN_CLAMP: f32 = 1e-4;

/// Room for rounding in [`snap_clamp`]: 2 % beyond the exact bound, 2e-3 cell for a tenth of a
/// cell, far above the `f32` rounding of positions within 10⁴ cells of the origin.
const SNAP_ROOM: f64 = 1.02;

/// The interpolation clamp for which marching cubes makes no edge shorter than `min_edge` cells
/// and no triangle smaller than `min_area` cells² (at most 0.5, which cannot promise more than
/// edges of 0.707 cell and triangles of 0.217 cell²): the larger of `min_edge / √2` and
/// `√(2 · min_area / √3)`, with 2 % to spare (see `edge_vertex.rs` for why). Vertices near a
/// sample snap to that distance from it along their edge; none moves farther. For cleaning's
/// defaults (0.1 cell, 1e-3 cell²) it is 0.0721: edges of 0.102 cell and triangles of 4.5e-3
/// cell² at the least.
///
/// ```
/// use voxlod_contouring::marching_cubes::snap_clamp;
///
/// assert!((snap_clamp(0.1, 1e-3) - 0.1 / 2f32.sqrt() * 1.02).abs() < 1e-6);
/// assert_eq!(snap_clamp(0.0, 0.0), voxlod_contouring::PLAIN_CLAMP);
/// ```
pub fn snap_clamp(min_edge: f64, min_area: f64) -> f32 {
    let edge = min_edge / std::f64::consts::SQRT_2;
    let area = (2.0 * min_area / 3f64.sqrt()).sqrt();
    let clamp = (edge.max(area) * SNAP_ROOM) as f32;
    if clamp.is_nan() {
        return PLAIN_CLAMP;
    }
    clamp.clamp(PLAIN_CLAMP, 0.5)
}

impl Default for ContourOptions {
    /// Isodensity 0.5 with normals: the paper's setting for filtered solids.
    fn default() -> Self {
        ContourOptions {
            iso: 0.5,
            normals: true,
            clamp: PLAIN_CLAMP,
        }
    }
}

impl ContourOptions {
    /// The surface at `iso`, with normals.
    pub fn at(iso: f32) -> Self {
        ContourOptions {
            iso,
            ..Default::default()
        }
    }

    /// Geometry only: what peers such as VTK's Flying Edges compute with normals off.
    pub fn geometry_only(iso: f32) -> Self {
        ContourOptions {
            iso,
            normals: false,
            ..Default::default()
        }
    }

    /// The same surface with interpolation parameters clamped to `[clamp, 1 - clamp]`
    /// (see [`snap_clamp`]).
    pub fn with_clamp(self, clamp: f32) -> Self {
        ContourOptions { clamp, ..self }
    }
}

/// Why marching cubes could not run.
#[derive(Debug, Error)]
pub enum ContourError {
    /// The iso value is NaN or infinite.
    #[error("the iso value {0} is not a finite number")]
    NonFiniteIso(f32),
    /// The interpolation clamp is not in `[0, 0.5]`.
    #[error("the interpolation clamp {0} is not between 0 and 0.5")]
    BadClamp(f32),
    /// The surface would have this many vertices, too many for `u32` triangle indices.
    #[error("the surface has {0} vertices, more than 32-bit indices can address")]
    TooManyVertices(u64),
    /// The grid has this many cells, too many for the `u32` cell indices of [`CellMesh`].
    #[error("the grid has {0} cells, more than 32-bit cell indices can address")]
    TooManyCells(u64),
    /// The samples given do not fill the grid.
    #[error("{given} samples given for a {}x{}x{} grid", dims[0], dims[1], dims[2])]
    SampleCount {
        /// How many samples were given.
        given: usize,
        /// The grid's samples along x, y, z.
        dims: [usize; 3],
    },
    /// The classification bits or the mesh would not fit in the memory limit.
    #[error(transparent)]
    Memory(#[from] CoreError),
}

/// Bit rows of one z-slice: `words` 64-bit words per row, `ny` rows.
struct BitVolume {
    words: usize,
    ny: usize,
    bits: Vec<u64>,
}

impl BitVolume {
    #[inline]
    fn row(&self, j: usize, k: usize) -> &[u64] {
        let start = (k * self.ny + j) * self.words;
        &self.bits[start..start + self.words]
    }
}

/// Crossed-edge masks of one vertex row, and the running count of its vertices per word.
#[derive(Clone, Default)]
struct RowEdges {
    x: Vec<u64>,
    y: Vec<u64>,
    z: Vec<u64>,
    /// Vertices in words before `w`.
    before: Vec<u32>,
    /// Index of the row's first vertex in the whole mesh.
    base: u32,
}

impl RowEdges {
    fn new(words: usize) -> Self {
        RowEdges {
            x: vec![0; words],
            y: vec![0; words],
            z: vec![0; words],
            before: vec![0; words + 1],
            base: 0,
        }
    }

    /// Fills the masks of row (j, k) from the bits; edges past the grid are never set.
    fn compute(&mut self, bits: &BitVolume, dims: [usize; 3], j: usize, k: usize) -> u32 {
        let [nx, ny, nz] = dims;
        let words = bits.words;
        let row = bits.row(j, k);
        let up = (j + 1 < ny).then(|| bits.row(j + 1, k));
        let front = (k + 1 < nz).then(|| bits.row(j, k + 1));
        let mut count = 0u32;
        for w in 0..words {
            let valid = valid_mask(nx, w);
            let valid_x = valid_mask(nx - 1, w);
            let shifted = shift_next(row, w);
            self.x[w] = (row[w] ^ shifted) & valid_x;
            self.y[w] = up.map_or(0, |u| (row[w] ^ u[w]) & valid);
            self.z[w] = front.map_or(0, |f| (row[w] ^ f[w]) & valid);
            self.before[w] = count;
            count += self.x[w].count_ones() + self.y[w].count_ones() + self.z[w].count_ones();
        }
        self.before[words] = count;
        count
    }

    /// Mesh index of the vertex on this row's edge along `axis` (0, 1, 2) from sample `x`.
    #[inline(always)]
    fn vertex(&self, axis: usize, x: usize) -> u32 {
        let (w, b) = (x / 64, x % 64);
        let below = (1u64 << b) - 1;
        let mut index = self.base
            + self.before[w]
            + (self.x[w] & below).count_ones()
            + (self.y[w] & below).count_ones()
            + (self.z[w] & below).count_ones();
        let bit = 1u64 << b;
        if axis >= 1 {
            index += ((self.x[w] & bit) != 0) as u32;
        }
        if axis == 2 {
            index += ((self.y[w] & bit) != 0) as u32;
        }
        debug_assert!(
            [&self.x, &self.y, &self.z][axis][w] & bit != 0,
            "edge {axis} at x={x} is not crossed"
        );
        index
    }
}

/// The bits of `row` shifted down by one sample: bit `x` of the result is sample `x + 1`.
#[inline]
fn shift_next(row: &[u64], w: usize) -> u64 {
    let next = row.get(w + 1).copied().unwrap_or(0);
    (row[w] >> 1) | (next << 63)
}

/// Bits of word `w` that stand for samples `x < n`.
#[inline]
fn valid_mask(n: usize, w: usize) -> u64 {
    let start = w * 64;
    if n >= start + 64 {
        u64::MAX
    } else if n <= start {
        0
    } else {
        (1u64 << (n - start)) - 1
    }
}

/// Extracts the isosurface of `volume` at `options.iso`, in the volume's world units (its
/// spacing and origin). See the module documentation.
///
/// One sample inside a grid of outside ones is cut off by the eight cells around it, one
/// triangle each: an octahedron with a vertex on each of the six edges from that sample, here at
/// a quarter of the way along since the iso value is a quarter of the way from 1 down to 0.
///
/// ```
/// use voxlod_contouring::{marching_cubes, ContourOptions};
/// use voxlod_core::{glam::Vec3, Grid, Volume};
///
/// let mut values = vec![0.0f32; 27];
/// values[13] = 1.0; // sample (1, 1, 1) of a 3×3×3 grid
/// let grid = Grid::new([3, 3, 3], [2.0; 3], [10.0, 0.0, 0.0])?; // 2 mm apart
/// let volume = Volume::from_vec(grid, values)?;
/// let mesh = marching_cubes(&volume, &ContourOptions::at(0.75))?;
/// assert_eq!((mesh.vertex_count(), mesh.triangle_count()), (6, 8));
///
/// let centre = Vec3::new(12.0, 2.0, 2.0);
/// for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
///     assert!(((*p - centre).length() - 0.5).abs() < 1e-6); // a quarter of 2 mm
///     assert!(n.dot(*p - centre) > 0.99 * 0.5); // unit normals, pointing outwards
/// }
/// // Counter-clockwise seen from outside: a positive enclosed volume, (4/3)·0.5³.
/// assert!((mesh.signed_volume() - 4.0 / 3.0 * 0.125).abs() < 1e-6);
///
/// // Geometry only: the same triangles, no normals.
/// let bare = marching_cubes(&volume, &ContourOptions::geometry_only(0.75))?;
/// assert_eq!(bare.triangles, mesh.triangles);
/// assert!(bare.normals.is_empty());
/// # Ok::<(), voxlod_contouring::ContourError>(())
/// ```
pub fn marching_cubes(
    volume: &Volume,
    options: &ContourOptions,
) -> Result<TriangleMesh, ContourError> {
    let iso = check_iso(options.iso)?;
    let clamp = check_clamp(options.clamp)?;
    let samples = volume.as_slice();
    let Some(bits) = classify(samples, volume.grid.dims, &[iso])?.pop() else {
        return Ok(TriangleMesh::default());
    };
    let wanted = Wanted {
        normals: options.normals,
        ..Wanted::default()
    };
    let level = Level { iso, clamp };
    Ok(extract(samples, &volume.grid, &bits, level, wanted)?.mesh)
}

/// A surface with, for every triangle, the cell it came from.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CellMesh {
    /// The surface, exactly as [`marching_cubes`] gives it.
    pub mesh: TriangleMesh,
    /// Linear index `i + (nx-1) * (j + (ny-1) * k)` of the cell (i, j, k) of each triangle, for
    /// a grid of `nx × ny × nz` samples. Non-decreasing: triangles are stored cell by cell.
    pub cells: Vec<u32>,
}

/// As [`marching_cubes`] (the same mesh), and the cell of each triangle: what a back-to-front
/// traversal of the cells needs (paper §3).
///
/// ```
/// use voxlod_contouring::{marching_cubes, marching_cubes_with_cells, ContourOptions};
/// use voxlod_core::{Grid, Volume};
///
/// // The octahedron of [`marching_cubes`]: one triangle in each of the 2×2×2 cells.
/// let mut values = vec![0.0f32; 27];
/// values[13] = 1.0;
/// let volume = Volume::from_vec(Grid::unit([3, 3, 3])?, values)?;
/// let with_cells = marching_cubes_with_cells(&volume, &ContourOptions::at(0.5))?;
/// assert_eq!(with_cells.cells, (0..8).collect::<Vec<u32>>());
/// assert_eq!(with_cells.mesh, marching_cubes(&volume, &ContourOptions::at(0.5))?);
/// # Ok::<(), voxlod_contouring::ContourError>(())
/// ```
pub fn marching_cubes_with_cells(
    volume: &Volume,
    options: &ContourOptions,
) -> Result<CellMesh, ContourError> {
    let clamp = check_clamp(options.clamp)?;
    Ok(
        multi_with_clamp(volume, &[options.iso], options.normals, clamp)?
            .pop()
            .unwrap_or_default(),
    )
}

/// Several isosurfaces of one volume, each with the cells of its triangles (see
/// [`marching_cubes_with_cells`]): the volume is read once to classify every sample against
/// every iso value; the later passes run per surface on the bits and touch the floats only at
/// crossed edges. Each surface is the one [`marching_cubes`] gives for its iso value.
///
/// ```
/// use voxlod_contouring::{marching_cubes, marching_cubes_multi, ContourOptions};
/// use voxlod_core::{Grid, Volume};
///
/// // Nested octahedra around the one inside sample: the lower the iso value, the larger.
/// let mut values = vec![0.0f32; 27];
/// values[13] = 1.0;
/// let volume = Volume::from_vec(Grid::unit([3, 3, 3])?, values)?;
/// let shells = marching_cubes_multi(&volume, &[0.25, 0.75], true)?;
/// let volumes: Vec<f64> = shells.iter().map(|s| s.mesh.signed_volume()).collect();
/// assert!((volumes[0] - 4.0 / 3.0 * 0.75f64.powi(3)).abs() < 1e-6);
/// assert!((volumes[1] - 4.0 / 3.0 * 0.25f64.powi(3)).abs() < 1e-6);
/// assert_eq!(shells[1].mesh, marching_cubes(&volume, &ContourOptions::at(0.75))?);
/// # Ok::<(), voxlod_contouring::ContourError>(())
/// ```
pub fn marching_cubes_multi(
    volume: &Volume,
    isos: &[f32],
    normals: bool,
) -> Result<Vec<CellMesh>, ContourError> {
    multi_with_clamp(volume, isos, normals, PLAIN_CLAMP)
}

/// [`marching_cubes_multi`] with the interpolation clamp `clamp`.
fn multi_with_clamp(
    volume: &Volume,
    isos: &[f32],
    normals: bool,
    clamp: f32,
) -> Result<Vec<CellMesh>, ContourError> {
    for &iso in isos {
        check_iso(iso)?;
    }
    check_cell_count(volume.grid.dims)?;
    let samples = volume.as_slice();
    let bits = classify(samples, volume.grid.dims, isos)?;
    if bits.is_empty() {
        return Ok(vec![CellMesh::default(); isos.len()]);
    }
    let wanted = Wanted {
        normals,
        cells: true,
        corner_ranges: false,
    };
    bits.par_iter()
        .zip(isos)
        .map(|(b, &iso)| {
            let surface = extract(samples, &volume.grid, b, Level { iso, clamp }, wanted)?;
            Ok(CellMesh {
                mesh: surface.mesh,
                cells: surface.cells,
            })
        })
        .collect()
}

/// Refuses grids with more cells than `u32` cell indices address.
fn check_cell_count([nx, ny, nz]: [usize; 3]) -> Result<(), ContourError> {
    let cells = (nx.max(1) - 1) as u64 * (ny.max(1) - 1) as u64 * (nz.max(1) - 1) as u64;
    if cells > u32::MAX as u64 {
        return Err(ContourError::TooManyCells(cells));
    }
    Ok(())
}

/// What [`marching_cubes_of_samples`] computes besides the triangles and positions.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Wanted {
    /// Per-vertex normals from the density gradient, as [`ContourOptions::normals`].
    pub normals: bool,
    /// The cell of each triangle, as [`CellMesh::cells`].
    pub cells: bool,
    /// Per vertex, the largest corner range (max − min of its eight samples) of the cells
    /// around the vertex's grid edge: scikit-image's `values`. Every crossed edge of a cell is
    /// used by that cell's triangles (the tables' test checks it), so this is also the largest
    /// range of the cells whose triangles use the vertex. Computed while the vertex is placed.
    pub corner_ranges: bool,
}

/// A surface and what [`Wanted`] asked for (empty vectors for what it did not).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SampleSurface {
    /// The surface, exactly as [`marching_cubes`] gives it (normals if asked for).
    pub mesh: TriangleMesh,
    /// The cell of each triangle, as [`CellMesh::cells`].
    pub cells: Vec<u32>,
    /// Per vertex, its corner range (see [`Wanted::corner_ranges`]).
    pub corner_ranges: Vec<f32>,
}

/// The isosurface of samples borrowed in place (x fastest, as [`Volume`] holds them) on
/// `grid`, samples `>= iso` inside: the same mesh as [`marching_cubes`] on a volume of these
/// samples, without the volume (the Python package hands NumPy's memory straight here), and
/// what `wanted` asks for besides, computed in the same passes.
///
/// ```
/// use voxlod_contouring::marching_cubes::{marching_cubes_of_samples, Wanted};
/// use voxlod_contouring::{marching_cubes, ContourOptions};
/// use voxlod_core::{Grid, Volume};
///
/// let mut values = vec![0.0f32; 27];
/// values[13] = 1.0; // the octahedron of [`marching_cubes`]
/// let grid = Grid::unit([3, 3, 3])?;
/// let wanted = Wanted { normals: true, cells: true, corner_ranges: true };
/// let surface = marching_cubes_of_samples(&values, &grid, 0.5, wanted)?;
/// let volume = Volume::from_vec(grid, values)?;
/// assert_eq!(surface.mesh, marching_cubes(&volume, &ContourOptions::at(0.5))?);
/// assert_eq!(surface.cells, (0..8).collect::<Vec<u32>>());
/// assert_eq!(surface.corner_ranges, vec![1.0; 6]); // every cell spans 0 to 1
/// # Ok::<(), voxlod_contouring::ContourError>(())
/// ```
pub fn marching_cubes_of_samples(
    samples: &[f32],
    grid: &Grid,
    iso: f32,
    wanted: Wanted,
) -> Result<SampleSurface, ContourError> {
    let iso = check_iso(iso)?;
    if samples.len() != grid.len() {
        return Err(ContourError::SampleCount {
            given: samples.len(),
            dims: grid.dims,
        });
    }
    check_cell_count(grid.dims)?;
    let Some(bits) = classify(samples, grid.dims, &[iso])?.pop() else {
        return Ok(SampleSurface::default());
    };
    let level = Level {
        iso,
        clamp: PLAIN_CLAMP,
    };
    extract(samples, grid, &bits, level, wanted)
}

/// Refuses a clamp outside `[0, 0.5]` (or NaN).
pub(crate) fn check_clamp(clamp: f32) -> Result<f32, ContourError> {
    if (0.0..=0.5).contains(&clamp) {
        Ok(clamp)
    } else {
        Err(ContourError::BadClamp(clamp))
    }
}

/// The surface's iso value and its vertices' interpolation clamp.
#[derive(Clone, Copy, Debug)]
struct Level {
    iso: f32,
    clamp: f32,
}

fn check_iso(iso: f32) -> Result<f32, ContourError> {
    if iso.is_finite() {
        Ok(iso)
    } else {
        Err(ContourError::NonFiniteIso(iso))
    }
}

/// Pass 1: one bit per sample and iso value (`value >= iso`), from one read of the volume.
/// Empty when the grid has no cells along some axis.
fn classify(data: &[f32], dims: [usize; 3], isos: &[f32]) -> Result<Vec<BitVolume>, ContourError> {
    let [nx, ny, nz] = dims;
    if nx < 2 || ny < 2 || nz < 2 {
        return Ok(Vec::new());
    }
    let words = nx.div_ceil(64);
    let rows = ny * nz;
    memory::check_allocation(
        "marching cubes classification bits",
        memory::bytes_of::<u64>(rows * words).saturating_mul(isos.len() as u64),
    )?;
    let mut all: Vec<Vec<u64>> = isos.iter().map(|_| vec![0u64; rows * words]).collect();
    if let ([bits], &[iso]) = (&mut all[..], isos) {
        // One iso value: the tight loop.
        bits.par_chunks_mut(words * ny)
            .zip(data.par_chunks(nx * ny))
            .for_each(|(slab, slice)| {
                for (bit_row, row) in slab.chunks_mut(words).zip(slice.chunks(nx)) {
                    for (word, chunk) in bit_row.iter_mut().zip(row.chunks(64)) {
                        *word = classify_word(chunk, iso);
                    }
                }
            });
    } else {
        // Several: each z-slice of the volume is read once for all of them.
        let slab = words * ny;
        let mut slabs: Vec<Vec<&mut [u64]>> = (0..nz).map(|_| Vec::new()).collect();
        for bits in all.iter_mut() {
            for (k, s) in bits.chunks_mut(slab).enumerate() {
                slabs[k].push(s);
            }
        }
        slabs
            .par_iter_mut()
            .zip(data.par_chunks(nx * ny))
            .for_each(|(outs, slice)| {
                // Row by row: the row stays in cache while every iso value classifies it.
                for (j, row) in slice.chunks(nx).enumerate() {
                    for (out, &iso) in outs.iter_mut().zip(isos) {
                        let bit_row = &mut out[j * words..(j + 1) * words];
                        for (word, chunk) in bit_row.iter_mut().zip(row.chunks(64)) {
                            *word = classify_word(chunk, iso);
                        }
                    }
                }
            });
    }
    Ok(all
        .into_iter()
        .map(|bits| BitVolume { words, ny, bits })
        .collect())
}

/// Bit `b` set when `chunk[b] >= iso` (NaN is outside), for up to 64 samples: four at a time
/// with SSE2 compares and move-masks on x86-64.
#[inline]
fn classify_word(chunk: &[f32], iso: f32) -> u64 {
    #[cfg(target_arch = "x86_64")]
    if chunk.len() == 64 {
        use std::arch::x86_64::{_mm_cmpge_ps, _mm_loadu_ps, _mm_movemask_ps, _mm_set1_ps};
        let mut bits = 0u64;
        // SAFETY: SSE2 is part of every x86-64 target; each load reads the four f32 values of
        // `four`, which `chunks_exact(4)` guarantees exist.
        unsafe {
            let threshold = _mm_set1_ps(iso);
            for (q, four) in chunk.chunks_exact(4).enumerate() {
                // An ordered comparison: false for NaN, like the scalar `>=` below.
                let inside = _mm_cmpge_ps(_mm_loadu_ps(four.as_ptr()), threshold);
                bits |= (_mm_movemask_ps(inside) as u64) << (4 * q);
            }
        }
        return bits;
    }
    chunk
        .iter()
        .enumerate()
        .fold(0u64, |bits, (b, &v)| bits | ((v >= iso) as u64) << b)
}

/// Passes 2 and 3 on the bits of one iso value, with what `wanted` asks for.
fn extract(
    data: &[f32],
    grid: &Grid,
    bits: &BitVolume,
    level: Level,
    wanted: Wanted,
) -> Result<SampleSurface, ContourError> {
    let dims = grid.dims;
    debug_assert_eq!(bits.bits.len(), dims[1] * dims[2] * bits.words);
    let table = tables();
    let counts = count_rows(bits, dims, table);
    let layout = OutputLayout::new(&counts, dims[1], wanted)?;

    // Fresh zero pages that the parallel writers touch first (huge ones where the kernel
    // allows): no serial fill of the outputs before the pass that writes them.
    let optional = |on: bool, len: usize| if on { len } else { 0 };
    let mut positions = zeroed_points(layout.vertices);
    let mut normals = zeroed_points(optional(wanted.normals, layout.vertices));
    let mut triangles: Vec<[u32; 3]> = memory::zeroed_vec(layout.triangles);
    let mut cells: Vec<u32> = memory::zeroed_vec(optional(wanted.cells, layout.triangles));
    let mut ranges: Vec<f32> = memory::zeroed_vec(optional(wanted.corner_ranges, layout.vertices));
    let parts = layout.split_per_slice(OutputSlices {
        k: 0,
        positions: &mut positions,
        normals: &mut normals,
        ranges: &mut ranges,
        triangles: &mut triangles,
        cells: &mut cells,
    });
    let samples = DenseSamples { data, dims };
    let writer = SliceWriter {
        data,
        bits,
        dims,
        table,
        row_vertex_base: &layout.row_vertex_base,
        field: VertexPlacer::new(&samples, grid, level.iso, level.clamp),
        wanted,
    };
    parts
        .into_par_iter()
        .for_each(|part| writer.write_slice(part));

    let mut mesh = TriangleMesh {
        positions,
        normals,
        triangles,
    };
    if wanted.normals {
        repair_zero_normals(&mut mesh);
    }
    Ok(SampleSurface {
        mesh,
        cells,
        corner_ranges: ranges,
    })
}

/// `len` zero points in fresh zero pages from the allocator, advised to be huge, not written
/// here: `vec![Vec3::ZERO; len]` would fill them serially, page fault by page fault.
fn zeroed_points(len: usize) -> Vec<Vec3> {
    if len == 0 {
        return Vec::new();
    }
    let layout = std::alloc::Layout::array::<Vec3>(len).expect("a mesh within the memory limit");
    // SAFETY: the layout has a non-zero size; all-zero bytes are a valid `Vec3` (three 0.0);
    // the buffer comes from the global allocator with the layout of `len` `Vec3`s, as
    // `Vec::from_raw_parts` requires, and all `len` of them are initialised.
    let points = unsafe {
        let ptr = std::alloc::alloc_zeroed(layout).cast::<Vec3>();
        if ptr.is_null() {
            std::alloc::handle_alloc_error(layout);
        }
        Vec::from_raw_parts(ptr, len, len)
    };
    memory::advise_huge_pages(&points);
    points
}

/// Pass 2: for every row (j, k), in z-then-y order, the vertices on the edges the vertex row
/// owns and the triangles of the cell row with the same corner (none past the last row).
fn count_rows(bits: &BitVolume, dims: [usize; 3], table: &Tables) -> Vec<(u32, u32)> {
    let [_, ny, nz] = dims;
    (0..nz)
        .into_par_iter()
        .flat_map_iter(|k| {
            let mut edges = RowEdges::new(bits.words);
            (0..ny).map(move |j| {
                let vertices = edges.compute(bits, dims, j, k);
                let mut triangles = 0u32;
                if j + 1 < ny && k + 1 < nz {
                    for_each_mixed_cell(bits, dims, j, k, |_, case| {
                        triangles += table.triangle_count[case as usize] as u32;
                    });
                }
                (vertices, triangles)
            })
        })
        .collect()
}

/// Where each row's and each z-slice's output goes: the prefix sums of pass 2's counts.
struct OutputLayout {
    vertices: usize,
    triangles: usize,
    /// Mesh index of the first vertex of each vertex row (j, k), at `k * ny + j`.
    row_vertex_base: Vec<u32>,
    /// Vertices and triangles of each z-slice.
    slice_vertices: Vec<usize>,
    slice_triangles: Vec<usize>,
}

impl OutputLayout {
    /// The layout of the counts of [`count_rows`], once the mesh is known to be addressable
    /// with 32-bit indices and to fit in memory.
    fn new(counts: &[(u32, u32)], ny: usize, wanted: Wanted) -> Result<OutputLayout, ContourError> {
        let total_vertices: u64 = counts.iter().map(|c| c.0 as u64).sum();
        let total_triangles: u64 = counts.iter().map(|c| c.1 as u64).sum();
        if total_vertices >= u32::MAX as u64 {
            return Err(ContourError::TooManyVertices(total_vertices));
        }
        let vertex_bytes = memory::bytes_of::<Vec3>(total_vertices as usize)
            * if wanted.normals { 2 } else { 1 }
            + if wanted.corner_ranges {
                memory::bytes_of::<f32>(total_vertices as usize)
            } else {
                0
            };
        let cell_bytes = if wanted.cells {
            memory::bytes_of::<u32>(total_triangles as usize)
        } else {
            0
        };
        memory::check_allocation(
            "the marching cubes mesh",
            vertex_bytes + memory::bytes_of::<[u32; 3]>(total_triangles as usize) + cell_bytes,
        )?;
        let mut row_vertex_base = Vec::with_capacity(counts.len());
        let mut running = 0u32;
        for c in counts {
            row_vertex_base.push(running);
            running += c.0;
        }
        let per_slice = |pick: fn(&(u32, u32)) -> u32| -> Vec<usize> {
            counts
                .chunks(ny)
                .map(|s| s.iter().map(|c| pick(c) as usize).sum())
                .collect()
        };
        Ok(OutputLayout {
            vertices: total_vertices as usize,
            triangles: total_triangles as usize,
            row_vertex_base,
            slice_vertices: per_slice(|c| c.0),
            slice_triangles: per_slice(|c| c.1),
        })
    }

    /// The output arrays cut into one part per z-slice (the optional ones empty when not asked
    /// for).
    fn split_per_slice<'a>(&self, whole: OutputSlices<'a>) -> Vec<OutputSlices<'a>> {
        let nz = self.slice_vertices.len();
        let mut parts = Vec::with_capacity(nz);
        let mut rest = whole;
        for k in 0..nz {
            let (part, others) = rest.split(k, self.slice_vertices[k], self.slice_triangles[k]);
            parts.push(part);
            rest = others;
        }
        parts
    }
}

/// The output arrays, or one z-slice's part of them: the vertices its vertex rows own, the
/// triangles of its cells. Normals, ranges and cells are empty when not asked for.
struct OutputSlices<'a> {
    k: usize,
    positions: &'a mut [Vec3],
    normals: &'a mut [Vec3],
    ranges: &'a mut [f32],
    triangles: &'a mut [[u32; 3]],
    cells: &'a mut [u32],
}

impl<'a> OutputSlices<'a> {
    /// The first `vertices` and `triangles` as slice `k`'s part, and the rest.
    fn split(self, k: usize, vertices: usize, triangles: usize) -> (Self, Self) {
        fn cut<T>(s: &mut [T], n: usize) -> (&mut [T], &mut [T]) {
            s.split_at_mut(if s.is_empty() { 0 } else { n })
        }
        let (p, pr) = self.positions.split_at_mut(vertices);
        let (n, nr) = cut(self.normals, vertices);
        let (v, vr) = cut(self.ranges, vertices);
        let (t, tr) = self.triangles.split_at_mut(triangles);
        let (c, cr) = cut(self.cells, triangles);
        let part = OutputSlices {
            k,
            positions: p,
            normals: n,
            ranges: v,
            triangles: t,
            cells: c,
        };
        let rest = OutputSlices {
            k: k + 1,
            positions: pr,
            normals: nr,
            ranges: vr,
            triangles: tr,
            cells: cr,
        };
        (part, rest)
    }
}

/// Pass 3: what every z-slice reads to write its part of the mesh.
struct SliceWriter<'a> {
    /// The samples, x fastest (those that `field` reads).
    data: &'a [f32],
    bits: &'a BitVolume,
    dims: [usize; 3],
    table: &'a Tables,
    /// See [`OutputLayout::row_vertex_base`].
    row_vertex_base: &'a [u32],
    field: VertexPlacer<'a, DenseSamples<'a>>,
    wanted: Wanted,
}

impl SliceWriter<'_> {
    /// Fills `edges` with the crossed edges of vertex row (j, k) and its first vertex index.
    #[inline]
    fn load_row(&self, edges: &mut RowEdges, j: usize, k: usize) {
        edges.compute(self.bits, self.dims, j, k);
        edges.base = self.row_vertex_base[k * self.dims[1] + j];
    }

    /// Writes the vertices of slice k's vertex rows and the triangles of its cell rows, row
    /// by row, keeping the four vertex rows around the current cell row.
    fn write_slice(&self, mut out: OutputSlices<'_>) {
        let [_, ny, nz] = self.dims;
        let k = out.k;
        let words = self.bits.words;
        let mut lower = [RowEdges::new(words), RowEdges::new(words)]; // rows (j, k), (j, k+1)
        let mut upper = [RowEdges::new(words), RowEdges::new(words)]; // rows (j+1, k), (j+1, k+1)
        self.load_row(&mut lower[0], 0, k);
        if k + 1 < nz {
            self.load_row(&mut lower[1], 0, k + 1);
        }
        let slice_base = lower[0].base;
        let mut written = 0usize;
        let mut tri_written = 0usize;
        for j in 0..ny {
            self.prefetch_samples(j + 2, k);
            self.write_row_vertices(&lower[0], [j, k], slice_base, &mut out, &mut written);
            if j + 1 < ny {
                self.load_row(&mut upper[0], j + 1, k);
                if k + 1 < nz {
                    self.load_row(&mut upper[1], j + 1, k + 1);
                    let rows = [&lower[0], &upper[0], &lower[1], &upper[1]];
                    self.write_row_triangles(&rows, [j, k], &mut out, &mut tri_written);
                }
                std::mem::swap(&mut lower, &mut upper);
            }
        }
        debug_assert_eq!(written, out.positions.len());
        debug_assert_eq!(tri_written, out.triangles.len());
    }

    /// Asks the cache for the sample rows (j, k - 1 ..= k + 2) that the vertices of vertex row
    /// j - 2 will read (gradients and corner ranges reach one row and slice around an edge):
    /// their reads are sparse along x, which the hardware prefetcher does not follow.
    #[inline]
    fn prefetch_samples(&self, j: usize, k: usize) {
        #[cfg(target_arch = "x86_64")]
        {
            let [nx, ny, nz] = self.dims;
            if j >= ny {
                return;
            }
            let data = self.data;
            for kk in k.saturating_sub(1)..(k + 3).min(nz) {
                let row = &data[(kk * ny + j) * nx..][..nx];
                for chunk in row.chunks(16) {
                    // SAFETY: a prefetch of a valid address has no effect on memory.
                    unsafe {
                        std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(
                            chunk.as_ptr().cast(),
                        )
                    };
                }
            }
        }
    }

    /// The vertices owned by vertex row `own` = (j, k), in the order [`RowEdges::vertex`]
    /// counts them: by x, then edge axis.
    #[inline]
    fn write_row_vertices(
        &self,
        own: &RowEdges,
        [j, k]: [usize; 2],
        slice_base: u32,
        out: &mut OutputSlices<'_>,
        written: &mut usize,
    ) {
        for w in 0..self.bits.words {
            let mut any = own.x[w] | own.y[w] | own.z[w];
            while any != 0 {
                let b = any.trailing_zeros() as usize;
                any &= any - 1;
                let x = w * 64 + b;
                let bit = 1u64 << b;
                for (axis, mask) in [own.x[w], own.y[w], own.z[w]].into_iter().enumerate() {
                    if mask & bit != 0 {
                        debug_assert_eq!(own.vertex(axis, x) - slice_base, *written as u32);
                        let (p, n) = self.field.edge_vertex([x, j, k], axis, self.wanted.normals);
                        out.positions[*written] = p;
                        if self.wanted.normals {
                            out.normals[*written] = n;
                        }
                        if self.wanted.corner_ranges {
                            out.ranges[*written] = self.field.corner_range([x, j, k], axis);
                        }
                        *written += 1;
                    }
                }
            }
        }
    }

    /// The triangles of cell row (j, k), given its four vertex rows (j,k), (j+1,k), (j,k+1),
    /// (j+1,k+1).
    #[inline]
    fn write_row_triangles(
        &self,
        rows: &[&RowEdges; 4],
        [j, k]: [usize; 2],
        out: &mut OutputSlices<'_>,
        tri_written: &mut usize,
    ) {
        let [nx, ny, _] = self.dims;
        let row_cell = ((nx - 1) * (j + (ny - 1) * k)) as u32;
        for_each_mixed_cell(self.bits, self.dims, j, k, |x, case| {
            let n = self.table.triangle_count[case as usize] as usize;
            for t in &self.table.triangles[case as usize][..n] {
                // Three plain calls: `[u8; 3]::map` here stays an out-of-line closure.
                out.triangles[*tri_written] = [
                    cell_edge_vertex(rows, t[0], x),
                    cell_edge_vertex(rows, t[1], x),
                    cell_edge_vertex(rows, t[2], x),
                ];
                if self.wanted.cells {
                    out.cells[*tri_written] = row_cell + x as u32;
                }
                *tri_written += 1;
            }
        });
    }
}

/// Calls `visit(x, case)` for every cell of cell row (j, k) whose corners are not all alike.
#[inline]
fn for_each_mixed_cell(
    bits: &BitVolume,
    dims: [usize; 3],
    j: usize,
    k: usize,
    mut visit: impl FnMut(usize, u8),
) {
    let nx = dims[0];
    let (r0, r2, r4, r6) = (
        bits.row(j, k),
        bits.row(j + 1, k),
        bits.row(j, k + 1),
        bits.row(j + 1, k + 1),
    );
    for w in 0..bits.words {
        let c = [
            r0[w],
            shift_next(r0, w),
            r2[w],
            shift_next(r2, w),
            r4[w],
            shift_next(r4, w),
            r6[w],
            shift_next(r6, w),
        ];
        let all = c.iter().fold(u64::MAX, |a, &b| a & b);
        let any = c.iter().fold(0, |a, &b| a | b);
        let mut mixed = any & !all & valid_mask(nx - 1, w);
        while mixed != 0 {
            let b = mixed.trailing_zeros();
            mixed &= mixed - 1;
            let mut case = 0u8;
            for (corner, word) in c.iter().enumerate() {
                case |= (((word >> b) & 1) as u8) << corner;
            }
            visit(w * 64 + b as usize, case);
        }
    }
}

/// Mesh index of cube edge `e` of the cell at `x`, given the rows (j,k), (j+1,k), (j,k+1), (j+1,k+1).
#[inline(always)]
fn cell_edge_vertex(rows: &[&RowEdges; 4], e: u8, x: usize) -> u32 {
    match e {
        0..=3 => rows[e as usize].vertex(0, x),
        // y edges from corners 0, 1, 4, 5: rows (j,k) and (j,k+1), at x or x + 1.
        4 => rows[0].vertex(1, x),
        5 => rows[0].vertex(1, x + 1),
        6 => rows[2].vertex(1, x),
        7 => rows[2].vertex(1, x + 1),
        // z edges from corners 0, 1, 2, 3: rows (j,k) and (j+1,k), at x or x + 1.
        8 => rows[0].vertex(2, x),
        9 => rows[0].vertex(2, x + 1),
        10 => rows[1].vertex(2, x),
        _ => rows[1].vertex(2, x + 1),
    }
}
