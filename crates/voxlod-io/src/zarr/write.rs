//! Writing a volume as an OME-Zarr 0.5 image: a Zarr v3 group whose `ome.multiscales` names one
//! dataset, the array `0` of `f32` samples (axes z, y, x; chunks of up to 64³; zstd), with the
//! volume's spacing as `scale` and its origin as `translation`. napari (with ome-zarr) and
//! neuroglancer open it as an image; zarr-python reads `0` as a plain array.
//!
//! One dataset, not a pyramid: a written volume is one level (its own resolution and filter
//! radius, paper §2); the coarser levels of `lod` are filtered from the original object with
//! wider filters, not downsampled from this one, so they are not a multiscale pyramid of it.
//!
//! The store is encoded in memory by zarrs ([`store_files`]); the output set stages its files,
//! so that it appears whole at commit or not at all, like every other output, and removes the
//! chunk files an earlier write left in the same folders ([`is_store_file`]; chunks that are all
//! fill value are not written). The axes carry no unit: a volume does not record one.
//!
//! Cost: O(N) to encode N samples; memory: the compressed store besides the volume.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde_json::json;
use voxlod_core::Volume;
use zarrs::array::codec::ZstdCodec;
use zarrs::array::{ArrayBuilder, DataType};
use zarrs::array_subset::ArraySubset;
use zarrs::group::GroupBuilder;
use zarrs::storage::store::MemoryStore;
use zarrs::storage::{Bytes, ListableStorageTraits, ReadableStorageTraits};

use crate::{IoError, IoErrorKind};

/// The largest chunk side written.
const CHUNK_SIDE: usize = 64;
/// zstd's level: its default, fast with a good ratio on filtered densities.
const ZSTD_LEVEL: i32 = 3;

/// The files of an OME-Zarr image of a volume, to be written below its folder.
pub(crate) struct StoreFiles {
    /// The folders that hold them.
    pub folders: Vec<PathBuf>,
    /// Each file's path and bytes (shared with the encoded store, not copied).
    pub files: Vec<(PathBuf, Bytes)>,
}

/// The files of an OME-Zarr image of `volume` at `path` (a folder, empty, missing or a Zarr
/// store, whose files may be replaced; anything else in the way is a conflict).
pub(crate) fn store_files(path: &Path, volume: &Volume) -> Result<StoreFiles, IoError> {
    if path.is_file() || (path.is_dir() && !is_zarr_store(path)) {
        return Err(IoError::new(
            path,
            IoErrorKind::Conflict,
            "cannot write a Zarr store here: something other than a Zarr store is in the way",
        ));
    }
    let store = encode(path, volume)?;
    let keys = store.list().map_err(|_| failed(path))?;
    let mut out = StoreFiles {
        folders: Vec::new(),
        files: Vec::with_capacity(keys.len()),
    };
    for key in keys {
        let bytes = store
            .get(&key)
            .map_err(|_| failed(path))?
            .unwrap_or_default();
        let file = path.join(key.as_str());
        let folder = file.parent().unwrap_or(path).to_path_buf();
        if !out.folders.contains(&folder) {
            out.folders.push(folder);
        }
        out.files.push((file, bytes));
    }
    Ok(out)
}

/// Whether a file name in a store's folder is one a store writes: metadata or a chunk.
pub(crate) fn is_store_file(name: &str) -> bool {
    name == "zarr.json" || name.bytes().all(|b| b.is_ascii_digit())
}

/// Whether `path` holds a Zarr store (so that writing may replace its files).
fn is_zarr_store(path: &Path) -> bool {
    ["zarr.json", ".zarray", ".zgroup"]
        .iter()
        .any(|f| path.join(f).is_file())
}

fn failed(path: &Path) -> IoError {
    IoError::new(path, IoErrorKind::Access, "cannot encode the Zarr store")
}

/// The whole store in memory: the group's metadata, the array's, and its chunks.
fn encode(path: &Path, volume: &Volume) -> Result<MemoryStore, IoError> {
    let g = &volume.grid;
    let store = Arc::new(MemoryStore::new());
    let shape: Vec<u64> = [2, 1, 0].map(|a| g.dims[a] as u64).to_vec();
    let chunks: Vec<u64> = [2, 1, 0]
        .map(|a| g.dims[a].clamp(1, CHUNK_SIDE) as u64)
        .to_vec();
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let axes: Vec<_> = ["z", "y", "x"]
        .iter()
        .map(|n| json!({"name": n, "type": "space"}))
        .collect();
    let ome = json!({
        "ome": {
            "version": "0.5",
            "multiscales": [{
                "name": name,
                "axes": axes,
                "datasets": [{
                    "path": "0",
                    "coordinateTransformations": [
                        {"type": "scale", "scale": [g.spacing[2], g.spacing[1], g.spacing[0]]},
                        {"type": "translation", "translation": [g.origin[2], g.origin[1], g.origin[0]]},
                    ],
                }],
            }],
        }
    });
    let attributes = ome.as_object().cloned().unwrap_or_default();
    GroupBuilder::new()
        .attributes(attributes)
        .build(store.clone(), "/")
        .map_err(|_| failed(path))?
        .store_metadata()
        .map_err(|_| failed(path))?;
    let array = ArrayBuilder::new(shape, chunks, DataType::Float32, 0.0f32)
        .bytes_to_bytes_codecs(vec![Arc::new(ZstdCodec::new(ZSTD_LEVEL, false))])
        .dimension_names(["z", "y", "x"].into())
        .build(store.clone(), "/0")
        .map_err(|_| failed(path))?;
    array.store_metadata().map_err(|_| failed(path))?;
    let samples = volume.as_slice();
    array
        .store_array_subset_elements::<f32>(
            &ArraySubset::new_with_shape(array.shape().to_vec()),
            samples,
        )
        .map_err(|_| failed(path))?;
    drop(array);
    Arc::try_unwrap(store).map_err(|_| failed(path))
}
