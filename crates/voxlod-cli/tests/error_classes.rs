//! Commands end with the exit status of their failure's class: a bad
//! selection is a usage error (2), a map without labels or a corrupt file bad input (1), work
//! beyond the memory limit 3, a file that cannot be read 4.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::{arg, assert_clean_failure, stderr, voxlod, write_mesh};
use voxlod::core::{Grid, Volume};
use voxlod_testkit::shapes::unit_cube;

/// A 24 × 24 × 24 map holding label 5, the index block 4..=19, in `dir`; or all background.
fn label_map(dir: &Path, name: &str, with_label: bool) -> PathBuf {
    let grid = Grid::new([24, 24, 24], [1.0; 3], [0.0; 3]).unwrap();
    let values = (0..grid.len())
        .map(|n| [n % 24, n / 24 % 24, n / 576])
        .map(|at| {
            let inside = at.iter().all(|a| (4..=19).contains(a));
            if with_label && inside {
                5.0
            } else {
                0.0
            }
        })
        .collect();
    let path = dir.join(name);
    voxlod::write_volume(&path, &Volume::from_vec(grid, values).unwrap()).unwrap();
    path
}

#[test]
fn labels_failures_end_with_their_class() {
    let dir = tempfile::tempdir().unwrap();
    let map = label_map(dir.path(), "map.nrrd", true);
    let out = dir.path().join("out");
    let o = voxlod(&["labels", arg(&map), "-o", arg(&out), "--labels", "5,6"]);
    assert_clean_failure(&o, "--labels 6: the map has no label 6 (it holds 5)");
    assert_eq!(o.status.code(), Some(2));
    assert!(!out.exists(), "no output folder is left");

    let empty = label_map(dir.path(), "empty.nrrd", false);
    let o = voxlod(&["labels", arg(&empty), "-o", arg(&out)]);
    assert_clean_failure(
        &o,
        &format!("{}: the map holds no label other than 0", empty.display()),
    );
    assert_eq!(o.status.code(), Some(1));

    let o = voxlod(&["labels", arg(&map), "-o", arg(&out), "--radius", "-1"]);
    assert_clean_failure(
        &o,
        "label 5: invalid option: the radius must be a positive number",
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));

    // The map (55 KiB) is read, then its label's filtering is refused by the budget.
    let o = Command::new(env!("CARGO_BIN_EXE_voxlod"))
        .args(["labels", arg(&map), "-o", arg(&out), "--levels", "1"])
        .env("VOXLOD_MAX_MEMORY", "128K")
        .output()
        .unwrap();
    assert_clean_failure(&o, "label 5");
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    assert!(!out.exists());

    let missing = dir.path().join("missing.nrrd");
    let o = voxlod(&["labels", arg(&missing), "-o", arg(&out)]);
    assert_clean_failure(&o, "missing.nrrd");
    assert_eq!(o.status.code(), Some(4));
}

#[test]
fn view_refuses_a_corrupt_glb_as_bad_input_and_a_missing_one_as_io() {
    let dir = tempfile::tempdir().unwrap();
    let corrupt = dir.path().join("corrupt.glb");
    std::fs::write(&corrupt, b"glTF, not really").unwrap();
    let page = dir.path().join("page.html");
    let o = voxlod(&["view", arg(&corrupt), "-o", arg(&page)]);
    assert_clean_failure(&o, "corrupt.glb");
    assert_eq!(o.status.code(), Some(1));
    let o = voxlod(&[
        "view",
        arg(&dir.path().join("missing.glb")),
        "-o",
        arg(&page),
    ]);
    assert_clean_failure(&o, "missing.glb: cannot read");
    assert_eq!(o.status.code(), Some(4));
    assert!(!page.exists());
}

#[test]
fn evaluate_without_budgets_is_a_usage_error_and_a_flat_mesh_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let cube = write_mesh(dir.path(), "cube.ply", &unit_cube());
    let out = dir.path().join("eval");
    let o = voxlod(&["evaluate", arg(&cube), "-o", arg(&out)]);
    assert_clean_failure(&o, "no budgets");
    assert_eq!(o.status.code(), Some(2));
    let mut flat = unit_cube();
    for p in &mut flat.positions {
        (p.x, p.z) = (0.0, 0.0);
    }
    let flat = write_mesh(dir.path(), "flat.ply", &flat);
    let o = voxlod(&["evaluate", arg(&flat), "-o", arg(&out)]);
    assert_clean_failure(&o, "flat.ply: the input mesh: the mesh has no area");
    assert_eq!(o.status.code(), Some(1));
    assert!(!out.exists());
}

/// Flags whose value the command cannot use are usage errors (2), before any file is written:
/// an output extension a command does not write, a radius of zero, a raw volume without its
/// dimensions.
#[test]
fn flag_values_a_command_cannot_use_are_usage_errors() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write_mesh(dir.path(), "cube.ply", &unit_cube());
    let raw = dir.path().join("scan.raw");
    std::fs::write(&raw, [0u8; 64]).unwrap();
    let stl = dir.path().join("out.stl");
    let cases: [(Vec<&str>, &str); 4] = [
        (
            vec!["cluster", arg(&mesh), "-o", arg(&stl), "--cells", "4"],
            "clustering output has dangling edges and points",
        ),
        (
            vec!["layers", arg(&mesh), "-o", arg(&stl)],
            "is not a layers output",
        ),
        (
            vec![
                "voxelize",
                arg(&mesh),
                "-o",
                arg(&stl),
                "--resolution",
                "8",
                "--radius",
                "0",
            ],
            "--radius must be a positive number of voxels",
        ),
        (
            vec!["contour", arg(&raw), "-o", arg(&stl), "--iso", "1"],
            "a headerless raw volume needs --dims",
        ),
    ];
    for (args, words) in cases {
        let o = voxlod(&args);
        assert_clean_failure(&o, words);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(!stl.exists(), "{args:?} wrote a file");
    }
}
