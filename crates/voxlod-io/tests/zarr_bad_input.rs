//! Zarr input that is broken or beyond voxlod: each a one-line error naming the store and the
//! problem in plain words (never zarrs' internals or debug formatting), or the behaviour the
//! reader documents (a missing chunk reads as the fill value).

mod zarr_fixtures;

use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde_json::{json, Value};
use voxlod_io::{open_zarr, read_volume, IoErrorKind};
use zarr_fixtures::{assert_plain_error, pattern, samples, v2_array, v3_array};
use zarrs::array::codec::ZstdCodec;
use zarrs::array::DataType;

fn plain_u8_v3(dir: &Path, name: &str, fill: u8) -> PathBuf {
    let path = dir.join(name);
    let zstd = Arc::new(ZstdCodec::new(3, false));
    v3_array(
        &path,
        DataType::UInt8,
        fill,
        &samples(|v| v as u8),
        Some(zstd),
    );
    path
}

fn raw_u16_v2(dir: &Path, name: &str, compressor: Value) -> PathBuf {
    let path = dir.join(name);
    let le = |v: f64| (v as u16).to_le_bytes().to_vec();
    v2_array(&path, "<u2", compressor, json!(9), le, <[u8]>::to_vec);
    path
}

fn gzip_u16_v2(dir: &Path, name: &str) -> PathBuf {
    let path = dir.join(name);
    let le = |v: f64| (v as u16).to_le_bytes().to_vec();
    let gzip = |b: &[u8]| voxlod_testkit::files::gzip(b);
    let compressor = json!({"id": "gzip", "level": 1});
    v2_array(&path, "<u2", compressor, json!(0), le, gzip);
    path
}

/// Rewrites the JSON file `file` through `edit`.
fn edit_json(file: &Path, edit: impl FnOnce(&mut Value)) {
    let mut json: Value = serde_json::from_slice(&std::fs::read(file).unwrap()).unwrap();
    edit(&mut json);
    std::fs::write(file, json.to_string()).unwrap();
}

#[test]
fn a_missing_chunk_reads_as_the_fill_value() {
    let dir = tempfile::tempdir().unwrap();
    // Format 3: chunk (z 1, y 1, x 2) holds z 2, y 3, x 4: the far corner sample only.
    let v3 = plain_u8_v3(dir.path(), "v3.zarr", 7);
    std::fs::remove_file(v3.join("c/1/1/2")).unwrap();
    // Format 2: chunk (0, 0, 1) holds z 0..2, y 0..3, x 2..4.
    let v2 = raw_u16_v2(dir.path(), "v2.zarr", Value::Null);
    std::fs::remove_file(v2.join("0.0.1")).unwrap();
    let a = read_volume(&v3, None).unwrap();
    let b = read_volume(&v2, None).unwrap();
    for k in 0..3 {
        for j in 0..4 {
            for i in 0..5 {
                let p = pattern(i, j, k) as f32;
                let in_v3_gap = (i, j, k) == (4, 3, 2);
                let in_v2_gap = (2..4).contains(&i) && j < 3 && k < 2;
                assert_eq!(a.get(i, j, k), if in_v3_gap { 7.0 } else { p });
                assert_eq!(b.get(i, j, k), if in_v2_gap { 9.0 } else { p });
            }
        }
    }
}

#[test]
fn a_compressor_voxlod_lacks_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let v2 = raw_u16_v2(
        dir.path(),
        "lz4.zarr",
        json!({"id": "lz4", "acceleration": 1}),
    );
    let err = assert_plain_error(read_volume(&v2, None), &v2, "lz4");
    assert_eq!(err.kind, IoErrorKind::Unsupported, "{err}");
    let v3 = plain_u8_v3(dir.path(), "bz2.zarr", 0);
    edit_json(&v3.join("zarr.json"), |j| {
        j["codecs"][1] = json!({"name": "numcodecs.bz2", "configuration": {"level": 1}});
    });
    let err = assert_plain_error(read_volume(&v3, None), &v3, "bz2");
    assert_eq!(err.kind, IoErrorKind::Unsupported, "{err}");
}

#[test]
fn edge_chunks_stored_cut_instead_of_padded() {
    // Format 2 stores every chunk whole, padded at the array's edges. A writer that cuts the
    // edge chunk to the array leaves a chunk that decodes to fewer samples than its shape:
    // compressed, that is a corrupt chunk.
    let dir = tempfile::tempdir().unwrap();
    let gz = gzip_u16_v2(dir.path(), "cut-gzip.zarr");
    let le = |v: f64| (v as u16).to_le_bytes().to_vec();
    // Chunk (0, 0, 2): z 0..2, y 0..3, x 4 (one column of two), cut to its 6 samples.
    let cut: Vec<u8> = (0..2)
        .flat_map(|z| (0..3).flat_map(move |y| le(pattern(4, y, z))))
        .collect();
    std::fs::write(gz.join("0.0.2"), voxlod_testkit::files::gzip(&cut)).unwrap();
    let err = assert_plain_error(read_volume(&gz, None), &gz, "chunk");
    assert_eq!(err.kind, IoErrorKind::Malformed, "{err}");
    // Uncompressed, the samples are read at their padded offsets: the cut file is too short for
    // the last of them, an error too.
    let raw = raw_u16_v2(dir.path(), "cut-raw.zarr", Value::Null);
    std::fs::write(raw.join("0.0.2"), &cut).unwrap();
    let err = assert_plain_error(read_volume(&raw, None), &raw, "chunk");
    assert_eq!(err.kind, IoErrorKind::Truncated, "{err}");
    // Cut along z only (the slowest axis), a chunk's stored samples are a prefix of the padded
    // ones, so the array reads correctly: chunk (1, 0, 0) keeps its one z slice of two.
    let z_cut = raw_u16_v2(dir.path(), "z-cut.zarr", Value::Null);
    let file = z_cut.join("1.0.0");
    let whole = std::fs::read(&file).unwrap();
    std::fs::write(&file, &whole[..whole.len() / 2]).unwrap();
    let v = read_volume(&z_cut, None).unwrap();
    assert_eq!(v.get(1, 2, 2), pattern(1, 2, 2) as f32);
}

#[test]
fn a_group_without_multiscales_is_refused_with_what_to_do() {
    let dir = tempfile::tempdir().unwrap();
    let v3 = dir.path().join("group3.zarr");
    std::fs::create_dir(&v3).unwrap();
    std::fs::write(
        v3.join("zarr.json"),
        r#"{"zarr_format": 3, "node_type": "group", "attributes": {"name": "scan"}}"#,
    )
    .unwrap();
    plain_u8_v3(&v3, "raw", 0);
    let err = assert_plain_error(read_volume(&v3, None), &v3, "multiscales");
    assert_eq!(err.kind, IoErrorKind::Unsupported, "{err}");
    assert!(err.message.contains("path of the array"), "{err}");
    let v2 = dir.path().join("group2.zarr");
    std::fs::create_dir(&v2).unwrap();
    std::fs::write(v2.join(".zgroup"), r#"{"zarr_format": 2}"#).unwrap();
    assert_plain_error(read_volume(&v2, None), &v2, "multiscales");
    // Multiscales whose first dataset names no array, or an array that is not there.
    std::fs::write(v2.join(".zattrs"), r#"{"multiscales": [{"datasets": []}]}"#).unwrap();
    assert_plain_error(read_volume(&v2, None), &v2, "no dataset path");
    std::fs::write(
        v2.join(".zattrs"),
        r#"{"multiscales": [{"datasets": [{"path": "0"}]}]}"#,
    )
    .unwrap();
    assert_plain_error(read_volume(&v2, None), &v2, "/0");
}

#[test]
fn sample_types_voxlod_does_not_read_are_named() {
    let dir = tempfile::tempdir().unwrap();
    for (name, dtype) in [("complex.zarr", "complex64"), ("bool.zarr", "bool")] {
        let path = plain_u8_v3(dir.path(), name, 0);
        edit_json(&path.join("zarr.json"), |j| {
            j["data_type"] = json!(dtype);
            j["fill_value"] = if dtype == "bool" {
                json!(false)
            } else {
                json!([0.0, 0.0])
            };
        });
        let err = assert_plain_error(read_volume(&path, None), &path, dtype);
        assert_eq!(err.kind, IoErrorKind::Unsupported, "{err}");
        assert!(err.message.contains("uint8, int8"), "{err}");
    }
    // Format 2 with a type zarrs itself does not know.
    let path = raw_u16_v2(dir.path(), "timedelta.zarr", Value::Null);
    edit_json(&path.join(".zarray"), |j| j["dtype"] = json!("<m8[s]"));
    let err = assert_plain_error(read_volume(&path, None), &path, "data type");
    assert_eq!(err.kind, IoErrorKind::Unsupported, "{err}");
}

#[test]
fn absurd_shapes_go_through_the_memory_budget() {
    let dir = tempfile::tempdir().unwrap();
    let path = plain_u8_v3(dir.path(), "huge.zarr", 0);
    edit_json(&path.join("zarr.json"), |j| {
        j["shape"] = json!([1_000_000, 1_000_000, 1_000_000]);
    });
    let err = assert_plain_error(read_volume(&path, None), &path, "");
    assert_eq!(err.kind, IoErrorKind::TooLarge, "{err}");
    // Beyond what a grid can index: refused before the budget is even asked.
    edit_json(&path.join("zarr.json"), |j| {
        j["shape"] = json!([1u64 << 62, 4, 4])
    });
    assert_plain_error(read_volume(&path, None), &path, "overflow");
    // Opening checks nothing large: the geometry of a huge store is known before any sample.
    edit_json(&path.join("zarr.json"), |j| {
        j["shape"] = json!([100_000, 100_000, 100_000]);
    });
    let zarr = open_zarr(&path).unwrap();
    assert_eq!(zarr.grid().dims, [100_000; 3]);
    let err = assert_plain_error(zarr.read_all(), &path, "");
    assert_eq!(err.kind, IoErrorKind::TooLarge, "{err}");
    // A small region of it is fine: every chunk there is missing, so it reads as the fill value.
    let region = zarr.read_region([50_000; 3], [4, 4, 4]).unwrap();
    assert!(region.as_slice().iter().all(|&v| v == 0.0));
}

#[test]
fn absurd_chunk_shapes_are_refused_before_decoding() {
    let dir = tempfile::tempdir().unwrap();
    let v2 = raw_u16_v2(dir.path(), "chunks2.zarr", Value::Null);
    let v3 = plain_u8_v3(dir.path(), "chunks3.zarr", 0);
    let huge = [json!([2, u64::MAX, 2]), json!([1 << 21, 1 << 21, 1 << 21])];
    for chunks in &huge {
        edit_json(&v2.join(".zarray"), |j| j["chunks"] = chunks.clone());
        edit_json(&v3.join("zarr.json"), |j| {
            j["chunk_grid"]["configuration"]["chunk_shape"] = chunks.clone();
        });
        for store in [&v2, &v3] {
            let err = assert_plain_error(read_volume(store, None), store, "chunk");
            assert!(
                matches!(err.kind, IoErrorKind::TooLarge | IoErrorKind::Malformed),
                "{err}"
            );
        }
    }
}

#[test]
fn truncated_compressed_chunks_are_corrupt() {
    let dir = tempfile::tempdir().unwrap();
    let v3 = plain_u8_v3(dir.path(), "zstd.zarr", 0);
    let chunk = v3.join("c/0/0/0");
    let bytes = std::fs::read(&chunk).unwrap();
    std::fs::write(&chunk, &bytes[..bytes.len() / 2]).unwrap();
    let err = assert_plain_error(read_volume(&v3, None), &v3, "chunk");
    assert!(
        matches!(err.kind, IoErrorKind::Malformed | IoErrorKind::Truncated),
        "{err}"
    );

    let gz = gzip_u16_v2(dir.path(), "gzip.zarr");
    let chunk = gz.join("0.0.0");
    let bytes = std::fs::read(&chunk).unwrap();
    std::fs::write(&chunk, &bytes[..bytes.len() - 6]).unwrap();
    let err = assert_plain_error(read_volume(&gz, None), &gz, "chunk");
    assert!(
        matches!(err.kind, IoErrorKind::Malformed | IoErrorKind::Truncated),
        "{err}"
    );
    // Garbage in place of a chunk.
    std::fs::write(&chunk, b"not gzip at all").unwrap();
    assert_plain_error(read_volume(&gz, None), &gz, "chunk");
}

#[test]
fn metadata_that_is_not_json_names_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let v3 = plain_u8_v3(dir.path(), "v3.zarr", 0);
    std::fs::write(
        v3.join("zarr.json"),
        b"{\"zarr_format\": 3, \"node_type\": ",
    )
    .unwrap();
    let err = assert_plain_error(
        read_volume(&v3, None),
        &v3.join("zarr.json"),
        "not valid JSON",
    );
    assert_eq!(err.kind, IoErrorKind::Malformed, "{err}");
    let v2 = raw_u16_v2(dir.path(), "v2.zarr", Value::Null);
    std::fs::write(v2.join(".zarray"), b"\x89PNG\r\n").unwrap();
    let err = assert_plain_error(read_volume(&v2, None), &v2, "not valid");
    assert_eq!(err.kind, IoErrorKind::Malformed, "{err}");
    // JSON, but not an array's metadata.
    std::fs::write(v2.join(".zarray"), br#"{"zarr_format": 2, "shape": "big"}"#).unwrap();
    assert_plain_error(read_volume(&v2, None), &v2, "not valid");
    // A file where the store's folder should be.
    let file = dir.path().join("file.zarr");
    std::fs::write(&file, b"{}").unwrap();
    assert_plain_error(read_volume(&file, None), &file, "folder");
    // An empty folder.
    let empty = dir.path().join("empty.zarr");
    std::fs::create_dir(&empty).unwrap();
    assert_plain_error(read_volume(&empty, None), &empty, "not a Zarr store");
}
