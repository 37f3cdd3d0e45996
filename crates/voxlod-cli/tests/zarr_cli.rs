//! Zarr from the command line: `voxelize -o out.zarr` round trip, `lod vol.zarr --threshold`
//! (the blockwise route) against the same samples as a raw file (the dense route), broken stores
//! refused cleanly, and a malformed `VOXLOD_MAX_MEMORY` refused before any work.

mod common;

use std::path::Path;
use std::process::Command;

use common::{arg, assert_clean_failure, files_in, json, stderr, voxlod, write_mesh};
use voxlod::core::{mesh_topology, Grid, Volume};
use voxlod_testkit::shapes::icosphere;

#[test]
fn voxelize_to_zarr_holds_the_samples_of_voxelize_to_nrrd() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write_mesh(dir.path(), "ball.obj", &icosphere(3));
    let zarr = dir.path().join("ball.zarr");
    let nrrd = dir.path().join("ball.nrrd");
    for out in [&zarr, &nrrd] {
        let o = voxlod(&["voxelize", arg(&mesh), "-o", arg(out), "--resolution", "24"]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let a = voxlod::io::read_volume(&zarr, None).unwrap();
    let b = voxlod::io::read_volume(&nrrd, None).unwrap();
    assert_eq!(a.grid.dims, b.grid.dims);
    for axis in 0..3 {
        assert!((a.grid.spacing[axis] - b.grid.spacing[axis]).abs() < 1e-12);
        assert!((a.grid.origin[axis] - b.grid.origin[axis]).abs() < 1e-12);
    }
    assert_eq!(a.as_slice(), b.as_slice());
    assert!(a.as_slice().iter().any(|&v| v > 0.5) && a.as_slice().iter().any(|&v| v < 0.5));
}

/// A ball of radius 9 samples (values 200 inside, 10 outside) in a 26 × 24 × 22 grid.
fn ball() -> Volume {
    let grid = Grid::new([26, 24, 22], [1.0; 3], [0.0; 3]).unwrap();
    let mut values = Vec::with_capacity(grid.len());
    for k in 0..22 {
        for j in 0..24 {
            for i in 0..26 {
                let d = [i as f64 - 12.5, j as f64 - 11.0, k as f64 - 10.5];
                let r = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                values.push(if r < 9.0 { 200.0 } else { 10.0 });
            }
        }
    }
    Volume::from_vec(grid, values).unwrap()
}

#[test]
fn lod_of_a_zarr_through_the_blockwise_route_matches_the_raw_file() {
    let dir = tempfile::tempdir().unwrap();
    let volume = ball();
    let zarr = dir.path().join("ball.zarr");
    voxlod::io::write_volume(&zarr, &volume).unwrap();
    let raw = dir.path().join("ball.raw");
    let bytes: Vec<u8> = volume
        .as_slice()
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    std::fs::write(&raw, bytes).unwrap();
    let run = |input: &Path, name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        let mut args = vec!["lod", arg(input), "-o", arg(&out), "--threshold", "100"];
        args.extend(["--resolution", "26", "--levels", "1", "--json"]);
        args.extend(extra);
        let report = json(&voxlod(&args));
        let mesh = voxlod::io::read_mesh(&out.join("level-0.ply"))
            .unwrap()
            .mesh;
        (report, mesh)
    };
    let (zr, zm) = run(&zarr, "from-zarr", &[]);
    let raw_layout = ["--dims", "26,24,22", "--dtype", "f32"];
    let (rr, rm) = run(&raw, "from-raw", &raw_layout);
    let triangles = zr["levels"][0]["triangles"].as_u64().unwrap();
    assert!(triangles > 500, "{zr}");
    assert_eq!(triangles, rr["levels"][0]["triangles"].as_u64().unwrap());
    assert_eq!(zm.triangles.len(), rm.triangles.len());
    let mut a: Vec<[u32; 3]> = zm
        .positions
        .iter()
        .map(|p| p.to_array().map(f32::to_bits))
        .collect();
    let mut b: Vec<[u32; 3]> = rm
        .positions
        .iter()
        .map(|p| p.to_array().map(f32::to_bits))
        .collect();
    a.sort_unstable();
    b.sort_unstable();
    assert_eq!(a, b, "vertex sets differ");
    assert!(mesh_topology(&zm).is_closed_manifold());
}

#[test]
fn a_store_with_an_unknown_compressor_or_broken_metadata_fails_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let lz4 = dir.path().join("lz4.zarr");
    std::fs::create_dir(&lz4).unwrap();
    let zarray = r#"{"zarr_format": 2, "shape": [4, 4, 4], "chunks": [4, 4, 4], "dtype": "|u1",
        "compressor": {"id": "lz4", "acceleration": 1}, "fill_value": 0, "order": "C",
        "filters": null}"#;
    std::fs::write(lz4.join(".zarray"), zarray).unwrap();
    std::fs::write(lz4.join("0.0.0"), [0u8; 16]).unwrap();
    let broken = dir.path().join("broken.zarr");
    std::fs::create_dir(&broken).unwrap();
    std::fs::write(broken.join("zarr.json"), b"{\"zarr_format\": 3,").unwrap();
    for (store, words) in [(&lz4, "lz4"), (&broken, "zarr.json: not valid JSON")] {
        for command in [["lod", "-o"], ["contour", "-o"]] {
            let out = dir.path().join("out");
            let mut args = vec![command[0], arg(store), command[1], arg(&out)];
            args.extend(if command[0] == "lod" {
                ["--threshold", "1"]
            } else {
                ["--iso", "1"]
            });
            if command[0] == "contour" {
                args[3] = "out.ply";
            }
            let o = voxlod(&args);
            assert_clean_failure(&o, words);
            assert_clean_failure(&o, store.file_name().unwrap().to_str().unwrap());
            assert!(!stderr(&o).contains("Error("), "{}", stderr(&o));
            assert!(!out.exists(), "output left behind");
        }
    }
    assert_eq!(files_in(&lz4).len(), 2);
}

#[test]
fn lod_refuses_a_malformed_memory_limit_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write_mesh(dir.path(), "ball.obj", &icosphere(2));
    let out = dir.path().join("out");
    let o = Command::new(env!("CARGO_BIN_EXE_voxlod"))
        .args(["lod", arg(&mesh), "-o", arg(&out), "--resolution", "32"])
        .env("VOXLOD_MAX_MEMORY", "abc")
        .output()
        .unwrap();
    assert_clean_failure(&o, "VOXLOD_MAX_MEMORY=\"abc\" is not a size");
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(!out.exists());
}
