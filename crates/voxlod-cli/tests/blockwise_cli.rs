//! `voxlod lod --blockwise`: a NRRD or raw scan read blockwise gives the files of the scan read
//! whole (same triangle counts, same vertex sets, in the requested frame too); what cannot be
//! read so is refused cleanly, before any file is written.

mod common;

use std::path::{Path, PathBuf};

use common::{arg, assert_clean_failure, json, voxlod};
use voxlod::core::{mesh_topology, TriangleMesh};
use voxlod_testkit::compare::sorted_vertex_bits;

/// A ball and a bar as int16 values (inside above 0) on a 37 × 33 × 29 grid, as little-endian
/// bytes.
fn scan_bytes() -> Vec<u8> {
    let [nx, ny, nz] = [37usize, 33, 29];
    let mut bytes = Vec::with_capacity(2 * nx * ny * nz);
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                let d = [x as f64 - 15.0, y as f64 - 16.0, z as f64 - 14.0];
                let ball = 11.0 - (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                let bar = 3.0 - (d[1].abs()).max(d[2].abs());
                let v = (100.0 * ball.max(bar.min(33.0 - x as f64))).round() as i16;
                bytes.extend(v.to_le_bytes());
            }
        }
    }
    bytes
}

/// The scan as an LPS NRRD with raw encoding and a flip along y.
fn write_nrrd(dir: &Path) -> PathBuf {
    let header = "NRRD0004\ntype: short\ndimension: 3\nsizes: 37 33 29\nendian: little\n\
                  encoding: raw\nspace: left-posterior-superior\n\
                  space directions: (0.7,0,0) (0,-0.7,0) (0,0,1.1)\nspace origin: (3,40,-9)\n\n";
    let path = dir.join("scan.nrrd");
    std::fs::write(&path, [header.as_bytes(), &scan_bytes()].concat()).unwrap();
    path
}

/// Runs `lod` on `input` into `dir/name` with `extra` flags; the report and the level meshes.
fn lod(
    input: &Path,
    dir: &Path,
    name: &str,
    extra: &[&str],
) -> (serde_json::Value, Vec<TriangleMesh>) {
    let out = dir.join(name);
    let mut args = vec!["lod", arg(input), "-o", arg(&out), "--json"];
    args.extend(["--resolution", "36", "--levels", "3"]);
    args.extend(extra);
    (json(&voxlod(&args)), level_meshes(&out))
}

/// The three level meshes a `lod` run wrote into `out`.
fn level_meshes(out: &Path) -> Vec<TriangleMesh> {
    (0..3)
        .map(|k| {
            let file = out.join(format!("level-{k}.ply"));
            voxlod::io::read_mesh(&file).unwrap().mesh
        })
        .collect()
}

fn assert_same_levels(a: &[TriangleMesh], b: &[TriangleMesh], what: &str) {
    for (k, (x, y)) in a.iter().zip(b).enumerate() {
        assert!(x.triangle_count() > 100, "{what} level {k}");
        assert_eq!(x.triangle_count(), y.triangle_count(), "{what} level {k}");
        assert_eq!(
            sorted_vertex_bits(x),
            sorted_vertex_bits(y),
            "{what} level {k}"
        );
        assert!(mesh_topology(y).is_closed_manifold(), "{what} level {k}");
    }
}

#[test]
fn blockwise_nrrd_and_raw_give_the_files_of_the_scan_read_whole() {
    let dir = tempfile::tempdir().unwrap();
    let nrrd = write_nrrd(dir.path());
    let t = ["--threshold", "0"];
    let (whole_report, whole) = lod(&nrrd, dir.path(), "whole", &t);
    let (report, blockwise) = lod(
        &nrrd,
        dir.path(),
        "blockwise",
        &[&t[..], &["--blockwise"]].concat(),
    );
    assert_same_levels(&whole, &blockwise, "nrrd");
    // The blockwise route samples bricks; the report keeps the frame and the transform.
    assert!(report["levels"][0]["band"].is_object(), "{report}");
    assert!(
        whole_report["levels"][0]["band"].is_null(),
        "{whole_report}"
    );
    assert_eq!(report["frame"], whole_report["frame"]);
    assert_eq!(report["transform"], whole_report["transform"]);
    // Converted to RAS, both routes alike.
    let ras = [&t[..], &["--frame", "ras"]].concat();
    let (_, whole_ras) = lod(&nrrd, dir.path(), "whole-ras", &ras);
    let (_, blockwise_ras) = lod(
        &nrrd,
        dir.path(),
        "blockwise-ras",
        &[&ras[..], &["--blockwise"]].concat(),
    );
    assert_same_levels(&whole_ras, &blockwise_ras, "ras");
    assert_ne!(
        sorted_vertex_bits(&whole_ras[0]),
        sorted_vertex_bits(&whole[0])
    );
    // The same samples as a headerless raw file.
    let raw = dir.path().join("scan.raw");
    std::fs::write(&raw, scan_bytes()).unwrap();
    let layout = [
        "--dims",
        "37,33,29",
        "--dtype",
        "i16",
        "--spacing",
        "0.7,0.7,1.1",
    ];
    let (_, raw_whole) = lod(
        &raw,
        dir.path(),
        "raw-whole",
        &[&t[..], &layout[..]].concat(),
    );
    let flags = [&t[..], &layout[..], &["--blockwise", "--no-monotone"]].concat();
    let (_, raw_blockwise) = lod(&raw, dir.path(), "raw-blockwise", &flags);
    let flags = [&t[..], &layout[..], &["--no-monotone"]].concat();
    let (_, raw_plain) = lod(&raw, dir.path(), "raw-plain", &flags);
    assert_same_levels(&raw_plain, &raw_blockwise, "raw");
    assert!(raw_whole[0].triangle_count() > 100);
}

#[test]
fn what_cannot_be_read_blockwise_is_refused_before_writing() {
    let dir = tempfile::tempdir().unwrap();
    let nrrd = write_nrrd(dir.path());
    let gz = dir.path().join("scan-gz.nrrd");
    let volume = voxlod::io::read_volume(&nrrd, None).unwrap();
    voxlod::io::write_volume_with(
        &gz,
        &volume,
        &voxlod::io::VolumeWriteOptions { compress: true },
    )
    .unwrap();
    let cut = dir.path().join("cut.nrrd");
    let bytes = std::fs::read(&nrrd).unwrap();
    std::fs::write(&cut, &bytes[..bytes.len() - 10]).unwrap();
    let out = dir.path().join("out");
    for (input, flags, words) in [
        (&gz, vec!["--threshold", "0"], "no random access"),
        (&nrrd, vec!["--direct", "--iso", "0"], "--blockwise"),
        (&cut, vec!["--threshold", "0"], "truncated"),
    ] {
        let mut args = vec!["lod", arg(input), "-o", arg(&out), "--blockwise"];
        args.extend(flags);
        let o = voxlod(&args);
        assert_clean_failure(&o, words);
        assert!(!out.exists(), "output left behind for {}", input.display());
    }
    // Without --blockwise the small gzip file is read whole.
    let o = voxlod(&[
        "lod",
        arg(&gz),
        "-o",
        arg(&out),
        "--threshold",
        "0",
        "--levels",
        "1",
    ]);
    assert!(o.status.success(), "{}", common::stderr(&o));
}

/// A 256³ uint8 raw scan of a ball (80 MiB as floats and bytes) run with and without a memory
/// budget below that: under the budget the blockwise route is chosen by itself and gives the files
/// of the scan read whole.
#[test]
fn a_scan_over_the_memory_budget_is_read_blockwise_by_itself() {
    let n = 256usize;
    let mut bytes = Vec::with_capacity(n * n * n);
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                let d = [x as f64 - 125.3, y as f64 - 130.7, z as f64 - 127.1];
                let r = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                bytes.push((100.0 + 20.0 * (60.0 - r)).clamp(0.0, 255.0) as u8);
            }
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let raw = dir.path().join("ball.raw");
    std::fs::write(&raw, bytes).unwrap();
    let run = |name: &str, budget: Option<&str>| {
        let out = dir.path().join(name);
        let mut command = std::process::Command::new(env!("CARGO_BIN_EXE_voxlod"));
        command.args(["lod", arg(&raw), "-o", arg(&out), "--json"]);
        command.args([
            "--dims",
            "256,256,256",
            "--dtype",
            "u8",
            "--threshold",
            "100",
        ]);
        command.args(["--resolution", "64", "--levels", "3"]);
        match budget {
            Some(b) => command.env("VOXLOD_MAX_MEMORY", b),
            None => command.env_remove("VOXLOD_MAX_MEMORY"),
        };
        (json(&command.output().unwrap()), level_meshes(&out))
    };
    let (whole_report, whole) = run("whole", None);
    let (report, blockwise) = run("blockwise", Some("64M"));
    assert!(
        whole_report["levels"][0]["band"].is_null(),
        "{whole_report}"
    );
    assert!(report["levels"][0]["band"].is_object(), "{report}");
    assert_same_levels(&whole, &blockwise, "over the budget");
}
