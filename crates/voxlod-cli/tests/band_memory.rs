//! A level through the narrow band refused by the memory budget: the refusal speaks of the
//! band (its bricks, its lattice, its mesh), not of a dense grid, and comes before any work.

mod common;

use std::process::Command;

use common::{arg, assert_clean_failure, write_mesh};
use voxlod_testkit::shapes::icosphere;

#[test]
fn a_band_level_over_the_budget_is_refused_in_terms_of_the_band() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write_mesh(dir.path(), "ball.obj", &icosphere(4));
    let out = dir.path().join("out");
    let started = std::time::Instant::now();
    let o = Command::new(env!("CARGO_BIN_EXE_voxlod"))
        .args(["lod", arg(&mesh), "-o", arg(&out), "--resolution", "1600"])
        .args(["--levels", "1"])
        .env("VOXLOD_MAX_MEMORY", "256M")
        .output()
        .unwrap();
    assert_clean_failure(&o, "level 0 at resolution 1600: the narrow band of ~");
    assert_clean_failure(&o, "bricks of 8³ samples");
    assert_clean_failure(&o, "but only 256.0 MiB");
    assert_eq!(o.status.code(), Some(3));
    assert!(!out.exists());
    // Refused by the plan, before the lattice is cast (which alone would take minutes here).
    assert!(started.elapsed().as_secs() < 60);
}
