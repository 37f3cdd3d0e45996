//! `lod --format glb` and `view` end to end: the chain file beside (or instead of) the level
//! files, its report, and clean refusals of bad flags and corrupt inputs.

mod common;

use std::path::Path;
use std::process::Output;

use common::*;

/// `voxlod lod INPUT -o OUT --resolutions 24,12,6 --format glb --json EXTRA...`
fn lod_glb(input: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "lod",
        arg(input),
        "-o",
        arg(out),
        "--resolutions",
        "24,12,6",
    ];
    args.extend(["--format", "glb", "--json"]);
    args.extend(extra);
    voxlod(&args)
}

#[test]
fn lod_writes_one_chain_file_and_split_keeps_the_levels() {
    let dir = tempfile::tempdir().unwrap();
    let input = write_mesh(dir.path(), "block.ply", &holed_block());
    let out = dir.path().join("out");
    let o = lod_glb(&input, &out, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let mut names: Vec<String> = files_in(&out)
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["lod.glb", "report.json"]);
    let report = json(&o);
    assert_eq!(report["glb"]["levels"], 3);
    let coverage = report["glb"]["screen_coverage"].as_array().unwrap();
    assert_eq!(coverage.len(), 3);
    let plain = report["glb"]["bytes"].as_u64().unwrap();
    assert_eq!(plain, std::fs::metadata(out.join("lod.glb")).unwrap().len());

    let o = lod_glb(&input, &out, &["--split", "--compress", "meshopt"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(out.join("level-0.ply").is_file() && out.join("level-2.ply").is_file());
    let packed = json(&o)["glb"]["bytes"].as_u64().unwrap();
    assert!(packed * 2 < plain, "meshopt {packed} bytes against {plain}");

    let page = dir.path().join("page.html");
    let o = voxlod(&[
        "view",
        arg(&out.join("lod.glb")),
        "-o",
        arg(&page),
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(json(&o)["models"][0]["kind"], "lod chain");
    assert!(std::fs::read_to_string(&page)
        .unwrap()
        .contains("voxlod-data"));
}

#[test]
fn bad_flags_and_corrupt_inputs_are_refused_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let input = write_mesh(dir.path(), "block.ply", &holed_block());
    let out = dir.path().join("out");
    let o = voxlod(&["lod", arg(&input), "-o", arg(&out), "--split"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--format glb"), "{}", stderr(&o));
    assert!(!out.exists());

    let corrupt = dir.path().join("corrupt.glb");
    std::fs::write(&corrupt, b"glTF\x02\x00\x00\x00garbage").unwrap();
    let page = dir.path().join("page.html");
    let o = voxlod(&["view", arg(&corrupt), "-o", arg(&page)]);
    assert_clean_failure(&o, "corrupt.glb");
    assert!(!page.exists());
}
