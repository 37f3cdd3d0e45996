//! A precomputed layer's labels read back (neuroglancer `volume.md`): the finest scale of a
//! layer whose chunks are raw or `compressed_segmentation` (`compressed_segmentation.rs`),
//! plain or gzipped, as this crate, igneous and cloud-volume write them. Other encodings
//! (`jpeg`, `png`, …) are refused naming the encoding.
//!
//! The map's world is the layer's physical space in nanometres: spacing the scale's
//! resolution, origin its voxel offset times the resolution. Cost: one read of every chunk; the
//! map's bytes are asked of the memory limit before anything is allocated.

use std::io::Read;
use std::path::{Path, PathBuf};

use voxlod_core::{memory, Grid, LabelVolume};

use crate::{compressed_segmentation, PrecomputedError};

/// The finest scale of a layer's `info`.
struct Scale {
    key: String,
    size: [usize; 3],
    resolution: [f64; 3],
    offset: [i64; 3],
    chunk: [usize; 3],
    bytes: usize,
    /// The blocks of `compressed_segmentation`, `None` for raw chunks.
    blocks: Option<[usize; 3]>,
}

/// The labels of the precomputed layer at `dir` (a folder holding `info`), at its finest scale.
/// Fails naming the file on a missing or malformed `info` or chunk, an encoding other than raw,
/// more than one channel, a data type that is not an unsigned integer, or a label above
/// 4294967295.
pub fn read_labels(dir: &Path) -> Result<LabelVolume, PrecomputedError> {
    let scale = read_info(dir)?;
    let count = scale.size.iter().product::<usize>();
    memory::check_allocation("the layer's labels", memory::bytes_of::<u32>(count))?;
    let mut values = vec![0u32; count];
    let [sx, sy, sz] = scale.size;
    for z0 in (0..sz).step_by(scale.chunk[2]) {
        for y0 in (0..sy).step_by(scale.chunk[1]) {
            for x0 in (0..sx).step_by(scale.chunk[0]) {
                read_chunk(dir, &scale, [x0, y0, z0], &mut values)?;
            }
        }
    }
    let origin: [f64; 3] = std::array::from_fn(|a| scale.offset[a] as f64 * scale.resolution[a]);
    let grid = Grid::new(scale.size, scale.resolution, origin)?;
    Ok(LabelVolume::from_vec(grid, values)?)
}

/// The finest scale of `dir/info`, checked.
fn read_info(dir: &Path) -> Result<Scale, PrecomputedError> {
    let path = dir.join("info");
    let bad = |reason: String| PrecomputedError::Format {
        path: path.clone(),
        reason,
    };
    let text = std::fs::read(&path).map_err(|e| PrecomputedError::io(&path, e))?;
    let info: serde_json::Value =
        serde_json::from_slice(&text).map_err(|e| bad(format!("not JSON: {e}")))?;
    if info["num_channels"].as_u64().unwrap_or(1) != 1 {
        return Err(bad(format!(
            "{} channels: a label map has one",
            info["num_channels"]
        )));
    }
    let bytes = match info["data_type"].as_str() {
        Some("uint8") => 1,
        Some("uint16") => 2,
        Some("uint32") => 4,
        Some("uint64") => 8,
        other => {
            return Err(bad(format!(
                "data type {other:?}: labels are unsigned integers"
            )))
        }
    };
    let scale = &info["scales"][0];
    let encoding = scale["encoding"].as_str().unwrap_or("");
    if !matches!(encoding, "raw" | "compressed_segmentation") {
        return Err(bad(format!(
            "encoding {encoding:?}: labels are read from raw or compressed_segmentation chunks"
        )));
    }
    let triple = |v: &serde_json::Value, what: &str| -> Result<[f64; 3], PrecomputedError> {
        let n = v
            .as_array()
            .filter(|a| a.len() == 3)
            .ok_or_else(|| bad(format!("no {what}")))?;
        let f = |x: &serde_json::Value| x.as_f64().ok_or_else(|| bad(format!("{what}: {x}")));
        Ok([f(&n[0])?, f(&n[1])?, f(&n[2])?])
    };
    let whole = |v: [f64; 3], what: &str| -> Result<[usize; 3], PrecomputedError> {
        if v.iter().any(|&x| !(x >= 1.0 && x.fract() == 0.0)) {
            return Err(bad(format!(
                "{what} {v:?} is not three positive whole numbers"
            )));
        }
        Ok(v.map(|x| x as usize))
    };
    Ok(Scale {
        key: scale["key"]
            .as_str()
            .ok_or_else(|| bad("no scale key".into()))?
            .to_string(),
        size: whole(triple(&scale["size"], "size")?, "size")?,
        resolution: triple(&scale["resolution"], "resolution")?,
        offset: triple(&scale["voxel_offset"], "voxel_offset")?.map(|x| x as i64),
        chunk: whole(
            triple(&scale["chunk_sizes"][0], "chunk_sizes")?,
            "chunk size",
        )?,
        bytes,
        blocks: match encoding {
            "raw" => None,
            _ => {
                let block = &scale["compressed_segmentation_block_size"];
                Some(whole(
                    triple(block, "compressed_segmentation_block_size")?,
                    "block size",
                )?)
            }
        },
    })
}

/// Reads the chunk starting at voxel `begin` of the scale (its file plain or `.gz`) into
/// `values`.
fn read_chunk(
    dir: &Path,
    scale: &Scale,
    begin: [usize; 3],
    values: &mut [u32],
) -> Result<(), PrecomputedError> {
    let end: [usize; 3] = std::array::from_fn(|a| (begin[a] + scale.chunk[a]).min(scale.size[a]));
    let name = (0..3)
        .map(|a| {
            let o = scale.offset[a];
            format!("{}-{}", o + begin[a] as i64, o + end[a] as i64)
        })
        .collect::<Vec<_>>()
        .join("_");
    let (path, data) = chunk_bytes(&dir.join(&scale.key).join(&name))?;
    let dims: [usize; 3] = std::array::from_fn(|a| end[a] - begin[a]);
    let labels = chunk_labels(scale, dims, &data).map_err(|reason| PrecomputedError::Format {
        path: path.clone(),
        reason,
    })?;
    let [sx, sy, _] = scale.size;
    for (n, label) in labels.into_iter().enumerate() {
        let at = [n % dims[0], n / dims[0] % dims[1], n / (dims[0] * dims[1])];
        let [x, y, z] = std::array::from_fn(|a| begin[a] + at[a]);
        values[(z * sy + y) * sx + x] =
            u32::try_from(label).map_err(|_| PrecomputedError::Format {
                path: path.clone(),
                reason: format!("label {label} at ({x}, {y}, {z}) is above 4294967295"),
            })?;
    }
    Ok(())
}

/// The labels of a chunk of `dims` voxels (x fastest) from its file's bytes.
fn chunk_labels(scale: &Scale, dims: [usize; 3], data: &[u8]) -> Result<Vec<u64>, String> {
    if let Some(block) = scale.blocks {
        if !data.len().is_multiple_of(4) {
            return Err(format!("{} bytes, not whole 32-bit words", data.len()));
        }
        let words: Vec<u32> = data
            .chunks_exact(4)
            .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
            .collect();
        return compressed_segmentation::decode(&words, dims, block, scale.bytes == 8);
    }
    let expected = dims.iter().product::<usize>() * scale.bytes;
    if data.len() != expected {
        return Err(format!(
            "{} bytes where the chunk holds {expected}",
            data.len()
        ));
    }
    Ok(data
        .chunks_exact(scale.bytes)
        .map(|sample| {
            let mut word = [0u8; 8];
            word[..sample.len()].copy_from_slice(sample);
            u64::from_le_bytes(word)
        })
        .collect())
}

/// The bytes of a chunk file, gunzipped when it is the `.gz` one.
fn chunk_bytes(path: &Path) -> Result<(PathBuf, Vec<u8>), PrecomputedError> {
    if let Ok(data) = std::fs::read(path) {
        return Ok((path.to_path_buf(), data));
    }
    let gz = PathBuf::from(format!("{}.gz", path.display()));
    let file = std::fs::File::open(&gz).map_err(|e| PrecomputedError::io(path, e))?;
    let mut data = Vec::new();
    flate2::read::GzDecoder::new(file)
        .read_to_end(&mut data)
        .map_err(|e| PrecomputedError::io(&gz, e))?;
    Ok((gz, data))
}
