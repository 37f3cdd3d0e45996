//! The threshold route of paper §4 block by block on a Dask cluster, for `voxlod.dask.lod_volume`:
//! the same levels as `voxlod.lod_volume` (the library's [`voxlod::Source::BlockwiseThreshold`],
//! whose sampling of each level is handed to the cluster).
//!
//! The client runs [`voxlod::lod_with`] as the single process does (planning, the iso value's
//! check, the genus step, contouring, cleaning, placement, warnings). Where it would sample a
//! level, [`ClusterScan::sample_level`] names the level's blocks and their windows of the scan
//! ([`voxlod::sampling::BlockwiseThreshold::scan_window`]) and calls the Python half, which runs
//! one task per block on the cluster: [`fill_threshold_block`] reads the block's window once,
//! answers a window without a crossing of the threshold with one value, and otherwise fills
//! the block's bricks ([`voxlod::sampling::BlockwiseThreshold::fill_block`]). The client gathers
//! the answers into the level's bricks ([`voxlod::sampling::BrickAssembly`]) and goes on.
//! Workers plan the levels again from the same arguments (arithmetic only), so that nothing but
//! plain numbers and arrays crosses the network.
//!
//! Beyond the paper. Cost on the client: the level's band of bricks (`4 B³` bytes per brick the
//! surface reaches) and, for a level small enough for the dense route, its dense density.

use std::path::Path;
use std::sync::Mutex;

use numpy::{PyArray1, PyReadonlyArray1, PyReadonlyArray3};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use voxlod::blockwise::{BlockwiseScan, BlockwiseSource};
use voxlod::core::{BrickVolume, Grid, Volume};
use voxlod::io::{IoError, IoErrorKind};
use voxlod::lod::LevelOptions;
use voxlod::sampling::narrow_band::BandReport;
use voxlod::sampling::{
    BlockBrick, BlockSamples, BlockwiseError, BlockwiseThreshold, BrickAssembly, DensityReport,
};

use crate::arrays::{column, volume_slice};
use crate::errors::{usage, Failure};
use crate::facade::{lod_options, run_lod, LevelArgs};

/// The scan as the client and the workers both describe it: NumPy shape, spacing and origin
/// (array-axis order), threshold, and the levels' options.
type ScanArgs = ([usize; 3], [f64; 3], [f64; 3], f32, LevelArgs);

/// The scan's grid (x = axis 2) from its NumPy shape, spacing and origin.
pub(crate) fn scan_grid(shape: [usize; 3], spacing: [f64; 3], origin: [f64; 3]) -> PyResult<Grid> {
    let zyx = |v: [f64; 3]| [v[2], v[1], v[0]];
    let dims = [shape[2], shape[1], shape[0]];
    Ok(Grid::new(dims, zyx(spacing), zyx(origin)).map_err(Failure::from)?)
}

/// A scan known by its grid only: enough to plan its levels.
struct GridOnly(Grid);

impl BlockwiseScan for GridOnly {
    fn grid(&self) -> Grid {
        self.0
    }

    fn read_window(&self, _: [usize; 3], _: [usize; 3]) -> Result<Volume, IoError> {
        Err(cluster_error(
            "a scan known by its grid only has no samples",
        ))
    }
}

/// A level's blocks as the Python half names them: per block (x, y, z), its window's first
/// sample and end in array-axis order, from the windows' first sample and extent (x, y, z).
pub(crate) type BlockWindows = Vec<([usize; 3], [usize; 3], [usize; 3])>;

/// [`BlockWindows`] from `(block, (window start, window extent))` in voxlod's axis order.
pub(crate) fn block_windows(
    blocks: impl Iterator<Item = ([usize; 3], ([usize; 3], [usize; 3]))>,
) -> BlockWindows {
    let zyx = |v: [usize; 3]| [v[2], v[1], v[0]];
    blocks
        .map(|(block, (start, extent))| {
            let stop = [0, 1, 2].map(|a| start[a] + extent[a]);
            (block, zyx(start), zyx(stop))
        })
        .collect()
}

fn cluster_error(message: &str) -> IoError {
    IoError::new(Path::new("the Dask cluster"), IoErrorKind::Access, message)
}

/// The blocks of every level of the scan `args` describes, finest first.
fn level_blocks(args: &ScanArgs) -> PyResult<Vec<BlockwiseThreshold>> {
    let (shape, spacing, origin, threshold, levels) = args.clone();
    let scan = GridOnly(scan_grid(shape, spacing, origin)?);
    let options = lod_options(levels)?;
    let level_options = LevelOptions {
        pyramid: options.pyramid,
        iso: options.iso.unwrap_or(0.5),
        normals: options.normals,
        clean: None,
        snap: false,
    };
    let blockwise = BlockwiseSource {
        scan: &scan,
        threshold,
    };
    Ok(blockwise
        .level_blocks(&level_options)
        .map_err(|e| Failure::from(voxlod::Error::from(e)))?)
}

/// The scan of the client: its levels' blocks are filled on the cluster by `run_level`.
struct ClusterScan {
    grid: Grid,
    levels: Vec<BlockwiseThreshold>,
    /// `run_level(level, blocks)`: one answer per block (see [`fill_threshold_block`]).
    run_level: Py<PyAny>,
    /// The Python error that stopped a level, raised in place of the library's.
    raised: Mutex<Option<PyErr>>,
}

/// One block's answer from a worker: its single value, or `(crossings, brick indices, values,
/// positions of the leaves among them, the leaves' samples)`.
#[derive(FromPyObject)]
enum BlockAnswer<'py> {
    Uniform(f32),
    Bricks(
        u64,
        PyReadonlyArray1<'py, u32>,
        PyReadonlyArray1<'py, f32>,
        PyReadonlyArray1<'py, u32>,
        PyReadonlyArray1<'py, f32>,
    ),
}

impl BlockAnswer<'_> {
    /// The block's bricks, checked against the level, and its crossings.
    fn bricks(
        &self,
        level: &BlockwiseThreshold,
        block: [usize; 3],
    ) -> PyResult<(Vec<BlockBrick>, u64)> {
        let (crossings, indices, values, leaf_at, leaves) = match self {
            BlockAnswer::Uniform(value) => return Ok((level.uniform_block(block, *value), 0)),
            BlockAnswer::Bricks(c, i, v, l, s) => (*c, i, v, l, s),
        };
        let (indices, values) = (indices.as_slice()?, values.as_slice()?);
        let (leaf_at, leaves) = (leaf_at.as_slice()?, leaves.as_slice()?);
        let n = level.brick_size.pow(3);
        let expected = level.uniform_block(block, 0.0);
        let fits = indices.len() == expected.len()
            && values.len() == indices.len()
            && leaves.len() == leaf_at.len() * n
            && indices.iter().zip(&expected).all(|(&i, e)| i == e.index);
        if !fits {
            return Err(usage(format!(
                "the answer for block {block:?} does not hold that block's bricks"
            )));
        }
        let mut bricks: Vec<BlockBrick> = indices
            .iter()
            .zip(values)
            .map(|(&index, &value)| BlockBrick {
                index,
                value,
                leaf: None,
            })
            .collect();
        for (k, &at) in leaf_at.iter().enumerate() {
            let brick = bricks
                .get_mut(at as usize)
                .ok_or_else(|| usage(format!("block {block:?}: a leaf of no brick")))?;
            brick.leaf = Some(leaves[k * n..(k + 1) * n].to_vec());
        }
        Ok((bricks, crossings))
    }
}

impl ClusterScan {
    /// The level's bricks from the cluster's answers.
    fn run(&self, level: &BlockwiseThreshold) -> PyResult<BrickAssembly> {
        let k = self
            .levels
            .iter()
            .position(|l| l.grid == level.grid)
            .ok_or_else(|| usage("a level the plan does not have"))?;
        let [bx, by, bz] = level.block_dims();
        let blocks = block_windows((0..bx * by * bz).map(|i| {
            let block = [i % bx, (i / bx) % by, i / (bx * by)];
            (block, level.scan_window(block))
        }));
        let mut assembly = BrickAssembly::new(level).map_err(Failure::from)?;
        Python::attach(|py| -> PyResult<()> {
            let answers = self.run_level.call1(py, (k, blocks.clone()))?;
            let answers: Vec<BlockAnswer<'_>> = answers.extract(py)?;
            if answers.len() != blocks.len() {
                return Err(usage(
                    "the cluster answered for a different number of blocks",
                ));
            }
            let mut all = Vec::new();
            let mut crossings = 0;
            for (answer, (block, _, _)) in answers.iter().zip(&blocks) {
                let (bricks, found) = answer.bricks(level, *block)?;
                all.extend(bricks);
                crossings += found;
            }
            Ok(assembly.add(all, crossings).map_err(Failure::from)?)
        })?;
        Ok(assembly)
    }
}

impl BlockwiseScan for ClusterScan {
    fn grid(&self) -> Grid {
        self.grid
    }

    fn read_window(&self, _: [usize; 3], _: [usize; 3]) -> Result<Volume, IoError> {
        Err(cluster_error("the client reads no window; the workers do"))
    }

    fn sample_level(
        &self,
        level: &BlockwiseThreshold,
    ) -> Result<(BrickVolume, DensityReport, BandReport), BlockwiseError<IoError>> {
        match self.run(level) {
            Ok(assembly) => Ok(assembly.finish()?),
            Err(e) => {
                let message = Python::attach(|py| e.value(py).to_string());
                *self.raised.lock().unwrap_or_else(|p| p.into_inner()) = Some(e);
                Err(BlockwiseError::Read(cluster_error(&message)))
            }
        }
    }
}

/// `lod_threshold_blockwise(shape, spacing, origin, threshold, levels, run_level, progress)`:
/// the levels of `voxlod.lod_volume(threshold=...)`, each level's blocks filled by
/// `run_level(level, [(block, window_start, window_stop), ...])` (windows in array-axis order),
/// which returns one answer of [`fill_threshold_block`] per block.
#[pyfunction]
#[pyo3(signature = (shape, spacing, origin, threshold, levels, run_level, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn lod_threshold_blockwise<'py>(
    py: Python<'py>,
    shape: [usize; 3],
    spacing: [f64; 3],
    origin: [f64; 3],
    threshold: f32,
    levels: LevelArgs,
    run_level: Py<PyAny>,
    progress: Option<Py<PyAny>>,
) -> PyResult<(Vec<Bound<'py, PyDict>>, Vec<String>)> {
    let args: ScanArgs = (shape, spacing, origin, threshold, levels.clone());
    let scan = ClusterScan {
        grid: scan_grid(shape, spacing, origin)?,
        levels: level_blocks(&args)?,
        run_level,
        raised: Mutex::new(None),
    };
    let options = lod_options(levels)?;
    let source = voxlod::Source::BlockwiseThreshold {
        scan: &scan,
        threshold,
    };
    let result = run_lod(py, &source, &options, progress);
    let raised = scan.raised.lock().unwrap_or_else(|p| p.into_inner()).take();
    match (result, raised) {
        (Err(_), Some(raised)) => Err(raised),
        (result, _) => result,
    }
}

/// One block's bricks: indices, values, positions of the leaves, the leaves' samples.
type BricksOut<'py> = (
    u64,
    Bound<'py, PyArray1<u32>>,
    Bound<'py, PyArray1<f32>>,
    Bound<'py, PyArray1<u32>>,
    Bound<'py, PyArray1<f32>>,
);

/// `fill_threshold_block(window, scan, level, block)`, on a worker: block `block` (x, y, z) of
/// level `level` of the scan `scan` (the client's `ScanArgs`), from `window`, its samples
/// `window_start .. window_stop` as the client named them. A window whose samples are all below
/// the threshold (or all at or above it, away from the scan's edge) holds no surface: the
/// answer is the block's one value, without the density pass. Otherwise the block's bricks.
#[pyfunction]
pub fn fill_threshold_block<'py>(
    py: Python<'py>,
    window: PyReadonlyArray3<'py, f32>,
    scan: ScanArgs,
    level: usize,
    block: [usize; 3],
) -> PyResult<Bound<'py, PyAny>> {
    let levels = level_blocks(&scan)?;
    let level = levels
        .get(level)
        .ok_or_else(|| usage(format!("level {level} of {}", levels.len())))?;
    let dims = level.block_dims();
    if (0..3).any(|a| block[a] >= dims[a]) {
        return Err(usage(format!("block {block:?} of {dims:?}")));
    }
    let (samples, window_dims) = volume_slice(&window, "window")?;
    let (start, extent) = level.scan_window(block);
    if window_dims != extent {
        return Err(usage(format!(
            "the window of block {block:?} has {window_dims:?} samples (x, y, z), not {extent:?}"
        )));
    }
    let answer = py.detach(|| -> Result<BlockSamples, Failure> {
        let s = &level.scan;
        let origin = [0, 1, 2].map(|a| s.origin[a] + start[a] as f64 * s.spacing[a]);
        let grid = Grid::new(extent, s.spacing, origin)?;
        let volume = Volume {
            grid,
            ..crate::contour::owned_volume(samples, extent)?
        };
        Ok(level.sample_block(block, &volume))
    })?;
    let (bricks, crossings) = match answer {
        BlockSamples::Uniform(value) => return Ok(value.into_pyobject(py)?.into_any()),
        BlockSamples::Bricks(bricks, crossings) => (bricks, crossings),
    };
    let mut leaf_at = Vec::new();
    let mut leaves = Vec::new();
    let mut indices = Vec::with_capacity(bricks.len());
    let mut values = Vec::with_capacity(bricks.len());
    for (k, brick) in bricks.into_iter().enumerate() {
        indices.push(brick.index);
        values.push(brick.value);
        if let Some(leaf) = brick.leaf {
            leaf_at.push(k as u32);
            leaves.extend(leaf);
        }
    }
    let out: BricksOut<'py> = (
        crossings,
        column(py, indices),
        column(py, values),
        column(py, leaf_at),
        column(py, leaves),
    );
    Ok(out.into_pyobject(py)?.into_any())
}
