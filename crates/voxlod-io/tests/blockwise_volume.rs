//! Volumes read window by window (`open_volume_blockwise`): every window of a raw file, a NRRD with
//! raw encoding (attached, detached, `line skip`, `byte skip: -1`) and a MetaImage (`.mha`,
//! `.mhd` with `HeaderSize`) holds exactly the samples of the volume read whole, with its grid
//! and orientation; compressed data is left to the whole read; short files and layouts that do
//! not fit are clean errors naming the file.

use std::path::{Path, PathBuf};

use voxlod_core::{Grid, Volume};
use voxlod_io::{
    open_volume_blockwise, read_volume, write_volume, write_volume_with, BlockwiseVolume, Endian,
    IoErrorKind, RawLayout, RawType, VolumeWriteOptions,
};
use voxlod_testkit::data::shared_data_or_skip;
use voxlod_testkit::volumes::window;

/// Odd dimensions, so that no window lines up with anything.
const DIMS: [usize; 3] = [13, 11, 7];

/// Distinct small integers (they survive every sample type exactly), as `i16`.
fn samples() -> Vec<i16> {
    (0..DIMS.iter().product::<usize>() as i32)
        .map(|i| ((i * 37) % 251 - 100) as i16)
        .collect()
}

fn as_volume(values: &[i16], spacing: [f64; 3], origin: [f64; 3]) -> Volume {
    let grid = Grid::new(DIMS, spacing, origin).unwrap();
    Volume::from_vec(grid, values.iter().map(|&v| v as f32).collect()).unwrap()
}

/// Every window of a few shapes, and the whole, equal the volume read whole.
fn check_windows(path: &Path, raw: Option<&RawLayout>) -> BlockwiseVolume {
    let whole = read_volume(path, raw).unwrap_or_else(|e| panic!("{e}"));
    let scan = open_volume_blockwise(path, raw)
        .unwrap_or_else(|e| panic!("{e}"))
        .unwrap_or_else(|| panic!("{} is not read in windows", path.display()));
    assert_eq!(scan.grid(), whole.grid, "{}", path.display());
    assert_eq!(scan.orientation(), whole.orientation, "{}", path.display());
    let all = scan.read_all().unwrap();
    assert_eq!(all.as_slice(), whole.as_slice(), "{}", path.display());
    let d = scan.grid().dims;
    for (start, extent) in [
        ([0, 0, 0], [1, 1, 1]),
        ([d[0] - 1, d[1] - 1, d[2] - 1], [1, 1, 1]),
        ([2, 3, 1], [5, 4, 3]),
        ([0, 1, 2], [d[0], d[1] - 1, d[2] - 2]),
        ([d[0] / 2, 0, 0], [d[0] - d[0] / 2, d[1], 1]),
    ] {
        let got = scan.read_window(start, extent).unwrap();
        let want = window(&whole, start, extent);
        assert_eq!(got.grid, want.grid, "{} {start:?}", path.display());
        assert_eq!(
            got.as_slice(),
            want.as_slice(),
            "{} {start:?}",
            path.display()
        );
    }
    scan
}

fn write(path: &Path, bytes: &[u8]) -> PathBuf {
    std::fs::write(path, bytes).unwrap();
    path.to_path_buf()
}

#[test]
fn raw_files_of_every_type_and_byte_order() {
    let dir = tempfile::tempdir().unwrap();
    let values = samples();
    for (dtype, endian) in [
        (RawType::U8, Endian::Little),
        (RawType::I16, Endian::Little),
        (RawType::I16, Endian::Big),
        (RawType::U16, Endian::Big),
        (RawType::I32, Endian::Little),
        (RawType::F32, Endian::Big),
        (RawType::I8, Endian::Little),
        (RawType::U32, Endian::Big),
        (RawType::I64, Endian::Little),
        (RawType::U64, Endian::Big),
        (RawType::F64, Endian::Little),
    ] {
        let bytes: Vec<u8> = values
            .iter()
            .flat_map(|&v| match (dtype, endian) {
                (RawType::U8, _) => vec![(v + 100) as u8],
                (RawType::I16, Endian::Little) => v.to_le_bytes().to_vec(),
                (RawType::I16, Endian::Big) => v.to_be_bytes().to_vec(),
                (RawType::U16, _) => ((v + 100) as u16).to_be_bytes().to_vec(),
                (RawType::I32, _) => (v as i32 * 1000).to_le_bytes().to_vec(),
                (RawType::F32, _) => (v as f32 * 0.25).to_be_bytes().to_vec(),
                (RawType::I8, _) => vec![(v / 4) as i8 as u8],
                (RawType::U32, _) => ((v as i32 + 100) as u32).to_be_bytes().to_vec(),
                (RawType::I64, _) => (v as i64 * 3).to_le_bytes().to_vec(),
                (RawType::U64, _) => ((v as i64 + 100) as u64).to_be_bytes().to_vec(),
                (RawType::F64, _) => (v as f64 * 0.5).to_le_bytes().to_vec(),
            })
            .collect();
        let header = vec![7u8; 5];
        let path = write(
            &dir.path().join(format!("{dtype}-{endian}.raw")),
            &[header, bytes].concat(),
        );
        let mut layout = RawLayout::new(DIMS, dtype, endian);
        layout.header_bytes = 5;
        layout.spacing = [0.5, 0.75, 2.0];
        layout.origin = [-3.0, 1.5, 10.0];
        let scan = check_windows(&path, Some(&layout));
        assert_eq!(scan.data_offset(), 5);
    }
}

#[test]
fn nrrd_attached_detached_and_skipped() {
    let dir = tempfile::tempdir().unwrap();
    let values = samples();
    let volume = as_volume(&values, [0.5, 0.5, 1.25], [4.0, -2.0, 0.5]);
    // The writer's own files: float, little-endian, attached and detached.
    for name in ["written.nrrd", "written.nhdr"] {
        let path = dir.path().join(name);
        write_volume(&path, &volume).unwrap();
        check_windows(&path, None);
    }
    let be: Vec<u8> = values.iter().flat_map(|v| v.to_be_bytes()).collect();
    let fields = "type: short\ndimension: 3\nsizes: 13 11 7\nendian: big\nencoding: raw\n\
                  space: left-posterior-superior\n\
                  space directions: (0,0.5,0) (-0.5,0,0) (0,0,1.5)\nspace origin: (1,2,3)\n";
    // Attached after the blank line; after two skipped lines; at the end of the file.
    let attached = format!("NRRD0004\n{fields}\n");
    let path = write(
        &dir.path().join("attached.nrrd"),
        &[attached.as_bytes(), &be].concat(),
    );
    let scan = check_windows(&path, None);
    assert_eq!(scan.data_offset(), attached.len() as u64);
    let skipped = format!("NRRD0004\n{fields}line skip: 2\n\nfirst\nsecond line\n");
    let path = write(
        &dir.path().join("skipped.nrrd"),
        &[skipped.as_bytes(), &be].concat(),
    );
    check_windows(&path, None);
    let at_end = format!("NRRD0004\n{fields}byte skip: -1\n\n");
    let path = write(
        &dir.path().join("at-end.nrrd"),
        &[at_end.as_bytes(), b"junk before the data", &be].concat(),
    );
    check_windows(&path, None);
    // Detached, with a byte skip into its data file.
    write(&dir.path().join("data.bin"), &[&[0u8; 3][..], &be].concat());
    let detached = format!("NRRD0004\n{fields}byte skip: 3\ndata file: data.bin\n");
    let path = write(&dir.path().join("detached.nhdr"), detached.as_bytes());
    let scan = check_windows(&path, None);
    assert_eq!(scan.path(), dir.path().join("data.bin"));
    assert_eq!(scan.data_offset(), 3);
}

#[test]
fn metaimage_local_and_detached() {
    let dir = tempfile::tempdir().unwrap();
    let values = samples();
    let volume = as_volume(&values, [1.0, 2.0, 0.5], [0.0, 0.0, -7.0]);
    for name in ["written.mha", "written.mhd"] {
        let path = dir.path().join(name);
        write_volume(&path, &volume).unwrap();
        check_windows(&path, None);
    }
    let le: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    write(&dir.path().join("ct.raw"), &[&[1u8; 16][..], &le].concat());
    let header = "ObjectType = Image\nNDims = 3\nDimSize = 13 11 7\nElementType = MET_SHORT\n\
                  ElementSpacing = 0.5 0.5 2\nOffset = 1 2 3\nTransformMatrix = 0 1 0 1 0 0 0 0 1\n\
                  HeaderSize = 16\nElementDataFile = ct.raw\n";
    let path = write(&dir.path().join("ct.mhd"), header.as_bytes());
    check_windows(&path, None);
    let at_end = header.replace("HeaderSize = 16", "HeaderSize = -1");
    let path = write(&dir.path().join("end.mhd"), at_end.as_bytes());
    let scan = check_windows(&path, None);
    assert_eq!(scan.data_offset(), 16);
}

#[test]
fn compressed_data_and_other_files_are_left_to_the_whole_read() {
    let dir = tempfile::tempdir().unwrap();
    let volume = as_volume(&samples(), [1.0; 3], [0.0; 3]);
    let compress = VolumeWriteOptions { compress: true };
    for name in ["gz.nrrd", "gz.nhdr", "z.mha", "z.mhd", "v.vti", "v.nii"] {
        let path = dir.path().join(name);
        write_volume_with(&path, &volume, &compress).unwrap();
        assert!(
            open_volume_blockwise(&path, None).unwrap().is_none(),
            "{name}"
        );
    }
    let text = "NRRD0004\ntype: short\ndimension: 1\nsizes: 3\nencoding: ascii\n\n1 2 3\n";
    let path = write(&dir.path().join("ascii.nrrd"), text.as_bytes());
    assert!(open_volume_blockwise(&path, None).unwrap().is_none());
    let mesh = write(&dir.path().join("m.obj"), b"v 0 0 0\n");
    assert!(open_volume_blockwise(&mesh, None).unwrap().is_none());
    // A raw file needs its layout.
    let raw = write(&dir.path().join("r.raw"), &[0u8; 8]);
    assert!(open_volume_blockwise(&raw, None).unwrap().is_none());
}

#[test]
fn short_files_and_layouts_that_do_not_fit_name_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let be: Vec<u8> = samples().iter().flat_map(|v| v.to_be_bytes()).collect();
    let fields = "type: short\ndimension: 3\nsizes: 13 11 7\nendian: big\nencoding: raw\n";
    // An attached NRRD cut short, a detached one whose data file is short.
    let cut = format!("NRRD0004\n{fields}\n");
    let path = write(
        &dir.path().join("cut.nrrd"),
        &[cut.as_bytes(), &be[..be.len() - 1]].concat(),
    );
    let err = open_volume_blockwise(&path, None).unwrap_err();
    assert_eq!(err.kind, IoErrorKind::Truncated, "{err}");
    assert!(err.to_string().contains("cut.nrrd"), "{err}");
    write(&dir.path().join("short.bin"), &be[..100]);
    let detached = format!("NRRD0004\n{fields}data file: short.bin\n");
    let path = write(&dir.path().join("short.nhdr"), detached.as_bytes());
    let err = open_volume_blockwise(&path, None).unwrap_err();
    assert_eq!(err.kind, IoErrorKind::Truncated, "{err}");
    assert!(err.to_string().contains("short.bin"), "{err}");
    assert!(err.message.contains("2002 bytes"), "{err}");
    let missing = format!("NRRD0004\n{fields}data file: nowhere.bin\n");
    let path = write(&dir.path().join("missing.nhdr"), missing.as_bytes());
    let err = open_volume_blockwise(&path, None).unwrap_err();
    assert_eq!(err.kind, IoErrorKind::Access, "{err}");
    assert!(err.to_string().contains("nowhere.bin"), "{err}");
    // A raw layout that does not match the file's size: the whole read's message and hints.
    let raw = write(&dir.path().join("ct.raw"), &be);
    let layout = RawLayout::new([13, 11, 8], RawType::I16, Endian::Big);
    let err = open_volume_blockwise(&raw, Some(&layout)).unwrap_err();
    assert_eq!(err.kind, IoErrorKind::SizeMismatch, "{err}");
    assert!(err.message.contains("dims 13 11 7"), "{err}");
    // Absurd sizes in a header: refused before anything of that size is allocated.
    let huge =
        "NRRD0004\ntype: short\ndimension: 3\nsizes: 100000 100000 100000\nencoding: raw\n\n";
    let path = write(&dir.path().join("huge.nrrd"), huge.as_bytes());
    let err = open_volume_blockwise(&path, None).unwrap_err();
    assert_eq!(err.kind, IoErrorKind::Truncated, "{err}");
    // A window beyond the volume is refused.
    let layout = RawLayout::new([13, 11, 7], RawType::I16, Endian::Big);
    let scan = open_volume_blockwise(&raw, Some(&layout)).unwrap().unwrap();
    let err = scan.read_window([0, 0, 0], [13, 11, 8]).unwrap_err();
    assert!(err.message.contains("not inside"), "{err}");
}

#[test]
fn the_shared_tooth_and_ct_head_read_in_windows_as_whole() {
    if let Some(path) =
        shared_data_or_skip("volumes/tooth_103x94x161_uint8.nrrd", "tooth blockwise")
    {
        check_windows(&path, None);
    }
    let head = "volumes/CThead_256x256x113_uint16be.raw";
    if let Some(path) = shared_data_or_skip(head, "CT head blockwise") {
        let mut layout = RawLayout::new([256, 256, 113], RawType::U16, Endian::Big);
        layout.spacing = [1.0, 1.0, 2.0];
        check_windows(&path, Some(&layout));
    }
}
