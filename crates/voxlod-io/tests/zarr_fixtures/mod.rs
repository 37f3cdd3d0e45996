//! Zarr stores for the Zarr tests: arrays written by zarrs itself (format 3), format-2 arrays
//! written by hand (their `.zarray` and chunk files are plain enough to spell out, which checks
//! the reader against the specification rather than against zarrs' own writer), and OME-Zarr
//! groups around them.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde_json::{json, Value};
use voxlod_io::IoError;
use zarrs::array::codec::BytesToBytesCodecTraits;
use zarrs::array::{ArrayBuilder, ArrayBuilderFillValue, DataType, Element};
use zarrs::array_subset::ArraySubset;
use zarrs::filesystem::FilesystemStore;

/// The test arrays' shape, z, y, x (C order): 3 × 4 × 5 samples, x fastest.
pub const SHAPE: [u64; 3] = [3, 4, 5];
/// Chunks that leave partial chunks at every upper edge (3 = 2 + 1, 4 = 3 + 1, 5 = 2 + 2 + 1).
pub const CHUNKS: [u64; 3] = [2, 3, 2];

/// The test pattern at sample (i, j, k) (x, y, z): distinct, and small enough for a byte.
pub fn pattern(i: usize, j: usize, k: usize) -> f64 {
    (i + 10 * j + 100 * k) as f64
}

/// The pattern in C order (z slowest), mapped to the stored type by `f`.
pub fn samples<T>(f: impl Fn(f64) -> T) -> Vec<T> {
    let [nz, ny, nx] = SHAPE.map(|n| n as usize);
    let mut out = Vec::with_capacity(nx * ny * nz);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                out.push(f(pattern(i, j, k)));
            }
        }
    }
    out
}

/// Writes a format-3 array of `values` (C order over [`SHAPE`], chunks [`CHUNKS`]) with zarrs
/// at `path`, compressed by `codec` (none: the bytes codec only).
pub fn v3_array<T: Element>(
    path: &Path,
    data_type: DataType,
    fill: impl Into<ArrayBuilderFillValue>,
    values: &[T],
    codec: Option<Arc<dyn BytesToBytesCodecTraits>>,
) {
    let store = Arc::new(FilesystemStore::new(path).unwrap());
    let mut builder = ArrayBuilder::new(SHAPE.to_vec(), CHUNKS.to_vec(), data_type, fill);
    if let Some(codec) = codec {
        builder.bytes_to_bytes_codecs(vec![codec]);
    }
    let array = builder.build(store, "/").unwrap();
    array.store_metadata().unwrap();
    array
        .store_array_subset_elements::<T>(&ArraySubset::new_with_shape(SHAPE.to_vec()), values)
        .unwrap();
}

/// Writes a format-2 array by hand: `.zarray` with `dtype` (e.g. `"<u2"`), `compressor`
/// (`null`, or `{"id": "gzip", "level": 1}`), fill value `fill` (an integer for integer types, as
/// zarr-python writes it), and one file per chunk
/// (C order, full chunk shape, edge chunks padded with `fill` as format 2 stores them), each
/// made from the chunk's little-endian bytes by `compress`.
pub fn v2_array(
    path: &Path,
    dtype: &str,
    compressor: Value,
    fill: Value,
    encode: impl Fn(f64) -> Vec<u8>,
    compress: impl Fn(&[u8]) -> Vec<u8>,
) {
    std::fs::create_dir_all(path).unwrap();
    let zarray = json!({
        "zarr_format": 2,
        "shape": SHAPE,
        "chunks": CHUNKS,
        "dtype": dtype,
        "compressor": compressor,
        "fill_value": fill,
        "order": "C",
        "filters": null,
    });
    std::fs::write(path.join(".zarray"), zarray.to_string()).unwrap();
    let padding = fill.as_f64().unwrap();
    let counts = [0, 1, 2].map(|d| SHAPE[d].div_ceil(CHUNKS[d]) as usize);
    let c = CHUNKS.map(|n| n as usize);
    let s = SHAPE.map(|n| n as usize);
    for cz in 0..counts[0] {
        for cy in 0..counts[1] {
            for cx in 0..counts[2] {
                let mut bytes = Vec::new();
                for z in cz * c[0]..(cz + 1) * c[0] {
                    for y in cy * c[1]..(cy + 1) * c[1] {
                        for x in cx * c[2]..(cx + 1) * c[2] {
                            let inside = z < s[0] && y < s[1] && x < s[2];
                            let v = if inside { pattern(x, y, z) } else { padding };
                            bytes.extend(encode(v));
                        }
                    }
                }
                let name = format!("{cz}.{cy}.{cx}");
                std::fs::write(path.join(name), compress(&bytes)).unwrap();
            }
        }
    }
}

/// Writes an OME-Zarr 0.4 group (format 2: `.zgroup`, `.zattrs`) around a format-2 array at
/// `path/0`, with the dataset's `scale` and `translation` (z, y, x) and the axes' unit.
pub fn ome_04(path: &Path, scale: [f64; 3], translation: [f64; 3], unit: &str) -> PathBuf {
    std::fs::create_dir_all(path).unwrap();
    std::fs::write(path.join(".zgroup"), r#"{"zarr_format": 2}"#).unwrap();
    let attrs = json!({"multiscales": [multiscale(scale, translation, unit, "0.4")]});
    std::fs::write(path.join(".zattrs"), attrs.to_string()).unwrap();
    let array = path.join("0");
    v2_array(
        &array,
        "<u2",
        Value::Null,
        json!(0),
        |v| (v as u16).to_le_bytes().to_vec(),
        <[u8]>::to_vec,
    );
    array
}

/// Writes an OME-Zarr 0.5 group (format 3: `attributes.ome`) around a zarrs-written `f32`
/// array at `path/s0`.
pub fn ome_05(path: &Path, scale: [f64; 3], translation: [f64; 3], unit: &str) -> PathBuf {
    std::fs::create_dir_all(path).unwrap();
    let mut m = multiscale(scale, translation, unit, "0.5");
    m["datasets"][0]["path"] = json!("s0");
    let group = json!({
        "zarr_format": 3,
        "node_type": "group",
        "attributes": {"ome": {"version": "0.5", "multiscales": [m]}},
    });
    std::fs::write(path.join("zarr.json"), group.to_string()).unwrap();
    let array = path.join("s0");
    v3_array(
        &array,
        DataType::Float32,
        0.0f32,
        &samples(|v| v as f32),
        None,
    );
    array
}

fn multiscale(scale: [f64; 3], translation: [f64; 3], unit: &str, version: &str) -> Value {
    let axes: Vec<Value> = ["z", "y", "x"]
        .iter()
        .map(|n| json!({"name": n, "type": "space", "unit": unit}))
        .collect();
    json!({
        "version": version,
        "axes": axes,
        "datasets": [{
            "path": "0",
            "coordinateTransformations": [
                {"type": "scale", "scale": scale},
                {"type": "translation", "translation": translation},
            ],
        }],
    })
}

/// Asserts that `result` failed with a one-line message that names `path` (its last
/// component) and says `words`, without a Rust type's or zarrs' debug formatting.
pub fn assert_plain_error<T>(result: Result<T, IoError>, path: &Path, words: &str) -> IoError {
    let err = match result {
        Ok(_) => panic!("expected an error about {words}"),
        Err(e) => e,
    };
    let text = err.to_string();
    let name = path.file_name().unwrap().to_string_lossy();
    assert!(text.contains(&*name), "does not name {name}: {text}");
    assert!(text.contains(words), "does not say '{words}': {text}");
    assert!(!text.contains('\n'), "spans lines: {text}");
    for debug in ["{", "}", "Error(", "Some(", "::", "\\\""] {
        assert!(!text.contains(debug), "debug formatting ({debug}): {text}");
    }
    err
}
