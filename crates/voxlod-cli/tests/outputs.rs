//! Output files end to end: no input is ever overwritten, an interrupted, killed or failed run
//! leaves nothing partial or temporary, and a command's files appear together or not at all.

mod common;

use std::os::unix::process::ExitStatusExt;
use std::path::Path;
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

use common::*;
use voxlod::core::{Grid, Volume};

/// The names in `dir`, sorted; none when it does not exist.
fn names(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = files_in(dir)
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// A ball of radius 5 in a 16³ volume of bytes, as headerless raw.
fn raw_ball(path: &Path) -> Vec<u8> {
    let mut bytes = Vec::with_capacity(16 * 16 * 16);
    for z in 0..16i32 {
        for y in 0..16i32 {
            for x in 0..16i32 {
                let r2 = (x - 8).pow(2) + (y - 8).pow(2) + (z - 8).pow(2);
                bytes.push(if r2 < 25 { 100 } else { 0 });
            }
        }
    }
    std::fs::write(path, &bytes).unwrap();
    bytes
}

// ----------------------------------------------------------------------------------------
// Inputs are never overwritten.

/// `voxelize head.raw … -o head.nhdr` must not write its data to head.raw: the input.
#[test]
fn a_detached_volume_never_overwrites_the_input_volume() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("head.raw");
    let original = raw_ball(&input);
    for (header, data) in [("head.nhdr", "head-1.raw"), ("head.mhd", "head-2.raw")] {
        let o = voxlod(&[
            "voxelize",
            arg(&input),
            "--dims",
            "16,16,16",
            "--threshold",
            "50",
            "--resolution",
            "8",
            "-o",
            arg(&dir.path().join(header)),
            "--json",
        ]);
        let report = json(&o);
        assert_eq!(std::fs::read(&input).unwrap(), original, "{header}");
        let warning = report["warnings"][0].as_str().unwrap();
        assert!(
            warning.contains("head.raw is an input") && warning.contains(data),
            "{warning}"
        );
        let files: Vec<&str> = report["files"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| f.as_str().unwrap())
            .collect();
        assert_eq!(
            files,
            [arg(&dir.path().join(data)), arg(&dir.path().join(header))]
        );
        // The header names the data file it got, and reads back as the grid written.
        let volume = voxlod::io::read_volume(&dir.path().join(header), None).unwrap();
        let dims = report["dims"].as_array().unwrap();
        assert_eq!(volume.grid.dims[0] as u64, dims[0].as_u64().unwrap());
        assert!(
            volume.range().unwrap().1 > 0.5,
            "{header}: the density is there"
        );
    }
    // head-1.raw is now the data of head.nhdr: the second header did not take it either.
    assert_eq!(
        names(dir.path()),
        [
            "head-1.raw",
            "head-2.raw",
            "head.mhd",
            "head.nhdr",
            "head.raw"
        ]
    );
}

/// The regular files below `dir` with their bytes.
fn contents(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut all = Vec::new();
    for path in files_in(dir) {
        if path.is_dir() {
            all.extend(contents(&path));
        } else if path.is_file() {
            all.push((arg(&path).to_string(), std::fs::read(&path).unwrap()));
        }
    }
    all.sort();
    all
}

/// Every command that writes refuses an output that is one of its inputs — by the same name,
/// through a link, or as the data file of an input header — naming both, before its work.
#[test]
fn an_output_that_is_an_input_is_refused_naming_both() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mesh = write_mesh(d, "block.ply", &holed_block());
    let grid = Grid::new([6, 6, 6], [1.0; 3], [0.0; 3]).unwrap();
    let mut volume = Volume::filled(grid, 0.0, "test").unwrap();
    volume.values[[2, 2, 2]] = 1.0;
    let nhdr = d.join("scan.nhdr");
    voxlod::io::write_volume(&nhdr, &volume).unwrap();
    let levels = d.join("levels");
    std::fs::create_dir(&levels).unwrap();
    let level0 = write_mesh(&levels, "level-0.ply", &holed_block());
    let link = |name: &str, to: &Path| {
        let path = d.join(name);
        std::os::unix::fs::symlink(to, &path).unwrap();
        path
    };
    let (mesh_link, volume_link, image_link) = (
        link("link.ply", &mesh),
        link("scan-link.ply", &nhdr),
        link("image.png", &mesh),
    );
    let before = contents(d);
    let (m, s) = (arg(&mesh), arg(&nhdr));
    let data = d.join("scan.raw");
    let cases: [(&[&str], &str, &str); 7] = [
        (
            &["lod", arg(&level0), "-o", arg(&levels), "--resolution", "8"],
            "level-0.ply:",
            "the input",
        ),
        (
            &["contour", s, "--iso", "0.5", "-o", arg(&volume_link)],
            "scan-link.ply:",
            "the input",
        ),
        (
            &["cluster", m, "--cells", "4", "-o", m],
            "block.ply:",
            "the input",
        ),
        (
            &["envelope", m, "--epsilon", "1%", "-o", arg(&mesh_link)],
            "link.ply:",
            "the input",
        ),
        (
            &["layers", m, "-o", m, "--resolution", "8"],
            "block.ply:",
            "the input",
        ),
        (
            &["render", m, "-o", arg(&image_link), "--size", "8x8"],
            "image.png:",
            "the input",
        ),
        (
            &[
                "voxelize",
                s,
                "--direct",
                "--resolution",
                "4",
                "-o",
                arg(&data),
            ],
            "scan.raw:",
            "the data file",
        ),
    ];
    for (args, output, what) in cases {
        let o = voxlod(args);
        assert_clean_failure(&o, &format!("{output} refusing to write over {what}"));
        let input = Path::new(args[1]).file_name().unwrap().to_str().unwrap();
        assert_clean_failure(&o, input);
    }
    assert_eq!(contents(d), before, "an input changed, or a file was left");
}

// ----------------------------------------------------------------------------------------
// Interrupted and killed runs leave nothing. (The clean-up of named temporaries, where a file
// system has no unnamed ones, is tested in voxlod-io: tests/named_temporaries.rs.)

/// A `lod` run that stages level 0 at once, then works for seconds on level 1.
fn spawn_slow_lod(input: &Path, out: &Path) -> Child {
    Command::new(env!("CARGO_BIN_EXE_voxlod"))
        .args(["lod", arg(input), "-o", arg(out), "--resolutions", "16,300"])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the voxlod binary runs")
}

/// How a run was seen writing.
#[derive(Debug, PartialEq)]
enum Writing {
    /// A new name in the folder: a named temporary (or a file put in place too early).
    Named,
    /// An open file in the folder that has no name there: an unnamed temporary (O_TMPFILE).
    Unnamed,
}

/// Waits until `child` writes into `dir`: a new name there, or an open file in it (an unnamed
/// temporary shows in /proc/PID/fd as `DIR/#N (deleted)`).
fn wait_until_writing(child: &mut Child, dir: &Path) -> Writing {
    let before = names(dir);
    let deadline = Instant::now() + Duration::from_secs(60);
    let fds = format!("/proc/{}/fd", child.id());
    loop {
        if names(dir) != before {
            return Writing::Named;
        }
        if let Ok(canonical) = dir.canonicalize() {
            let open_there = std::fs::read_dir(&fds)
                .into_iter()
                .flatten()
                .flatten()
                .filter_map(|fd| std::fs::read_link(fd.path()).ok())
                .any(|target| target.starts_with(&canonical));
            if open_there {
                return Writing::Unnamed;
            }
        }
        if let Some(status) = child.try_wait().unwrap() {
            panic!("voxlod ended ({status}) before it was seen writing");
        }
        assert!(Instant::now() < deadline, "voxlod never started writing");
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// Runs a slow `lod` into `out` (made beforehand, holding `notes.txt`, when `existing`), sends
/// `signal` once it writes, and checks that `out` is as it was. Returns how it ended, or `None`
/// for `kill -9` where the file system has no unnamed temporaries (nothing can clean up then).
fn interrupt(signal: &str, existing: bool) -> Option<(ExitStatus, String)> {
    let dir = tempfile::tempdir().unwrap();
    let input = write_mesh(dir.path(), "block.ply", &holed_block());
    let out = dir.path().join("out");
    if existing {
        std::fs::create_dir(&out).unwrap();
        std::fs::write(out.join("notes.txt"), "mine").unwrap();
    }
    let mut child = spawn_slow_lod(&input, &out);
    let writing = wait_until_writing(&mut child, &out);
    if signal == "KILL" {
        child.kill().unwrap();
    } else {
        let sent = Command::new("kill")
            .args(["-s", signal, &child.id().to_string()])
            .status()
            .unwrap();
        assert!(sent.success());
    }
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    if signal == "KILL"
        && writing == Writing::Named
        && names(&out).iter().any(|n| n.contains(".tmp-"))
    {
        voxlod_testkit::skips::skip(format!(
            "the file system of {} has no O_TMPFILE, so kill -9 leaves the named temporary",
            std::env::temp_dir().display()
        ));
        return None;
    }
    if existing {
        assert_eq!(names(&out), ["notes.txt"], "{signal}: {err}");
    } else {
        assert!(!out.exists(), "{signal}: {:?} left; {err}", names(&out));
    }
    assert_eq!(names(dir.path()).len(), 1 + existing as usize, "{signal}");
    Some((o.status, err))
}

#[test]
fn sigint_leaves_nothing_and_exits_130() {
    for existing in [true, false] {
        let (status, err) = interrupt("INT", existing).unwrap();
        assert_eq!(status.code(), Some(130), "{err}");
        assert!(err.contains("stopped") && err.contains("SIGINT"), "{err}");
    }
}

#[test]
fn sigterm_leaves_nothing_and_exits_143() {
    let (status, err) = interrupt("TERM", true).unwrap();
    assert_eq!(status.code(), Some(143), "{err}");
}

/// Nothing can clean up after `kill -9`: the file being written has no name until it is done.
#[test]
fn kill_9_leaves_nothing_visible() {
    if let Some((status, _)) = interrupt("KILL", true) {
        assert_eq!(status.signal(), Some(9));
    }
}

// ----------------------------------------------------------------------------------------
// A command's outputs are one set.

/// `layers` keeps no .glb when its preview cannot be written.
#[test]
fn layers_writes_neither_file_when_the_preview_fails() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write_mesh(dir.path(), "block.ply", &holed_block());
    let glb = dir.path().join("block.glb");
    let preview = dir.path().join("no-such-folder/preview.png");
    let o = voxlod(&[
        "layers",
        arg(&mesh),
        "-o",
        arg(&glb),
        "--resolution",
        "12",
        "--preview",
        arg(&preview),
        "--size",
        "16x16",
    ]);
    assert_clean_failure(&o, "preview.png");
    assert_eq!(names(dir.path()), ["block.ply"]);
}

fn level_files(report: &serde_json::Value) -> Vec<String> {
    report["levels"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|l| l["file"].as_str().map(str::to_string))
        .collect()
}

/// A rerun into the same folder with fewer levels (or another format) removes the level files
/// of the earlier run, says so, and touches nothing else.
#[test]
fn a_rerun_of_lod_removes_its_stale_levels_and_nothing_else() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write_mesh(dir.path(), "block.ply", &holed_block());
    let out = dir.path().join("out");
    let lod = |extra: &[&str]| {
        let mut args = vec!["lod", arg(&mesh), "-o", arg(&out), "--json"];
        args.extend_from_slice(extra);
        json(&voxlod(&args))
    };
    let first = lod(&["--resolutions", "16,12,8"]);
    assert_eq!(
        level_files(&first),
        ["level-0.ply", "level-1.ply", "level-2.ply"]
    );
    assert_eq!(first["warnings"].as_array().unwrap().len(), 0);
    for mine in ["level-notes.txt", "level-9.ply.bak", "my-level-1.ply"] {
        std::fs::write(out.join(mine), "mine").unwrap();
    }
    let second = lod(&["--resolutions", "16,12", "--format", "obj"]);
    assert_eq!(level_files(&second), ["level-0.obj", "level-1.obj"]);
    let warnings = second["warnings"].as_array().unwrap();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(
        warnings[0]
            .as_str()
            .unwrap()
            .ends_with("level-0.ply, level-1.ply, level-2.ply"),
        "{warnings:?}"
    );
    assert_eq!(
        names(&out),
        [
            "level-0.obj",
            "level-1.obj",
            "level-9.ply.bak",
            "level-notes.txt",
            "my-level-1.ply",
            "report.json"
        ]
    );
    let on_disk: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(on_disk["warnings"], second["warnings"]);
}

/// One triangle at resolution 1: no level has a surface. That is an error, and nothing is
/// written, not even the folder.
#[test]
fn lod_without_any_surface_fails_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let triangle = dir.path().join("triangle.obj");
    std::fs::write(&triangle, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let out = dir.path().join("out");
    let o = voxlod(&["lod", arg(&triangle), "-o", arg(&out), "--resolution", "1"]);
    assert_clean_failure(&o, "triangle.obj: no level has a surface");
    assert_clean_failure(&o, "--resolution");
    assert!(!out.exists(), "{:?}", names(&out));
}

// ----------------------------------------------------------------------------------------
// Images.

/// A name whose extension is not PNG (we would write PNG bytes under it) is refused before
/// any work, naming the format we write.
#[test]
fn an_image_name_we_do_not_write_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write_mesh(dir.path(), "block.ply", &holed_block());
    let m = arg(&mesh);
    let jpg = dir.path().join("x.jpg");
    let glb = dir.path().join("x.glb");
    for args in [
        vec!["render", m, "-o", arg(&jpg), "--size", "8x8"],
        vec![
            "layers",
            m,
            "-o",
            arg(&glb),
            "--resolution",
            "8",
            "--preview",
            arg(&jpg),
        ],
        vec!["render", m, "-o", "picture", "--size", "8x8"],
    ] {
        let o = voxlod(&args);
        assert_clean_failure(&o, "not an image format voxlod writes");
        assert_clean_failure(&o, ".png");
    }
    assert_eq!(names(dir.path()), ["block.ply"]);
}
