//! Zarr and OME-Zarr read as volumes: format 3 arrays written by zarrs, format 2 arrays written
//! by hand from the specification, files written by zarr-python (when the peers' Python is
//! installed), OME-Zarr 0.4 and 0.5 geometry, regions, and the writer's round trip.

mod zarr_fixtures;

use std::path::Path;
use std::sync::Arc;

use serde_json::{json, Value};
use voxlod_core::{Grid, Volume};
use voxlod_io::{open_zarr, read_volume, write_volume};
use zarr_fixtures::{ome_04, ome_05, pattern, samples, v2_array, v3_array};
use zarrs::array::codec::{GzipCodec, ZstdCodec};
use zarrs::array::DataType;

/// Asserts that `volume` is the 5 × 4 × 3 test pattern, each sample mapped by `f`.
fn assert_pattern(volume: &Volume, f: impl Fn(f64) -> f64, what: &str) {
    assert_eq!(volume.grid.dims, [5, 4, 3], "{what}");
    for k in 0..3 {
        for j in 0..4 {
            for i in 0..5 {
                let expected = f(pattern(i, j, k)) as f32;
                assert_eq!(volume.get(i, j, k), expected, "{what} at ({i}, {j}, {k})");
            }
        }
    }
}

/// Asserts that two points agree to 1e-12 (relative).
fn assert_close(got: [f64; 3], expected: [f64; 3]) {
    for a in 0..3 {
        let tolerance = 1e-12 * expected[a].abs().max(1e-9);
        assert!(
            (got[a] - expected[a]).abs() <= tolerance,
            "{got:?} != {expected:?}"
        );
    }
}

fn read(path: &Path) -> Volume {
    read_volume(path, None).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn format_3_arrays_of_each_sample_type_with_partial_edge_chunks() {
    let dir = tempfile::tempdir().unwrap();
    let gzip = || Some(Arc::new(GzipCodec::new(5).unwrap()) as _);
    let zstd = || Some(Arc::new(ZstdCodec::new(3, true)) as _);

    let p = dir.path().join("u8.zarr");
    v3_array(&p, DataType::UInt8, 0u8, &samples(|v| v as u8), None);
    assert_pattern(&read(&p), |v| v, "uint8");
    let p = dir.path().join("u16.zarr");
    v3_array(
        &p,
        DataType::UInt16,
        0u16,
        &samples(|v| (v * 250.0) as u16),
        gzip(),
    );
    assert_pattern(&read(&p), |v| v * 250.0, "uint16");
    let p = dir.path().join("i16.zarr");
    v3_array(
        &p,
        DataType::Int16,
        -1i16,
        &samples(|v| (v - 300.0) as i16),
        zstd(),
    );
    assert_pattern(&read(&p), |v| v - 300.0, "int16");
    let p = dir.path().join("f32.zarr");
    v3_array(
        &p,
        DataType::Float32,
        0f32,
        &samples(|v| (v * 0.5 - 3.0) as f32),
        zstd(),
    );
    assert_pattern(&read(&p), |v| v * 0.5 - 3.0, "float32");
    // A plain array has unit spacing and its first sample at the origin.
    let grid = read(&p).grid;
    assert_eq!((grid.spacing, grid.origin), ([1.0; 3], [0.0; 3]));
}

#[test]
fn format_2_arrays_written_from_the_specification() {
    let dir = tempfile::tempdir().unwrap();
    let none = |b: &[u8]| b.to_vec();
    let gzip = |b: &[u8]| voxlod_testkit::files::gzip(b);
    let gz = json!({"id": "gzip", "level": 1});

    let p = dir.path().join("u8.zarr");
    v2_array(&p, "|u1", Value::Null, json!(0), |v| vec![v as u8], none);
    assert_pattern(&read(&p), |v| v, "|u1");
    let p = dir.path().join("u16.zarr");
    v2_array(
        &p,
        "<u2",
        gz.clone(),
        json!(0),
        |v| ((v * 250.0) as u16).to_le_bytes().to_vec(),
        gzip,
    );
    assert_pattern(&read(&p), |v| v * 250.0, "<u2");
    let p = dir.path().join("i16.zarr");
    v2_array(
        &p,
        "<i2",
        Value::Null,
        json!(0),
        |v| ((v - 300.0) as i16).to_le_bytes().to_vec(),
        none,
    );
    assert_pattern(&read(&p), |v| v - 300.0, "<i2");
    // Big-endian samples, as older tools wrote them.
    let p = dir.path().join("i16be.zarr");
    v2_array(
        &p,
        ">i2",
        gz.clone(),
        json!(0),
        |v| ((v - 300.0) as i16).to_be_bytes().to_vec(),
        gzip,
    );
    assert_pattern(&read(&p), |v| v - 300.0, ">i2");
    let p = dir.path().join("f32.zarr");
    v2_array(
        &p,
        "<f4",
        gz,
        json!(0.0),
        |v| ((v * 0.5 - 3.0) as f32).to_le_bytes().to_vec(),
        gzip,
    );
    assert_pattern(&read(&p), |v| v * 0.5 - 3.0, "<f4");
}

#[test]
fn ome_zarr_scale_and_translation_become_spacing_and_origin_in_millimetres() {
    let dir = tempfile::tempdir().unwrap();
    // 0.4: format 2, micrometres; scale and translation are z, y, x.
    let group = dir.path().join("v04.ome.zarr");
    ome_04(&group, [4.0, 2.0, 0.5], [100.0, -50.0, 25.0], "micrometer");
    let v = read(&group);
    assert_pattern(&v, |v| v, "OME-Zarr 0.4");
    assert_close(v.grid.spacing, [0.5e-3, 2.0e-3, 4.0e-3]);
    assert_close(v.grid.origin, [25.0e-3, -50.0e-3, 100.0e-3]);
    // 0.5: format 3, the metadata under `ome`, millimetres.
    let group = dir.path().join("v05.ome.zarr");
    ome_05(&group, [1.5, 0.75, 0.25], [-8.0, 3.0, 1.0], "millimeter");
    let v = read(&group);
    assert_pattern(&v, |v| v, "OME-Zarr 0.5");
    assert_eq!(v.grid.spacing, [0.25, 0.75, 1.5]);
    assert_eq!(v.grid.origin, [1.0, 3.0, -8.0]);
    // The array inside the group reads as a plain array.
    let plain = read(&group.join("s0"));
    assert_eq!(
        (plain.grid.spacing, plain.grid.origin),
        ([1.0; 3], [0.0; 3])
    );
}

#[test]
fn a_region_across_chunks_keeps_the_samples_and_moves_the_origin() {
    let dir = tempfile::tempdir().unwrap();
    let group = dir.path().join("img.ome.zarr");
    ome_05(&group, [2.0, 1.0, 0.5], [10.0, 20.0, 30.0], "millimeter");
    let zarr = open_zarr(&group).unwrap();
    assert_eq!(zarr.grid().dims, [5, 4, 3]);
    assert_eq!(zarr.chunk_shape(), [2, 3, 2]);
    assert_eq!(zarr.sample_type(), "float32");
    let region = zarr.read_region([1, 2, 1], [3, 2, 2]).unwrap();
    assert_eq!(region.grid.dims, [3, 2, 2]);
    assert_eq!(region.grid.origin, [30.5, 22.0, 12.0]);
    for (k, j, i) in [(0, 0, 0), (1, 1, 2), (0, 1, 1), (1, 0, 2)] {
        assert_eq!(
            region.get(i, j, k),
            pattern(i + 1, j + 2, k + 1) as f32,
            "({i}, {j}, {k})"
        );
    }
    // Outside the array: an error, not a panic.
    assert!(zarr.read_region([4, 0, 0], [2, 1, 1]).is_err());
}

#[test]
fn the_writer_round_trips_samples_spacing_and_origin_and_replaces_an_earlier_store() {
    let dir = tempfile::tempdir().unwrap();
    // 70 samples along x: two chunks of the writer's 64, the second partial.
    let grid = Grid::new([70, 3, 2], [0.5, 1.0, 2.0], [-1.0, 2.0, 3.5]).unwrap();
    let values: Vec<f32> = (0..grid.len()).map(|n| (n as f32 * 0.37).sin()).collect();
    let volume = Volume::from_vec(grid, values).unwrap();
    let path = dir.path().join("out.zarr");
    write_volume(&path, &volume).unwrap();
    let back = read(&path);
    assert_eq!(back.grid, volume.grid);
    assert_eq!(back.as_slice(), volume.as_slice());
    let group: Value =
        serde_json::from_slice(&std::fs::read(path.join("zarr.json")).unwrap()).unwrap();
    assert_eq!(group["attributes"]["ome"]["version"], "0.5");
    assert_eq!(
        group["attributes"]["ome"]["multiscales"][0]["datasets"][0]["coordinateTransformations"][0]
            ["scale"],
        json!([2.0, 1.0, 0.5])
    );
    // A smaller volume written over it: its chunk files only.
    let small = Volume::from_vec(
        Grid::new([2, 2, 2], [1.0; 3], [0.0; 3]).unwrap(),
        (0..8).map(|n| n as f32).collect(),
    )
    .unwrap();
    write_volume(&path, &small).unwrap();
    let back = read(&path);
    assert_eq!(back.as_slice(), small.as_slice());
    let chunk_files = walk(&path.join("0").join("c"));
    assert_eq!(chunk_files, 1, "stale chunks left behind");
}

/// Files under `dir`, recursively.
fn walk(dir: &Path) -> usize {
    let mut n = 0;
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        n += if path.is_dir() { walk(&path) } else { 1 };
    }
    n
}

/// zarr-python 3's writer: format 2 (its default compressor and blosc) and format 3 (its
/// default zstd), four sample types, partial edge chunks, and OME-Zarr groups whose attributes
/// zarr-python writes.
const ZARR_PYTHON: &str = r#"
import sys, numpy as np, zarr
from numcodecs import Blosc
root = sys.argv[1]
z, y, x = np.meshgrid(np.arange(3), np.arange(4), np.arange(5), indexing="ij")
pattern = x + 10 * y + 100 * z
kinds = {"u1": pattern, "u2": pattern * 250, "i2": pattern - 300, "f4": pattern * 0.5 - 3}
for fmt in (2, 3):
    for dtype, values in kinds.items():
        extra = {}
        if fmt == 2 and dtype == "u2":
            extra["compressors"] = Blosc(cname="lz4", clevel=5, shuffle=Blosc.SHUFFLE)
        a = zarr.create_array(f"{root}/v{fmt}-{dtype}.zarr", shape=(3, 4, 5), chunks=(2, 3, 2),
                              dtype=dtype, zarr_format=fmt, fill_value=0, **extra)
        a[:] = values.astype(dtype)
for fmt, version in ((2, "0.4"), (3, "0.5")):
    g = zarr.open_group(f"{root}/ome-{version}.zarr", mode="w", zarr_format=fmt)
    a = g.create_array("scale0", shape=(1, 3, 4, 5), chunks=(1, 2, 3, 2), dtype="u2")
    a[:] = pattern[None].astype("u2")
    axes = [{"name": "c", "type": "channel"}] + [
        {"name": n, "type": "space", "unit": "micrometer"} for n in "zyx"]
    ms = [{"version": version, "axes": axes, "datasets": [{"path": "scale0",
           "coordinateTransformations": [{"type": "scale", "scale": [1, 3, 2, 1]},
                                         {"type": "translation", "translation": [0, 9, 6, 3]}]}]}]
    if fmt == 2:
        g.attrs["multiscales"] = ms
    else:
        g.attrs["ome"] = {"version": version, "multiscales": ms}
print("ok")
"#;

/// A sample type's mapping of the test pattern.
type Mapping = fn(f64) -> f64;

#[test]
fn stores_written_by_zarr_python_read_as_zarr_python_wrote_them() {
    let dir = tempfile::tempdir().unwrap();
    let Some(out) = voxlod_testkit::peers::run_python(ZARR_PYTHON, &[dir.path().as_os_str()])
    else {
        eprintln!("skipped: zarr-python (the peers' Python with zarr >= 3) is not available");
        return;
    };
    assert_eq!(out.trim(), "ok");
    let kinds: [(&str, Mapping); 4] = [
        ("u1", |v| v),
        ("u2", |v| v * 250.0),
        ("i2", |v| v - 300.0),
        ("f4", |v| v * 0.5 - 3.0),
    ];
    for format in [2, 3] {
        for (dtype, f) in kinds {
            let path = dir.path().join(format!("v{format}-{dtype}.zarr"));
            assert_pattern(&read(&path), f, &format!("zarr-python v{format} {dtype}"));
        }
    }
    // The pattern's first sample is 0, the fill value: zarr-python leaves chunks that hold only
    // the fill value unwritten, and those read back as the fill value.
    for version in ["0.4", "0.5"] {
        let path = dir.path().join(format!("ome-{version}.zarr"));
        let v = read(&path);
        assert_pattern(&v, |v| v, &format!("zarr-python OME-Zarr {version}"));
        assert_close(v.grid.spacing, [1e-3, 2e-3, 3e-3]);
        assert_close(v.grid.origin, [3e-3, 6e-3, 9e-3]);
    }
}
