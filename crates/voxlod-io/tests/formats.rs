//! Readers against files written by hand (or by other tools' conventions), not by our own
//! writers: the variants of each format that real files use.

mod common;

use common::{assert_error, gzip, write, zlib};
use voxlod_core::glam::Vec3;
use voxlod_io::{read_mesh, read_poly_mesh, read_volume, IoErrorKind};

// ---------------------------------------------------------------------------------------------
// Meshes.

/// The unit cube's 12 triangles as an ASCII STL with a nameless `solid` line.
fn ascii_cube_stl(name: &str) -> String {
    let mesh = common::cube();
    let mut text = format!(
        "solid{}\n",
        if name.is_empty() {
            String::new()
        } else {
            format!(" {name}")
        }
    );
    for t in &mesh.triangles {
        text.push_str("  facet normal 0 0 0\n    outer loop\n");
        for &v in t {
            let p = mesh.positions[v as usize];
            text.push_str(&format!("      vertex {:e} {:e} {:e}\n", p.x, p.y, p.z));
        }
        text.push_str("    endloop\n  endfacet\n");
    }
    text.push_str("endsolid\n");
    text
}

#[test]
fn ascii_stl_cube_is_welded_to_eight_vertices() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["cube", ""] {
        let path = write(dir.path(), "ascii.stl", ascii_cube_stl(name).as_bytes());
        let loaded = read_mesh(&path).unwrap_or_else(|e| panic!("{e}"));
        let report = loaded.welded.unwrap();
        assert_eq!((report.vertices_before, report.vertices_after), (36, 8));
        assert_eq!(loaded.mesh.triangles.len(), 12);
        assert!((loaded.mesh.signed_volume() - 1.0).abs() < 1e-6);
    }
}

#[test]
fn binary_stl_whose_header_starts_with_solid() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("b.stl");
    voxlod_io::write_mesh(&path, &common::cube()).unwrap();
    let mut bytes = std::fs::read(&path).unwrap();
    bytes[..20].copy_from_slice(b"solid exported by CA");
    std::fs::write(&path, &bytes).unwrap();
    let loaded = read_mesh(&path).unwrap();
    assert_eq!(loaded.mesh.vertex_count(), 8);
    assert_eq!(loaded.mesh.triangle_count(), 12);
}

#[test]
fn obj_with_polygons_and_negative_indices() {
    let dir = tempfile::tempdir().unwrap();
    // An L-shaped prism: two non-convex hexagon caps and six quad sides, all by relative
    // indices after each cap's vertices.
    let mut text = String::from("# L prism\no L\n");
    // Starting at (2, 0), from where a fan would fold outside the L.
    let l = [(2., 0.), (2., 1.), (1., 1.), (1., 3.), (0., 3.), (0., 0.)];
    for (x, y) in l {
        text.push_str(&format!("v {x} {y} 0\n"));
    }
    text.push_str("f -1 -2 -3 -4 -5 -6\n"); // bottom, facing -z
    for (x, y) in l {
        text.push_str(&format!("v {x} {y} 1\n"));
    }
    text.push_str("f -6 -5 -4 -3 -2 -1\n"); // top, facing +z
    for i in 1..=6 {
        let j = i % 6 + 1;
        text.push_str(&format!("f {i} {j} {} {}\n", j + 6, i + 6));
    }
    let path = write(dir.path(), "l.obj", text.as_bytes());
    let loaded = read_mesh(&path).unwrap();
    assert_eq!(loaded.mesh.vertex_count(), 12);
    assert_eq!(loaded.polygons_triangulated, 8);
    assert_eq!(loaded.mesh.triangle_count(), 2 * 4 + 6 * 2);
    // A closed, consistently wound prism of volume 4 only if both caps were clipped right.
    let t = voxlod_core::mesh_topology(&loaded.mesh);
    assert!(
        t.is_closed_manifold() && t.is_consistently_oriented(),
        "{t:?}"
    );
    assert!(
        (loaded.mesh.signed_volume() - 4.0).abs() < 1e-6,
        "{}",
        loaded.mesh.signed_volume()
    );
    assert!((loaded.mesh.area() - (2.0 * 4.0 + 10.0)).abs() < 1e-6);
}

#[test]
fn ascii_ply_with_polygons_doubles_and_other_elements() {
    let dir = tempfile::tempdir().unwrap();
    let text = "ply\nformat ascii 1.0\ncomment made by hand\n\
        element vertex 6\nproperty double x\nproperty double y\nproperty double z\n\
        property uchar red\nproperty float confidence\n\
        element face 1\nproperty list uint8 int32 vertex_index\n\
        element material 1\nproperty float shininess\n\
        end_header\n\
        2 0 0 255 0.5\n2 1 0 0 1\n1 1 0 0 1\n1 3 0 0 1\n0 3 0 0 1\n0 0 0 0 1\n\
        6 0 1 2 3 4 5\n\
        0.25\n";
    let path = write(dir.path(), "l.ply", text.as_bytes());
    let loaded = read_mesh(&path).unwrap();
    assert_eq!(loaded.polygons_triangulated, 1);
    assert_eq!(loaded.mesh.triangle_count(), 4);
    assert!((loaded.mesh.area() - 4.0).abs() < 1e-9);
    let poly = read_poly_mesh(&path).unwrap();
    let names: Vec<&str> = poly
        .vertex_attributes
        .iter()
        .map(|a| a.name.as_str())
        .collect();
    assert_eq!(names, ["red", "confidence"]);
    assert_eq!(poly.vertex_attributes[0].values[0], 255.0);
    assert_eq!(poly.vertex_attributes[1].values[0], 0.5);
}

#[test]
fn ply_triangle_strips_become_triangles_wound_alike() {
    // Two strips in one list, as the Stanford tools write them: 0 1 2 3 is a unit square
    // (two triangles, the second's winding alternated), -1 ends it, 2 3 4 adds a half square.
    let dir = tempfile::tempdir().unwrap();
    let text = "ply\nformat ascii 1.0\nelement vertex 5\n\
        property float x\nproperty float y\nproperty float z\n\
        element tristrips 1\nproperty list int int vertex_indices\nend_header\n\
        0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 2 0\n\
        8 0 1 2 3 -1 2 3 4\n";
    let path = write(dir.path(), "strips.ply", text.as_bytes());
    let m = read_mesh(&path).unwrap().mesh;
    assert_eq!(m.triangles, vec![[0, 1, 2], [2, 1, 3], [2, 3, 4]]);
    for [a, b, c] in m
        .triangles
        .iter()
        .map(|t| t.map(|v| m.positions[v as usize]))
    {
        assert!((b - a).cross(c - a).z > 0.0, "every triangle faces +z");
    }
    assert!((m.area() - 1.5).abs() < 1e-6);

    // A join (a repeated corner) makes no triangle; an index past the vertices names the strip.
    std::fs::write(&path, text.replace("8 0 1 2 3 -1 2 3 4", "5 0 1 1 2 3")).unwrap();
    assert_eq!(read_mesh(&path).unwrap().mesh.triangle_count(), 1);
    std::fs::write(&path, text.replace("2 3 4\n", "2 3 9\n")).unwrap();
    let err = assert_error(read_mesh(&path), IoErrorKind::Malformed, &path);
    assert!(err.message.contains("triangle strip 0"), "{err}");
}

#[test]
fn big_endian_binary_ply_with_short_indices() {
    let dir = tempfile::tempdir().unwrap();
    let mut bytes = b"ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\n\
        property float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\n\
        element face 1\nproperty list uchar ushort vertex_indices\nend_header\n"
        .to_vec();
    for p in [[0f32, 0., 0.], [1., 0., 0.], [0., 1., 0.]] {
        for c in p.iter().chain(&[0f32, 0., 1.]) {
            bytes.extend(c.to_be_bytes());
        }
    }
    bytes.push(3);
    for i in [0u16, 1, 2] {
        bytes.extend(i.to_be_bytes());
    }
    let path = write(dir.path(), "be.ply", &bytes);
    let m = read_mesh(&path).unwrap().mesh;
    assert_eq!(m.triangles, vec![[0, 1, 2]]);
    assert_eq!(m.positions[1], Vec3::X);
    assert_eq!(m.normals, vec![Vec3::Z; 3]);

    // A face pointing past the vertices names the face.
    let last = bytes.len() - 1;
    bytes[last] = 9;
    std::fs::write(&path, &bytes).unwrap();
    let err = assert_error(read_mesh(&path), IoErrorKind::Malformed, &path);
    assert!(err.message.contains("face 0"), "{err}");
}

#[test]
fn legacy_vtk_polydata_with_polygon_and_strip() {
    let dir = tempfile::tempdir().unwrap();
    let text = "# vtk DataFile Version 3.0\nhand made\nASCII\nDATASET POLYDATA\n\
        POINTS 8 float\n0 0 0  2 0 0  2 1 0  1 1 0  1 3 0  0 3 0  5 0 0  5 1 0\n\
        POLYGONS 1 7\n6 1 2 3 4 5 0\n\
        TRIANGLE_STRIPS 1 5\n4 1 6 2 7\n\
        POINT_DATA 8\nSCALARS temperature float 1\nLOOKUP_TABLE default\n0 1 2 3 4 5 6 7\n";
    let path = write(dir.path(), "hand.vtk", text.as_bytes());
    let loaded = read_mesh(&path).unwrap();
    assert_eq!(loaded.polygons_triangulated, 1);
    assert_eq!(loaded.mesh.triangle_count(), 4 + 2);
    // Every triangle faces +z: the polygon's ear clipping and the strip's alternation agree.
    for t in 0..loaded.mesh.triangle_count() {
        let [a, b, c] = loaded.mesh.corners(t);
        assert!((b - a).cross(c - a).z > 0.0, "triangle {t} is flipped");
    }
    let poly = read_poly_mesh(&path).unwrap();
    assert_eq!(poly.vertex_attributes[0].name, "temperature");
    assert_eq!(poly.vertex_attributes[0].values[7], 7.0);
}

// ---------------------------------------------------------------------------------------------
// Volumes.

/// 3×2×2 samples 0..12 as big-endian u16, times 100.
fn u16_be_samples() -> (Vec<u8>, Vec<f32>) {
    let values: Vec<u16> = (0..12).map(|i| i * 100).collect();
    (
        values.iter().flat_map(|v| v.to_be_bytes()).collect(),
        values.iter().map(|&v| v as f32).collect(),
    )
}

#[test]
fn nrrd_gzip_big_endian() {
    let dir = tempfile::tempdir().unwrap();
    let (data, expected) = u16_be_samples();
    let mut bytes =
        b"NRRD0004\n# hand made\ntype: uint16\ndimension: 3\nspace: RAS\nsizes: 3 2 2\n\
        space directions: (0.7,0,0) (0,0.8,0) (0,0,-1.5)\nspace origin: (-10,20.5,3)\n\
        endian: big\nencoding: gzip\n\n"
            .to_vec();
    bytes.extend(gzip(&data));
    let path = write(dir.path(), "g.nrrd", &bytes);
    let v = read_volume(&path, None).unwrap();
    assert_eq!(v.grid.dims, [3, 2, 2]);
    assert_eq!(v.grid.spacing, [0.7, 0.8, 1.5]);
    assert_eq!(v.grid.origin, [-10.0, 20.5, 3.0]);
    assert_eq!(v.as_slice(), &expected[..]);
}

#[test]
fn nhdr_with_detached_data_at_the_end_of_a_file() {
    let dir = tempfile::tempdir().unwrap();
    let (data, expected) = u16_be_samples();
    let mut blob = b"some preamble the header skips with byte skip -1".to_vec();
    blob.extend(&data);
    write(dir.path(), "blob.bin", &blob);
    let path = write(
        dir.path(),
        "d.nhdr",
        b"NRRD0004\ntype: ushort\ndimension: 3\nsizes: 3 2 2\nspacings: 1 1 2\nendian: big\nencoding: raw\ndata file: blob.bin\nbyte skip: -1\n",
    );
    let v = read_volume(&path, None).unwrap();
    assert_eq!(v.as_slice(), &expected[..]);
    assert_eq!(v.grid.spacing, [1.0, 1.0, 2.0]);
}

#[test]
fn nrrd_ascii_encoding() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(
        dir.path(),
        "a.nrrd",
        b"NRRD0004\ntype: float\ndimension: 2\nsizes: 2 2\nencoding: ascii\n\n1.5 -2\n3e2 4\n",
    );
    let v = read_volume(&path, None).unwrap();
    assert_eq!(v.grid.dims, [2, 2, 1]);
    assert_eq!(v.as_slice(), &[1.5, -2.0, 300.0, 4.0]);
}

#[test]
fn metaimage_zlib_big_endian_and_detached() {
    let dir = tempfile::tempdir().unwrap();
    let (data, expected) = u16_be_samples();
    let mut bytes =
        b"ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = True\n\
        CompressedData = True\nOffset = 1 2 3\nElementSpacing = 0.5 0.5 3\nDimSize = 3 2 2\n\
        ElementType = MET_USHORT\nElementDataFile = LOCAL\n"
            .to_vec();
    bytes.extend(zlib(&data));
    let path = write(dir.path(), "z.mha", &bytes);
    let v = read_volume(&path, None).unwrap();
    assert_eq!(v.as_slice(), &expected[..]);
    assert_eq!(v.grid.spacing, [0.5, 0.5, 3.0]);
    assert_eq!(v.grid.origin, [1.0, 2.0, 3.0]);

    let mut padded = vec![0xAAu8; 16];
    padded.extend(&data);
    write(dir.path(), "d.dat", &padded);
    let path = write(
        dir.path(),
        "d.mhd",
        b"NDims = 3\nDimSize = 3 2 2\nElementType = MET_USHORT\nElementByteOrderMSB = True\nHeaderSize = 16\nElementDataFile = d.dat\n",
    );
    assert_eq!(read_volume(&path, None).unwrap().as_slice(), &expected[..]);
}

#[test]
fn legacy_vtk_structured_points() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(
        dir.path(),
        "sp.vtk",
        b"# vtk DataFile Version 3.0\nimage\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 2 2\n\
          ORIGIN -1 0.5 2\nSPACING 0.25 0.5 4\nPOINT_DATA 8\nSCALARS density unsigned_char 1\n\
          LOOKUP_TABLE default\n0 1 2 3 4 5 6 255\n",
    );
    let v = read_volume(&path, None).unwrap();
    assert_eq!(v.grid.dims, [2, 2, 2]);
    assert_eq!(v.grid.spacing, [0.25, 0.5, 4.0]);
    assert_eq!(v.grid.origin, [-1.0, 0.5, 2.0]);
    assert_eq!(v.as_slice(), &[0., 1., 2., 3., 4., 5., 6., 255.]);
}

/// A single-file NIfTI-1 image, written field by field as the standard lays it out.
struct Nifti {
    big_endian: bool,
    dim: [i16; 8],
    datatype: i16,
    bitpix: i16,
    pixdim: [f32; 8],
    vox_offset: f32,
    slope: f32,
    inter: f32,
    units: u8,
    qform: (i16, [f32; 3]),
    sform: (i16, [f32; 3]),
}

impl Nifti {
    fn bytes(&self, data: &[u8]) -> Vec<u8> {
        let mut b = vec![0u8; self.vox_offset as usize];
        let be = self.big_endian;
        let i32b = |v: i32| if be { v.to_be_bytes() } else { v.to_le_bytes() };
        let i16b = |v: i16| if be { v.to_be_bytes() } else { v.to_le_bytes() };
        let f32b = |v: f32| if be { v.to_be_bytes() } else { v.to_le_bytes() };
        b[0..4].copy_from_slice(&i32b(348));
        for (k, d) in self.dim.iter().enumerate() {
            b[40 + 2 * k..42 + 2 * k].copy_from_slice(&i16b(*d));
        }
        b[70..72].copy_from_slice(&i16b(self.datatype));
        b[72..74].copy_from_slice(&i16b(self.bitpix));
        for (k, p) in self.pixdim.iter().enumerate() {
            b[76 + 4 * k..80 + 4 * k].copy_from_slice(&f32b(*p));
        }
        b[108..112].copy_from_slice(&f32b(self.vox_offset));
        b[112..116].copy_from_slice(&f32b(self.slope));
        b[116..120].copy_from_slice(&f32b(self.inter));
        b[123] = self.units;
        b[252..254].copy_from_slice(&i16b(self.qform.0));
        b[254..256].copy_from_slice(&i16b(self.sform.0));
        for k in 0..3 {
            b[268 + 4 * k..272 + 4 * k].copy_from_slice(&f32b(self.qform.1[k]));
        }
        // The sform's steps are the voxel sizes of pixdim, as real writers make them (the
        // sform wins over pixdim when its code is set, as in nibabel).
        let p = self.pixdim;
        let srow = [
            [p[1], 0.0, 0.0, self.sform.1[0]],
            [0.0, p[2], 0.0, self.sform.1[1]],
            [0.0, 0.0, p[3], self.sform.1[2]],
        ];
        for (r, row) in srow.iter().enumerate() {
            for (k, v) in row.iter().enumerate() {
                let at = 280 + 16 * r + 4 * k;
                b[at..at + 4].copy_from_slice(&f32b(*v));
            }
        }
        b[344..348].copy_from_slice(b"n+1\0");
        b.extend_from_slice(data);
        b
    }
}

fn nifti_i16() -> Nifti {
    Nifti {
        big_endian: false,
        dim: [3, 3, 2, 2, 1, 1, 1, 1],
        datatype: 4,
        bitpix: 16,
        pixdim: [1.0, 0.5, 0.75, 2.0, 0.0, 0.0, 0.0, 0.0],
        vox_offset: 352.0,
        slope: 2.0,
        inter: -10.0,
        units: 2,
        qform: (0, [0.0; 3]),
        sform: (1, [10.0, 20.0, 30.0]),
    }
}

#[test]
fn nifti_scaled_int16_with_sform() {
    let dir = tempfile::tempdir().unwrap();
    let raw: Vec<i16> = (0..12).map(|i| i - 6).collect();
    let data: Vec<u8> = raw.iter().flat_map(|v| v.to_le_bytes()).collect();
    let path = write(dir.path(), "s.nii", &nifti_i16().bytes(&data));
    let v = read_volume(&path, None).unwrap();
    assert_eq!(v.grid.dims, [3, 2, 2]);
    assert_eq!(v.grid.spacing, [0.5, 0.75, 2.0]);
    assert_eq!(v.grid.origin, [10.0, 20.0, 30.0]);
    let expected: Vec<f32> = raw.iter().map(|&r| r as f32 * 2.0 - 10.0).collect();
    assert_eq!(v.as_slice(), &expected[..]);

    // Truncated data names both byte counts.
    let bytes = nifti_i16().bytes(&data[..20]);
    let path = write(dir.path(), "short.nii", &bytes);
    let err = assert_error(read_volume(&path, None), IoErrorKind::Truncated, &path);
    assert!(err.message.contains("expected 24 bytes, found 20"), "{err}");

    // A time series is refused rather than cut to its first volume.
    let mut series = nifti_i16();
    series.dim = [4, 3, 2, 2, 2, 1, 1, 1];
    let path = write(
        dir.path(),
        "series.nii",
        &series.bytes(&[data.clone(), data.clone()].concat()),
    );
    assert_error(read_volume(&path, None), IoErrorKind::Unsupported, &path);
}

#[test]
fn nifti_gzip_big_endian_in_metres_with_qform_and_padding() {
    let dir = tempfile::tempdir().unwrap();
    let (data, expected) = u16_be_samples();
    let header = Nifti {
        big_endian: true,
        dim: [3, 3, 2, 2, 1, 1, 1, 1],
        datatype: 512,
        bitpix: 16,
        pixdim: [1.0, 0.001, 0.001, 0.002, 0.0, 0.0, 0.0, 0.0],
        vox_offset: 416.0,
        slope: 0.0,
        inter: 0.0,
        units: 1,
        qform: (1, [0.1, -0.2, 0.3]),
        sform: (0, [0.0; 3]),
    };
    let path = write(dir.path(), "m.nii.gz", &gzip(&header.bytes(&data)));
    let v = read_volume(&path, None).unwrap();
    assert_eq!(v.as_slice(), &expected[..]);
    for (got, want) in v.grid.spacing.iter().zip([1.0, 1.0, 2.0]) {
        assert!((got - want).abs() < 1e-6, "{:?}", v.grid.spacing);
    }
    for (got, want) in v.grid.origin.iter().zip([100.0, -200.0, 300.0]) {
        assert!((got - want).abs() < 1e-4, "{:?}", v.grid.origin);
    }
}

#[test]
fn a_binary_stl_with_rounding_noise_near_zero_welds_watertight() {
    // A tetrahedron as a binary STL whose header starts with "solid", as CAD tools write it;
    // one copy of the corner at the origin carries the exporter's noise (2.7e-16, 0, -1e-17).
    let corners = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
    let faces = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    let mut bytes = b"solid exported by a CAD tool".to_vec();
    bytes.resize(80, b' ');
    bytes.extend((faces.len() as u32).to_le_bytes());
    for (f, face) in faces.iter().enumerate() {
        bytes.extend([0u8; 12]);
        for &v in face {
            let p = match (f, v) {
                (2, 0) => Vec3::new(2.7e-16, 0.0, -1e-17),
                _ => corners[v],
            };
            bytes.extend(p.to_array().iter().flat_map(|c| c.to_le_bytes()));
        }
        bytes.extend([0u8; 2]);
    }
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), "noisy.stl", &bytes);
    let loaded = read_mesh(&path).unwrap();
    let t = voxlod_core::mesh_topology(&loaded.mesh);
    assert_eq!(loaded.mesh.vertex_count(), 4);
    assert!(
        t.is_closed_manifold() && t.is_consistently_oriented(),
        "{t:?}"
    );
    assert_eq!(loaded.mesh.positions[0], Vec3::ZERO);
}

/// The unit cube as an MNI polygon file (the `.obj` of the MNI tools, VTK's
/// `vtkMNIObjectWriter`): its 8 corners, their normals, 6 quads, one colour per vertex.
fn mni_cube() -> String {
    let corners: Vec<[u8; 3]> = (0..8u8)
        .map(|k| [k & 1, (k >> 1) & 1, (k >> 2) & 1])
        .collect();
    let mut text = String::from("P 0.3 0.3 0.4 10 1 8\n");
    for c in &corners {
        text.push_str(&format!(" {} {} {}\n", c[0], c[1], c[2]));
    }
    for c in &corners {
        let n = c.map(|v| 2.0 * v as f32 - 1.0);
        text.push_str(&format!(" {} {} {}\n", n[0], n[1], n[2]));
    }
    text.push_str("\n 6\n 2\n");
    text.push_str(&" 0.5 0.5 0.5 1\n".repeat(8));
    text.push_str("\n 4 8 12 16 20 24\n\n");
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    for q in quads {
        text.push_str(&format!(" {} {} {} {}\n", q[0], q[1], q[2], q[3]));
    }
    text
}

#[test]
fn an_mni_polygon_obj_reads_as_its_closed_surface_mesh_and_asset() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), "surface.obj", mni_cube().as_bytes());
    let loaded = read_mesh(&path).unwrap_or_else(|e| panic!("{e}"));
    let mesh = &loaded.mesh;
    assert_eq!((mesh.vertex_count(), mesh.triangle_count()), (8, 12));
    let topology = voxlod_core::mesh_topology(mesh);
    assert!(topology.is_closed_manifold() && topology.is_consistently_oriented());
    assert!((mesh.signed_volume() - 1.0).abs() < 1e-6);
    let asset = voxlod_io::read_asset(&path).unwrap().asset;
    assert_eq!(asset.mesh.triangles.len(), 12);
    // Cut short inside its corners: an error that says the file ends early, naming it.
    let text = mni_cube();
    let cut = write(dir.path(), "cut.obj", &text.as_bytes()[..text.len() - 12]);
    let err = read_mesh(&cut).unwrap_err();
    assert_eq!(err.kind, IoErrorKind::Truncated, "{err}");
    assert!(err.to_string().contains("cut.obj") && err.to_string().contains("ends early"));
}
