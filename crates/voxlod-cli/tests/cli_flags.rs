//! The command line's flags, behaviour and messages: negative numbers are values,
//! flags are range-checked, reports say what was written, every error is one line.

mod common;

use std::path::{Path, PathBuf};

use clap::{ArgAction, CommandFactory};
use common::*;
use voxlod::core::glam::Vec3;
use voxlod::core::TriangleMesh;
use voxlod_cli::commands::Cli;
use voxlod_testkit::data::shared_data_or_skip;

// -------------------------------------------------------------------------------------------
// Negative numbers, for every numeric flag of every subcommand.

/// A value shaped like the flag's value name, each name part (a run of capitals and digits)
/// replaced by `number`: `X,Y,Z` -> `-1,-1,-1`, `WxH` -> `1x1`, `A,B,...` -> `1,1`.
fn shaped_like(value_name: &str, number: &str) -> String {
    let name = value_name.trim_end_matches(",...");
    let mut out = String::new();
    let mut in_part = false;
    for c in name.chars() {
        let part = c.is_ascii_uppercase() || c.is_ascii_digit();
        if part && !in_part {
            out.push_str(number);
        } else if !part {
            out.push(c);
        }
        in_part = part;
    }
    out
}

/// The raw value clap stored for `id` when parsing `args`, a list joined again by its
/// delimiter (errors ignored, so that missing required flags do not matter; a value its parser
/// refuses is stored as nothing), and whether `--json` was set.
fn parsed(args: &[String], id: &str, delimiter: Option<char>) -> (Option<String>, bool) {
    let m = Cli::command()
        .ignore_errors(true)
        .try_get_matches_from(args)
        .expect("errors are ignored");
    let (_, sub) = m.subcommand().expect("a subcommand");
    let separator = delimiter.map(String::from).unwrap_or_default();
    let raw = sub.get_raw(id).map(|v| {
        v.map(|s| s.to_string_lossy().into_owned())
            .collect::<Vec<_>>()
            .join(&separator)
    });
    let json = sub.try_get_one::<bool>("json").ok().flatten() == Some(&true);
    (raw, json)
}

#[test]
fn every_numeric_flag_takes_a_negative_value_as_written() {
    let cli = Cli::command();
    let mut numeric = Vec::new();
    for sub in cli.get_subcommands() {
        let name = sub.get_name().to_string();
        // Every positional filled, so that values land in options.
        let mut base = vec!["voxlod".to_string(), name.clone()];
        base.extend(sub.get_positionals().map(|_| "in.obj".to_string()));
        for arg in sub.get_opts() {
            let (Some(long), Some(value_names)) = (arg.get_long(), arg.get_value_names()) else {
                continue;
            };
            let is_path = arg.get_value_parser().type_id() == std::any::TypeId::of::<PathBuf>();
            if is_path || matches!(arg.get_action(), ArgAction::SetTrue | ArgAction::Help) {
                continue;
            }
            let value_name = value_names[0].as_str();
            let flag = format!("--{long}");
            let id = arg.get_id().as_str();
            let with = |value: &str, then_json: bool| {
                let mut args = base.clone();
                args.extend([flag.clone(), value.to_string()]);
                if then_json {
                    args.push("--json".into());
                }
                args
            };
            // A flag is numeric when it takes a positive number shaped like its value name.
            let positive = shaped_like(value_name, "1");
            let delimiter = arg.get_value_delimiter();
            if parsed(&with(&positive, false), id, delimiter).0.as_ref() != Some(&positive) {
                continue;
            }
            numeric.push(format!("{name} {flag}"));
            // The negative value is the flag's value: stored as written, and a flag after it
            // still a flag; or refused by the flag's own parser (a count cannot be negative),
            // never taken for an unknown flag.
            let negative = shaped_like(value_name, "-1");
            negative_kept_or_refused(
                &format!("{name} {flag}"),
                &negative,
                with(&negative, true),
                id,
                delimiter,
            );
            // A value left out: the flag after it is not swallowed as the value.
            let (raw, _) = parsed(&with("--json", false), id, delimiter);
            assert_ne!(
                raw.as_deref(),
                Some("--json"),
                "{name} {flag} swallowed --json"
            );
        }
    }
    for expected in [
        "contour --iso",
        "lod --iso",
        "lod --threshold",
        "lod --origin",
        "lod --spacing",
        "lod --resolutions",
        "voxelize --origin",
        "envelope --region",
        "envelope --epsilon",
        "envelope --keep-sharp",
        "layers --error",
        "layers --view",
        "render --fov",
        "render --background",
        "render --line-width",
        "render --size",
        "select --distance",
        "evaluate --budgets",
        "compare --seed",
        "cluster --cells",
    ] {
        assert!(
            numeric.iter().any(|n| n == expected),
            "{expected} not found among {numeric:?}"
        );
    }
    assert!(numeric.len() >= 50, "{} numeric flags", numeric.len());
}

/// A 24³ CT-like volume in Hounsfield units, written as little-endian i16: air (−1000) with a
/// ball of bone (+400) of radius 8 samples around sample (12, 12, 12).
fn hounsfield_ball(dir: &Path) -> PathBuf {
    let n = 24;
    let mut bytes = Vec::with_capacity(n * n * n * 2);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let d2 = [i, j, k]
                    .iter()
                    .map(|&c| (c as f64 - 12.0).powi(2))
                    .sum::<f64>();
                let v: i16 = if d2 <= 64.0 { 400 } else { -1000 };
                bytes.extend_from_slice(&v.to_le_bytes());
            }
        }
    }
    let path = dir.join("head.raw");
    std::fs::write(&path, bytes).unwrap();
    path
}

const RAW_BALL: [&str; 6] = ["--dims", "24,24,24", "--dtype", "i16", "--endian", "little"];

#[test]
fn negative_thresholds_isos_and_origins_reach_the_commands() {
    let dir = tempfile::tempdir().unwrap();
    let raw = hounsfield_ball(dir.path());
    // lod --threshold -500 with a negative origin and 2 mm spacing: the ball of radius 16 mm
    // sits at (-128 + 24, -86.5 + 24, 0 + 24).
    let out = dir.path().join("levels");
    let mut args = vec![
        "lod",
        arg(&raw),
        "-o",
        arg(&out),
        "--threshold",
        "-500",
        "--origin",
        "-128,-86.5,0",
        "--spacing",
        "2,2,2",
        "--resolutions",
        "32",
        "--json",
    ];
    args.extend(RAW_BALL);
    let report = json(&voxlod(&args));
    let level = &report["levels"][0];
    let mesh = voxlod::io::read_mesh(&out.join(level["file"].as_str().unwrap()))
        .unwrap()
        .mesh;
    let b = mesh.bounds();
    let centre = (b.min + b.max) * 0.5;
    for (axis, expected) in [-104.0, -62.5, 24.0].into_iter().enumerate() {
        assert!(
            (centre[axis] - expected).abs() < 1.0,
            "centre {centre:?} (bounds {b:?})"
        );
        let side = b.max[axis] - b.min[axis];
        assert!((side - 32.0).abs() < 4.0, "side {side} (bounds {b:?})");
    }
    // contour --iso -500 (in the data's units) and --iso=-.5 style spellings.
    for iso in [
        &["--iso", "-500"][..],
        &["--iso", "-500.0"],
        &["--iso=-5e2"],
    ] {
        let c = dir.path().join("ball.ply");
        let mut args = vec!["contour", arg(&raw), "-o", arg(&c), "--json"];
        args.extend(iso);
        args.extend(RAW_BALL);
        let r = json(&voxlod(&args));
        assert_eq!(r["iso"], -500.0, "{iso:?}");
        assert_eq!(r["closed_manifold"], true, "{iso:?}");
        assert_eq!(r["genus"], 0, "{iso:?}");
    }
    // A value written with a leading dot, and a flag right after it.
    let c = dir.path().join("dot.ply");
    let mut args = vec![
        "contour",
        arg(&raw),
        "-o",
        arg(&c),
        "--iso",
        "-.5",
        "--json",
    ];
    args.extend(RAW_BALL);
    assert_eq!(json(&voxlod(&args))["iso"], -0.5);
    // A box with a negative corner reaches the envelope's options.
    let block = write_mesh(dir.path(), "block.obj", &holed_block());
    let env = dir.path().join("env.ply");
    let r = json(&voxlod(&[
        "envelope",
        arg(&block),
        "-o",
        arg(&env),
        "--epsilon",
        "2%",
        "--region",
        "-0.2,-0.2,-1,0.2,0.2,1:0.25",
        "--samples",
        "1000",
        "--json",
    ]));
    let region = &r["options"]["regions"][0];
    assert_eq!(region["min"], serde_json::json!([-0.2, -0.2, -1.0]), "{r}");
    assert_eq!(region["scale"], 0.25);
}

// -------------------------------------------------------------------------------------------
// What was written, and what is chosen.

/// A closed axis-aligned cube of side 2 around the origin, as an OBJ file.
fn cube_obj(dir: &Path) -> PathBuf {
    let mesh = voxlod_testkit::shapes::unit_cube();
    let positions = mesh
        .positions
        .iter()
        .map(|p| *p * 2.0 - Vec3::ONE)
        .collect();
    write_mesh(
        dir,
        "cube.obj",
        &TriangleMesh::new(positions, mesh.triangles),
    )
}

#[test]
fn lod_counts_what_it_wrote_and_select_passes_over_empty_levels() {
    let dir = tempfile::tempdir().unwrap();
    let cube = cube_obj(dir.path());
    let out = dir.path().join("levels");
    // At one sample across, the filter removes the whole cube: level 2 has no mesh.
    let o = voxlod(&[
        "lod",
        arg(&cube),
        "-o",
        arg(&out),
        "--resolutions",
        "16,8,1",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(
        text.contains("2 of 3 levels written (level 2 is empty)"),
        "{text}"
    );
    let warning = stderr(&o);
    assert!(
        warning.starts_with("warning: level 2: the filter of radius"),
        "{warning}"
    );
    let files: Vec<_> = files_in(&out)
        .into_iter()
        .filter(|p| p.extension().is_some_and(|e| e == "ply"))
        .collect();
    assert_eq!(files.len(), 2, "{files:?}");
    // The same warning in the JSON report.
    let report = json(&voxlod(&[
        "lod",
        arg(&cube),
        "-o",
        arg(&out),
        "--resolutions",
        "16,8,1",
        "--json",
    ]));
    let warnings = report["warnings"].as_array().unwrap();
    assert_eq!(warnings.len(), 1);
    assert_eq!(
        format!("warning: {}\n", warnings[0].as_str().unwrap()),
        warning
    );
    assert!(report["levels"][2]["file"].is_null());
    // Pixels far larger than every level: the coarsest level with a mesh, level 1.
    let report_path = out.join("report.json");
    let r = json(&voxlod(&[
        "select",
        arg(&report_path),
        "--pixel-size",
        "100",
        "--json",
    ]));
    assert_eq!(r["level"], 1, "{r}");
    let file = PathBuf::from(r["file"].as_str().unwrap());
    assert!(file.is_file(), "{file:?}");
    assert!(r["warnings"][0]
        .as_str()
        .unwrap()
        .starts_with("level 2 fits but has no mesh"));
}

// -------------------------------------------------------------------------------------------
// inspect: loops through non-manifold edges, layered .glb files.

#[test]
fn inspect_counts_a_rim_through_a_non_manifold_edge_as_a_loop() {
    let dir = tempfile::tempdir().unwrap();
    // The cube plus a fin on its edge 0–2 (then used three times): the fin's two free edges
    // close one loop through the fin's base (counted by hand).
    let mut mesh = voxlod_testkit::shapes::unit_cube();
    mesh.positions.push(Vec3::new(0.5, -1.0, -1.0));
    mesh.triangles.push([0, 2, 8]);
    let path = write_mesh(dir.path(), "fin.obj", &mesh);
    let r = json(&voxlod(&["inspect", arg(&path), "--json"]));
    assert_eq!(r["boundary_edges"], 2);
    assert_eq!(r["boundary_loops"], 1);
    assert_eq!(r["non_manifold_edges"], 1);
    assert!(r["warnings"].as_array().unwrap().is_empty());
    let o = voxlod(&["inspect", arg(&path)]);
    assert!(
        stdout(&o).contains("2 boundary edges in 1 loop (a loop closes through"),
        "{}",
        stdout(&o)
    );
    let test = "inspect_counts_a_rim_through_a_non_manifold_edge_as_a_loop";
    if let Some(stl) = shared_data_or_skip("meshes/thingi10k-42722.stl", test) {
        let o = voxlod(&["inspect", arg(&stl)]);
        assert!(
            stdout(&o).contains("4 boundary edges in 2 loops"),
            "{}",
            stdout(&o)
        );
    }
}

#[test]
fn inspect_reads_the_layered_glb_that_render_reads() {
    let dir = tempfile::tempdir().unwrap();
    let block = write_mesh(dir.path(), "block.obj", &holed_block());
    let glb = dir.path().join("block.glb");
    let layers = json(&voxlod(&[
        "layers",
        arg(&block),
        "-o",
        arg(&glb),
        "--resolution",
        "24",
        "--error",
        "0.05",
        "--json",
    ]));
    let png = dir.path().join("block.png");
    let o = voxlod(&["render", arg(&glb), "-o", arg(&png), "--size", "40x30"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let r = json(&voxlod(&["inspect", arg(&glb), "--json"]));
    let parts = r["parts"].as_array().unwrap();
    let expected = layers["layers"].as_array().unwrap();
    assert_eq!(parts.len(), expected.len());
    for (p, l) in parts.iter().zip(expected) {
        assert_eq!(p["triangles"], l["triangles"]);
        assert_eq!(p["closed_manifold"], true);
        assert_eq!(p["genus"], 1, "each shell keeps the block's hole");
        assert!((p["alpha"].as_f64().unwrap() - l["alpha"].as_f64().unwrap()).abs() < 1e-6);
    }
    assert_eq!(r["components"], parts.len());
    assert_eq!(r["triangles"], layers["triangles"]);
    let text = stdout(&voxlod(&["inspect", arg(&glb)]));
    assert!(text.contains("mesh 0 'layer 0'"), "{text}");
}

// -------------------------------------------------------------------------------------------
// Messages.

#[test]
fn repair_is_described_in_words() {
    let dir = tempfile::tempdir().unwrap();
    // Two tetrahedra sharing a vertex: a pinched vertex that --repair splits.
    let mut positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
    positions.extend([-Vec3::X, -Vec3::Y, -Vec3::Z]);
    let triangles = vec![
        [0, 2, 1],
        [0, 1, 3],
        [0, 3, 2],
        [1, 2, 3],
        [0, 4, 5],
        [0, 6, 4],
        [0, 5, 6],
        [4, 6, 5],
    ];
    let path = write_mesh(
        dir.path(),
        "pinched.obj",
        &TriangleMesh::new(positions, triangles),
    );
    let out = dir.path().join("out.ply");
    let base = [
        "envelope",
        arg(&path),
        "-o",
        arg(&out),
        "--epsilon",
        "1%",
        "--repair",
        "--samples",
        "100",
    ];
    let o = voxlod(&base);
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains(
            "cut into a manifold for the envelope: 1 vertex added to give each fan its own"
        ),
        "{err}"
    );
    assert!(!err.contains('{'), "{err}");
    let mut with_json = base.to_vec();
    with_json.push("--json");
    let r = json(&voxlod(&with_json));
    assert_eq!(r["repair"]["vertices_added"], 1);
    assert!(r["warnings"][0]
        .as_str()
        .unwrap()
        .contains("1 vertex added to give each fan its own"));
}

#[test]
fn obj_index_errors_count_in_the_plural() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.obj");
    let mut text: String = (0..8).map(|i| format!("v {i} 0 0\n")).collect();
    text.push_str("f 1 2 9\n");
    std::fs::write(&path, text).unwrap();
    let o = voxlod(&["inspect", arg(&path)]);
    assert_clean_failure(&o, "vertex index 9 is out of range (8 vertices so far)");
}

/// A u8 raw volume 8³: 0 outside, 255 in a 4³ block.
fn u8_block(dir: &Path) -> PathBuf {
    let n = 8;
    let mut bytes = vec![0u8; n * n * n];
    for k in 2..6 {
        for j in 2..6 {
            for i in 2..6 {
                bytes[i + n * (j + n * k)] = 255;
            }
        }
    }
    let path = dir.join("block.raw");
    std::fs::write(&path, bytes).unwrap();
    path
}

#[test]
fn iso_at_the_minimum_says_what_happens() {
    let dir = tempfile::tempdir().unwrap();
    let raw = u8_block(dir.path());
    let out = dir.path().join("c.ply");
    let base = ["contour", arg(&raw), "-o", arg(&out), "--dims", "8,8,8"];
    let mut args = base.to_vec();
    args.extend(["--iso", "0"]);
    let o = voxlod(&args);
    assert_clean_failure(
        &o,
        "--iso 0 is at or below the data's minimum: every sample is inside",
    );
    assert!(!stderr(&o).contains("outside"), "{}", stderr(&o));
    assert!(!out.exists());
    // With --close, all of the volume is inside: the surface is the padded box, and a warning
    // says so (also in the JSON report).
    args.extend(["--close", "--json"]);
    let r = json(&voxlod(&args));
    assert_eq!(r["closed_manifold"], true);
    assert!(r["warnings"][0]
        .as_str()
        .unwrap()
        .contains("the surface is the box --close puts around it"));
}

#[test]
fn a_result_beyond_32_bit_floats_blames_the_flags_not_the_output() {
    let dir = tempfile::tempdir().unwrap();
    let raw = u8_block(dir.path());
    let out = dir.path().join("c.ply");
    for (flag, value) in [("--spacing", "1e39,1,1"), ("--origin", "-1e39,0,0")] {
        let o = voxlod(&[
            "contour",
            arg(&raw),
            "-o",
            arg(&out),
            "--dims",
            "8,8,8",
            "--iso",
            "128",
            flag,
            value,
        ]);
        assert_clean_failure(&o, "beyond the ±3.4e38 of 32-bit mesh coordinates");
        let err = stderr(&o);
        assert!(err.contains("check --spacing and --origin"), "{err}");
        assert!(!err.contains("c.ply"), "{err}");
        assert!(!out.exists());
    }
}

#[test]
fn render_refuses_flags_out_of_range() {
    let dir = tempfile::tempdir().unwrap();
    let cube = cube_obj(dir.path());
    let png = dir.path().join("c.png");
    for (flags, expect) in [
        (
            &["--perspective", "--fov", "0"][..],
            "--fov 0: the field of view",
        ),
        (
            &["--perspective", "--fov", "180"],
            "--fov 180: the field of view",
        ),
        (
            &["--perspective", "--fov", "-10"],
            "--fov -10: the field of view",
        ),
        (
            &["--line-width", "-1"],
            "--line-width -1: choose more than 0",
        ),
        (&["--point-size", "0"], "--point-size 0: choose more than 0"),
        (
            &["--background", "2,-1,0"],
            "--background 2,-1,0: each component is linear RGB from 0 to 1",
        ),
        (
            &["--background", "0,0,nan"],
            "invalid value '0,0,nan' for '--background <R,G,B>': 'nan' is not a finite number",
        ),
        (&["--supersample", "0"], "--supersample 0: choose 1 to 32"),
        (
            &["--size", "0x10"],
            "both sides must be between 1 and 16384",
        ),
    ] {
        let mut args = vec!["render", arg(&cube), "-o", arg(&png)];
        args.extend(flags);
        let o = voxlod(&args);
        assert_clean_failure(&o, expect);
        assert_eq!(stderr(&o).lines().count(), 1, "{}", stderr(&o));
        assert!(!png.exists());
    }
    // --fov without --perspective: drawn, with a warning (also in the JSON report).
    let r = json(&voxlod(&[
        "render",
        arg(&cube),
        "-o",
        arg(&png),
        "--size",
        "20x20",
        "--fov",
        "20",
        "--json",
    ]));
    assert!(r["warnings"][0]
        .as_str()
        .unwrap()
        .contains("--fov 20 has no effect without --perspective"));
}

#[test]
fn every_json_report_has_its_warnings() {
    let dir = tempfile::tempdir().unwrap();
    let d = |n: &str| dir.path().join(n);
    let cube = cube_obj(dir.path());
    let c = arg(&cube);
    let raw = u8_block(dir.path());
    let r = arg(&raw);
    let lod_out = d("lod");
    let glb = d("c.glb");
    let volume = d("c.nrrd");
    let [c_ply, cl_ply, e_ply, c_png, ev] = ["c.ply", "cl.ply", "e.ply", "c.png", "ev"].map(d);
    let runs: Vec<Vec<&str>> = vec![
        vec!["lod", c, "-o", arg(&lod_out), "--resolutions", "8"],
        vec!["voxelize", c, "-o", arg(&volume), "--resolution", "8"],
        vec![
            "contour",
            r,
            "-o",
            arg(&c_ply),
            "--dims",
            "8,8,8",
            "--iso",
            "100",
        ],
        vec!["cluster", c, "-o", arg(&cl_ply), "--cells", "4"],
        vec![
            "envelope",
            c,
            "-o",
            arg(&e_ply),
            "--epsilon",
            "1%",
            "--samples",
            "100",
        ],
        vec!["inspect", c],
        vec!["compare", c, c, "--samples", "100"],
        vec![
            "layers",
            c,
            "-o",
            arg(&glb),
            "--resolution",
            "12",
            "--error",
            "0.1",
        ],
        vec!["render", c, "-o", arg(&c_png), "--size", "20x20"],
        vec![
            "evaluate",
            c,
            "-o",
            arg(&ev),
            "--budgets",
            "6",
            "--methods",
            "rossignac-borrel",
            "--views",
            "0",
            "--samples",
            "100",
        ],
    ];
    for mut args in runs {
        args.push("--json");
        let report = json(&voxlod(&args));
        assert!(report["warnings"].is_array(), "{}: {report}", args[0]);
    }
    let select = json(&voxlod(&[
        "select",
        arg(&lod_out.join("report.json")),
        "--pixel-size",
        "1",
        "--json",
    ]));
    assert!(select["warnings"].is_array());
}

// -------------------------------------------------------------------------------------------
// Every error is one line.

#[test]
fn every_error_is_one_line_naming_the_flag_or_file() {
    let dir = tempfile::tempdir().unwrap();
    let cube = cube_obj(dir.path());
    let c = arg(&cube);
    let out = dir.path().join("o.ply");
    let o = arg(&out);
    let raw = u8_block(dir.path());
    let r = arg(&raw);
    for (args, expect) in [
        (vec!["contour", c, "-o", o], "--iso <V>"),
        (
            vec!["lod", c, "-o", o, "--bogus"],
            "unexpected argument '--bogus'",
        ),
        (
            vec!["lod", c, "-o", o, "--resolution", "-3"],
            "'-3' is not a whole number",
        ),
        (
            vec!["lod", c, "-o", o, "--iso", "--json"],
            "'--json' is a flag, not a number",
        ),
        (
            vec!["lod", c, "-o", o, "--origin", "1,2"],
            "takes 3 comma-separated numbers",
        ),
        (
            vec!["lod", c, "-o", o, "--iso", "1.5"],
            "--iso 1.5: the filtered density",
        ),
        (
            vec!["select", c, "--pixel-size", "0"],
            "--pixel-size 0: must be more than 0",
        ),
        (
            vec![
                "select",
                c,
                "--distance",
                "1",
                "--fov",
                "180",
                "--viewport",
                "10",
            ],
            "--fov 180: the field of view",
        ),
        (
            vec!["envelope", c, "-o", o, "--epsilon", "-1"],
            "ε must be a positive distance",
        ),
        (
            vec![
                "envelope",
                c,
                "-o",
                o,
                "--epsilon",
                "1%",
                "--keep-sharp",
                "-5",
            ],
            "--keep-sharp -5: a dihedral angle",
        ),
        (vec!["inspect", "/nonexistent/x.obj"], "/nonexistent/x.obj"),
        (
            vec!["contour", r, "-o", o, "--iso", "1", "--dims", "0,8,8"],
            "--dims 0,8,8: each dimension must be at least 1 sample",
        ),
        (
            vec![
                "contour",
                r,
                "-o",
                o,
                "--iso",
                "1",
                "--dims",
                "8,8,8",
                "--spacing",
                "1,0,1",
            ],
            "--spacing 1,0,1: the distance between samples must be more than 0",
        ),
    ] {
        let result = voxlod(&args);
        assert_clean_failure(&result, expect);
        let err = stderr(&result);
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        assert!(err.starts_with("voxlod: error: "), "{args:?}: {err}");
        assert!(!err.contains("Usage:"), "{args:?}: {err}");
    }
}

/// A negative value `negative` of a flag (`label`: subcommand and flag; `args`: the command line
/// with `--json` after the value) is either stored as written with the `--json` after it still
/// a flag, or refused by the flag's own parser, naming the value: never taken for an unknown flag.
fn negative_kept_or_refused(
    label: &str,
    negative: &str,
    args: Vec<String>,
    id: &str,
    delimiter: Option<char>,
) {
    match parsed(&args, id, delimiter) {
        (Some(raw), json) if raw == negative => {
            assert!(json, "{label} {negative}: the --json after it was lost");
        }
        _ => {
            let e = Cli::command()
                .try_get_matches_from(args)
                .expect_err("refused");
            let text = e.to_string();
            assert_eq!(
                e.kind(),
                clap::error::ErrorKind::ValueValidation,
                "{label} {negative}: {text}"
            );
            // The value (or, in a list, its first element) is named as the flag's.
            let flag = label.split(' ').nth(1).unwrap_or_default();
            assert!(
                text.contains("invalid value '-1") && text.contains(&format!("for '{flag} ")),
                "{label} {negative}: {text}"
            );
        }
    }
}
