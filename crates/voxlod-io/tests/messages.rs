//! Every reader's errors are plain words about the file: many bad files, each refused with a
//! one-line message that names the file and carries none of the signs of a parser's `Debug`
//! output (`ParseError { location: LineCol …`, `InvalidXml(IllFormed(…))`,
//! `DataArraySizeMismatch {…}`, "Parse error: Digit" were seen before).

mod common;

use std::path::Path;

use common::{gzip, nifti, read_by_extension, write, zlib};
use voxlod_io::read_poly_mesh;

/// Signs of a parser's internals in a message.
const DEBUG_SIGNS: [&str; 14] = [
    "{",
    "}",
    "Error(",
    "::",
    "Some(",
    "None",
    "Custom(",
    "LineCol",
    "ErrorKind",
    "\\n",
    "\\t",
    "panicked",
    "Digit",
    "IllFormed",
];

/// Asserts that every file is refused in plain words; returns how many were checked.
fn check_all(dir: &Path, cases: &[(&str, Vec<u8>)]) -> usize {
    for (name, bytes) in cases {
        let path = write(dir, name, bytes);
        let err = read_by_extension(&path).expect_err(&format!("{name} was accepted"));
        let text = err.to_string();
        if std::env::var("VOXLOD_SHOW_MESSAGES").is_ok() {
            eprintln!("{name}: {}", err.message);
        }
        // A detached header's error may name its data file, and then names the header too.
        assert!(text.contains(*name), "{text}");
        assert!(!text.contains('\n'), "{name}: {text}");
        for sign in DEBUG_SIGNS {
            assert!(!err.message.contains(sign), "{name}: '{sign}' in: {text}");
        }
        assert!(err.message.len() > 10, "{name}: {text}");
        std::fs::remove_file(&path).unwrap();
    }
    cases.len()
}

fn text(s: &str) -> Vec<u8> {
    s.as_bytes().to_vec()
}

const PLY_HEAD: &str = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";

fn mesh_cases() -> Vec<(&'static str, Vec<u8>)> {
    let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    let mut binary_ply = text("ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list int int vertex_indices\nend_header\n");
    binary_ply.extend_from_slice(&[0; 12]);
    binary_ply.extend_from_slice(&(-3i32).to_le_bytes());
    vec![
        ("a.obj", text(&format!("{tri}f 1 2 x\n"))),
        ("b.obj", text(&format!("{tri}f 1 2 9\n"))),
        ("c.obj", text("v 1 2 three\n")),
        ("d.obj", text(&format!("{tri}f 1//7 2 3\n"))),
        ("a.ply", text("ply\nformat ascii 1.0\nelement vertex x\nend_header\n")),
        ("b.ply", text("ply\nformat ascii 1.0\nelement vertex 1\nproperty floot x\nend_header\n")),
        ("c.ply", text("ply\nformat ascii 1.0\nproperty float x\nend_header\n")),
        ("d.ply", text("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n")),
        ("e.ply", text("plyx\n")),
        ("f.ply", text(&format!("{PLY_HEAD}0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n"))),
        ("g.ply", text(&format!("{PLY_HEAD}0 0 0\n1 0 0\n0 1 0\n3 0 1\n"))),
        ("h.ply", text(&format!("{PLY_HEAD}0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n"))),
        ("i.ply", text(&format!("{PLY_HEAD}0 0 0\n1 0 0\n"))),
        ("j.ply", text("ply\nformat binary_big_endian 2\nend_header\n")),
        ("k.ply", binary_ply),
        ("a.stl", text("solid x\nfacet normal 0 0 1\nouter lop\n")),
        ("b.stl", text("solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 zero\n")),
        ("c.stl", text("solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n")),
        ("d.stl", text("solid x\nfacet 0 0 1\n")),
        ("e.stl", text("solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n")),
        ("f.stl", vec![7; 100]),
        ("a.off", text("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 zero\n3 0 1 2\n")),
        ("b.off", text("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 -2\n")),
        ("c.off", text("OFF\nthree 1 0\n")),
        ("a.vtp", text("<VTKFile type=\"PolyData\"><PolyData><Piece NumberOfPoints=\"3\"")),
        ("b.vtp", text("<VTKFile type=\"PolyData\" version=\"1.0\"><PolyData><Piece NumberOfPoints=\"1\"><Points><DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"ascii\">0 0 0</DataArray></Points></PolyData></VTKFile>")),
        ("c.vtp", text("<VTKFile type=\"PolyData\" version=\"1.0\"><PolyData><Piece NumberOfPoints=\"1\"><Points><DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"ascii\">0 0 x</DataArray></Points></Piece></PolyData></VTKFile>")),
        ("d.vtp", text("<VTKFile type=\"PolyData\" version=\"1.0\"><PolyData><Piece NumberOfPoints=\"1\"><Points><DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"binary\">!!!!</DataArray></Points></Piece></PolyData></VTKFile>")),
        ("e.vtp", text("<VTKFile type=\"PolyData\" version=\"1.0\"><PolyData><Piece NumberOfPoints=\"2\"><Points><DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"ascii\">0 0 0</DataArray></Points></Piece></PolyData></VTKFile>")),
        ("f.vtp", text("<VTKFile type=\"PolyData\" version=\"1.0\"><PolyData><Piece NumberOfPoints=\"1\"><Points><DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"appended\" offset=\"0\"/></Points></Piece></PolyData></VTKFile>")),
        ("g.vtp", text("<VTKFile type=\"PolyData\" version=\"1.0\"><PolyData><Piece NumberOfPoints=\"1\"></Piece></PolyData></VTKFile>")),
        ("h.vtp", text("<VTKFile type=\"PolyData\" version=\"1.0\"><PolyData><Piece NumberOfPoints=\"1\"><Points><DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"ascii\">0 0 0</DataArray></Points><Polys><DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">0 0</DataArray><DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">3</DataArray></Polys></Piece></PolyData></VTKFile>")),
        ("i.vtp", text("<VTKFile type=\"UnstructuredGrid\" version=\"1.0\"><Bogus/></VTKFile>")),
        ("j.vtp", text("<VTKFile type=\"PolyData\" version=\"x\" compressor=\"vtkZLibDataCompressor\"><PolyData/></VTKFile>")),
        ("k.vtp", text("<VTKFile type=\"PolyData\" version=\"1.0\"><PolyData><Piece NumberOfPoints=\"1\" NumberOfPolys=\"1\"><Points><DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"ascii\">0 0 0</DataArray></Points><Polys><DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">0 0 0</DataArray><DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">-3</DataArray></Polys></Piece></PolyData></VTKFile>")),
        ("l.vtp", text("<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"Middle\"><PolyData/></VTKFile>")),
        ("m.vtp", text("<VTKFile type=\"PolyData\" version=\"1.0\"><PolyData><Piece NumberOfPoints=\"1\"><Points><DataArray type=\"Float32\" format=\"ascii\" NumberOfComponents=\"3\">0 0 0</DataArray></Points></Piece></PolyData></VTKFile"))
        ,
        ("mesh-a.vtk", text("# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 3 float\n0 0 0 1 0 0 0 x 0\n")),
        ("mesh-b.vtk", text("# vtk DataFile Version 3.0\nt\nASCI\nDATASET POLYDATA\n")),
        ("mesh-c.vtk", text("# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 3 float\n0 0 0 1 0 0 0 1 0\nPOLYGONS 1 4\n3 0 1 5\n")),
        ("mesh-d.vtk", text("# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 3 int\n0 0 0 1 0 0 0 1 0\n")),
        ("mesh-e.vtk", text("# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 9 float\n0 0 0\n")),
        ("mesh-f.vtk", text("# vtk DataFile\n")),
    ]
}

fn volume_cases() -> Vec<(&'static str, Vec<u8>)> {
    let nrrd = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n";
    let mha = "NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\n";
    let image = |extent: &str, values: &str| {
        text(&format!("<VTKFile type=\"ImageData\" version=\"1.0\"><ImageData WholeExtent=\"{extent}\" Origin=\"0 0 0\" Spacing=\"1 1 1\"><Piece Extent=\"{extent}\"><PointData><DataArray type=\"Float32\" Name=\"v\" format=\"ascii\">{values}</DataArray></PointData></Piece></ImageData></VTKFile>"))
    };
    let mut short_gzip = text(&format!(
        "{}encoding: gzip\n\n",
        nrrd.replace("encoding: raw\n", "")
    ));
    short_gzip.extend(gzip(&[1, 2, 3]));
    let mut corrupt_zlib = text(&format!(
        "{mha}CompressedData = True\nElementDataFile = LOCAL\n"
    ));
    let mut z = zlib(&[5; 8]);
    z[4] ^= 0xff;
    corrupt_zlib.extend(z);
    let mut nii_short = nifti([3, 2, 2, 2, 1, 1, 1, 1], 2, 8);
    nii_short.extend([1, 2, 3]);
    vec![
        ("a.nrrd", text(&format!("{nrrd}\n\x01\x02"))),
        ("b.nrrd", text("NRRD0004\ntype: quad\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n")),
        ("c.nrrd", text("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 -2 2\nencoding: raw\n\n")),
        ("d.nrrd", text("NRRD0004\ntype: uchar\ndimension: 9\nsizes: 2 2 2\nencoding: raw\n\n")),
        ("e.nrrd", text("NRRD0004\ntype: uchar\nsizes: 2 2 2\nencoding: raw\n\n")),
        ("f.nrrd", short_gzip),
        ("g.nrrd", text(&format!("{}encoding: ascii\n\n1 2 x 4 5 6 7 8\n", nrrd.replace("encoding: raw\n", "")))),
        ("h.nrrd", text("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: bzip2\n\n")),
        ("i.nrrd", text("not a nrrd\n")),
        ("a.nhdr", text(&format!("{nrrd}data file: missing.raw\n"))),
        ("a.mha", text(&format!("{mha}ElementDataFile = LOCAL\n\x01"))),
        ("b.mha", corrupt_zlib),
        ("c.mha", text("NDims = 3\nDimSize = 2 x 2\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n")),
        ("d.mha", text("no equals sign here\n")),
        ("a.mhd", text(&format!("{mha}ElementDataFile = missing.raw\n"))),
        ("a.nii", nifti([3, 2, 2, 0, 1, 1, 1, 1], 2, 8)),
        ("b.nii", nifti([3, 2, -2, 2, 1, 1, 1, 1], 2, 8)),
        ("c.nii", nifti([9, 2, 2, 2, 1, 1, 1, 1], 2, 8)),
        ("d.nii", nifti([3, 2, 2, 2, 1, 1, 1, 1], 128, 24)),
        ("e.nii", nifti([3, 2, 2, 2, 1, 1, 1, 1], 77, 8)),
        ("f.nii", nifti([4, 2, 2, 2, 5, 1, 1, 1], 2, 8)),
        ("g.nii", nii_short),
        ("h.nii", vec![1; 100]),
        ("i.nii.gz", gzip(&nifti([3, 2, 2, 2, 1, 1, 1, 1], 2, 8))),
        ("a.vti", image("0 1 0 1 0 1", "1 2 3 4 5 6 7")),
        ("b.vti", image("0 1 0 -1 0 1", "1 2 3 4 5 6 7 8")),
        ("c.vti", image("0 1 0 1", "1 2 3 4")),
        ("d.vti", image("0 1 0 1 0 1", "1 2 3 4 5 6 7 x")),
        ("e.vti", text("<VTKFile type=\"ImageData\" version=\"1.0\"><ImageData WholeExtent=\"0 0 0 0 0 0\" Origin=\"0 0\" Spacing=\"1 1 1\"><Piece><PointData/></Piece></ImageData></VTKFile>")),
        ("f.vti", text("<VTKFile type=\"ImageData\" version=\"1.0\"><ImageData WholeExtent=\"0 0 0 0 0 0\" Origin=\"0 0 0\" Spacing=\"1 1 1\"><Piece><PointData/></Piece></ImageData></VTKFile>")),
        ("a.vtk", text("# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 2 2\nSPACING 1 1 1\nORIGIN 0 0 0\nPOINT_DATA 8\nSCALARS v float 1\nLOOKUP_TABLE default\n1 2 3\n")),
        ("b.vtk", text("# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 two 2\n")),
        ("c.vtk", text("# vtk DataFile Version 3.0\nt\nBINARY\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 2 2\nSPACING 1 1 1\nORIGIN 0 0 0\nPOINT_DATA 8\nSCALARS v float 1\nLOOKUP_TABLE default\n\x01\x02")),
        ("d.vtk", text("# vtk DataFile Version 3.0\n\nASCII\n")),
        ("a.raw", vec![0; 15]),
    ]
}

#[test]
fn every_reader_says_what_is_wrong_in_plain_words() {
    let dir = tempfile::tempdir().unwrap();
    let checked = check_all(dir.path(), &mesh_cases()) + check_all(dir.path(), &volume_cases());
    assert!(checked >= 75, "{checked}");
}

/// The class made impossible: no source file of the crate formats anything with `{:?}` outside
/// its tests, so no parser's `Debug` form can reach a message.
#[test]
fn no_debug_formatting_in_the_readers() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = vec![src.clone()];
    let mut offenders = Vec::new();
    while let Some(path) = files.pop() {
        if path.is_dir() {
            files.extend(std::fs::read_dir(&path).unwrap().map(|e| e.unwrap().path()));
            continue;
        }
        let source = std::fs::read_to_string(&path).unwrap();
        let code = source.split("#[cfg(test)]").next().unwrap();
        for (i, line) in code.lines().enumerate() {
            let is_comment = line.trim_start().starts_with("//");
            if !is_comment && (line.contains(":?}") || line.contains(":#?}")) {
                offenders.push(format!("{}:{}: {}", path.display(), i + 1, line.trim()));
            }
        }
    }
    assert!(offenders.is_empty(), "{offenders:#?}");
}

/// vtkio still panics on some files that voxlod does not read (a structured grid piece
/// without points reaches an `unwrap`): the panic is caught and, seen from outside, nothing
/// but the error is printed. Run in a child process, whose stderr is what a user would see.
#[test]
fn a_panic_inside_vtkio_prints_nothing() {
    const CHILD: &str = "VOXLOD_TEST_READ_IN_CHILD";
    if let Ok(path) = std::env::var(CHILD) {
        let err = read_poly_mesh(Path::new(&path)).unwrap_err();
        println!("child error: {err}");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let path = write(
        dir.path(),
        "grid.vtp",
        b"<VTKFile type=\"StructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\"><StructuredGrid WholeExtent=\"0 0 0 0 0 0\"><Piece Extent=\"0 0 0 0 0 0\"></Piece></StructuredGrid></VTKFile>",
    );
    let output = std::process::Command::new(std::env::current_exe().unwrap())
        .args([
            "--exact",
            "a_panic_inside_vtkio_prints_nothing",
            "--nocapture",
        ])
        .env(CHILD, &path)
        .output()
        .unwrap();
    let (stdout, stderr) = (
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr),
    );
    assert!(output.status.success(), "{stdout}\n{stderr}");
    for text in [&stdout, &stderr] {
        for sign in ["panicked", "unwrap", ".rs:", "RUST_BACKTRACE"] {
            assert!(!text.contains(sign), "{text}");
        }
    }
    assert!(
        stdout.contains("child error:") && stdout.contains("grid.vtp: the VTK file is corrupt"),
        "{stdout}"
    );
}

/// The messages the hardening issue quoted as misleading, each now saying what is wrong.
#[test]
fn the_misleading_messages_of_the_issue() {
    let dir = tempfile::tempdir().unwrap();
    let cube = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n";
    let image = |extent: &str| {
        text(&format!("<VTKFile type=\"ImageData\" version=\"1.0\" byte_order=\"LittleEndian\"><ImageData WholeExtent=\"{extent}\" Origin=\"0 0 0\" Spacing=\"1 1 1\"><Piece Extent=\"{extent}\"><PointData><DataArray type=\"Float32\" Name=\"density\" format=\"ascii\">1 2 3 4 5 6 7 8</DataArray></PointData></Piece></ImageData></VTKFile>"))
    };
    for (name, bytes, expected) in [
        ("v.obj", text(&format!("{cube}f 1 2 9\n")), "vertex index 9 is out of range (8 vertices so far)"),
        ("w.vti", image("0 1 0 1 0 2"), "data array 'density' of piece 0 holds 8 values where its 12 points of 1 component need 12"),
        ("x.vti", image("0 1 0 1 1 0"), "ends before it starts along z (0 < 1)"),
        ("z.nii", nifti([3, 64, 64, 0, 1, 1, 1, 1], 2, 8), "dim[3] = 0: the size along axis 3 must be at least 1"),
        ("s.ply", text("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 x\n"), "line 13: this 'face' element does not match"),
        ("t.ply", text("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x y\nend_header\n"), "line 4 of the header: expected 'property TYPE NAME'"),
        ("u.vtk", text("# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 two 2\n"), "a number is missing or is not a number"),
    ] {
        let path = write(dir.path(), name, &bytes);
        let err = read_by_extension(&path).expect_err(name);
        assert!(err.message.contains(expected), "{name}: {err}");
    }
}
