//! Sizes read from files meet the memory budget before anything of that size is allocated:
//! with `VOXLOD_MAX_MEMORY` at 150 KiB, files of about 100 KB whose counts are plausible for
//! their size, but whose data would take more than the budget in memory, are refused as
//! too large, each by the reader's own count. (One test in this binary, since it sets the
//! environment for the whole process.)

mod common;

use common::write;
use voxlod_io::{read_poly_mesh, read_volume, IoErrorKind};

#[test]
fn counts_from_files_go_through_the_budget() {
    std::env::set_var("VOXLOD_MAX_MEMORY", "150K");
    let dir = tempfile::tempdir().unwrap();
    let n = 16_000;
    let mut ply = format!("ply\nformat ascii 1.0\nelement vertex {n}\nproperty float x\nproperty float y\nproperty float z\nend_header\n");
    ply.push_str(&"0 0 0\n".repeat(n));
    let mut off = format!("OFF\n{n} 0 0\n");
    off.push_str(&"0 0 0\n".repeat(n));
    let mut stl = vec![0u8; 84 + 50 * 2000];
    stl[80..84].copy_from_slice(&2000u32.to_le_bytes());
    let mut nrrd =
        b"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 100 100 10\nencoding: raw\n\n".to_vec();
    nrrd.extend(vec![0u8; 100_000]);
    let vtp = "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\"><PolyData><Piece NumberOfPoints=\"10000\"><Points><DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"ascii\">0 0 0</DataArray></Points></Piece></PolyData></VTKFile>";
    for (name, bytes, counted) in [
        ("n.ply", ply.into_bytes(), "'vertex' elements"),
        ("n.off", off.into_bytes(), "vertices of the OFF file"),
        ("n.stl", stl, "triangles of the binary STL"),
        ("n.nrrd", nrrd, "100x100x10 uint8 volume"),
        ("n.vtp", vtp.as_bytes().to_vec(), "points of a piece"),
    ] {
        let path = write(dir.path(), name, &bytes);
        let result = if name.ends_with(".nrrd") {
            read_volume(&path, None).map(|_| ())
        } else {
            read_poly_mesh(&path).map(|_| ())
        };
        let err = result.expect_err(name);
        assert_eq!(err.kind, IoErrorKind::TooLarge, "{err}");
        assert!(err.message.contains(counted), "{counted}: {err}");
    }
}
