//! Marching cubes for every label of a map in one pass: each label's surface is the isosurface
//! ½ of its indicator (1 on its voxels, 0 elsewhere and outside the map), the surface zmesh and
//! the paper's thresholding route (§4) give without a filter.
//!
//! **Pass.** The cells (2 × 2 × 2 voxels, one more on every side so that labels at the map's
//! border close) are visited once, in parallel over slabs of z. A cell whose eight voxels carry
//! one label is skipped at the cost of a few comparisons; in a mixed cell, each label present
//! gets its case (the corners that carry it) and the cell is recorded for that label as one
//! 64-bit word (cell index and case), so the pass stores a word per label and mixed cell, not
//! its triangles. Then each label, in parallel, turns its words into triangles with the
//! tables of [`voxlod_contouring::tables`] (inside corners separated on ambiguous faces, so
//! cells agree across faces) and one vertex per crossed edge, at the edge's midpoint: the
//! indicator is ½ there. Every label's mesh is closed, 2-manifold and outward
//! (counter-clockwise seen from outside), whatever its neighbours; neighbours share the vertex
//! positions along the edges between them but not their triangles where three or more labels
//! meet (the surface nets of `surface_nets.rs` share them).
//!
//! **Cost.** One read of the map (four rows at a time), O(1) per uniform cell; then per label
//! O(T), each triangle corner's vertex found in two layers of slots over the label's box.
//! Memory: 8 bytes per label and mixed cell, the slots of the labels in flight, the meshes.

use glam::{DMat4, DVec3, Vec3};
use rayon::prelude::*;
use rustc_hash::FxHashMap;
use voxlod_contouring::tables::{tables, EDGE_AXIS, EDGE_CORNERS};
use voxlod_core::glam;
use voxlod_core::{memory, LabelVolume, TriangleMesh};

use crate::find::{find_labels, select_labels, LabelInfo};
use crate::LabelsError;

/// Cell layers (along z) per task of the pass.
const LAYERS_PER_TASK: usize = 4;

/// Every non-zero label of `map` meshed by marching cubes (see the module), in increasing
/// order of label, each with its [`LabelInfo`]. Fails on a map of background alone.
pub fn marching_cubes(map: &LabelVolume) -> Result<Vec<(LabelInfo, TriangleMesh)>, LabelsError> {
    let labels = select_labels(find_labels(map), None)?;
    let meshes = marching_cubes_of(map, &labels)?;
    Ok(labels.into_iter().zip(meshes).collect())
}

/// The meshes of `labels` (found by [`find_labels`]), in their order; a label absent from the
/// map gets an empty mesh. Asks the memory limit before each mesh is allocated.
pub fn marching_cubes_of(
    map: &LabelVolume,
    labels: &[LabelInfo],
) -> Result<Vec<TriangleMesh>, LabelsError> {
    let slots: FxHashMap<u32, u32> = labels
        .iter()
        .enumerate()
        .map(|(n, l)| (l.value, n as u32))
        .collect();
    let cells = CellGrid::of(map);
    let tasks: Vec<Vec<Vec<u64>>> = (0..cells.dims[2].div_ceil(LAYERS_PER_TASK))
        .into_par_iter()
        .map(|t| {
            let layers = t * LAYERS_PER_TASK..((t + 1) * LAYERS_PER_TASK).min(cells.dims[2]);
            let mut words = vec![Vec::new(); labels.len()];
            for ck in layers {
                scan_layer(map, &cells, ck, &slots, &mut words);
            }
            words
        })
        .collect();
    check_meshes(&tasks, labels.len())?;
    let world = map.world();
    let to_world = DMat4::from_cols_array_2d(&world.matrix()).transpose();
    let flips = world.flips_handedness();
    (0..labels.len())
        .into_par_iter()
        .map(|slot| {
            let words = tasks.iter().map(|task| task[slot].as_slice());
            let mut mesh = label_mesh(&cells, words, &to_world)?;
            if flips {
                // A mirror turns counter-clockwise into clockwise: wind back outward.
                mesh.triangles.iter_mut().for_each(|t| t.swap(1, 2));
            }
            Ok(mesh)
        })
        .collect()
}

/// The cells of a map padded by one voxel of background on every side: cell `(ci, cj, ck)`
/// has its lowest corner at the map's voxel `(ci - 1, cj - 1, ck - 1)`.
struct CellGrid {
    /// Cells along x, y, z: one more than the voxels.
    dims: [usize; 3],
}

impl CellGrid {
    fn of(map: &LabelVolume) -> CellGrid {
        CellGrid {
            dims: map.grid.dims.map(|n| n + 1),
        }
    }

    /// The word of a cell and its case.
    fn word(&self, [ci, cj, ck]: [usize; 3], case: u8) -> u64 {
        let cell = ((ck * self.dims[1] + cj) * self.dims[0] + ci) as u64;
        (cell << 8) | case as u64
    }

    /// The cell and case of a word.
    fn cell_of(&self, word: u64) -> ([usize; 3], u8) {
        let cell = (word >> 8) as usize;
        let [dx, dy, _] = self.dims;
        ([cell % dx, cell / dx % dy, cell / (dx * dy)], word as u8)
    }

    /// The lower corner of edge `e` of a cell, in the padded voxel grid, and the edge's axis.
    /// Two cells sharing the edge give the same corner and axis.
    fn edge_corner([ci, cj, ck]: [usize; 3], e: u8) -> ([usize; 3], usize) {
        let c = EDGE_CORNERS[e as usize].0 as usize;
        let at = [ci + (c & 1), cj + ((c >> 1) & 1), ck + ((c >> 2) & 1)];
        (at, EDGE_AXIS[e as usize] as usize)
    }

    /// The midpoint of the edge from padded corner `at` along `axis`, in the map's voxel
    /// indices.
    fn edge_midpoint(at: [usize; 3], axis: usize) -> DVec3 {
        let mut p = DVec3::new(at[0] as f64, at[1] as f64, at[2] as f64) - DVec3::ONE;
        p[axis] += 0.5;
        p
    }
}

/// The vertex of each crossed edge of one label, by its corner and axis, for two layers of
/// corners along z at a time: a cell of layer `ck` uses corners of layers `ck` and `ck + 1`
/// only, and the label's cells come in increasing `ck`, so a layer's slots are reset (only
/// those set) when the cells move past it. Memory: two layers of the label's box along x and y.
struct VertexWindow {
    /// The box's first corner along x and y, and its corners per row along x.
    x0: usize,
    y0: usize,
    row: usize,
    /// Per layer parity, the vertex of each (corner, axis), `NONE` when not made yet.
    slots: [Vec<u32>; 2],
    /// Per layer parity, the slots set, and the layer they belong to.
    touched: [Vec<u32>; 2],
    layer: [usize; 2],
}

const NONE: u32 = u32::MAX;

impl VertexWindow {
    /// A window over cells `lo..=hi` along x and y.
    fn new(lo: [usize; 2], hi: [usize; 2]) -> VertexWindow {
        let row = hi[0] - lo[0] + 2;
        let len = row * (hi[1] - lo[1] + 2) * 3;
        VertexWindow {
            x0: lo[0],
            y0: lo[1],
            row,
            slots: [vec![NONE; len], vec![NONE; len]],
            touched: [Vec::new(), Vec::new()],
            layer: [usize::MAX; 2],
        }
    }

    /// The slot of the edge from `at` along `axis`, its layer's slots reset first if they
    /// belonged to an older layer.
    fn slot(&mut self, at: [usize; 3], axis: usize) -> &mut u32 {
        let parity = at[2] & 1;
        if self.layer[parity] != at[2] {
            for &n in &self.touched[parity] {
                self.slots[parity][n as usize] = NONE;
            }
            self.touched[parity].clear();
            self.layer[parity] = at[2];
        }
        let n = ((at[1] - self.y0) * self.row + (at[0] - self.x0)) * 3 + axis;
        if self.slots[parity][n] == NONE {
            self.touched[parity].push(n as u32);
        }
        &mut self.slots[parity][n]
    }
}

/// One row of voxels along x at (j, k) of the padded grid: the map's row, or none (background)
/// outside the map.
fn row(map: &LabelVolume, j: usize, k: usize) -> Option<&[u32]> {
    let [nx, ny, nz] = map.grid.dims;
    if j == 0 || k == 0 || j > ny || k > nz {
        return None;
    }
    let start = ((k - 1) * ny + (j - 1)) * nx;
    Some(&map.values[start..start + nx])
}

/// Records every mixed cell of layer `ck` for each chosen label present in it.
fn scan_layer(
    map: &LabelVolume,
    cells: &CellGrid,
    ck: usize,
    slots: &FxHashMap<u32, u32>,
    words: &mut [Vec<u64>],
) {
    for cj in 0..cells.dims[1] {
        // Corner rows: bit 1 of a corner is y, bit 2 is z.
        let rows = [
            row(map, cj, ck),
            row(map, cj + 1, ck),
            row(map, cj, ck + 1),
            row(map, cj + 1, ck + 1),
        ];
        if rows.iter().all(Option::is_none) {
            continue;
        }
        scan_cell_row(&rows, cells, [cj, ck], slots, words);
    }
}

/// The label at padded x index `x` of a corner row.
#[inline]
fn at(row: Option<&[u32]>, x: usize) -> u32 {
    match row {
        Some(r) if x >= 1 && x <= r.len() => r[x - 1],
        _ => 0,
    }
}

/// The cells of one row along x: uniform ones skipped, mixed ones recorded per label.
fn scan_cell_row(
    rows: &[Option<&[u32]>; 4],
    cells: &CellGrid,
    [cj, ck]: [usize; 2],
    slots: &FxHashMap<u32, u32>,
    words: &mut [Vec<u64>],
) {
    let column = |x: usize| rows.map(|r| at(r, x));
    let mut low = column(0);
    for ci in 0..cells.dims[0] {
        let high = column(ci + 1);
        let first = low[0];
        if low.iter().chain(&high).all(|&v| v == first) {
            low = high;
            continue;
        }
        // Corner c = x + 2y + 4z; rows are indexed y + 2z.
        let corners: [u32; 8] = std::array::from_fn(|c| {
            let r = c >> 1;
            if c & 1 == 0 {
                low[r]
            } else {
                high[r]
            }
        });
        record_cell(&corners, cells, [ci, cj, ck], slots, words);
        low = high;
    }
}

/// Records a mixed cell once per chosen, non-zero label among its corners.
fn record_cell(
    corners: &[u32; 8],
    cells: &CellGrid,
    cell: [usize; 3],
    slots: &FxHashMap<u32, u32>,
    words: &mut [Vec<u64>],
) {
    for (c, &value) in corners.iter().enumerate() {
        if value == 0 || corners[..c].contains(&value) {
            continue;
        }
        let Some(&slot) = slots.get(&value) else {
            continue;
        };
        let case = corners
            .iter()
            .enumerate()
            .fold(0u8, |m, (n, &v)| m | (u8::from(v == value) << n));
        words[slot as usize].push(cells.word(cell, case));
    }
}

/// Asks the memory limit, once for all labels, for their meshes: a triangle per table entry of
/// each word and about half a vertex per triangle (each vertex is shared by about six
/// triangles' corners).
fn check_meshes(tasks: &[Vec<Vec<u64>>], labels: usize) -> Result<(), LabelsError> {
    let table = tables();
    let count: usize = tasks
        .par_iter()
        .flat_map(|task| task.par_iter().take(labels))
        .map(|words| {
            let triangles = |w: &u64| table.triangle_count[(w & 0xff) as usize] as usize;
            words.iter().map(triangles).sum::<usize>()
        })
        .sum();
    let bytes = memory::bytes_of::<[u32; 3]>(count) + memory::bytes_of::<Vec3>(count / 2 + 8);
    memory::check_allocation("the labels' meshes", bytes)?;
    Ok(())
}

/// One label's mesh from its words (in cell order): triangles from the tables, one vertex per
/// crossed edge at its midpoint (found in a [`VertexWindow`]), placed in the world by
/// `to_world`; vertices numbered as they first appear. The memory limit was asked by
/// [`check_meshes`] (the vertex window, two layers of the label's box, is not counted).
fn label_mesh<'a>(
    cells: &CellGrid,
    words: impl Iterator<Item = &'a [u64]> + Clone,
    to_world: &DMat4,
) -> Result<TriangleMesh, LabelsError> {
    let table = tables();
    let (mut count, mut lo, mut hi) = (0usize, [usize::MAX; 2], [0usize; 2]);
    for &w in words.clone().flatten() {
        count += table.triangle_count[(w & 0xff) as usize] as usize;
        let (cell, _) = cells.cell_of(w);
        for a in 0..2 {
            lo[a] = lo[a].min(cell[a]);
            hi[a] = hi[a].max(cell[a]);
        }
    }
    if count == 0 {
        return Ok(TriangleMesh::default());
    }
    let mut vertices = VertexWindow::new(lo, hi);
    let mut positions = Vec::with_capacity(count / 2 + 8);
    let mut triangles = Vec::with_capacity(count);
    for &word in words.flatten() {
        let (cell, case) = cells.cell_of(word);
        let case = case as usize;
        for tri in &table.triangles[case][..table.triangle_count[case] as usize] {
            let mut corner = |e: u8| {
                let (at, axis) = CellGrid::edge_corner(cell, e);
                let slot = vertices.slot(at, axis);
                if *slot == NONE {
                    let p = to_world.transform_point3(CellGrid::edge_midpoint(at, axis));
                    positions.push(p.as_vec3());
                    *slot = (positions.len() - 1) as u32;
                }
                *slot
            };
            triangles.push([corner(tri[0]), corner(tri[1]), corner(tri[2])]);
        }
    }
    Ok(TriangleMesh::new(positions, triangles))
}

#[cfg(test)]
mod tests {
    use super::*;
    use voxlod_core::{mesh_topology, Grid};

    fn map(dims: [usize; 3], spacing: [f64; 3], labels: impl Fn([usize; 3]) -> u32) -> LabelVolume {
        let grid = Grid::new(dims, spacing, [0.0; 3]).unwrap();
        let values = (0..grid.len())
            .map(|n| labels([n % dims[0], n / dims[0] % dims[1], n / (dims[0] * dims[1])]))
            .collect();
        LabelVolume::from_vec(grid, values).unwrap()
    }

    fn closed_outward(mesh: &TriangleMesh) -> bool {
        let t = mesh_topology(mesh);
        t.is_closed_manifold() && t.is_consistently_oriented() && mesh.signed_volume() > 0.0
    }

    #[test]
    fn one_voxel_is_an_octahedron_of_eight_triangles() {
        // The indicator of one voxel crosses ½ at the midpoints of its six edges to the
        // neighbours: an octahedron of half-diagonal ½, volume 4/3 · (½)³ = 1/6.
        let meshes = marching_cubes(&map([1, 1, 1], [1.0; 3], |_| 3)).unwrap();
        assert_eq!(meshes.len(), 1);
        let (info, mesh) = &meshes[0];
        assert_eq!((info.value, info.voxels), (3, 1));
        assert_eq!((mesh.positions.len(), mesh.triangles.len()), (6, 8));
        assert!(closed_outward(mesh));
        assert!((mesh.signed_volume() - 1.0 / 6.0).abs() < 1e-6);
    }

    #[test]
    fn spacing_and_origin_place_the_vertices() {
        let grid = Grid::new([1, 1, 1], [2.0, 3.0, 4.0], [10.0, 20.0, 30.0]).unwrap();
        let map = LabelVolume::from_vec(grid, vec![1]).unwrap();
        let (_, mesh) = &marching_cubes(&map).unwrap()[0];
        let mut xs: Vec<[f32; 3]> = mesh.positions.iter().map(|p| p.to_array()).collect();
        xs.sort_by(|a, b| a.partial_cmp(b).unwrap());
        assert_eq!(xs[0], [9.0, 20.0, 30.0]);
        assert_eq!(xs[5], [11.0, 20.0, 30.0]);
        assert!(xs.contains(&[10.0, 18.5, 30.0]) && xs.contains(&[10.0, 20.0, 32.0]));
    }

    #[test]
    fn a_mirrored_map_stays_outward() {
        use voxlod_core::glam::DMat3;
        use voxlod_core::world::{Frame, Orientation};
        let mirror = Orientation {
            direction: DMat3::from_diagonal(DVec3::new(-1.0, 1.0, 1.0)),
            frame: Frame::Unknown,
        };
        let map = map([3, 2, 2], [1.0; 3], |[i, _, _]| u32::from(i > 0)).oriented(mirror);
        let (_, mesh) = &marching_cubes(&map).unwrap()[0];
        assert!(closed_outward(mesh));
        assert!(mesh.positions.iter().all(|p| p.x <= 0.5));
    }

    #[test]
    fn neighbours_each_close_and_share_their_boundary_vertices() {
        // Two labels filling a 4 × 3 × 3 box, split at x = 2.
        let map = map([4, 3, 3], [1.0; 3], |[i, _, _]| if i < 2 { 1 } else { 2 });
        let meshes = marching_cubes(&map).unwrap();
        assert_eq!(meshes.len(), 2);
        for (_, mesh) in &meshes {
            assert!(closed_outward(mesh));
        }
        // Both cross the plane x = 1.5 (between voxels 1 and 2) at the same points.
        let on_plane = |m: &TriangleMesh| {
            let mut v: Vec<[f32; 3]> = m
                .positions
                .iter()
                .filter(|p| p.x == 1.5)
                .map(|p| p.to_array())
                .collect();
            v.sort_by(|a, b| a.partial_cmp(b).unwrap());
            v
        };
        assert_eq!(on_plane(&meshes[0].1), on_plane(&meshes[1].1));
        assert_eq!(on_plane(&meshes[0].1).len(), 9);
    }

    #[test]
    fn diagonal_voxels_stay_separate_and_every_label_of_a_random_map_closes() {
        // Voxels touching along an edge only: the ambiguous faces separate them.
        let diagonal = map([2, 2, 1], [1.0; 3], |[i, j, _]| u32::from(i == j));
        let (_, mesh) = &marching_cubes(&diagonal).unwrap()[0];
        assert!(closed_outward(mesh));
        assert_eq!(voxlod_core::components::triangle_components(mesh).len(), 2);
        let random = map([9, 8, 7], [1.0, 1.0, 1.5], |[i, j, k]| {
            let n = ((k * 8 + j) * 9 + i) as u64;
            let hash = (n + 1).wrapping_mul(6364136223846793005).rotate_right(29);
            (hash.wrapping_mul(1442695040888963407) >> 61) as u32 % 4
        });
        for (info, mesh) in marching_cubes(&random).unwrap() {
            assert!(closed_outward(&mesh), "label {}", info.value);
        }
    }

    #[test]
    fn a_large_ball_keeps_its_voxel_volume_closely() {
        let r = 12.0;
        let ball = map([32, 32, 32], [1.0; 3], |at| {
            let d: f64 = at.iter().map(|&a| (a as f64 - 15.5).powi(2)).sum();
            u32::from(d.sqrt() <= r)
        });
        let (info, mesh) = &marching_cubes(&ball).unwrap()[0];
        assert!(closed_outward(mesh));
        let error = (mesh.signed_volume() - info.voxels as f64).abs() / info.voxels as f64;
        assert!(
            error < 0.02,
            "volume {} against {} voxels",
            mesh.signed_volume(),
            info.voxels
        );
    }

    #[test]
    fn only_the_labels_asked_for_are_meshed_in_their_order() {
        let map = map([6, 2, 2], [1.0; 3], |[i, _, _]| (i / 2 + 1) as u32);
        let all = find_labels(&map);
        let chosen = select_labels(all.clone(), Some(&[3, 1])).unwrap();
        let meshes = marching_cubes_of(&map, &chosen).unwrap();
        let whole = marching_cubes(&map).unwrap();
        assert_eq!(meshes[0].triangles, whole[2].1.triangles);
        assert_eq!(meshes[1].triangles, whole[0].1.triangles);
    }
}
