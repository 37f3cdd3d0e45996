//! The cells of a thresholded scan classified once, for the walks of [`crate::ThresholdSolid`]
//! along the lattice lines (paper §4, first route: "tri-linearly interpolating the point value
//! from the neighboring eight vertices and comparing it to the isodensity").
//!
//! A cell (the box between eight neighbouring samples) is all-outside when its eight corners are
//! below the threshold, all-inside when they are all at or above it, and mixed otherwise; only in
//! a mixed cell can the trilinear interpolant cross the threshold. Along each axis the cells of
//! every column (the cells between four data rows) are run-length encoded, so that a lattice
//! line through the column skips its uniform runs at once.
//!
//! Every sample is compared with the threshold once, into one byte; a cell's state is the sum of
//! its corners' bytes (0 or 8: uniform). The three axes' runs are built from rows of cell states
//! along x, made in the scan's memory order (a z-column of cells is extended slice after slice,
//! never read with the stride of a slice per cell). A degenerate axis (one sample) has one cell
//! across it, its corners repeated; along it, no cells.
//!
//! Beyond the paper, which tests each point. **Cost**: one comparison per sample, then about ten
//! byte operations per cell and axis, O(samples); **memory**: one byte per sample while the runs
//! are made, then 12 bytes per run and 4 per column.

use rayon::prelude::*;
use voxlod_core::Axis;

/// The state shared by a run of cells.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum CellState {
    Outside,
    Inside,
    Mixed,
}

/// Cells `start..end` of a column (indices of their lower samples along the column's axis, in
/// the whole scan) share a state.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct CellRun {
    pub(crate) start: u32,
    pub(crate) end: u32,
    pub(crate) state: CellState,
}

/// The runs of every column along one axis: column `c`'s are `runs[offsets[c]..offsets[c + 1]]`.
/// Columns are numbered `b * cu + a` by their cells across the axis (`a` along the first of
/// [`Axis::others`], `b` along the second), from the held samples' first.
#[derive(Clone, Debug, Default)]
pub(crate) struct ColumnRuns {
    offsets: Vec<u32>,
    runs: Vec<CellRun>,
}

impl ColumnRuns {
    /// The runs of column `c`.
    #[inline]
    pub(crate) fn column(&self, c: usize) -> &[CellRun] {
        &self.runs[self.offsets[c] as usize..self.offsets[c + 1] as usize]
    }

    /// Gathers per-column run lists, in column order.
    fn gather<'r>(columns: impl Iterator<Item = &'r [CellRun]>) -> ColumnRuns {
        let mut out = ColumnRuns {
            offsets: vec![0],
            runs: Vec::new(),
        };
        for runs in columns {
            out.runs.extend_from_slice(runs);
            out.offsets.push(out.runs.len() as u32);
        }
        out
    }
}

/// The runs of many columns made at once, one cell of each per step: each column's open run
/// (its start and state) sits in a flat array, and a run is stored only when its column's
/// state changes.
struct OpenRuns {
    start: Vec<u32>,
    state: Vec<CellState>,
    columns: Vec<Vec<CellRun>>,
}

impl OpenRuns {
    /// Columns whose first cells (at whole-scan index `index` along them) are `row`.
    fn new(index: u32, row: &[CellState]) -> OpenRuns {
        OpenRuns {
            start: vec![index; row.len()],
            state: row.to_vec(),
            columns: vec![Vec::new(); row.len()],
        }
    }

    /// The columns' cells at `index`, the one after the last step's.
    #[inline]
    fn step(&mut self, index: u32, row: &[CellState]) {
        for (c, &state) in row.iter().enumerate() {
            if state != self.state[c] {
                self.columns[c].push(CellRun {
                    start: self.start[c],
                    end: index,
                    state: self.state[c],
                });
                self.start[c] = index;
                self.state[c] = state;
            }
        }
    }

    /// The runs of every column, whose last cells end at `end`.
    fn finish(mut self, end: u32) -> Vec<Vec<CellRun>> {
        for (c, runs) in self.columns.iter_mut().enumerate() {
            runs.push(CellRun {
                start: self.start[c],
                end,
                state: self.state[c],
            });
        }
        self.columns
    }
}

/// Held samples (x fastest) of `dims`, their inside bytes, and where they start in the scan.
struct Flags {
    dims: [usize; 3],
    first: [usize; 3],
    inside: Vec<u8>,
}

impl Flags {
    /// Cells across each axis: one fewer than the samples, at least one.
    fn cells(&self) -> [usize; 3] {
        self.dims.map(|d| d.saturating_sub(1).max(1))
    }

    /// The states of the cells of row (y, z) of cells along x, into `out` (one per cell).
    fn cell_row(&self, y: usize, z: usize, counts: &mut [u8], out: &mut [CellState]) {
        let [nx, ny, nz] = self.dims;
        let next = |c: usize, n: usize| if n > 1 { c + 1 } else { c };
        let row = |y: usize, z: usize| &self.inside[(y + ny * z) * nx..][..nx];
        let (y1, z1) = (next(y, ny), next(z, nz));
        let (r00, r10, r01, r11) = (row(y, z), row(y1, z), row(y, z1), row(y1, z1));
        for (x, c) in counts.iter_mut().enumerate() {
            *c = r00[x] + r10[x] + r01[x] + r11[x];
        }
        let x1 = usize::from(nx > 1);
        for (x, state) in out.iter_mut().enumerate() {
            *state = match counts[x] + counts[x + x1] {
                0 => CellState::Outside,
                8 => CellState::Inside,
                _ => CellState::Mixed,
            };
        }
    }
}

/// The column runs along x, y and z of the samples `samples` (x fastest, `dims`, the first at
/// index `first` of the whole scan) thresholded at `threshold` (inside: `v >= threshold`);
/// with `side_by_side`, the three axes at once (faster, more memory held at once), else one
/// after another.
pub(crate) fn classify(
    samples: &[f32],
    dims: [usize; 3],
    first: [usize; 3],
    threshold: f32,
    side_by_side: bool,
) -> [ColumnRuns; 3] {
    debug_assert_eq!(samples.len(), dims.iter().product::<usize>());
    let mut inside = vec![0u8; samples.len()];
    inside
        .par_chunks_mut(dims[0].max(1) * 64)
        .zip(samples.par_chunks(dims[0].max(1) * 64))
        .for_each(|(flags, values)| {
            for (f, &v) in flags.iter_mut().zip(values) {
                *f = u8::from(v >= threshold);
            }
        });
    let flags = Flags {
        dims,
        first,
        inside,
    };
    if !side_by_side {
        return [Axis::X, Axis::Y, Axis::Z].map(|axis| runs_along(&flags, axis));
    }
    // The three axes side by side: one axis's gathering (sequential) overlaps the others' work.
    let flags = &flags;
    let (x, (y, z)) = rayon::join(
        || runs_along(flags, Axis::X),
        || rayon::join(|| runs_along(flags, Axis::Y), || runs_along(flags, Axis::Z)),
    );
    [x, y, z]
}

/// The runs of every column along `axis`.
fn runs_along(flags: &Flags, axis: Axis) -> ColumnRuns {
    let [cx, cy, cz] = flags.cells();
    let nx = flags.dims[0];
    let first = flags.first[0] as u32;
    let scratch = || (vec![0u8; nx], vec![CellState::Mixed; cx]);
    match axis {
        // Column (y, z): one row of cells.
        Axis::X => {
            let columns: Vec<Vec<CellRun>> = (0..cy * cz)
                .into_par_iter()
                .map_init(scratch, |(counts, row), c| {
                    if nx < 2 {
                        return Vec::new();
                    }
                    flags.cell_row(c % cy, c / cy, counts, row);
                    let mut runs = Vec::new();
                    let mut start = 0;
                    for x in 1..=row.len() {
                        if x == row.len() || row[x] != row[start] {
                            runs.push(CellRun {
                                start: first + start as u32,
                                end: first + x as u32,
                                state: row[start],
                            });
                            start = x;
                        }
                    }
                    runs
                })
                .collect();
            ColumnRuns::gather(columns.iter().map(Vec::as_slice))
        }
        // Column (z, x), numbered x * cz + z: one plane of cells per z, walked along y.
        Axis::Y => {
            let planes = sweep(flags, Axis::Y);
            ColumnRuns::gather((0..cx * cz).map(|c| planes[c % cz][c / cz].as_slice()))
        }
        // Column (x, y), numbered y * cx + x: the cells of one y, extended slice by slice.
        Axis::Z => {
            let rows = sweep(flags, Axis::Z);
            ColumnRuns::gather(rows.iter().flatten().map(Vec::as_slice))
        }
    }
}

/// The columns along `axis` (y or z) of cells, made in memory order: for each cell index
/// across the other of y and z (a z plane, or a y row of planes), the rows of cells along x
/// taken in turn along `axis`, each extending the runs of its `cx` columns.
fn sweep(flags: &Flags, axis: Axis) -> Vec<Vec<Vec<CellRun>>> {
    let [cx, cy, cz] = flags.cells();
    let a = axis.index();
    let (across, along) = if axis == Axis::Y { (cz, cy) } else { (cy, cz) };
    let along = if flags.dims[a] > 1 { along } else { 0 };
    let first = flags.first[a] as u32;
    (0..across)
        .into_par_iter()
        .map_init(
            || (vec![0u8; flags.dims[0]], vec![CellState::Mixed; cx]),
            |(counts, row), c| {
                let mut open: Option<OpenRuns> = None;
                for w in 0..along {
                    let (y, z) = if axis == Axis::Y { (w, c) } else { (c, w) };
                    flags.cell_row(y, z, counts, row);
                    match open.as_mut() {
                        Some(open) => open.step(first + w as u32, row),
                        None => open = Some(OpenRuns::new(first, row)),
                    }
                }
                match open {
                    Some(open) => open.finish(first + along as u32),
                    None => vec![Vec::new(); cx],
                }
            },
        )
        .collect()
}
