//! Files written by VTK 9.7 itself (`scripts/vtk-fixtures.py`, committed under
//! `tests/data/vtk`): every mode of `vtkXMLPolyDataWriter` and `vtkXMLImageDataWriter`
//! (the default, appended raw or base64, inline, ascii; zlib, LZ4, LZMA or no compression;
//! `UInt32` or `UInt64` headers; both byte orders; blocks that divide the data exactly), and
//! the legacy writers. Each is checked against values computed from how the script built the
//! data, not against another reader.

mod common;

use std::path::Path;

use common::{vtk_data, VTK_MODES};

use voxlod_core::glam::Vec3;
use voxlod_io::{read_mesh, read_poly_mesh, read_volume, IoErrorKind};

/// The unit cube of 6 quads, with `Normals` = corner - centre and `height` = z.
fn check_cube(path: &Path) {
    let name = path.file_name().unwrap().to_string_lossy().into_owned();
    let loaded = read_mesh(path).unwrap_or_else(|e| panic!("{e}"));
    let mesh = &loaded.mesh;
    assert_eq!(mesh.positions.len(), 8, "{name}");
    assert_eq!(mesh.triangles.len(), 12, "{name}");
    assert_eq!(loaded.polygons_triangulated, 6, "{name}");
    assert!((mesh.signed_volume() - 1.0).abs() < 1e-6, "{name}");
    assert_eq!(mesh.normals.len(), 8, "{name}: normals dropped");
    for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
        assert_eq!(*n, *p - Vec3::splat(0.5), "{name}");
    }
    let poly = read_poly_mesh(path).unwrap();
    let height = poly
        .vertex_attributes
        .iter()
        .find(|a| a.name == "height")
        .unwrap_or_else(|| panic!("{name}: no height attribute"));
    let z: Vec<f32> = poly.mesh.positions.iter().map(|p| p.z).collect();
    assert_eq!(height.values, z, "{name}");
}

#[test]
fn vtp_of_every_writer_mode_reads_the_cube() {
    for mode in VTK_MODES {
        check_cube(&vtk_data(&format!("cube-{mode}.vtp")));
    }
}

#[test]
fn legacy_polydata_ascii_and_binary() {
    for kind in ["ascii", "binary"] {
        check_cube(&vtk_data(&format!("cube-legacy-{kind}.vtk")));
    }
}

/// VTK 9 writes a legacy file's cell topology in the cell array's own integer type: `int` for
/// 32-bit storage and `vtkIdType` for `vtkIdTypeArray`s, both as 32-bit integers, which
/// vtkio alone misreads (binary) or refuses (ASCII).
#[test]
fn legacy_polydata_with_32_bit_topology() {
    for kind in ["ascii", "binary"] {
        for storage in ["int32", "idtype"] {
            check_cube(&vtk_data(&format!("cube-legacy-{kind}-{storage}.vtk")));
        }
    }
}

/// One cell of each kind: vertex {0}, poly-line {0,1,2}, triangle {3,4,5}, strip {1,2,3,4};
/// cell data `width` in VTK's cell order (verts, lines, polys, strips) = 0, 10, 20, 30.
#[test]
fn vtp_verts_lines_polys_strips_and_cell_data() {
    for mode in VTK_MODES {
        let path = vtk_data(&format!("cells-{mode}.vtp"));
        let poly = read_poly_mesh(&path).unwrap_or_else(|e| panic!("{e}"));
        let expected: Vec<Vec3> = (0..6)
            .map(|x| Vec3::new(x as f32, 0.0, (x % 2) as f32))
            .collect();
        assert_eq!(poly.mesh.positions, expected, "{mode}");
        assert_eq!(poly.points, vec![0], "{mode}");
        assert_eq!(poly.lines, vec![[0, 1], [1, 2]], "{mode}");
        assert_eq!(
            poly.mesh.triangles,
            vec![[3, 4, 5], [1, 2, 3], [3, 2, 4]],
            "{mode}"
        );
        assert_eq!(poly.line_attributes.len(), 1, "{mode}");
        assert_eq!(poly.line_attributes[0].name, "width");
        assert_eq!(poly.line_attributes[0].values, vec![10.0, 10.0], "{mode}");
    }
}

/// The 4x3x5 image with extent 2..5 x 0..2 x 1..5: the origin moves to the first sample.
fn check_image(path: &Path) {
    let name = path.file_name().unwrap().to_string_lossy().into_owned();
    let volume = read_volume(path, None).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(volume.grid.dims, [4, 3, 5], "{name}");
    assert_eq!(volume.grid.spacing, [0.5, 1.0, 2.0], "{name}");
    assert_eq!(volume.grid.origin, [2.0, 2.0, 5.0], "{name}");
    for k in 0..5 {
        for j in 0..3 {
            for i in 0..4 {
                let expected = (i + 2) + 10 * j + 100 * (k + 1) - 50;
                assert_eq!(
                    volume.get(i, j, k),
                    expected as f32,
                    "{name} at {i} {j} {k}"
                );
            }
        }
    }
}

#[test]
fn vti_of_every_writer_mode_reads_the_image() {
    for mode in VTK_MODES {
        check_image(&vtk_data(&format!("image-{mode}.vti")));
    }
}

#[test]
fn legacy_structured_points_ascii_and_binary() {
    for kind in ["ascii", "binary"] {
        check_image(&vtk_data(&format!("image-legacy-{kind}.vtk")));
    }
}

/// Damaged copies of VTK's files: clean errors, not vtkio's panic or its internals.
#[test]
fn damaged_vtk_files_give_plain_errors() {
    let dir = tempfile::tempdir().unwrap();
    let original = std::fs::read(vtk_data("cube-raw-zlib.vtp")).unwrap();
    let section = original
        .windows(13)
        .position(|w| w == b"<AppendedData")
        .unwrap();
    let start = section + original[section..].iter().position(|&b| b == b'_').unwrap() + 1;
    // A block count of 2^32 - 1 in the first array's compression header.
    let mut huge = original.clone();
    huge[start..start + 4].copy_from_slice(&u32::MAX.to_le_bytes());
    // The appended data cut in the middle.
    let cut = original[..start + 40].to_vec();
    // A compressed block flipped.
    let mut flipped = original.clone();
    for b in &mut flipped[start + 40..start + 60] {
        *b ^= 0x5a;
    }
    for (name, bytes, kind) in [
        ("huge.vtp", huge, IoErrorKind::Truncated),
        ("cut.vtp", cut, IoErrorKind::Truncated),
        ("flipped.vtp", flipped, IoErrorKind::Malformed),
    ] {
        let path = dir.path().join(name);
        std::fs::write(&path, &bytes).unwrap();
        let err = read_mesh(&path).expect_err(name);
        assert_eq!(err.kind, kind, "{err}");
        let text = err.to_string();
        assert!(text.starts_with(&path.display().to_string()), "{text}");
        for sign in ["{", "Error(", "::", "panicked", "overflow"] {
            assert!(!text.contains(sign), "{text}");
        }
    }
    // An image whose extent promises more samples than its array holds.
    let image = std::fs::read_to_string(vtk_data("image-ascii.vti")).unwrap();
    let path = dir.path().join("extent.vti");
    std::fs::write(&path, image.replace("2 5 0 2 1 5", "2 5 0 2 1 6")).unwrap();
    let err = read_volume(&path, None).unwrap_err();
    assert_eq!(err.kind, IoErrorKind::Truncated, "{err}");
    assert!(
        err.message.contains("'ImageScalars'")
            && err.message.contains("60")
            && err.message.contains("72"),
        "{err}"
    );
    std::fs::write(&path, image.replace("2 5 0 2 1 5", "2 5 0 2 5 1")).unwrap();
    let err = read_volume(&path, None).unwrap_err();
    assert!(
        err.message.contains("ends before it starts along z"),
        "{err}"
    );
}
