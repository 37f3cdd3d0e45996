//! `voxlod layers` on an asset with looks: a glTF scene (and an OBJ with its MTL and texture)
//! gives every layer of the `.glb` a baked base colour texture, reported and validated; a
//! plain mesh gives the layers one colour as before, and `--texture` there warns; every level
//! of a `--lod` chain gets its layers' textures too; `--texture` out of range or with a `.ply`
//! output is a usage error (exit 2).

mod common;

use std::path::{Path, PathBuf};

use common::{arg, json, stderr, voxlod};
use voxlod::gltf::{asset_glb, read_glb, AssetGlbOptions};

/// The three-part scene (two checker-textured spheres and a plain green one) as `dir/scene.glb`.
fn scene_glb(dir: &Path) -> PathBuf {
    let path = dir.join("scene.glb");
    let scene = voxlod_testkit::assets::three_part_scene();
    let bytes = asset_glb(&[scene], &AssetGlbOptions::default()).unwrap();
    std::fs::write(&path, bytes).unwrap();
    path
}

/// The JSON chunk of a `.glb` file (the first chunk, after the 12-byte header and the chunk's
/// length and type).
fn gltf_json(path: &Path) -> serde_json::Value {
    let bytes = std::fs::read(path).unwrap();
    let length = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    assert_eq!(&bytes[16..20], b"JSON");
    serde_json::from_slice(&bytes[20..20 + length]).unwrap()
}

/// Asserts that primitive `p` of `doc` has texture coordinates and a material with a base
/// colour texture.
fn assert_textured(doc: &serde_json::Value, p: &serde_json::Value) {
    assert!(p["attributes"]["TEXCOORD_0"].is_u64(), "{p}");
    let m = &doc["materials"][p["material"].as_u64().unwrap() as usize];
    let texture = &m["pbrMetallicRoughness"]["baseColorTexture"];
    assert!(texture.is_object(), "{m}");
}

/// `voxlod layers INPUT -o OUT --error 0.05` with `extra` flags.
fn layers(input: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    let mut all = vec!["layers", arg(input), "-o", arg(out), "--error", "0.05"];
    all.extend_from_slice(extra);
    voxlod(&all)
}

#[test]
fn a_textured_scene_gives_every_layer_a_baked_base_colour() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_glb(dir.path());
    let out = dir.path().join("layers.glb");
    let o = layers(
        &scene,
        &out,
        &["--resolution", "40", "--texture", "128", "--json"],
    );
    let report = json(&o);
    // ε = 0.05: three hyper-cone layers, each baked.
    assert_eq!(report["layers"].as_array().unwrap().len(), 3);
    let texture = &report["texture"];
    assert_eq!(texture["size"], 128);
    assert_eq!(texture["layers"].as_array().unwrap().len(), 3);
    // The only warnings are the bakes' own, each naming its layer (folds of slivers).
    for w in report["warnings"].as_array().unwrap() {
        assert!(w.as_str().unwrap().starts_with("layer "), "{w}");
    }
    let read = read_glb(&out).unwrap();
    assert!(read.is_layered());
    assert_eq!(read.parts.len(), 3);
    assert_eq!(read.mesh.positions.len() as u64, report["vertices"]);
    let doc = gltf_json(&out);
    assert_eq!(doc["images"].as_array().unwrap().len(), 3);
    for mesh in doc["meshes"].as_array().unwrap() {
        assert_textured(&doc, &mesh["primitives"][0]);
    }
    if let Some(v) = voxlod_testkit::gltf_validator::validate_gltf(&out) {
        assert_eq!(v.errors, 0, "{}", v.report);
    }
    // Without --json the texture is in the summary.
    let o = layers(&scene, &out, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = common::stdout(&o);
    assert!(
        text.contains("base colour baked onto 3 layers: 512² texels each"),
        "{text}"
    );
}

/// An OBJ with its MTL and texture takes the same route.
#[test]
fn an_obj_with_a_texture_is_baked_too() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("halves.obj");
    voxlod::io::write_asset(&obj, &voxlod_testkit::assets::textured_sphere(3)).unwrap();
    let out = dir.path().join("halves.glb");
    let o = layers(
        &obj,
        &out,
        &["--resolution", "24", "--texture", "64", "--json"],
    );
    let report = json(&o);
    assert_eq!(report["texture"]["size"], 64);
    assert_eq!(gltf_json(&out)["images"].as_array().unwrap().len(), 3);
}

/// A plain mesh: no texture coordinate or image, as before; --texture there is a warning.
#[test]
fn a_plain_mesh_has_one_colour_and_texture_warns() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = common::write_mesh(
        dir.path(),
        "ball.ply",
        &voxlod_testkit::shapes::icosphere(3),
    );
    let out = dir.path().join("ball.glb");
    let run = |extra: &[&str]| {
        let mut all = vec!["--resolution", "24", "--json"];
        all.extend_from_slice(extra);
        layers(&mesh, &out, &all)
    };
    let report = json(&run(&[]));
    assert!(report["texture"].is_null());
    assert_eq!(report["warnings"], serde_json::json!([]));
    let plain = std::fs::read(&out).unwrap();
    let text = String::from_utf8_lossy(&plain);
    assert!(!text.contains("TEXCOORD") && !text.contains("\"images\""));
    let report = json(&run(&["--texture", "256"]));
    let warnings = report["warnings"].as_array().unwrap();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    let w = warnings[0].as_str().unwrap();
    assert!(
        w.contains("--texture") && w.contains("no base colour"),
        "{w}"
    );
    // The same file with the flag: nothing baked.
    assert_eq!(std::fs::read(&out).unwrap(), plain);
}

#[test]
fn texture_where_it_cannot_apply_is_a_usage_error() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_glb(dir.path());
    let glb = dir.path().join("out.glb");
    let ply = dir.path().join("out.ply");
    for (out, extra, expect) in [
        (&glb, &["--texture", "4"][..], "must be 8 to 16384"),
        (&glb, &["--texture", "20000"][..], "must be 8 to 16384"),
        (&ply, &["--texture", "256"][..], "holds no textures"),
    ] {
        let mut all = vec!["layers", arg(&scene), "-o", arg(out)];
        all.extend_from_slice(extra);
        let o = voxlod(&all);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {}", stderr(&o));
        common::assert_clean_failure(&o, expect);
        assert!(!out.exists());
    }
}

#[test]
fn every_level_of_a_chain_takes_the_base_colour() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_glb(dir.path());
    let out = dir.path().join("chain.glb");
    let extra: Vec<&str> = "--lod --resolutions 32,16 --texture 64 --json"
        .split(' ')
        .collect();
    let o = layers(&scene, &out, &extra);
    let report = json(&o);
    let levels = report["lod"]["levels"].as_array().unwrap();
    assert_eq!(levels.len(), 2);
    for level in levels {
        assert!(level["charts"].as_u64().unwrap() >= 3, "{level}");
    }
    // The only warnings are the bakes' own, each naming its level and layer.
    for w in report["warnings"].as_array().unwrap() {
        assert!(w.as_str().unwrap().starts_with("chain level "), "{w}");
    }
    // Every primitive of every level has texture coordinates and a base colour texture of
    // its own: three layers a level, six images.
    let doc = gltf_json(&out);
    assert_eq!(doc["images"].as_array().unwrap().len(), 6);
    let meshes = doc["meshes"].as_array().unwrap();
    assert_eq!(meshes.len(), 2);
    for p in meshes
        .iter()
        .flat_map(|m| m["primitives"].as_array().unwrap())
    {
        assert_textured(&doc, p);
    }
    if let Some(v) = voxlod_testkit::gltf_validator::validate_gltf(&out) {
        assert_eq!(v.errors, 0, "{}", v.report);
    }
}

/// An asset's looks that the output cannot carry are a warning, and the geometry is layered.
#[test]
fn looks_a_ply_output_cannot_carry_are_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_glb(dir.path());
    let out = dir.path().join("layers.ply");
    let o = layers(&scene, &out, &["--resolution", "24", "--json"]);
    let report = json(&o);
    let warnings = report["warnings"].as_array().unwrap();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].as_str().unwrap().contains("holds no textures"));
    assert!(out.exists());
}
