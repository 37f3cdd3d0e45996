//! The label volume of a precomputed layer (neuroglancer `volume.md`): the layer's `info` and
//! one scale of raw chunks, each the labels of the voxels `[begin, end)` (clipped to the
//! volume), x fastest, little-endian, in a file named `x0-x1_y0-y1_z0-z1` under the scale's key.
//! Cost: one pass over the labels; chunks are written in parallel, one chunk buffer per thread.

use std::path::Path;

use rayon::prelude::*;
use serde_json::json;
use voxlod_core::{memory, LabelVolume};

use crate::quantize::StoredFrame;
use crate::{LabelType, PrecomputedError};

/// The scale's resolution in nanometres per voxel.
pub fn resolution(frame: &StoredFrame, nanometres_per_unit: f64) -> [f64; 3] {
    (frame.spacing * nanometres_per_unit).to_array()
}

/// The scale's key: its resolution as `x_y_z` (cloud-volume's convention).
pub fn scale_key(resolution: [f64; 3]) -> String {
    format!("{}_{}_{}", resolution[0], resolution[1], resolution[2])
}

/// The layer's `info`: a segmentation of one scale, with meshes in `mesh_dir`.
pub fn info(
    map: &LabelVolume,
    frame: &StoredFrame,
    resolution: [f64; 3],
    chunk: [usize; 3],
    label_type: LabelType,
    mesh_dir: &str,
) -> serde_json::Value {
    json!({
        "@type": "neuroglancer_multiscale_volume",
        "type": "segmentation",
        "data_type": match label_type {
            LabelType::Uint32 => "uint32",
            LabelType::Uint64 => "uint64",
        },
        "num_channels": 1,
        "scales": [{
            "key": scale_key(resolution),
            "size": map.grid.dims,
            "resolution": resolution,
            "voxel_offset": frame.voxel_offset,
            "chunk_sizes": [chunk],
            "encoding": "raw",
        }],
        "mesh": mesh_dir,
    })
}

/// Writes the raw chunks of `map` into `dir` (the scale's folder, created) and returns the
/// bytes written. Fails naming the chunk file that could not be written, or if the memory limit
/// refuses the chunk buffers.
pub fn write_chunks(
    dir: &Path,
    map: &LabelVolume,
    frame: &StoredFrame,
    chunk: [usize; 3],
    label_type: LabelType,
) -> Result<u64, PrecomputedError> {
    std::fs::create_dir_all(dir).map_err(|e| PrecomputedError::io(dir, e))?;
    let width = match label_type {
        LabelType::Uint32 => 4,
        LabelType::Uint64 => 8,
    };
    let per_chunk = (chunk[0] * chunk[1] * chunk[2] * width) as u64;
    memory::check_allocation(
        "the volume's chunk buffers",
        per_chunk * rayon::current_num_threads() as u64,
    )?;
    let dims = map.grid.dims;
    let grid: [usize; 3] = std::array::from_fn(|a| dims[a].div_ceil(chunk[a]));
    let count = grid[0] * grid[1] * grid[2];
    (0..count)
        .into_par_iter()
        .map(|n| {
            let g = [n % grid[0], n / grid[0] % grid[1], n / (grid[0] * grid[1])];
            let begin: [usize; 3] = std::array::from_fn(|a| g[a] * chunk[a]);
            let end: [usize; 3] = std::array::from_fn(|a| ((g[a] + 1) * chunk[a]).min(dims[a]));
            let bytes = chunk_bytes(map, begin, end, width);
            let name: Vec<String> = (0..3)
                .map(|a| {
                    let o = frame.voxel_offset[a];
                    format!("{}-{}", o + begin[a] as i64, o + end[a] as i64)
                })
                .collect();
            let path = dir.join(name.join("_"));
            std::fs::write(&path, &bytes).map_err(|e| PrecomputedError::io(&path, e))?;
            Ok(bytes.len() as u64)
        })
        .sum()
}

/// The labels of voxels `[begin, end)`, x fastest, each `width` little-endian bytes.
fn chunk_bytes(map: &LabelVolume, begin: [usize; 3], end: [usize; 3], width: usize) -> Vec<u8> {
    let [nx, ny, _] = map.grid.dims;
    let mut out =
        Vec::with_capacity((end[0] - begin[0]) * (end[1] - begin[1]) * (end[2] - begin[2]) * width);
    for k in begin[2]..end[2] {
        for j in begin[1]..end[1] {
            let row = (k * ny + j) * nx;
            for &v in &map.values[row + begin[0]..row + end[0]] {
                match width {
                    4 => out.extend_from_slice(&v.to_le_bytes()),
                    _ => out.extend_from_slice(&(v as u64).to_le_bytes()),
                }
            }
        }
    }
    out
}
