//! `voxlod contour` from the command line: an oblique, flipped scan's surface lands where `lod`
//! and the library put it (open, closed, in either frame), and work beyond the memory budget is
//! refused with exit status 3.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::{arg, assert_clean_failure, centroid_and_volume, json, stderr, voxlod};
use voxlod::core::glam::{DMat3, DVec3};
use voxlod::core::{Frame, Grid, Orientation, Volume};

/// Index of the ball's centre.
const CENTRE: [f64; 3] = [10.3, 9.6, 7.2];

/// A ball of radius 6 mm around [`CENTRE`] of a 24 × 22 × 16 scan with spacing 0.8, 1.1, 1.5 mm,
/// rotated 30° about z, tilted and flipped, in LPS: its values are millimetres inside the ball.
fn oblique_ball() -> Volume {
    let grid = Grid::new([24, 22, 16], [0.8, 1.1, 1.5], [-20.5, 13.25, -7.0]).unwrap();
    let centre = DVec3::from_array(CENTRE);
    let mut values = Vec::with_capacity(grid.len());
    for k in 0..16 {
        for j in 0..22 {
            for i in 0..24 {
                let d = (DVec3::new(i as f64, j as f64, k as f64) - centre) * grid.spacing_vec();
                values.push((6.0 - d.length()) as f32);
            }
        }
    }
    let direction = DMat3::from_rotation_z(30f64.to_radians())
        * DMat3::from_rotation_x(8f64.to_radians())
        * DMat3::from_diagonal(DVec3::new(1.0, -1.0, 1.0));
    Volume::from_vec(grid, values)
        .unwrap()
        .oriented(Orientation {
            direction,
            frame: Frame::Lps,
        })
}

fn write_scan(dir: &Path) -> (PathBuf, DVec3) {
    let scan = oblique_ball();
    let path = dir.join("oblique.nrrd");
    voxlod::io::write_volume(&path, &scan).unwrap();
    (path, scan.world().index_to_world(DVec3::from_array(CENTRE)))
}

fn centroid_of(path: &Path) -> DVec3 {
    centroid_and_volume(&voxlod::io::read_mesh(path).unwrap().mesh).0
}

#[test]
fn an_oblique_scan_is_contoured_where_lod_puts_it() {
    let dir = tempfile::tempdir().unwrap();
    let (scan, centre) = write_scan(dir.path());
    let ras = centre * DVec3::new(-1.0, -1.0, 1.0);
    let levels = dir.path().join("levels");
    let lod = json(&voxlod(&[
        "lod",
        arg(&scan),
        "-o",
        arg(&levels),
        "--threshold",
        "0",
        "--resolutions",
        "40",
        "--json",
    ]));
    assert_eq!(lod["frame"], "lps");
    let by_lod = centroid_of(&levels.join("level-0.ply"));
    for (flags, expected) in [
        (&[][..], centre),
        (&["--close"], centre),
        (&["--frame", "ras"], ras),
        (&["--close", "--frame", "ras"], ras),
    ] {
        let out = dir.path().join("ball.ply");
        let mut args = vec![
            "contour",
            arg(&scan),
            "-o",
            arg(&out),
            "--iso",
            "0",
            "--json",
        ];
        args.extend(flags);
        let report = json(&voxlod(&args));
        assert_eq!(report["closed_manifold"], true, "{flags:?}");
        let frame = if flags.contains(&"--frame") {
            "ras"
        } else {
            "lps"
        };
        assert_eq!(report["frame"], frame);
        assert_eq!(report["transform"].as_array().unwrap().len(), 4);
        let found = centroid_of(&out);
        // Half the finest spacing.
        assert!(
            (found - expected).length() < 0.4,
            "{flags:?}: {found} {expected}"
        );
        if flags.len() <= 1 {
            assert!(
                (found - by_lod).length() < 0.4,
                "{flags:?}: {found} {by_lod}"
            );
        }
    }
}

#[test]
fn contour_beyond_the_memory_budget_exits_3() {
    let dir = tempfile::tempdir().unwrap();
    let (scan, _) = write_scan(dir.path());
    let out = dir.path().join("ball.ply");
    for flags in [&[][..], &["--close"]] {
        let o = Command::new(env!("CARGO_BIN_EXE_voxlod"))
            .args(["contour", arg(&scan), "-o", arg(&out), "--iso", "0"])
            .args(flags)
            .env("VOXLOD_MAX_MEMORY", "16K")
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
        assert_clean_failure(&o, "VOXLOD_MAX_MEMORY");
        assert!(!out.exists());
    }
}
