//! Standard output closed by its reader (`voxlod … --json | head -c 10`): the run ends quietly
//! with 141 (128 + SIGPIPE), no panic text, and every output file whole, none temporary.

mod common;

use std::path::Path;
use std::process::{Command, Stdio};

use common::{arg, files_in, write_mesh};
use voxlod_testkit::shapes::{icosphere, unit_cube};

/// Runs `voxlod args` with standard output a pipe whose reading end is closed before the
/// command writes anything; returns its exit code and standard error.
fn into_closed_pipe(args: &[&str]) -> (Option<i32>, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_voxlod"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// No file of `dir` is a temporary (`.NAME.tmp-PID-N`), and its meshes and report read.
fn assert_whole(dir: &Path) {
    let files = files_in(dir);
    assert!(!files.is_empty());
    for file in files {
        let name = file.file_name().unwrap().to_string_lossy().into_owned();
        assert!(!name.contains(".tmp-"), "temporary left: {name}");
        if name.ends_with(".ply") {
            voxlod::io::read_mesh(&file).unwrap();
        }
        if name == "report.json" {
            let text = std::fs::read_to_string(&file).unwrap();
            serde_json::from_str::<serde_json::Value>(&text).unwrap();
        }
    }
}

#[test]
fn reports_into_a_closed_pipe_end_quietly_and_leave_whole_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let ball = write_mesh(dir.path(), "ball.obj", &icosphere(3));
    let cube = write_mesh(dir.path(), "cube.obj", &unit_cube());
    let out = dir.path().join("lod");
    let lod = ["lod", arg(&ball), "-o", arg(&out), "--resolutions", "24,12"];
    let runs: Vec<Vec<&str>> = vec![
        [&lod[..], &["--json"]].concat(),
        lod.to_vec(),
        vec!["inspect", arg(&ball), "--json"],
        vec!["inspect", arg(&ball)],
        vec!["compare", arg(&ball), arg(&cube), "--json"],
        vec!["compare", arg(&ball), arg(&cube)],
    ];
    for args in runs {
        let (code, err) = into_closed_pipe(&args);
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert!(!err.contains("Broken pipe"), "{args:?}: {err}");
        assert_eq!(code, Some(141), "{args:?}: {err}");
    }
    assert_whole(&out);
    assert!(out.join("level-0.ply").is_file() && out.join("level-1.ply").is_file());
}
