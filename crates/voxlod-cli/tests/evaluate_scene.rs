//! `voxlod evaluate` on a scene with looks: the proxy is one more method, measured with its own
//! baked textures and previewed beside the others; every level and the input report their
//! draw calls. A mesh without looks gets no proxy, with a warning when it was asked for.

mod common;

use std::path::Path;

use common::{arg, json, stderr, voxlod, write_mesh};
use serde_json::Value;

/// `voxlod evaluate INPUT -o OUT` with quick measures and `extra`, its JSON report.
fn evaluate(input: &Path, out: &Path, extra: &[&str]) -> Value {
    let mut args = vec!["evaluate", arg(input), "-o", arg(out), "--samples", "5000"];
    args.extend_from_slice(extra);
    args.push("--json");
    let o = voxlod(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    json(&o)
}

/// The curve of `method` in a report.
fn curve<'r>(report: &'r Value, method: &str) -> &'r Value {
    let curves = report["curves"].as_array().unwrap();
    curves.iter().find(|c| c["method"] == method).unwrap()
}

#[test]
fn a_scene_s_proxy_is_evaluated_beside_the_simplifiers_with_draw_calls() {
    let dir = tempfile::tempdir().unwrap();
    let glb = dir.path().join("scene.glb");
    let scene = voxlod_testkit::assets::three_part_scene();
    let options = voxlod::gltf::AssetGlbOptions::default();
    std::fs::write(&glb, voxlod::gltf::asset_glb(&[scene], &options).unwrap()).unwrap();
    let out = dir.path().join("eval");
    let report = evaluate(
        &glb,
        &out,
        &[
            "--methods",
            "voxel-hypercone,rossignac-borrel,proxy",
            "--budgets",
            "2000,500",
            "--views",
            "6",
            "--proxy-texture",
            "512",
        ],
    );
    assert_eq!(report["input"]["draw_calls"], 3);
    assert_eq!(report["appearance_views"], 14);
    let psnr = |method: &str| -> Vec<f64> {
        let points = curve(&report, method)["points"].as_array().unwrap();
        assert_eq!(points.len(), 2, "{method}: {}", curve(&report, method));
        let at = |p: &Value| {
            assert_eq!(p["draw_calls"], 1, "{method}: {p}");
            let (psnr, ssim) = (&p["appearance"]["psnr"], &p["appearance"]["ssim"]);
            eprintln!("{method} at {}: PSNR {psnr} dB, SSIM {ssim}", p["budget"]);
            assert!(ssim.as_f64().unwrap() > 0.0 && ssim.as_f64().unwrap() < 1.0);
            psnr.as_f64().unwrap()
        };
        points.iter().map(at).collect()
    };
    let (proxy, voxel) = (psnr("proxy"), psnr("voxel-hypercone"));
    psnr("rossignac-borrel");
    for (p, v) in proxy.iter().zip(&voxel) {
        assert!(p > v, "proxy {proxy:?}, voxel-hypercone {voxel:?}");
    }
    let previews: Vec<&str> = (report["previews"].as_array().unwrap().iter())
        .map(|p| p.as_str().unwrap())
        .collect();
    assert!(previews.contains(&"previews/proxy.png"), "{previews:?}");
    assert!(out.join("previews/proxy.png").is_file());
    let markdown = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(markdown.contains("## proxy"), "{markdown}");
    assert!(
        markdown.contains("| draw calls | 3 | 1 | 1 | 1 |"),
        "{markdown}"
    );
}

#[test]
fn an_obj_with_its_materials_gets_a_proxy_and_a_bare_mesh_none() {
    let dir = tempfile::tempdir().unwrap();
    let scene = voxlod_testkit::assets::three_part_scene();
    let obj = dir.path().join("scene.obj");
    voxlod::io::write_asset(&obj, &scene).unwrap();
    let flags = ["--methods", "rossignac-borrel,proxy", "--budgets", "500"];
    let report = evaluate(
        &obj,
        &dir.path().join("obj"),
        &[&flags[..], &["--views", "0"]].concat(),
    );
    assert_eq!(report["input"]["draw_calls"], 3);
    let proxy = &curve(&report, "proxy")["points"][0];
    assert_eq!(proxy["draw_calls"], 1);
    assert!(
        proxy["appearance"]["psnr"].as_f64().unwrap() > 20.0,
        "{proxy}"
    );

    let bare = write_mesh(dir.path(), "bare.ply", &scene.mesh.geometry());
    let report = evaluate(
        &bare,
        &dir.path().join("bare"),
        &[&flags[..], &["--views", "0"]].concat(),
    );
    let methods: Vec<&Value> = report["curves"].as_array().unwrap().iter().collect();
    assert_eq!(methods.len(), 1);
    assert_eq!(methods[0]["method"], "rossignac-borrel");
    assert_eq!(methods[0]["points"][0]["draw_calls"], 1);
    assert_eq!(report["input"]["draw_calls"], 1);
    assert_eq!(report["appearance_views"], 0);
    let warnings = report["warnings"].to_string();
    assert!(
        warnings.contains("proxy: the input has no looks"),
        "{warnings}"
    );
}
