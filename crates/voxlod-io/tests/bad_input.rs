//! Broken, hostile and unexpected input: every failure is an error of the right kind whose
//! one-line message names the file; nothing panics; failed writes leave nothing behind.

mod common;

use std::path::Path;

use common::{assert_error, cube, entries, small_volume, write};
use voxlod_core::{Attribute, PolyMesh, TriangleMesh};
use voxlod_io::{
    file_kind, mesh_format_of, read_mesh, read_poly_mesh, read_volume, volume_format_of,
    write_mesh, write_poly_mesh, write_volume, Endian, FileKind, IoErrorKind, MeshFormat,
    RawLayout, RawType, VolumeFormat,
};

#[test]
fn empty_files() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["e.obj", "e.ply", "e.stl", "e.off", "e.vtp", "e.vtk"] {
        let path = write(dir.path(), name, b"");
        assert_error(read_mesh(&path), IoErrorKind::Empty, &path);
    }
    for name in ["e.nrrd", "e.nii.gz", "e.mha", "e.vti"] {
        let path = write(dir.path(), name, b"");
        assert_error(read_volume(&path, None), IoErrorKind::Empty, &path);
    }
}

#[test]
fn missing_files_and_unknown_extensions() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("nowhere.obj");
    let err = assert_error(read_mesh(&missing), IoErrorKind::Access, &missing);
    assert!(err.message.contains("cannot open"), "{err}");
    let missing = dir.path().join("nowhere.nrrd");
    assert_error(read_volume(&missing, None), IoErrorKind::Access, &missing);

    let odd = write(dir.path(), "model.xyz", b"1 2 3\n");
    assert_error(read_mesh(&odd), IoErrorKind::Unsupported, &odd);
    assert_error(read_volume(&odd, None), IoErrorKind::Unsupported, &odd);
    assert_error(mesh_format_of(&odd), IoErrorKind::Unsupported, &odd);
    assert_error(file_kind(&odd), IoErrorKind::Unsupported, &odd);
    let bare = dir.path().join("noextension");
    assert_error(mesh_format_of(&bare), IoErrorKind::Unsupported, &bare);
    let raw = write(dir.path(), "data.raw", &[0; 8]);
    let err = assert_error(read_volume(&raw, None), IoErrorKind::Unsupported, &raw);
    assert!(err.message.contains("layout"), "{err}");
}

#[test]
fn formats_by_extension_and_content() {
    let dir = tempfile::tempdir().unwrap();
    assert_eq!(mesh_format_of(Path::new("A.OBJ")).unwrap(), MeshFormat::Obj);
    assert_eq!(
        volume_format_of(Path::new("brain.NII.GZ")).unwrap(),
        VolumeFormat::Nifti
    );
    assert_eq!(
        volume_format_of(Path::new("x.mhd")).unwrap(),
        VolumeFormat::Mhd
    );
    assert!(volume_format_of(Path::new("x.obj")).is_err());
    assert_eq!(
        file_kind(Path::new("a.stl")).unwrap(),
        FileKind::Mesh(MeshFormat::Stl)
    );
    assert_eq!(
        file_kind(Path::new("a.nhdr")).unwrap(),
        FileKind::Volume(VolumeFormat::Nhdr)
    );
    let mesh_vtk = dir.path().join("m.vtk");
    write_mesh(&mesh_vtk, &cube()).unwrap();
    assert_eq!(
        file_kind(&mesh_vtk).unwrap(),
        FileKind::Mesh(MeshFormat::Vtk)
    );
    let image_vtk = dir.path().join("i.vtk");
    write_volume(&image_vtk, &small_volume()).unwrap();
    assert_eq!(
        file_kind(&image_vtk).unwrap(),
        FileKind::Volume(VolumeFormat::Vtk)
    );
    // And each reader says what the other kind of .vtk holds.
    assert_error(read_mesh(&image_vtk), IoErrorKind::Unsupported, &image_vtk);
    assert_error(
        read_volume(&mesh_vtk, None),
        IoErrorKind::Unsupported,
        &mesh_vtk,
    );
}

#[test]
fn truncated_binary_ply_stl_and_nrrd() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["t.ply", "t.stl"] {
        let path = dir.path().join(name);
        write_mesh(&path, &cube()).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        std::fs::write(&path, &bytes[..bytes.len() - 30]).unwrap();
        let err = assert_error(read_mesh(&path), IoErrorKind::Truncated, &path);
        if name.ends_with("stl") {
            assert!(err.message.contains("12 triangles"), "{err}");
        }
    }
    let path = dir.path().join("t.nrrd");
    write_volume(&path, &small_volume()).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    std::fs::write(&path, &bytes[..bytes.len() - 7]).unwrap();
    let err = assert_error(read_volume(&path, None), IoErrorKind::Truncated, &path);
    assert!(
        err.message.contains("expected 240 bytes, found 233"),
        "{err}"
    );
}

#[test]
fn truncated_compressed_and_detached_volumes() {
    let dir = tempfile::tempdir().unwrap();
    let options = voxlod_io::VolumeWriteOptions { compress: true };
    for name in ["z.nrrd", "z.mha"] {
        let path = dir.path().join(name);
        voxlod_io::write_volume_with(&path, &small_volume(), &options).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        std::fs::write(&path, &bytes[..bytes.len() - 40]).unwrap();
        let err = read_volume(&path, None).unwrap_err();
        assert!(
            matches!(err.kind, IoErrorKind::Truncated | IoErrorKind::Malformed),
            "{err}"
        );
        assert!(err.to_string().contains(name), "{err}");
    }
    // A detached header whose data file lost its end names the data file.
    let header = dir.path().join("d.nhdr");
    write_volume(&header, &small_volume()).unwrap();
    let data = dir.path().join("d.raw");
    let bytes = std::fs::read(&data).unwrap();
    std::fs::write(&data, &bytes[..100]).unwrap();
    let err = assert_error(read_volume(&header, None), IoErrorKind::Truncated, &data);
    assert!(
        err.message.contains("expected 240 bytes, found 100"),
        "{err}"
    );
    std::fs::remove_file(&data).unwrap();
    assert_error(read_volume(&header, None), IoErrorKind::Access, &data);
}

#[test]
fn a_truncated_mha_names_expected_and_found_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.mha");
    write_volume(&path, &small_volume()).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    std::fs::write(&path, &bytes[..bytes.len() - 4]).unwrap();
    let err = assert_error(read_volume(&path, None), IoErrorKind::Truncated, &path);
    assert!(
        err.message.contains("expected 240 bytes, found 236"),
        "{err}"
    );
}

#[test]
fn nan_coordinates_name_the_vertex() {
    let dir = tempfile::tempdir().unwrap();
    let obj = write(
        dir.path(),
        "nan.obj",
        b"v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n",
    );
    let err = assert_error(read_mesh(&obj), IoErrorKind::NonFinite, &obj);
    assert!(err.message.contains("vertex 2"), "{err}");

    let off = write(
        dir.path(),
        "inf.off",
        b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 inf 0\n3 0 1 2\n",
    );
    let err = assert_error(read_mesh(&off), IoErrorKind::NonFinite, &off);
    assert!(err.message.contains("vertex 2"), "{err}");

    // Binary PLY and STL: write a good file, then poison one coordinate in place.
    let ply = dir.path().join("nan.ply");
    write_mesh(&ply, &TriangleMesh::new(cube().positions, cube().triangles)).unwrap();
    let mut bytes = std::fs::read(&ply).unwrap();
    let data = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .unwrap()
        + 11;
    let at = data + 5 * 12 + 4; // y of vertex 5
    bytes[at..at + 4].copy_from_slice(&f32::NAN.to_le_bytes());
    std::fs::write(&ply, &bytes).unwrap();
    let err = assert_error(read_mesh(&ply), IoErrorKind::NonFinite, &ply);
    assert!(err.message.contains("vertex 5"), "{err}");

    let stl = dir.path().join("nan.stl");
    write_mesh(&stl, &cube()).unwrap();
    let mut bytes = std::fs::read(&stl).unwrap();
    let at = 84 + 50 * 3 + 12 + 12 + 8; // z of corner 1 of triangle 3
    bytes[at..at + 4].copy_from_slice(&f32::INFINITY.to_le_bytes());
    std::fs::write(&stl, &bytes).unwrap();
    let err = assert_error(read_mesh(&stl), IoErrorKind::NonFinite, &stl);
    assert!(err.message.contains("triangle 3"), "{err}");

    let ascii = write(
        dir.path(),
        "nan_ascii.stl",
        b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 NaN 0\nendloop\nendfacet\nendsolid x\n",
    );
    assert_error(read_mesh(&ascii), IoErrorKind::NonFinite, &ascii);
}

#[test]
fn no_triangles_is_malformed() {
    let dir = tempfile::tempdir().unwrap();
    let obj = write(dir.path(), "points.obj", b"v 0 0 0\nv 1 0 0\n");
    let err = assert_error(read_mesh(&obj), IoErrorKind::Malformed, &obj);
    assert!(err.message.contains("no triangles"), "{err}");
    let off = write(dir.path(), "none.off", b"OFF\n0 0 0\n");
    assert_error(read_mesh(&off), IoErrorKind::Malformed, &off);
    // A PLY with only points is fine for read_poly_mesh, not for read_mesh.
    let ply = dir.path().join("points.ply");
    let mut pm = PolyMesh::from(TriangleMesh::new(cube().positions, Vec::new()));
    pm.points = vec![0, 7];
    write_poly_mesh(&ply, &pm).unwrap();
    assert_eq!(read_poly_mesh(&ply).unwrap().points, vec![0, 7]);
    assert_error(read_mesh(&ply), IoErrorKind::Malformed, &ply);
}

#[test]
fn degenerate_and_duplicate_triangles_are_kept() {
    let dir = tempfile::tempdir().unwrap();
    let obj = write(
        dir.path(),
        "dup.obj",
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 3\nf 3 2 1\nf 1 1 2\n",
    );
    assert_eq!(read_mesh(&obj).unwrap().mesh.triangles.len(), 4);
}

#[test]
fn raw_size_mismatch_names_both_sizes_and_suggests() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), "head.raw", &vec![0u8; 256 * 256 * 100 * 2]);
    let layout = RawLayout::new([256, 256, 113], RawType::U16, Endian::Big);
    let err = assert_error(
        read_volume(&path, Some(&layout)),
        IoErrorKind::SizeMismatch,
        &path,
    );
    assert!(err.message.contains("13107200"), "{err}");
    assert!(err.message.contains("14811136"), "{err}");
    assert!(err.message.contains("dims 256 256 100"), "{err}");
}

#[test]
fn absurd_header_sizes_are_too_large_not_an_abort() {
    let dir = tempfile::tempdir().unwrap();
    let nrrd = write(
        dir.path(),
        "huge.nrrd",
        b"NRRD0004\ntype: short\ndimension: 3\nsizes: 100000 100000 100000\nendian: little\nencoding: raw\n\n\x01\x02",
    );
    let err = assert_error(read_volume(&nrrd, None), IoErrorKind::TooLarge, &nrrd);
    assert!(err.message.contains("bytes"), "{err}");
    let mha = write(
        dir.path(),
        "huge.mha",
        b"NDims = 3\nDimSize = 100000 100000 100000\nElementType = MET_FLOAT\nElementDataFile = LOCAL\n\x00",
    );
    assert_error(read_volume(&mha, None), IoErrorKind::TooLarge, &mha);
    let raw = write(dir.path(), "huge.raw", &[0; 16]);
    let layout = RawLayout::new([100000, 100000, 100000], RawType::U8, Endian::Little);
    assert_error(
        read_volume(&raw, Some(&layout)),
        IoErrorKind::TooLarge,
        &raw,
    );
    let vtk = write(
        dir.path(),
        "huge.vtk",
        b"# vtk DataFile Version 3.0\nx\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 100000 100000 100000\nSPACING 1 1 1\nORIGIN 0 0 0\nPOINT_DATA 2\nSCALARS v float 1\nLOOKUP_TABLE default\n1 2\n",
    );
    let err = read_volume(&vtk, None).unwrap_err();
    assert!(
        matches!(
            err.kind,
            IoErrorKind::TooLarge | IoErrorKind::Truncated | IoErrorKind::Malformed
        ),
        "{err}"
    );
    // Element counts a PLY cannot hold.
    let ply = write(
        dir.path(),
        "huge.ply",
        b"ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n\x00\x00",
    );
    assert_error(read_mesh(&ply), IoErrorKind::Truncated, &ply);
    // ... even when the elements have no properties and would take no bytes at all.
    let empty = write(
        dir.path(),
        "spin.ply",
        b"ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\nelement nothing 4000000000\nend_header\n",
    );
    assert_error(read_mesh(&empty), IoErrorKind::Truncated, &empty);
    let stl = dir.path().join("huge.stl");
    let mut bytes = vec![0u8; 84 + 50];
    bytes[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
    std::fs::write(&stl, &bytes).unwrap();
    assert_error(read_mesh(&stl), IoErrorKind::Truncated, &stl);
}

#[test]
fn bad_geometry_in_headers() {
    let dir = tempfile::tempdir().unwrap();
    let zero = write(
        dir.path(),
        "zero.nrrd",
        b"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nspacings: 1 0 1\nencoding: raw\n\n\x05",
    );
    let err = assert_error(read_volume(&zero, None), IoErrorKind::Malformed, &zero);
    assert!(err.message.contains("spacing"), "{err}");
    let nan = write(
        dir.path(),
        "nan.mha",
        b"NDims = 3\nDimSize = 1 1 1\nElementSpacing = 1 nan 1\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n\x05",
    );
    assert_error(read_volume(&nan, None), IoErrorKind::Malformed, &nan);
    let mut layout = RawLayout::new([1, 1, 1], RawType::U8, Endian::Little);
    layout.spacing = [1.0, -2.0, 1.0];
    let raw = write(dir.path(), "neg.raw", &[1]);
    assert_error(
        read_volume(&raw, Some(&layout)),
        IoErrorKind::Malformed,
        &raw,
    );
}

#[test]
fn failed_writes_leave_nothing_behind() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("no-such-dir");
    for name in ["m.ply", "m.obj", "m.stl", "m.off", "m.vtp", "m.vtk"] {
        let path = missing.join(name);
        assert_error(write_mesh(&path, &cube()), IoErrorKind::Access, &path);
    }
    for name in [
        "v.nrrd", "v.nhdr", "v.vti", "v.vtk", "v.mha", "v.mhd", "v.raw", "v.nii", "v.nii.gz",
    ] {
        let path = missing.join(name);
        assert_error(
            write_volume(&path, &small_volume()),
            IoErrorKind::Access,
            &path,
        );
    }
    assert!(!missing.exists());

    // Things that cannot be written fail before a file is touched.
    let dcm = dir.path().join("v.dcm");
    assert_error(
        write_volume(&dcm, &small_volume()),
        IoErrorKind::Unsupported,
        &dcm,
    );
    let mut bad = cube();
    bad.triangles[4][2] = 99;
    let ply = dir.path().join("bad.ply");
    assert_error(write_mesh(&ply, &bad), IoErrorKind::Malformed, &ply);
    let mut nan = cube();
    nan.positions[2].x = f32::NAN;
    let stl = dir.path().join("nan.stl");
    assert_error(write_mesh(&stl, &nan), IoErrorKind::NonFinite, &stl);
    let mut lines = PolyMesh::from(cube());
    lines.lines.push([0, 1]);
    let off = dir.path().join("lines.off");
    assert_error(
        write_poly_mesh(&off, &lines),
        IoErrorKind::Unsupported,
        &off,
    );
    lines.line_attributes.push(Attribute {
        name: "two words".into(),
        values: vec![1.0],
    });
    for name in ["names.ply", "names.vtk"] {
        let path = dir.path().join(name);
        assert_error(
            write_poly_mesh(&path, &lines),
            IoErrorKind::Unsupported,
            &path,
        );
    }
    let unknown = dir.path().join("m.xyz");
    assert_error(
        write_mesh(&unknown, &cube()),
        IoErrorKind::Unsupported,
        &unknown,
    );
    assert!(entries(dir.path()).is_empty(), "{:?}", entries(dir.path()));

    // A failed write keeps the file that was there.
    let keep = dir.path().join("keep.ply");
    write_mesh(&keep, &cube()).unwrap();
    let before = std::fs::read(&keep).unwrap();
    assert!(write_mesh(&keep, &bad).is_err());
    assert_eq!(std::fs::read(&keep).unwrap(), before);
    assert_eq!(entries(dir.path()), ["keep.ply"]);
}

/// Feeds every reader with truncations and corruptions of valid files and with noise: any
/// result is fine except a panic (or an abort), and errors must name the file.
#[test]
fn garbage_never_panics() {
    let dir = tempfile::tempdir().unwrap();
    let seeds = dir.path().join("seeds");
    std::fs::create_dir(&seeds).unwrap();
    let mut poly = PolyMesh::from(cube());
    poly.lines = vec![[0, 6]];
    poly.points = vec![3];
    poly.line_attributes = vec![Attribute {
        name: "width".into(),
        values: vec![2.0],
    }];
    for name in ["s.ply", "s.vtp", "s.vtk", "s.obj"] {
        if name == "s.obj" {
            write_mesh(&seeds.join(name), &cube()).unwrap();
        } else {
            write_poly_mesh(&seeds.join(name), &poly).unwrap();
        }
    }
    write_mesh(&seeds.join("s.stl"), &cube()).unwrap();
    write_mesh(&seeds.join("s.off"), &cube()).unwrap();
    std::fs::write(
        seeds.join("a.stl"),
        b"solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid a\n",
    )
    .unwrap();
    std::fs::write(
        seeds.join("a.ply"),
        b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
    )
    .unwrap();
    let options = voxlod_io::VolumeWriteOptions { compress: true };
    for name in ["v.nrrd", "v.vti", "v.vtk", "v.mha"] {
        write_volume(&seeds.join(name), &small_volume()).unwrap();
        voxlod_io::write_volume_with(&seeds.join(format!("z{name}")), &small_volume(), &options)
            .unwrap();
    }

    // VOXLOD_FUZZ_ROUNDS=5000 for a longer run.
    let rounds: usize = std::env::var("VOXLOD_FUZZ_ROUNDS")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(60);
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut random = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let work = dir.path().join("work");
    std::fs::create_dir(&work).unwrap();
    for seed in entries(&seeds) {
        let original = std::fs::read(seeds.join(&seed)).unwrap();
        let path = work.join(&seed);
        let mut variants: Vec<Vec<u8>> = Vec::new();
        for cut in [1, 2, 10, 40, 83, 84, 85, 100, 150, 200, 300, 500] {
            variants.push(original[..cut.min(original.len())].to_vec());
        }
        for _ in 0..rounds {
            let mut v = original.clone();
            for _ in 0..1 + random() % 8 {
                let at = (random() as usize) % v.len();
                v[at] = random() as u8;
            }
            variants.push(v);
        }
        variants.push((0..300).map(|_| random() as u8).collect());
        for bytes in variants {
            std::fs::write(&path, &bytes).unwrap();
            let is_volume = seed.starts_with('v') || seed.starts_with("zv");
            let outcome = if is_volume {
                read_volume(&path, None).map(|_| ())
            } else {
                read_poly_mesh(&path).map(|_| ())
            };
            if let Err(e) = outcome {
                assert!(e.to_string().contains(&seed), "{e}");
            }
        }
    }
}
