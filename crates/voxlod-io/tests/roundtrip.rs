//! Every writer against its reader: counts exact, positions and samples within f32 precision,
//! normals, attributes, spacing and origin kept.

mod common;

use common::{cube, entries, small_volume};
use voxlod_core::glam::Vec3;
use voxlod_core::{mesh_topology, Attribute, PolyMesh, Volume};
use voxlod_io::{
    read_mesh, read_poly_mesh, read_volume, write_mesh, write_poly_mesh, write_volume,
    write_volume_with, Endian, MeshFormat, RawLayout, RawType, VolumeWriteOptions,
};

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).abs().max_element() <= 1e-6 * a.abs().max_element().max(1.0)
}

#[test]
fn indexed_mesh_formats_keep_vertices_triangles_and_normals() {
    let dir = tempfile::tempdir().unwrap();
    let mut mesh = cube();
    // Coordinates that need all of an f32's digits.
    mesh.positions[6] = Vec3::new(1.0 / 3.0, 123456.79, -2.5e-7);
    for (name, format, normals) in [
        ("c.ply", MeshFormat::Ply, true),
        ("c.PLY", MeshFormat::Ply, true),
        ("c.obj", MeshFormat::Obj, true),
        ("c.off", MeshFormat::Off, true),
        ("c.vtp", MeshFormat::Vtp, true),
        ("c.vtk", MeshFormat::Vtk, true),
    ] {
        let path = dir.path().join(name);
        write_mesh(&path, &mesh).unwrap();
        let loaded = read_mesh(&path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(loaded.format, format);
        assert_eq!(loaded.welded, None);
        assert_eq!(loaded.polygons_triangulated, 0);
        let m = &loaded.mesh;
        assert_eq!(m.triangles, mesh.triangles, "{name}");
        assert_eq!(m.positions.len(), 8, "{name}");
        for (a, b) in m.positions.iter().zip(&mesh.positions) {
            assert!(close(*a, *b), "{name}: {a} vs {b}");
        }
        if normals {
            assert_eq!(m.normals.len(), 8, "{name} lost its normals");
            for (a, b) in m.normals.iter().zip(&mesh.normals) {
                assert!(close(*a, *b), "{name}: normal {a} vs {b}");
            }
        }
    }
    assert_eq!(entries(dir.path()).len(), 6, "temporary files left behind");
}

#[test]
fn stl_binary_round_trip_is_welded_back_to_eight_vertices() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cube.stl");
    write_mesh(&path, &cube()).unwrap();
    assert_eq!(std::fs::metadata(&path).unwrap().len(), 84 + 50 * 12);
    let loaded = read_mesh(&path).unwrap();
    assert_eq!(loaded.format, MeshFormat::Stl);
    let report = loaded.welded.unwrap();
    assert_eq!((report.vertices_before, report.vertices_after), (36, 8));
    assert_eq!(loaded.mesh.triangles.len(), 12);
    assert!(loaded.mesh.normals.is_empty());
    let topology = mesh_topology(&loaded.mesh);
    assert!(topology.is_closed_manifold());
    assert!((loaded.mesh.signed_volume() - 1.0).abs() < 1e-6);
}

fn poly_mesh() -> PolyMesh {
    let mut mesh = cube();
    mesh.positions
        .extend([Vec3::new(2.0, 0.0, 0.0), Vec3::new(3.0, 0.5, 0.25)]);
    mesh.normals.extend([Vec3::X, Vec3::Y]);
    let n = mesh.positions.len();
    PolyMesh {
        mesh,
        lines: vec![[1, 8], [8, 9], [6, 9]],
        points: vec![9, 3],
        vertex_attributes: vec![
            Attribute {
                name: "opacity".into(),
                values: (0..n).map(|i| i as f32 / 10.0).collect(),
            },
            Attribute {
                name: "layer".into(),
                values: (0..n).map(|i| (i % 3) as f32).collect(),
            },
        ],
        line_attributes: vec![Attribute {
            name: "width".into(),
            values: vec![0.5, 1.25, 2.0],
        }],
    }
}

#[test]
fn poly_mesh_round_trips_through_ply_and_vtk() {
    let dir = tempfile::tempdir().unwrap();
    let original = poly_mesh();
    for name in ["p.ply", "p.vtp", "p.vtk"] {
        let path = dir.path().join(name);
        write_poly_mesh(&path, &original).unwrap();
        let back = read_poly_mesh(&path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(back.mesh.triangles, original.mesh.triangles, "{name}");
        assert_eq!(back.mesh.positions, original.mesh.positions, "{name}");
        assert_eq!(back.mesh.normals, original.mesh.normals, "{name}");
        assert_eq!(back.lines, original.lines, "{name}");
        assert_eq!(back.points, original.points, "{name}");
        assert_eq!(back.vertex_attributes, original.vertex_attributes, "{name}");
        assert_eq!(back.line_attributes, original.line_attributes, "{name}");
        // The triangles alone, for read_mesh.
        let loaded = read_mesh(&path).unwrap();
        assert_eq!(loaded.mesh.triangles.len(), 12);
    }
}

#[test]
fn ply_header_names_the_documented_elements() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("p.ply");
    write_poly_mesh(&path, &poly_mesh()).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let end = bytes.windows(10).position(|w| w == b"end_header").unwrap();
    let header = String::from_utf8_lossy(&bytes[..end]);
    for line in [
        "format binary_little_endian 1.0",
        "element vertex 10",
        "property float nx",
        "property float opacity",
        "element face 12",
        "property list uchar int vertex_indices",
        "element edge 3",
        "property int vertex1",
        "property int vertex2",
        "property float width",
        "element point 2",
        "property int vertex_index",
    ] {
        assert!(header.contains(line), "missing '{line}' in\n{header}");
    }
}

#[test]
fn obj_keeps_lines_and_points_but_refuses_attributes() {
    let dir = tempfile::tempdir().unwrap();
    let mut original = poly_mesh();
    let path = dir.path().join("p.obj");
    let err = write_poly_mesh(&path, &original).unwrap_err();
    assert_eq!(err.kind, voxlod_io::IoErrorKind::Unsupported);
    assert!(entries(dir.path()).is_empty());
    original.vertex_attributes.clear();
    original.line_attributes.clear();
    write_poly_mesh(&path, &original).unwrap();
    let back = read_poly_mesh(&path).unwrap();
    assert_eq!(back.lines, original.lines);
    assert_eq!(back.points, original.points);
    assert_eq!(back.mesh.triangles, original.mesh.triangles);
    // The two extra vertices are used by no face: their normals cannot be stored per corner.
    assert_eq!(back.mesh.positions, original.mesh.positions);
}

fn assert_same_volume(a: &Volume, b: &Volume, what: &str) {
    assert_eq!(a.grid.dims, b.grid.dims, "{what}");
    for axis in 0..3 {
        let (sa, sb) = (a.grid.spacing[axis], b.grid.spacing[axis]);
        assert!(
            (sa - sb).abs() <= 1e-6 * sa.abs(),
            "{what}: spacing {sa} vs {sb}"
        );
        let (oa, ob) = (a.grid.origin[axis], b.grid.origin[axis]);
        assert!(
            (oa - ob).abs() <= 1e-5 * oa.abs().max(1.0),
            "{what}: origin {oa} vs {ob}"
        );
    }
    assert_eq!(a.as_slice(), b.as_slice(), "{what}");
}

#[test]
fn volume_formats_keep_samples_spacing_and_origin() {
    let dir = tempfile::tempdir().unwrap();
    let volume = small_volume();
    for name in [
        "v.nrrd", "v.nhdr", "v.vti", "v.vtk", "v.mha", "v.mhd", "V.NRRD", "v.nii", "v.nii.gz",
    ] {
        for compress in [false, true] {
            let path = dir.path().join(name);
            write_volume_with(&path, &volume, &VolumeWriteOptions { compress }).unwrap();
            let back = read_volume(&path, None).unwrap_or_else(|e| panic!("{e}"));
            assert_same_volume(&volume, &back, &format!("{name} compress={compress}"));
        }
    }
    // Spacing and origin are exact where the format stores text or f64.
    for name in ["v.nrrd", "v.mha"] {
        let back = read_volume(&dir.path().join(name), None).unwrap();
        assert_eq!(back.grid, volume.grid, "{name}");
    }
    let names = entries(dir.path());
    assert!(names.contains(&"v.raw".to_string()) && names.contains(&"v.raw.gz".to_string()));
    assert!(names.contains(&"v.zraw".to_string()));
    assert!(!names.iter().any(|n| n.contains(".tmp-")), "{names:?}");
}

#[test]
fn compression_shrinks_a_smooth_volume() {
    let dir = tempfile::tempdir().unwrap();
    let grid = voxlod_core::Grid::unit([32, 32, 32]).unwrap();
    let volume = Volume::from_vec(grid, (0..32768).map(|i| (i / 1024) as f32).collect()).unwrap();
    for name in ["s.nrrd", "s.vti", "s.mha"] {
        let plain = dir.path().join(format!("plain-{name}"));
        let packed = dir.path().join(format!("packed-{name}"));
        write_volume(&plain, &volume).unwrap();
        write_volume_with(&packed, &volume, &VolumeWriteOptions { compress: true }).unwrap();
        let (a, b) = (
            std::fs::metadata(&plain).unwrap().len(),
            std::fs::metadata(&packed).unwrap().len(),
        );
        assert!(b * 4 < a, "{name}: {b} compressed vs {a} plain");
        assert_eq!(
            read_volume(&packed, None).unwrap().as_slice(),
            volume.as_slice()
        );
    }
}

#[test]
fn raw_round_trip_with_its_layout() {
    let dir = tempfile::tempdir().unwrap();
    let volume = small_volume();
    let path = dir.path().join("v.raw");
    write_volume(&path, &volume).unwrap();
    assert_eq!(std::fs::metadata(&path).unwrap().len(), 60 * 4);
    let mut layout = RawLayout::new([5, 4, 3], RawType::F32, Endian::Little);
    layout.spacing = volume.grid.spacing;
    layout.origin = volume.grid.origin;
    let back = read_volume(&path, Some(&layout)).unwrap();
    assert_eq!(back, volume);
    // Any extension is raw when a layout is given.
    let other = dir.path().join("v.bin");
    std::fs::copy(&path, &other).unwrap();
    assert_eq!(read_volume(&other, Some(&layout)).unwrap(), volume);
}

#[test]
fn raw_reads_every_type_and_byte_order() {
    let dir = tempfile::tempdir().unwrap();
    let values: [i32; 4] = [0, 1, 200, 3272];
    for (dtype, endian) in [
        (RawType::U8, Endian::Little),
        (RawType::U16, Endian::Big),
        (RawType::U16, Endian::Little),
        (RawType::I16, Endian::Big),
        (RawType::I32, Endian::Little),
        (RawType::F32, Endian::Big),
    ] {
        let mut bytes = vec![9u8; 3]; // a 3-byte header
        for &v in &values {
            let v = if dtype == RawType::U8 { v.min(255) } else { v };
            let b: Vec<u8> = match (dtype, endian) {
                (RawType::U8, _) => vec![v as u8],
                (RawType::U16, Endian::Big) => (v as u16).to_be_bytes().to_vec(),
                (RawType::U16, Endian::Little) => (v as u16).to_le_bytes().to_vec(),
                (RawType::I16, Endian::Big) => (-(v as i16)).to_be_bytes().to_vec(),
                (RawType::I32, Endian::Little) => (-v).to_le_bytes().to_vec(),
                (RawType::F32, Endian::Big) => (v as f32 + 0.5).to_be_bytes().to_vec(),
                _ => unreachable!(),
            };
            bytes.extend(b);
        }
        let path = dir.path().join(format!("{dtype}-{endian}.raw"));
        std::fs::write(&path, &bytes).unwrap();
        let mut layout = RawLayout::new([2, 2, 1], dtype, endian);
        layout.header_bytes = 3;
        let v = read_volume(&path, Some(&layout)).unwrap();
        let expected: Vec<f32> = values
            .iter()
            .map(|&x| match dtype {
                RawType::U8 => x.min(255) as f32,
                RawType::U16 => x as f32,
                RawType::I16 | RawType::I32 => -x as f32,
                RawType::F32 => x as f32 + 0.5,
                _ => unreachable!("only the types written above"),
            })
            .collect();
        assert_eq!(v.as_slice(), &expected[..], "{dtype} {endian}");
    }
}
