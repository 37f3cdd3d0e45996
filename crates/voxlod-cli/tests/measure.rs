//! The measurement commands end to end: `inspect`, `compare` and `evaluate` on meshes whose
//! answers are known, on the shared real data when present, and on bad input (clean failure,
//! one line naming the file, nothing written).

mod common;

use std::path::Path;
use std::process::{Command, Output};

use common::*;
use voxlod::core::glam::Vec3;
use voxlod::core::TriangleMesh;
use voxlod_testkit::data::shared_data_or_skip;
use voxlod_testkit::shapes::{torus, unit_cube};

/// Every triangle with its own three vertices: the same surface as a soup.
fn soup(mesh: &TriangleMesh) -> TriangleMesh {
    let mut out = TriangleMesh::default();
    for t in 0..mesh.triangles.len() {
        for v in mesh.triangles[t] {
            out.positions.push(mesh.positions[v as usize]);
        }
        let base = out.positions.len() as u32 - 3;
        out.triangles.push([base, base + 1, base + 2]);
    }
    out
}

fn shifted(mut mesh: TriangleMesh, by: Vec3) -> TriangleMesh {
    for p in &mut mesh.positions {
        *p += by;
    }
    mesh
}

/// Three triangles, all with zero area (collinear corners).
fn flat_mesh() -> TriangleMesh {
    TriangleMesh::new(
        vec![Vec3::ZERO, Vec3::X, Vec3::X * 2.0, Vec3::X * 3.0],
        vec![[0, 1, 2], [1, 2, 3], [0, 2, 3]],
    )
}

fn close(a: f64, b: f64, tolerance: f64) -> bool {
    (a - b).abs() <= tolerance * b.abs().max(1e-300)
}

/// Runs `voxlod` with an extra environment variable.
fn voxlod_with_env(args: &[&str], key: &str, value: &str) -> Output {
    Command::new(env!("CARGO_BIN_EXE_voxlod"))
        .args(args)
        .env(key, value)
        .output()
        .expect("the voxlod binary runs")
}

// ---------------------------------------------------------------------------------------------
// inspect

#[test]
fn inspect_reports_the_holed_block() {
    let dir = tempfile::tempdir().unwrap();
    let input = write_mesh(dir.path(), "block.obj", &holed_block());
    let r = json(&voxlod(&["inspect", arg(&input), "--json"]));
    assert_eq!(r["components"], 1);
    assert_eq!(r["boundary_loops"], 0);
    assert_eq!(r["genus"], 1);
    assert_eq!(r["euler_characteristic"], 0);
    assert_eq!(r["closed_manifold"], true);
    assert_eq!(r["consistently_oriented"], true);
    assert_eq!(r["welded"], true);
    assert_eq!(r["file_vertices"], 16);
    assert_eq!(r["vertices"], 16);
    assert_eq!(r["triangles"], 32);
    // A 2 × 2 × 1 block less a 0.8 × 0.8 hole through it.
    let volume = r["volume"].as_f64().unwrap();
    assert!(close(volume, 4.0 - 0.64, 1e-6), "volume {volume}");
    assert_eq!(r["volume_is_enclosed"], true);
    let area = 2.0 * (4.0 - 0.64) + 4.0 * 2.0 * 1.0 + 4.0 * 0.8 * 1.0;
    assert!(close(r["area"].as_f64().unwrap(), area, 1e-6));
    let human = voxlod(&["inspect", arg(&input)]);
    assert!(human.status.success());
    let text = stdout(&human);
    assert!(text.contains("genus 1"), "{text}");
    assert!(text.contains("counted after welding"), "{text}");
}

#[test]
fn inspect_welds_a_soup_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let block = holed_block();
    let input = write_mesh(dir.path(), "soup.obj", &soup(&block));
    let r = json(&voxlod(&["inspect", arg(&input), "--json"]));
    assert_eq!(r["file_vertices"], 96);
    assert_eq!(r["vertices"], 16);
    assert_eq!(r["welding"]["vertices_before"], 96);
    assert_eq!(r["welding"]["vertices_after"], 16);
    assert_eq!(r["genus"], 1);
    assert_eq!(r["closed_manifold"], true);
    let notes = r["notes"].as_array().unwrap();
    assert!(notes[0].as_str().unwrap().contains("96 vertices became 16"));

    // As indexed, the soup is 32 separate triangles, each with a boundary loop.
    let r = json(&voxlod(&["inspect", arg(&input), "--as-indexed", "--json"]));
    assert_eq!(r["welded"], false);
    assert_eq!(r["vertices"], 96);
    assert_eq!(r["components"], 32);
    assert_eq!(r["boundary_loops"], 32);
    assert_eq!(r["closed_manifold"], false);
    assert!(r["genus"].is_null() || r["genus"] == 0, "{}", r["genus"]);
    assert!(r["notes"][0].as_str().unwrap().contains("not welded"));

    // An STL file is a soup the reader welds: the file's corners are still reported.
    let stl = write_mesh(dir.path(), "block.stl", &block);
    let r = json(&voxlod(&["inspect", arg(&stl), "--json"]));
    assert_eq!(r["format"], "STL");
    assert_eq!(r["file_vertices"], 96);
    assert_eq!(r["vertices"], 16);
    assert_eq!(r["genus"], 1);
}

#[test]
fn inspect_reports_an_inside_out_shell_and_a_mesh_without_area() {
    let dir = tempfile::tempdir().unwrap();
    let mut cube = unit_cube();
    cube.flip_orientation();
    let input = write_mesh(dir.path(), "inside-out.ply", &cube);
    let r = json(&voxlod(&["inspect", arg(&input), "--json"]));
    assert_eq!(r["inside_out"], true);
    assert!(close(r["volume"].as_f64().unwrap(), -1.0, 1e-6));

    // No area is reported (with a note), not refused: inspecting is how one finds out.
    let flat = write_mesh(dir.path(), "flat.obj", &flat_mesh());
    let r = json(&voxlod(&["inspect", arg(&flat), "--json"]));
    assert_eq!(r["area"], 0.0);
    assert_eq!(r["zero_area_triangles"], 3);
    let notes: Vec<&str> = r["notes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n.as_str().unwrap())
        .collect();
    assert!(notes.iter().any(|n| n.contains("has no area")), "{notes:?}");
}

#[test]
fn inspect_matches_the_shared_meshes_documented_shape() {
    // ../shared/data/README.md: the bunny has 5 holes and 1,113 unreferenced vertices; the
    // rocker arm is closed with genus 1; the ASCII STL 68247 is closed only after welding.
    let Some(bunny) = shared_data_or_skip("meshes/stanford-bunny.obj", "inspect shared meshes")
    else {
        return;
    };
    let r = json(&voxlod(&["inspect", arg(&bunny), "--json"]));
    assert_eq!(r["boundary_loops"], 5);
    assert_eq!(r["unreferenced_vertices"], 1113);
    assert_eq!(r["triangles"], 69_451);
    let rocker = bunny.with_file_name("rocker-arm.obj");
    let r = json(&voxlod(&["inspect", arg(&rocker), "--json"]));
    assert_eq!(r["genus"], 1);
    assert_eq!(r["closed_manifold"], true);
    let stl = bunny.with_file_name("thingi10k-68247.stl");
    let r = json(&voxlod(&["inspect", arg(&stl), "--json"]));
    assert_eq!(r["file_vertices"], 3 * 78);
    assert_eq!(r["boundary_loops"], 0);
    assert_eq!(r["inside_out"], true);
}

// ---------------------------------------------------------------------------------------------
// compare

#[test]
fn compare_gives_the_shift_between_two_cubes() {
    let dir = tempfile::tempdir().unwrap();
    let d = 0.125f32;
    let a = write_mesh(dir.path(), "a.ply", &unit_cube());
    let b = write_mesh(dir.path(), "b.obj", &shifted(unit_cube(), Vec3::X * d));
    let r = json(&voxlod(&[
        "compare",
        arg(&a),
        arg(&b),
        "--samples",
        "20000",
        "--json",
    ]));
    let d = d as f64;
    let hausdorff = r["hausdorff"].as_f64().unwrap();
    assert!((hausdorff - d).abs() < 1e-9, "hausdorff {hausdorff}");
    // The analytic mean of this pair (see the metrics crate's shifted-cube test).
    let mean = d / 3.0 + 2.0 * d.powi(3) / 9.0;
    assert!(close(r["mean"].as_f64().unwrap(), mean, 0.01));
    let diagonal = ((1.0 + d) * (1.0 + d) + 2.0f64).sqrt();
    assert!(close(r["diagonal"].as_f64().unwrap(), diagonal, 1e-9));
    for key in ["hausdorff", "mean", "rms"] {
        let fraction = r[format!("{key}_fraction")].as_f64().unwrap();
        assert!(close(fraction, r[key].as_f64().unwrap() / diagonal, 1e-12));
    }
    assert_eq!(r["samples"], 20_000);
    assert_eq!(r["a_triangles"], 12);
    assert!(r["first_to_second"]["max"].is_number());
    assert!(r["rms"].as_f64().unwrap() >= r["mean"].as_f64().unwrap());
    assert!(r["warnings"].as_array().unwrap().is_empty());

    // Swapping the files swaps the sides and keeps the two-sided figures.
    let s = json(&voxlod(&[
        "compare",
        arg(&b),
        arg(&a),
        "--samples",
        "20000",
        "--json",
    ]));
    assert!((s["hausdorff"].as_f64().unwrap() - d).abs() < 1e-9);
    assert_eq!(s["diagonal"], r["diagonal"]);

    let human = voxlod(&["compare", arg(&a), arg(&b), "--samples", "1000"]);
    assert!(human.status.success(), "{}", stderr(&human));
    let text = stdout(&human);
    assert!(
        text.contains("hausdorff") && text.contains("% of the diagonal"),
        "{text}"
    );
}

#[test]
fn compare_of_a_mesh_with_itself_is_zero_and_seeded() {
    let dir = tempfile::tempdir().unwrap();
    let ring = torus(60, 30, 2.0, 0.6);
    let a = write_mesh(dir.path(), "a.ply", &ring);
    let b = write_mesh(dir.path(), "b.stl", &ring);
    let r = json(&voxlod(&["compare", arg(&a), arg(&b), "--json"]));
    assert!(r["hausdorff"].as_f64().unwrap() < 1e-6, "{r}");
    let bumpy =
        voxlod_testkit::shapes::torus_with(50, 25, 2.0, |u, _| 0.6 + 0.05 * (5.0 * u).sin());
    let c = write_mesh(dir.path(), "c.ply", &bumpy);
    let run = |seed: &str| {
        json(&voxlod(&[
            "compare",
            arg(&a),
            arg(&c),
            "--samples",
            "5000",
            "--seed",
            seed,
            "--json",
        ]))
    };
    let (one, again, other) = (run("7"), run("7"), run("8"));
    assert_eq!(one["mean"], again["mean"]);
    assert_ne!(one["mean"], other["mean"]);
    assert!(close(
        one["mean"].as_f64().unwrap(),
        other["mean"].as_f64().unwrap(),
        0.05
    ));
}

#[test]
fn compare_warns_about_meshes_in_different_frames() {
    let dir = tempfile::tempdir().unwrap();
    let a = write_mesh(dir.path(), "a.ply", &unit_cube());
    let far = write_mesh(
        dir.path(),
        "far.ply",
        &shifted(unit_cube(), Vec3::new(100.0, 0.0, 0.0)),
    );
    let r = json(&voxlod(&[
        "compare",
        arg(&a),
        arg(&far),
        "--samples",
        "100",
        "--json",
    ]));
    let warnings = r["warnings"].as_array().unwrap();
    assert!(warnings[0].as_str().unwrap().contains("do not overlap"));
}

#[test]
fn compare_refuses_bad_input_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let good = write_mesh(dir.path(), "good.ply", &unit_cube());
    let flat = write_mesh(dir.path(), "flat.obj", &flat_mesh());
    let empty = dir.path().join("empty.ply");
    std::fs::write(&empty, b"").unwrap();
    let no_faces = dir.path().join("points.obj");
    std::fs::write(&no_faces, "v 0 0 0\nv 1 0 0\nv 0 1 0\n").unwrap();
    let garbage = dir.path().join("garbage.ply");
    std::fs::write(&garbage, b"this is not a PLY file\n").unwrap();
    let volume = dir.path().join("volume.nrrd");
    let grid = voxlod::core::Grid::new([4, 4, 4], [1.0; 3], [0.0; 3]).unwrap();
    voxlod::io::write_volume(
        &volume,
        &voxlod::core::Volume::filled(grid, 1.0, "v").unwrap(),
    )
    .unwrap();
    let missing = dir.path().join("missing.obj");
    let cases: [(&Path, &str); 6] = [
        (&flat, "no area"),
        (&empty, "empty.ply"),
        (&no_faces, "points.obj"),
        (&garbage, "garbage.ply"),
        (&volume, "volume"),
        (&missing, "missing.obj"),
    ];
    for (bad, what) in cases {
        let o = voxlod(&["compare", arg(&good), arg(bad)]);
        assert_clean_failure(&o, what);
        assert_clean_failure(&o, bad.file_name().unwrap().to_str().unwrap());
        let o = voxlod(&["compare", arg(bad), arg(&good), "--json"]);
        assert_clean_failure(&o, bad.file_name().unwrap().to_str().unwrap());
        assert!(stdout(&o).is_empty(), "no JSON on failure");
    }
    let o = voxlod(&["compare", arg(&good), arg(&good), "--samples", "0"]);
    assert_clean_failure(&o, "--samples");
}

// ---------------------------------------------------------------------------------------------
// evaluate

/// The PNG's width and height, after checking its signature.
fn png_size(path: &Path) -> (u32, u32) {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "not a PNG");
    assert_eq!(&bytes[12..16], b"IHDR");
    let be = |b: &[u8]| u32::from_be_bytes([b[0], b[1], b[2], b[3]]);
    (be(&bytes[16..20]), be(&bytes[20..24]))
}

const ALL_METHODS: [&str; 9] = [
    "voxel-hypercone",
    "voxel-gaussian",
    "rossignac-borrel",
    "low-tan",
    "envelope",
    "voxel-envelope",
    "budget",
    "meshopt-simplify",
    "meshopt-sloppy",
];

/// Every method but the two simplification-envelope ones, the slow ones on real meshes.
const FAST_METHODS: [&str; 7] = [
    "voxel-hypercone",
    "voxel-gaussian",
    "rossignac-borrel",
    "low-tan",
    "budget",
    "meshopt-simplify",
    "meshopt-sloppy",
];

/// Checks the files and the curves of an evaluation written to `out`; returns report.json.
fn check_evaluation(out: &Path, methods: &[&str]) -> serde_json::Value {
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    let markdown = std::fs::read_to_string(out.join("report.md")).unwrap();
    // Two panels (Hausdorff, mean), and a third for silhouettes when they were measured.
    let views = report["image_views"].as_u64().unwrap();
    let panels = if views > 0 { 3 } else { 2 };
    assert_eq!(png_size(&out.join("plot.png")), (700 * panels, 600));
    assert_eq!(report["plot"], "plot.png");
    let previews = report["previews"].as_array().unwrap();
    assert_eq!(previews.len(), if views > 0 { methods.len() } else { 0 });
    for p in previews {
        let file = p.as_str().unwrap();
        let (w, h) = png_size(&out.join(file));
        assert_eq!(h, 200);
        assert!(w > 400, "{file}: {w} wide");
        assert!(markdown.contains(&format!("]({file})")));
    }
    assert!(markdown.contains("](plot.png)"));
    let curves = report["curves"].as_array().unwrap();
    let names: Vec<&str> = curves
        .iter()
        .map(|c| c["method"].as_str().unwrap())
        .collect();
    assert_eq!(names, methods);
    let tolerance = report["tolerance"].as_f64().unwrap();
    for c in curves {
        let method = c["method"].as_str().unwrap();
        assert!(
            markdown.contains(&format!("## {method}")),
            "{method} missing from report.md"
        );
        let points = c["points"].as_array().unwrap();
        assert!(!points.is_empty(), "{method} has no measured level");
        for p in points {
            check_point(method, p, &report, tolerance, views);
        }
        // Fewer triangles, more error: the coarsest level is further from the input than the
        // finest (mean distance, which sampling measures stably).
        let by_triangles = |p: &serde_json::Value| p["triangles"].as_u64().unwrap();
        let finest = points.iter().max_by_key(|p| by_triangles(p)).unwrap();
        let coarsest = points.iter().min_by_key(|p| by_triangles(p)).unwrap();
        if points.len() > 1 {
            assert!(
                coarsest["mean_fraction"].as_f64().unwrap()
                    > finest["mean_fraction"].as_f64().unwrap(),
                "{method}: coarse {coarsest} vs fine {finest}"
            );
            if views > 0 {
                let silhouette =
                    |p: &serde_json::Value| p["image_difference"]["fraction"].as_f64().unwrap();
                assert!(
                    silhouette(coarsest) > silhouette(finest),
                    "{method}: coarse {coarsest} vs fine {finest}"
                );
            }
        }
    }
    // The inputs here are manifolds: nothing is left out.
    assert_eq!(report["omitted"], serde_json::json!([]));
    report
}

/// The checks of one measured level `p` of `method` in an `evaluate` report.
fn check_point(
    method: &str,
    p: &serde_json::Value,
    report: &serde_json::Value,
    tolerance: f64,
    views: u64,
) {
    let (t, b) = (
        p["triangles"].as_f64().unwrap(),
        p["budget"].as_f64().unwrap(),
    );
    // Near the budget: within the tolerance where the parameter's integer steps allow,
    // and never off by more than a factor of 1.5.
    assert!(
        (t / b).ln().abs() <= 1.5f64.ln().max((1.0 + tolerance).ln()),
        "{method}: {t} triangles for budget {b}"
    );
    let h = p["hausdorff_fraction"].as_f64().unwrap();
    let m = p["mean_fraction"].as_f64().unwrap();
    assert!(h > 0.0 && m > 0.0 && m <= h, "{method}: {p}");
    let sides = p["input_to_level_fraction"]
        .as_f64()
        .unwrap()
        .max(p["level_to_input_fraction"].as_f64().unwrap());
    assert!(close(sides, h, 1e-12));
    if method.starts_with("voxel") {
        assert_eq!(p["closed_manifold"], true, "{method}: {p}");
    }
    if method == "envelope" {
        // The envelope's guarantees: within ε (the parameter, in percent of the
        // diagonal) both ways, the input's topology kept.
        let epsilon = p["parameter"].as_f64().unwrap() / 100.0;
        assert!(h <= epsilon * (1.0 + 1e-6), "{method}: {p}");
        assert_eq!(p["genus"], report["input"]["genus"], "{p}");
        assert_eq!(p["components"], report["input"]["components"], "{p}");
        assert_eq!(
            p["boundary_loops"], report["input"]["boundary_loops"],
            "{p}"
        );
    }
    if views > 0 {
        let d = &p["image_difference"];
        let f = d["fraction"].as_f64().unwrap();
        assert!((0.0..=1.0).contains(&f), "{method}: {d}");
        assert_eq!(d["views"], views);
        assert!(d["differing_pixels"].as_u64() <= d["covered_pixels"].as_u64());
    } else {
        assert!(p["image_difference"].is_null());
    }
}

#[test]
fn evaluate_runs_every_method_on_a_torus() {
    let dir = tempfile::tempdir().unwrap();
    let input = write_mesh(dir.path(), "ring.ply", &torus(64, 32, 2.0, 0.7));
    let out = dir.path().join("eval");
    let o = voxlod(&[
        "evaluate",
        arg(&input),
        "-o",
        arg(&out),
        "--budgets",
        "1000,250",
        "--samples",
        "5000",
        "--meshes",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report = check_evaluation(&out, &ALL_METHODS);
    assert_eq!(report["budgets"], serde_json::json!([1000, 250]));
    assert_eq!(report["input"]["triangles"], 4096);
    assert_eq!(report["input"]["genus"], 1);
    assert_eq!(report["samples_per_side"], 5000);
    for c in report["curves"].as_array().unwrap() {
        let first = &c["points"][0];
        assert_eq!(first["budget"], 1000);
        // At 1000 triangles the ring's hole (1.2 wide in a ring 5.4 across) survives the voxel
        // filters: a closed genus-1 surface.
        if c["method"].as_str().unwrap().starts_with("voxel") {
            assert_eq!(first["genus"], 1, "{first}");
            assert_eq!(first["components"], 1);
        }
    }
    // --meshes wrote every kept level, readable, with the reported triangle counts.
    for file in report["meshes"].as_array().unwrap() {
        let mesh = voxlod::io::read_mesh(&out.join(file.as_str().unwrap()))
            .unwrap()
            .mesh;
        assert!(!mesh.triangles.is_empty());
    }
    let levels: usize = report["curves"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["points"].as_array().unwrap().len())
        .sum();
    assert_eq!(report["meshes"].as_array().unwrap().len(), levels);
}

#[test]
fn evaluate_runs_the_methods_asked_for_and_prints_json() {
    let dir = tempfile::tempdir().unwrap();
    let input = write_mesh(dir.path(), "ring.obj", &torus(32, 16, 2.0, 0.7));
    let out = dir.path().join("eval");
    let o = voxlod(&[
        "evaluate",
        arg(&input),
        "-o",
        arg(&out),
        "--budgets",
        "2000,300",
        "--samples",
        "2000",
        "--views",
        "0",
        "--methods",
        "rossignac-borrel,voxel-gaussian,rossignac-borrel",
        "--json",
    ]);
    let printed = json(&o);
    let on_disk = check_evaluation(&out, &["rossignac-borrel", "voxel-gaussian"]);
    assert_eq!(printed["curves"], on_disk["curves"]);
    // Clustering cannot make more triangles than the input's 1024: budget 2000 is a miss, said
    // so; the voxel pipeline reaches it.
    let clustering = &on_disk["curves"][0];
    assert_eq!(clustering["points"].as_array().unwrap().len(), 1);
    let misses = clustering["misses"].as_array().unwrap();
    assert!(
        misses[0]
            .as_str()
            .unwrap()
            .contains("budget 2000: out of reach"),
        "{misses:?}"
    );
    assert_eq!(on_disk["curves"][1]["points"].as_array().unwrap().len(), 2);
    let markdown = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(markdown.contains("budget 2000: out of reach"));
    assert!(
        !out.join("previews").exists(),
        "--views 0 draws no previews"
    );
}

#[test]
fn evaluate_repairs_a_non_manifold_input_for_the_envelope_and_says_so() {
    // A ring with a fin: a third triangle on one of its edges makes that edge non-manifold.
    let mut mesh = torus(32, 16, 2.0, 0.7);
    let [a, b, _] = mesh.triangles[0];
    let tip = mesh.positions[a as usize] + Vec3::new(0.0, 0.0, 3.0);
    mesh.positions.push(tip);
    mesh.triangles.push([a, b, mesh.positions.len() as u32 - 1]);
    let dir = tempfile::tempdir().unwrap();
    let input = write_mesh(dir.path(), "fin.ply", &mesh);
    let out = dir.path().join("eval");
    let o = voxlod(&[
        "evaluate",
        arg(&input),
        "-o",
        arg(&out),
        "--budgets",
        "300",
        "--samples",
        "2000",
        "--views",
        "0",
        "--methods",
        "envelope",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    let curve = &report["curves"][0];
    assert_eq!(curve["method"], "envelope");
    let notes = curve["notes"].as_array().unwrap();
    assert_eq!(notes.len(), 1, "{notes:?}");
    assert!(notes[0].as_str().unwrap().contains("repaired"), "{notes:?}");
    let markdown = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(markdown.contains("repaired copy"));
    assert_eq!(curve["points"].as_array().unwrap().len(), 1, "{curve}");
}

#[test]
fn evaluate_without_a_font_draws_a_plain_chart_and_a_legend_in_words() {
    let dir = tempfile::tempdir().unwrap();
    let input = write_mesh(dir.path(), "ring.ply", &torus(40, 20, 2.0, 0.7));
    let out = dir.path().join("eval");
    let o = voxlod_with_env(
        &[
            "evaluate",
            arg(&input),
            "-o",
            arg(&out),
            "--budgets",
            "600",
            "--samples",
            "2000",
        ],
        "VOXLOD_FONT",
        "none",
    );
    assert!(o.status.success(), "{}", stderr(&o));
    check_evaluation(&out, &ALL_METHODS);
    let markdown = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(markdown.contains("The chart has no text"), "{markdown}");
    assert!(markdown.contains("`#d62728`: voxel-hypercone"));
}

#[test]
fn evaluate_refuses_bad_input_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let flat = write_mesh(dir.path(), "flat.obj", &flat_mesh());
    let empty = dir.path().join("empty.obj");
    std::fs::write(&empty, b"").unwrap();
    let volume = dir.path().join("volume.nrrd");
    let grid = voxlod::core::Grid::new([4, 4, 4], [1.0; 3], [0.0; 3]).unwrap();
    voxlod::io::write_volume(
        &volume,
        &voxlod::core::Volume::filled(grid, 1.0, "v").unwrap(),
    )
    .unwrap();
    let good = write_mesh(dir.path(), "good.ply", &torus(16, 8, 2.0, 0.7));
    let out = dir.path().join("never");
    let cases: [(&Path, &[&str], &str); 8] = [
        (&flat, &[], "no area"),
        (&empty, &[], "empty.obj"),
        (&volume, &[], "volume"),
        (&good, &["--budgets", "100,0"], "--budgets"),
        (&good, &["--samples", "0"], "--samples"),
        (&good, &["--tolerance", "1.5"], "--tolerance"),
        (&good, &["--methods", "quadric"], "quadric"),
        (&good, &["--views", "20"], "--views"),
    ];
    for (input, extra, what) in cases {
        let mut args = vec!["evaluate", arg(input), "-o", arg(&out)];
        args.extend_from_slice(extra);
        let o = voxlod(&args);
        assert!(!o.status.success(), "{args:?} succeeded");
        let err = stderr(&o);
        assert!(!err.contains("panicked"), "{err}");
        assert!(
            err.contains(what),
            "{args:?}: error does not mention {what}: {err}"
        );
        assert!(!out.exists(), "{args:?} created the output folder");
    }
    // Too few triangles for any halving budget.
    let tiny = write_mesh(dir.path(), "cube.ply", &unit_cube());
    let o = voxlod(&["evaluate", arg(&tiny), "-o", arg(&out)]);
    assert_clean_failure(&o, "no budgets");
    assert!(!out.exists());
}

#[test]
fn evaluate_completes_on_the_bunny_and_the_rocker_arm() {
    for name in ["stanford-bunny.obj", "rocker-arm.obj"] {
        let Some(input) = shared_data_or_skip(&format!("meshes/{name}"), "evaluate real meshes")
        else {
            return;
        };
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("eval");
        let o = voxlod(&[
            "evaluate",
            arg(&input),
            "-o",
            arg(&out),
            "--budgets",
            "4000,2000,1000,500",
            "--samples",
            "20000",
            // The envelope methods take about a minute per mesh here; on these meshes they
            // are run by voxlod-envelope's `envelope_real_data` tests, and through `evaluate`
            // on the generated inputs above.
            "--methods",
            &FAST_METHODS.join(","),
        ]);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        let report = check_evaluation(&out, &FAST_METHODS);
        for c in report["curves"].as_array().unwrap() {
            assert!(
                c["points"].as_array().unwrap().len() >= 4,
                "{name}: {} kept too few levels: {}",
                c["method"],
                c["misses"]
            );
        }
    }
}
