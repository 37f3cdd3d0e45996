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

/// The JSON chunk of a `.glb` (the first chunk, after the 12-byte header and its own 8).
fn glb_json(path: &Path) -> serde_json::Value {
    let bytes = std::fs::read(path).unwrap();
    let len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    serde_json::from_slice(&bytes[20..20 + len]).unwrap()
}

fn assert_validator_clean(path: &Path) {
    if let Some(v) = voxlod_testkit::gltf_validator::validate_gltf(path) {
        assert_eq!((v.errors, v.warnings), (0, 0), "{}", v.report);
    }
}

#[test]
fn cluster_writes_every_level_with_its_edges_and_points_into_one_glb() {
    let dir = tempfile::tempdir().unwrap();
    let input = write_mesh(dir.path(), "block.ply", &holed_block());
    let out = dir.path().join("rb.glb");
    let o = voxlod(&[
        "cluster",
        arg(&input),
        "-o",
        arg(&out),
        "--cells",
        "3",
        "--levels",
        "3",
        "--thick-edges",
        "true",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(files_in(dir.path()).len(), 2, "the input and rb.glb only");
    let report = json(&o);
    let levels = report["levels"].as_array().unwrap();
    assert_eq!(levels.len(), 3);
    let doc = glb_json(&out);
    assert_eq!(
        doc["nodes"][0]["extensions"]["MSFT_lod"]["ids"],
        serde_json::json!([1, 2])
    );
    let mut edges_seen = 0;
    for (k, level) in levels.iter().enumerate() {
        let n = |key: &str| level[key].as_u64().unwrap();
        assert_eq!(level["file"], arg(&out));
        // One primitive per kind the level has: triangles (4), lines (1), points (0).
        let prims = doc["meshes"][k]["primitives"].as_array().unwrap();
        let modes: Vec<u64> = prims
            .iter()
            .map(|p| p["mode"].as_u64().unwrap_or(4))
            .collect();
        let expect: Vec<u64> = [
            (n("triangles"), 4),
            (n("dangling_edges"), 1),
            (n("isolated_points"), 0),
        ]
        .iter()
        .filter(|(count, _)| *count > 0)
        .map(|&(_, mode)| mode)
        .collect();
        assert_eq!(modes, expect, "level {k}");
        for p in prims {
            let count = doc["accessors"][p["attributes"]["POSITION"].as_u64().unwrap() as usize]
                ["count"]
                .as_u64()
                .unwrap();
            match p["mode"].as_u64().unwrap_or(4) {
                1 => {
                    assert_eq!(count, 2 * n("dangling_edges"));
                    // Thick edges: a width per line end.
                    let w = p["attributes"]["_WIDTH"].as_u64().unwrap() as usize;
                    assert_eq!(doc["accessors"][w]["count"].as_u64(), Some(count));
                    edges_seen += 1;
                }
                0 => assert_eq!(count, n("isolated_points")),
                _ => {}
            }
        }
    }
    assert!(edges_seen > 0, "the coarse levels have dangling edges");
    assert_validator_clean(&out);
    let page = dir.path().join("page.html");
    let o = voxlod(&["view", arg(&out), "-o", arg(&page), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(json(&o)["models"][0]["kind"], "lod chain");
}

#[test]
fn layers_lod_writes_a_layered_chain_the_viewer_knows() {
    let dir = tempfile::tempdir().unwrap();
    let input = write_mesh(dir.path(), "block.ply", &holed_block());
    let out = dir.path().join("chain.glb");
    let o = voxlod(&[
        "layers",
        arg(&input),
        "-o",
        arg(&out),
        "--resolution",
        "24",
        "--lod",
        "--levels",
        "2",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report = json(&o);
    let lod = &report["lod"];
    let res: Vec<u64> = lod["levels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l["resolution"].as_u64().unwrap())
        .collect();
    assert_eq!(res, vec![24, 12]);
    assert_eq!(lod["radius_limit_pixels"], 0.45);
    assert_eq!(
        lod["bytes"].as_u64(),
        Some(std::fs::metadata(&out).unwrap().len())
    );
    let doc = glb_json(&out);
    assert_eq!(doc["meshes"].as_array().unwrap().len(), 2);
    for (k, level) in lod["levels"].as_array().unwrap().iter().enumerate() {
        let prims = doc["meshes"][k]["primitives"].as_array().unwrap().len() as u64;
        assert_eq!(
            Some(prims),
            level["layers"].as_u64(),
            "level {k}: a primitive per layer"
        );
        let radius = doc["nodes"][k]["extras"]["voxlod"]["radius"]
            .as_f64()
            .unwrap();
        assert_eq!(Some(radius), level["radius"].as_f64());
    }
    assert_validator_clean(&out);
    let page = dir.path().join("page.html");
    let o = voxlod(&["view", arg(&out), "-o", arg(&page), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(json(&o)["models"][0]["kind"], "layered lod chain");
    assert_eq!(json(&o)["models"][0]["levels"], 2);

    // Refused before any work: a chain into a mesh file, rising resolutions, too many halvings.
    for (extra, what) in [
        (vec!["-o", "x.ply", "--lod"], "must be a .glb"),
        (
            vec!["-o", "x.glb", "--lod", "--resolutions", "12,24"],
            "decrease strictly",
        ),
        (
            vec!["-o", "x.glb", "--lod", "--levels", "6"],
            "at least 2 samples",
        ),
        (vec!["-o", "x.glb", "--resolutions", "24,12"], "needs --lod"),
    ] {
        let mut args = vec!["layers", arg(&input), "--resolution", "24"];
        args.extend(extra);
        let o = voxlod(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(what), "{args:?}: {}", stderr(&o));
    }
}

/// The centre of the box of `doc`'s node 0's positions (its accessors' bounds): where the page
/// aims its camera for a plain `MSFT_lod` chain.
fn finest_centre(doc: &serde_json::Value) -> [f64; 3] {
    let mesh = doc["nodes"][0]["mesh"].as_u64().unwrap() as usize;
    let (mut lo, mut hi) = ([f64::MAX; 3], [f64::MIN; 3]);
    for p in doc["meshes"][mesh]["primitives"].as_array().unwrap() {
        let a = &doc["accessors"][p["attributes"]["POSITION"].as_u64().unwrap() as usize];
        for k in 0..3 {
            lo[k] = lo[k].min(a["min"][k].as_f64().unwrap());
            hi[k] = hi[k].max(a["max"][k].as_f64().unwrap());
        }
    }
    std::array::from_fn(|k| (lo[k] + hi[k]) / 2.0)
}

/// The proxy of the three-part scene (`voxlod proxy`, one baked material per level) seen from
/// +z in the page: at points of the source's surfaces, the colours of their checker squares
/// (red and white on the large sphere, blue and yellow on the one passing through it) and the
/// third sphere's green, not the grey an untextured viewer shows.
#[test]
fn a_scene_proxy_shows_its_baked_colours_in_the_viewer() {
    let Some(browser) = voxlod_testkit::browser::chromium() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.glb");
    let source = voxlod_testkit::assets::three_part_scene();
    let bytes = voxlod::gltf::asset_glb(&[source], &Default::default()).unwrap();
    std::fs::write(&scene, bytes).unwrap();
    let proxy = dir.path().join("proxy.glb");
    let o = voxlod(&[
        "proxy",
        arg(&scene),
        "-o",
        arg(&proxy),
        "--triangles",
        "1500",
        "--texture",
        "256",
        "--no-appearance",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let page = dir.path().join("proxy.html");
    let o = voxlod(&["view", arg(&proxy), "-o", arg(&page)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (size, distance) = (400u32, 7.0);
    let png = dir.path().join("proxy.png");
    let options = voxlod_testkit::browser::ShotOptions {
        size,
        distance,
        direction: [0.0, 0.0, 1.0],
        ..Default::default()
    };
    voxlod_testkit::browser::screenshot(&browser, &page, &options, &png);
    let img = image::open(&png).unwrap().to_rgb8();
    // Seen along −z with +y up: a point's pixel by the page's 45° perspective.
    let centre = finest_centre(&glb_json(&proxy));
    let focal = size as f64 / 2.0 / (std::f64::consts::PI / 8.0).tan();
    let colour_at = |p: [f64; 3]| -> [f64; 3] {
        let depth = distance - (p[2] - centre[2]);
        let x = size as f64 / 2.0 + focal * (p[0] - centre[0]) / depth;
        let y = size as f64 / 2.0 - focal * (p[1] - centre[1]) / depth;
        // The mean of the 5 × 5 pixels around it.
        let (px, py) = (x.round() as u32, y.round() as u32);
        let block: Vec<[u8; 3]> = (py - 2..=py + 2)
            .flat_map(|row| (px - 2..=px + 2).map(move |col| (col, row)))
            .map(|(col, row)| img.get_pixel(col, row).0)
            .collect();
        std::array::from_fn(|c| block.iter().map(|q| q[c] as f64).sum::<f64>() / 25.0)
    };
    let front = |c: [f64; 3], r: f64, dx: f64, dy: f64| {
        [
            c[0] + r * dx,
            c[1] + r * dy,
            c[2] + r * (1.0 - dx * dx - dy * dy).sqrt(),
        ]
    };
    type Test = fn([f64; 3]) -> bool;
    let cases: [(&str, [f64; 3], Test); 5] = [
        // The large sphere's checker has 8 squares a side over (x, y) in −1..1: the square
        // right of the centre's corner (4, 4) is red, the one left of it (3, 4) white.
        ("red", front([0.0; 3], 1.0, 0.125, 0.125), |c| {
            c[0] > 150.0 && c[1] < 90.0 && c[2] < 90.0
        }),
        ("white", front([0.0; 3], 1.0, -0.125, 0.125), |c| {
            c.iter().all(|&v| v > 170.0)
        }),
        // The smaller sphere's 4 squares a side: (2, 2) blue, (2, 1) yellow.
        ("blue", front([1.1, 0.0, 0.0], 0.6, 0.25, 0.25), |c| {
            c[2] > 130.0 && c[0] < 90.0 && c[1] < 90.0
        }),
        ("yellow", front([1.1, 0.0, 0.0], 0.6, 0.25, -0.25), |c| {
            c[0] > 150.0 && c[1] > 130.0 && c[2] < 100.0
        }),
        ("green", front([0.0, 2.2, 0.0], 0.4, 0.0, 0.0), |c| {
            c[1] > 150.0 && c[1] > c[0] + 60.0 && c[1] > c[2] + 60.0
        }),
    ];
    for (name, p, test) in cases {
        let c = colour_at(p);
        assert!(test(c), "{name} at {p:?}: pixel colour {c:?}");
    }
}
