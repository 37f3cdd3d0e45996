//! Label maps read as exact unsigned 32-bit labels (`read_label_map`), from files made here by
//! hand in every volume format and sample type (NRRD raw, gzip, ascii and detached; NIfTI plain
//! and gzipped; MetaImage local, zlib and detached; VTK XML and legacy images; headerless raw;
//! Zarr v2), and written back by `write_label_map`: each label comes back as stored, 2²⁴+1 and
//! 4294967295 included. Maps that are not labels (negative, fractional, beyond 2³²−1, NaN),
//! 4-D maps and empty maps are refused naming the file, the voxel or the axis; absurd header
//! sizes meet the memory budget before anything is allocated; and a uint32 map written by
//! nibabel (the peers' Python) is read voxel for voxel with its affine.

mod common;

use std::path::{Path, PathBuf};

use common::{gzip, write, zlib};
use voxlod_core::glam::{DMat3, DVec3};
use voxlod_core::{Frame, Grid, LabelVolume, Orientation};
use voxlod_io::{
    read_label_map, read_label_map_with, read_volume, write_label_map, Endian, IoError,
    IoErrorKind, RawLayout, RawType,
};

/// The maps' size: x fastest.
const DIMS: [usize; 3] = [3, 2, 2];

/// A stored sample type and its names in each format.
struct Type {
    /// NRRD's `type`.
    nrrd: &'static str,
    /// NIfTI-1's `datatype` code.
    nifti: i16,
    /// MetaImage's `ElementType`.
    meta: &'static str,
    /// VTK XML's `type`.
    vti: &'static str,
    /// Legacy VTK's type, when vtkio reads it.
    legacy: Option<&'static str>,
    /// Zarr v2's `dtype` without its byte order.
    zarr: &'static str,
    raw: RawType,
    /// The largest label the type holds exactly.
    max: u32,
}

const TYPES: [Type; 10] = [
    Type {
        nrrd: "uchar",
        nifti: 2,
        meta: "MET_UCHAR",
        vti: "UInt8",
        legacy: Some("unsigned_char"),
        zarr: "u1",
        raw: RawType::U8,
        max: 255,
    },
    Type {
        nrrd: "signed char",
        nifti: 256,
        meta: "MET_CHAR",
        vti: "Int8",
        legacy: Some("char"),
        zarr: "i1",
        raw: RawType::I8,
        max: 127,
    },
    Type {
        nrrd: "ushort",
        nifti: 512,
        meta: "MET_USHORT",
        vti: "UInt16",
        legacy: None,
        zarr: "u2",
        raw: RawType::U16,
        max: 65535,
    },
    Type {
        nrrd: "short",
        nifti: 4,
        meta: "MET_SHORT",
        vti: "Int16",
        legacy: Some("short"),
        zarr: "i2",
        raw: RawType::I16,
        max: 32767,
    },
    Type {
        nrrd: "uint",
        nifti: 768,
        meta: "MET_UINT",
        vti: "UInt32",
        legacy: Some("unsigned_int"),
        zarr: "u4",
        raw: RawType::U32,
        max: u32::MAX,
    },
    Type {
        nrrd: "int",
        nifti: 8,
        meta: "MET_INT",
        vti: "Int32",
        legacy: Some("int"),
        zarr: "i4",
        raw: RawType::I32,
        max: i32::MAX as u32,
    },
    Type {
        nrrd: "uint64",
        nifti: 1280,
        meta: "MET_ULONG_LONG",
        vti: "UInt64",
        legacy: Some("unsigned_long"),
        zarr: "u8",
        raw: RawType::U64,
        max: u32::MAX,
    },
    Type {
        nrrd: "int64",
        nifti: 1024,
        meta: "MET_LONG_LONG",
        vti: "Int64",
        legacy: Some("long"),
        zarr: "i8",
        raw: RawType::I64,
        max: u32::MAX,
    },
    // The largest f32 below 2³²: 2³² − 256.
    Type {
        nrrd: "float",
        nifti: 16,
        meta: "MET_FLOAT",
        vti: "Float32",
        legacy: Some("float"),
        zarr: "f4",
        raw: RawType::F32,
        max: 4294967040,
    },
    Type {
        nrrd: "double",
        nifti: 64,
        meta: "MET_DOUBLE",
        vti: "Float64",
        legacy: Some("double"),
        zarr: "f8",
        raw: RawType::F64,
        max: u32::MAX,
    },
];

impl Type {
    fn size(&self) -> usize {
        self.raw.size()
    }

    /// `v` stored as this type (negative and fractional values too, for the refusals).
    fn encode(&self, v: f64, big: bool) -> Vec<u8> {
        macro_rules! bytes {
            ($t:ty) => {
                if big {
                    (v as $t).to_be_bytes().to_vec()
                } else {
                    (v as $t).to_le_bytes().to_vec()
                }
            };
        }
        match self.raw {
            RawType::U8 => bytes!(u8),
            RawType::I8 => bytes!(i8),
            RawType::U16 => bytes!(u16),
            RawType::I16 => bytes!(i16),
            RawType::U32 => bytes!(u32),
            RawType::I32 => bytes!(i32),
            RawType::U64 => bytes!(u64),
            RawType::I64 => bytes!(i64),
            RawType::F32 => bytes!(f32),
            RawType::F64 => bytes!(f64),
        }
    }

    fn data(&self, values: &[f64], big: bool) -> Vec<u8> {
        values.iter().flat_map(|&v| self.encode(v, big)).collect()
    }

    /// A file-name friendly name.
    fn tag(&self) -> &'static str {
        self.raw.name()
    }
}

/// The labels of a type's test map: small ones, and its largest.
fn labels_for(t: &Type) -> Vec<u32> {
    let mut values: Vec<u32> = (0..11).map(|v| v * 7 % 12).collect();
    values.push(t.max);
    values
}

fn as_f64(labels: &[u32]) -> Vec<f64> {
    labels.iter().map(|&v| f64::from(v)).collect()
}

fn nrrd(dir: &Path, name: &str, t: &Type, values: &[f64], encoding: &str, dims: &str) -> PathBuf {
    let big = encoding == "raw";
    let mut bytes = format!(
        "NRRD0004\ntype: {}\ndimension: {}\nsizes: {dims}\nendian: {}\nencoding: {encoding}\nspacings: 0.5 0.5 2{}\n\n",
        t.nrrd,
        dims.split_whitespace().count(),
        if big { "big" } else { "little" },
        if dims.split_whitespace().count() > 3 { " 1" } else { "" },
    )
    .into_bytes();
    let data = t.data(values, big);
    match encoding {
        "raw" => bytes.extend(data),
        "gzip" => bytes.extend(gzip(&data)),
        _ => {
            let text: Vec<String> = values.iter().map(|v| v.to_string()).collect();
            bytes.extend(text.join(" ").into_bytes());
        }
    }
    write(dir, name, &bytes)
}

fn nifti(dir: &Path, name: &str, t: &Type, values: &[f64], dim: [i16; 8]) -> PathBuf {
    let mut bytes = common::nifti(dim, t.nifti, 8 * t.size() as i16);
    bytes.extend(t.data(values, false));
    if name.ends_with(".gz") {
        bytes = gzip(&bytes);
    }
    write(dir, name, &bytes)
}

fn metaimage(dir: &Path, name: &str, t: &Type, values: &[f64], compressed: bool) -> PathBuf {
    let data = t.data(values, true);
    let data = if compressed { zlib(&data) } else { data };
    let detached = name.ends_with(".mhd");
    let header = format!(
        "ObjectType = Image\nNDims = 3\nDimSize = 3 2 2\nElementType = {}\nBinaryDataByteOrderMSB = True\nCompressedData = {}\nElementDataFile = {}\n",
        t.meta,
        if compressed { "True" } else { "False" },
        if detached { "data.bin" } else { "LOCAL" }
    );
    if detached {
        write(dir, "data.bin", &data);
        write(dir, name, header.as_bytes())
    } else {
        write(dir, name, &[header.into_bytes(), data].concat())
    }
}

fn vti(dir: &Path, name: &str, t: &Type, values: &[f64]) -> PathBuf {
    let text: Vec<String> = values.iter().map(|v| v.to_string()).collect();
    let xml = format!(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"1.0\" byte_order=\"LittleEndian\">\
         <ImageData WholeExtent=\"0 2 0 1 0 1\" Origin=\"0 0 0\" Spacing=\"1 1 1\">\
         <Piece Extent=\"0 2 0 1 0 1\"><PointData Scalars=\"labels\">\
         <DataArray type=\"{}\" Name=\"labels\" format=\"ascii\">{}</DataArray>\
         </PointData><CellData></CellData></Piece></ImageData></VTKFile>\n",
        t.vti,
        text.join(" ")
    );
    write(dir, name, xml.as_bytes())
}

fn legacy(dir: &Path, name: &str, type_name: &str, t: &Type, values: &[f64]) -> PathBuf {
    let header = format!(
        "# vtk DataFile Version 3.0\nlabels\nBINARY\nDATASET STRUCTURED_POINTS\nDIMENSIONS 3 2 2\n\
         SPACING 1 1 1\nORIGIN 0 0 0\nPOINT_DATA 12\nSCALARS labels {type_name} 1\nLOOKUP_TABLE default\n"
    );
    let mut bytes = header.into_bytes();
    bytes.extend(t.data(values, true));
    bytes.push(b'\n');
    write(dir, name, &bytes)
}

/// A Zarr v2 array of shape (z, y, x) = (2, 2, 3) in two chunks of one plane each.
fn zarr(dir: &Path, name: &str, t: &Type, values: &[f64], shape: &[usize]) -> PathBuf {
    let store = dir.join(name);
    std::fs::create_dir_all(&store).unwrap();
    let order = if t.size() == 1 { "|" } else { "<" };
    let mut chunks: Vec<usize> = shape.iter().map(|&n| n.max(1)).collect();
    chunks[0] = 1;
    let meta = format!(
        "{{\"zarr_format\": 2, \"shape\": {shape:?}, \"chunks\": {chunks:?}, \"dtype\": \"{order}{}\", \
         \"compressor\": null, \"fill_value\": 0, \"order\": \"C\", \"filters\": null}}",
        t.zarr
    );
    write(&store, ".zarray", meta.as_bytes());
    let per_chunk: usize = chunks.iter().product();
    for (c, chunk) in values.chunks(per_chunk).enumerate() {
        let key: Vec<String> = std::iter::once(c.to_string())
            .chain(shape[1..].iter().map(|_| "0".to_string()))
            .collect();
        write(&store, &key.join("."), &t.data(chunk, false));
    }
    store
}

fn raw(dir: &Path, name: &str, t: &Type, values: &[f64], big: bool) -> (PathBuf, RawLayout) {
    let path = write(dir, name, &t.data(values, big));
    let endian = if big { Endian::Big } else { Endian::Little };
    (path, RawLayout::new(DIMS, t.raw, endian))
}

/// Every file of one type's map, in every format (with the layout raw files need).
fn files_for(dir: &Path, t: &Type, values: &[f64]) -> Vec<(PathBuf, Option<RawLayout>)> {
    let tag = t.tag();
    let mut files = vec![
        nrrd(dir, &format!("{tag}.nrrd"), t, values, "raw", "3 2 2"),
        nrrd(dir, &format!("{tag}-gz.nrrd"), t, values, "gzip", "3 2 2"),
        nrrd(
            dir,
            &format!("{tag}-ascii.nrrd"),
            t,
            values,
            "ascii",
            "3 2 2",
        ),
        nifti(
            dir,
            &format!("{tag}.nii"),
            t,
            values,
            [3, 3, 2, 2, 1, 1, 1, 1],
        ),
        nifti(
            dir,
            &format!("{tag}.nii.gz"),
            t,
            values,
            [3, 3, 2, 2, 1, 1, 1, 1],
        ),
        metaimage(dir, &format!("{tag}.mha"), t, values, false),
        metaimage(dir, &format!("{tag}-z.mha"), t, values, true),
        vti(dir, &format!("{tag}.vti"), t, values),
        zarr(dir, &format!("{tag}.zarr"), t, values, &[2, 2, 3]),
    ];
    if let Some(name) = t.legacy {
        files.push(legacy(dir, &format!("{tag}.vtk"), name, t, values));
    }
    let mut files: Vec<_> = files.into_iter().map(|p| (p, None)).collect();
    for big in [false, true] {
        let (path, layout) = raw(dir, &format!("{tag}-{big}.raw"), t, values, big);
        files.push((path, Some(layout)));
    }
    // A detached NRRD: its header names the data file of the attached one's twin.
    let data = write(dir, &format!("{tag}.data"), &t.data(values, false));
    let header = format!(
        "NRRD0004\ntype: {}\ndimension: 3\nsizes: 3 2 2\nendian: little\nencoding: raw\ndata file: {}\n",
        t.nrrd,
        data.file_name().unwrap().to_string_lossy()
    );
    files.push((write(dir, &format!("{tag}.nhdr"), header.as_bytes()), None));
    files
}

fn read(path: &Path, layout: Option<&RawLayout>) -> Result<LabelVolume, IoError> {
    read_label_map_with(path, layout).map(|m| m.labels)
}

#[test]
fn every_format_and_sample_type_gives_the_labels_as_stored() {
    let dir = tempfile::tempdir().unwrap();
    let mut read_files = 0;
    for t in &TYPES {
        let labels = labels_for(t);
        let folder = dir.path().join(t.tag());
        std::fs::create_dir(&folder).unwrap();
        for (path, layout) in files_for(&folder, t, &as_f64(&labels)) {
            let map =
                read(&path, layout.as_ref()).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            assert_eq!(map.grid.dims, DIMS, "{}", path.display());
            assert_eq!(map.values, labels, "{}", path.display());
            read_files += 1;
        }
    }
    // 12 files a type, and the legacy VTK file of the nine types vtkio reads.
    assert_eq!(read_files, 10 * 12 + 9);
}

#[test]
fn a_uint32_nrrd_keeps_labels_beyond_what_f32_holds() {
    let dir = tempfile::tempdir().unwrap();
    let t = &TYPES[4];
    let labels = [
        0,
        1,
        (1 << 24) + 1,
        u32::MAX,
        16777217,
        3,
        123456789,
        4,
        5,
        6,
        7,
        8,
    ];
    let path = nrrd(dir.path(), "big.nrrd", t, &as_f64(&labels), "raw", "3 2 2");
    let map = read_label_map(&path).unwrap();
    assert_eq!(map.labels.values, labels);
    assert_eq!(map.labels.grid.spacing, [0.5, 0.5, 2.0]);
    // As a volume the same file rounds 2²⁴+1 to 2²⁴: why label maps have their own reader.
    let volume = read_volume(&path, None).unwrap();
    assert_eq!(volume.as_slice()[2], 16777216.0);
}

/// A map on an oblique grid, with labels at the edges of what `u32` holds.
fn oblique_map(frame: Frame) -> LabelVolume {
    let grid = Grid::new([4, 3, 2], [0.5, 0.75, 2.0], [10.0, -20.0, 30.0]).unwrap();
    let mut values: Vec<u32> = (0..24).map(|v| v * 1000).collect();
    values[0] = 0;
    values[1] = 1;
    values[5] = (1 << 24) + 1;
    values[23] = u32::MAX;
    let turn = DMat3::from_rotation_z(0.3) * DMat3::from_rotation_x(-0.2);
    let orientation = Orientation {
        direction: turn,
        frame,
    };
    LabelVolume::from_vec(grid, values)
        .unwrap()
        .oriented(orientation)
}

#[test]
fn written_label_maps_read_back_exactly_with_their_geometry() {
    let dir = tempfile::tempdir().unwrap();
    for (name, frame) in [
        ("m.nrrd", Frame::Lps),
        ("m.nrrd", Frame::Ras),
        ("m.nii", Frame::Ras),
        ("m.nii.gz", Frame::Lps),
    ] {
        let map = oblique_map(frame);
        let path = dir.path().join(name);
        write_label_map(&path, &map).unwrap();
        let back = read_label_map(&path).unwrap().labels;
        assert_eq!(back.values, map.values, "{name}");
        assert_eq!(back.grid.dims, map.grid.dims);
        // The same index-to-world transform, in whichever frame the format keeps.
        let (a, b) = (map.world(), back.world().in_frame(frame));
        for corner in [DVec3::ZERO, DVec3::new(3.0, 2.0, 1.0), DVec3::X, DVec3::Z] {
            let d = a.index_to_world(corner) - b.index_to_world(corner);
            assert!(d.length() < 1e-4, "{name} {frame:?}: {d}");
        }
    }
    // Only NRRD and NIfTI are written; nothing is left behind by a refusal.
    let e = write_label_map(&dir.path().join("m.mha"), &oblique_map(Frame::Lps)).unwrap_err();
    assert_eq!(e.kind, IoErrorKind::Unsupported);
    assert!(!dir.path().join("m.mha").exists());
}

/// Asserts a refusal naming the file, with `needle` in its message.
fn refused(result: Result<LabelVolume, IoError>, path: &Path, kind: IoErrorKind, needle: &str) {
    let err = common::assert_error(result, kind, path);
    assert!(err.message.contains(needle), "{needle}: {err}");
}

#[test]
fn values_that_are_not_labels_are_named_with_their_voxel() {
    let dir = tempfile::tempdir().unwrap();
    // Voxel (2, 0, 1) of the 3x2x2 map is index 8.
    let at = |v: f64| {
        let mut values = vec![1.0; 12];
        values[8] = v;
        values
    };
    let words = "labels are whole numbers from 0 to 4294967295";
    let by_type = |name: &str| TYPES.iter().find(|t| t.tag() == name).unwrap();
    let cases: Vec<(&str, f64, &str)> = vec![
        ("i16", -3.0, "-3"),
        ("i8", -128.0, "-128"),
        ("i32", -2147483648.0, "-2147483648"),
        ("i64", -1.0, "-1"),
        ("i64", 4294967296.0, "4294967296"),
        ("u64", 4294967301.0, "4294967301"),
        ("f32", 2.5, "2.5"),
        ("f32", -0.5, "-0.5"),
        ("f64", 4294967296.0, "4294967296"),
        ("f64", f64::NAN, "NaN"),
        ("f32", f64::INFINITY, "inf"),
    ];
    for (tag, value, shown) in cases {
        let t = by_type(tag);
        let folder = dir.path().join(format!("{tag}-{shown}"));
        std::fs::create_dir(&folder).unwrap();
        let needle = format!("label {shown} at (2, 0, 1): {words}");
        for (path, layout) in files_for(&folder, t, &at(value)) {
            let name = path.to_string_lossy();
            // Text formats cannot spell NaN and infinity as numbers VTK or NRRD read.
            if !value.is_finite() && (name.ends_with(".vti") || name.contains("ascii")) {
                continue;
            }
            let result = read(&path, layout.as_ref());
            // A detached header's error names the data file, which holds the voxel.
            let named = if name.ends_with(".nhdr") {
                path.with_extension("data")
            } else {
                path.clone()
            };
            refused(result, &named, IoErrorKind::Malformed, &needle);
        }
    }
}

#[test]
fn scaled_nifti_labels_are_kept_only_when_whole() {
    let dir = tempfile::tempdir().unwrap();
    let t = &TYPES[2];
    let scaled = |name: &str, slope: f32, inter: f32| {
        let mut bytes = common::nifti([3, 3, 2, 2, 1, 1, 1, 1], t.nifti, 16);
        bytes[112..116].copy_from_slice(&slope.to_le_bytes());
        bytes[116..120].copy_from_slice(&inter.to_le_bytes());
        bytes.extend(t.data(&as_f64(&[0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 65535]), false));
        write(dir.path(), name, &bytes)
    };
    // Slope 2, intercept 1: every stored value becomes 2v + 1, exactly.
    let path = scaled("double.nii", 2.0, 1.0);
    let map = read_label_map(&path).unwrap().labels;
    assert_eq!(map.values[..3], [1, 3, 5]);
    assert_eq!(map.values[11], 131071);
    // Slope 0.5: stored 1 becomes 0.5, which is no label.
    let path = scaled("half.nii", 0.5, 0.0);
    refused(
        read_label_map(&path).map(|m| m.labels),
        &path,
        IoErrorKind::Malformed,
        "label 0.5 (stored 1, scaled by scl_slope 0.5 and scl_inter 0) at (1, 0, 0)",
    );
    // A zero slope means unscaled.
    let path = scaled("plain.nii", 0.0, 7.0);
    assert_eq!(read_label_map(&path).unwrap().labels.values[11], 65535);
}

#[test]
fn four_dimensional_and_empty_maps_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let t = &TYPES[4];
    let values = vec![1.0; 36];
    let p = nrrd(dir.path(), "t.nrrd", t, &values, "raw", "3 2 2 3");
    refused(
        read(&p, None),
        &p,
        IoErrorKind::Unsupported,
        "axis 4 holds 3 values",
    );
    let p = nifti(dir.path(), "t.nii", t, &values, [4, 3, 2, 2, 3, 1, 1, 1]);
    refused(
        read(&p, None),
        &p,
        IoErrorKind::Unsupported,
        "axis 4 holds 3",
    );
    let header = "NDims = 4\nDimSize = 3 2 2 3\nElementType = MET_UINT\nElementDataFile = LOCAL\n";
    let p = write(
        dir.path(),
        "t.mha",
        &[header.as_bytes(), &t.data(&values, true)].concat(),
    );
    refused(
        read(&p, None),
        &p,
        IoErrorKind::Unsupported,
        "axis 4 holds 3 values",
    );
    let p = zarr(dir.path(), "t.zarr", t, &values, &[3, 2, 2, 3]);
    refused(
        read(&p, None),
        &p,
        IoErrorKind::Unsupported,
        "axis 0 holds 3 values",
    );
    // A fourth axis of one value is a 3-D map in NIfTI, as a volume is.
    let p = nifti(
        dir.path(),
        "one.nii",
        t,
        &values[..12],
        [4, 3, 2, 2, 1, 1, 1, 1],
    );
    assert_eq!(read(&p, None).unwrap().grid.dims, DIMS);

    // Empty: a zero size.
    let p = nrrd(dir.path(), "e.nrrd", t, &[], "raw", "3 0 2");
    refused(read(&p, None), &p, IoErrorKind::Malformed, "include a zero");
    let p = nifti(dir.path(), "e.nii", t, &[], [3, 3, 0, 2, 1, 1, 1, 1]);
    refused(read(&p, None), &p, IoErrorKind::Malformed, "at least 1");
    let header = "NDims = 3\nDimSize = 3 0 2\nElementType = MET_UINT\nElementDataFile = LOCAL\n";
    let p = write(dir.path(), "e.mha", header.as_bytes());
    refused(read(&p, None), &p, IoErrorKind::Malformed, "include a zero");
    let p = write(dir.path(), "e.raw", &[0; 4]);
    let layout = RawLayout::new([3, 0, 2], RawType::U32, Endian::Little);
    refused(
        read(&p, Some(&layout)),
        &p,
        IoErrorKind::Malformed,
        "include a zero",
    );
    let p = zarr(dir.path(), "e.zarr", t, &[], &[2, 0, 3]);
    refused(read(&p, None), &p, IoErrorKind::Malformed, "include a zero");
}

#[test]
fn absurd_header_sizes_meet_the_memory_budget_before_allocating() {
    let dir = tempfile::tempdir().unwrap();
    let t = &TYPES[4];
    let size = "100000 100000 100000";
    let p = nrrd(dir.path(), "huge.nrrd", t, &[1.0], "raw", size);
    refused(
        read(&p, None),
        &p,
        IoErrorKind::TooLarge,
        "100000x100000x100000 uint32 label map",
    );
    let p = nrrd(dir.path(), "huge-gz.nrrd", t, &[1.0], "gzip", size);
    refused(read(&p, None), &p, IoErrorKind::TooLarge, "label map");
    let header =
        format!("NDims = 3\nDimSize = {size}\nElementType = MET_UINT\nElementDataFile = LOCAL\n");
    let p = write(dir.path(), "huge.mha", header.as_bytes());
    refused(
        read(&p, None),
        &p,
        IoErrorKind::TooLarge,
        "uint32 label map",
    );
    let p = nifti(
        dir.path(),
        "huge.nii",
        t,
        &[1.0],
        [3, 32767, 32767, 32767, 1, 1, 1, 1],
    );
    refused(
        read(&p, None),
        &p,
        IoErrorKind::TooLarge,
        "32767x32767x32767 uint32 label map",
    );
    let p = write(dir.path(), "huge.raw", &[0; 4]);
    let layout = RawLayout::new([100000; 3], RawType::U32, Endian::Little);
    refused(
        read(&p, Some(&layout)),
        &p,
        IoErrorKind::TooLarge,
        "label map",
    );
    // Zarr meets the budget twice: for one decoded chunk when the array is opened, then for the
    // map; this chunk (a plane of 10⁵ x 10⁵) is refused first.
    let p = zarr(
        dir.path(),
        "huge.zarr",
        t,
        &[1.0],
        &[100000, 100000, 100000],
    );
    refused(read(&p, None), &p, IoErrorKind::TooLarge, "100000x100000");
}

/// nibabel (an independent writer) makes a uint32 NIfTI with labels above 2²⁴ and an oblique
/// affine: every label and the affine come back.
#[test]
fn a_uint32_map_written_by_nibabel_is_read_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("nib.nii.gz");
    let script = r#"
import sys
import numpy as np
import nibabel as nib
shape = (5, 4, 3)
n = np.arange(np.prod(shape), dtype=np.uint64)
labels = ((n * 2654435761 + 16777217) % 4294967296).astype(np.uint32)
labels[0] = 4294967295
data = labels.reshape(shape, order="F")
affine = np.array([[0.0, -0.8, 0.0, 10.0], [0.9, 0.0, 0.0, -5.0], [0.0, 0.0, 1.5, 7.0], [0, 0, 0, 1]])
image = nib.Nifti1Image(data, affine)
image.set_data_dtype(np.uint32)
nib.save(image, sys.argv[1])
back = nib.load(sys.argv[1])
print(back.get_data_dtype(), int(np.asarray(back.dataobj).astype(np.uint64).sum()))
"#;
    let Some(out) = voxlod_testkit::peers::run_python(script, &[path.as_os_str()]) else {
        return;
    };
    let fields: Vec<&str> = out.split_whitespace().collect();
    assert_eq!(fields[0], "uint32", "{out}");
    let map = read_label_map(&path).unwrap().labels;
    assert_eq!(map.grid.dims, [5, 4, 3]);
    let expected: Vec<u32> = (0..60u64)
        .map(|n| ((n * 2654435761 + 16777217) % 4294967296) as u32)
        .enumerate()
        .map(|(i, v)| if i == 0 { u32::MAX } else { v })
        .collect();
    assert_eq!(map.values, expected);
    assert!(expected.iter().filter(|&&v| v > 1 << 24).count() > 50);
    let sum: u64 = map.values.iter().map(|&v| u64::from(v)).sum();
    assert_eq!(sum.to_string(), fields[1]);
    // The affine: columns (0, 0.9, 0), (-0.8, 0, 0), (0, 0, 1.5), origin (10, -5, 7), in RAS.
    let world = map.world();
    assert_eq!(world.frame, Frame::Ras);
    let at = |i: f64, j: f64, k: f64| world.index_to_world(DVec3::new(i, j, k));
    assert!((at(0.0, 0.0, 0.0) - DVec3::new(10.0, -5.0, 7.0)).length() < 1e-5);
    assert!((at(1.0, 0.0, 0.0) - DVec3::new(10.0, -4.1, 7.0)).length() < 1e-5);
    assert!((at(0.0, 1.0, 0.0) - DVec3::new(9.2, -5.0, 7.0)).length() < 1e-5);
    assert!((at(0.0, 0.0, 1.0) - DVec3::new(10.0, -5.0, 8.5)).length() < 1e-5);

    // And back: the map written by voxlod is uint32 to nibabel, with the same labels and affine.
    let ours = dir.path().join("ours.nii.gz");
    write_label_map(&ours, &map).unwrap();
    let check = r#"
import sys
import numpy as np
import nibabel as nib
image = nib.load(sys.argv[1])
data = np.asarray(image.dataobj)
print(image.get_data_dtype(), int(data.astype(np.uint64).sum()), int(data[0, 0, 0]), int(data[4, 3, 2]))
print(" ".join("%.4f" % v for v in image.affine[:3].ravel()))
"#;
    let Some(out) = voxlod_testkit::peers::run_python(check, &[ours.as_os_str()]) else {
        return;
    };
    let lines: Vec<&str> = out.lines().collect();
    let last = u64::from(map.values[59]);
    assert_eq!(lines[0], format!("uint32 {sum} 4294967295 {last}"), "{out}");
    assert_eq!(
        lines[1],
        "0.0000 -0.8000 0.0000 10.0000 0.9000 0.0000 0.0000 -5.0000 0.0000 0.0000 1.5000 7.0000"
    );
}
