//! `voxlod lod` on a glTF asset: a sphere textured red on its −x half and blue on its +x half
//! (texture coordinates projected along z, a 2×1 PNG). Every level comes out of the binary
//! within its budget and textured or coloured (never grey), in one `.glb` in both layouts and
//! as level files with `--split`; the report says per level how it got its looks. A file
//! requiring an extension the reader cannot decode is refused naming it; a mesh with
//! `--triangles --format glb` gets its chain. With `--format obj` or `ply` each level is an OBJ
//! with its MTL and texture, or a coloured, textured PLY, read back with its looks; with
//! `--compress meshopt` the `.glb` is compressed, validates and reads back; `--compress` or
//! `--split` with OBJ or PLY output is a usage error naming the flag. The report lists every
//! file written with what it carries.

mod common;

use std::path::{Path, PathBuf};
use voxlod_testkit::assets::textured_sphere;

use common::{arg, json, stderr, voxlod};
use serde_json::Value;
use voxlod::asset::Asset;
use voxlod::core::glam::Vec4;
use voxlod::gltf::{asset_glb, read_scene, AssetGlbOptions};
use voxlod_testkit::shapes::icosphere;

const BUDGETS: [usize; 3] = [2000, 200, 40];

/// The textured sphere written as `dir/sphere.glb`.
fn sphere_glb(dir: &Path) -> PathBuf {
    let path = dir.join("sphere.glb");
    let bytes = asset_glb(&[textured_sphere(4)], &AssetGlbOptions::default()).unwrap();
    std::fs::write(&path, bytes).unwrap();
    path
}

/// The JSON chunk of a `.glb` file, and its binary chunk.
fn glb_chunks(bytes: &[u8]) -> (Value, Vec<u8>) {
    assert_eq!(&bytes[..4], b"glTF");
    let len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let json = serde_json::from_slice(&bytes[20..20 + len]).unwrap();
    let rest = &bytes[20 + len..];
    let bin = if rest.len() >= 8 {
        let n = u32::from_le_bytes(rest[..4].try_into().unwrap()) as usize;
        rest[8..8 + n].to_vec()
    } else {
        Vec::new()
    };
    (json, bin)
}

fn glb_json(path: &Path) -> Value {
    glb_chunks(&std::fs::read(path).unwrap()).0
}

/// Whether every primitive of `mesh` in `doc` is coloured (COLOR_0) or textured.
fn mesh_has_looks(doc: &Value, mesh: usize) -> bool {
    let prims = doc["meshes"][mesh]["primitives"].as_array().unwrap();
    prims.iter().all(|p| {
        let coloured = p["attributes"].get("COLOR_0").is_some();
        let textured = p["material"].as_u64().is_some_and(|m| {
            doc["materials"][m as usize]["pbrMetallicRoughness"]
                .get("baseColorTexture")
                .is_some()
        });
        coloured || textured
    })
}

/// Asserts that `asset` shows red where the input is red and blue where it is blue: by its
/// texture coordinates into the input's texture, or by its vertex colours.
fn assert_red_and_blue(asset: &Asset, what: &str) {
    let textured = asset
        .materials
        .iter()
        .any(|m| m.base_color_texture.is_some());
    let baked = asset.materials.len() == 1 && asset.images.len() > 1;
    if baked {
        return assert_baked_red_and_blue(asset, what);
    }
    let red = Vec4::new(1.0, 0.0, 0.0, 1.0);
    let blue = Vec4::new(0.0, 0.0, 1.0, 1.0);
    let mut checked = 0;
    for (i, p) in asset.mesh.positions.iter().enumerate() {
        if p.x.abs() <= 0.2 {
            continue;
        }
        checked += 1;
        if textured {
            let u = asset.mesh.uv[0][i].x;
            assert_eq!(u < 0.5, p.x < 0.0, "{what}: {p} has u {u}");
        } else {
            let c = asset.mesh.colors[i];
            let want = if p.x < 0.0 { red } else { blue };
            assert!((c - want).abs().max_element() < 0.02, "{what}: {p} has {c}");
        }
    }
    assert!(checked > 0, "{what}: no vertex checked");
}

/// A baked level (one material, its own atlas and textures): its base colour texture read at
/// each vertex away from the sphere's middle is red where x < 0 and blue where x > 0.
fn assert_baked_red_and_blue(asset: &Asset, what: &str) {
    let slot = asset.materials[0].base_color_texture.as_ref().unwrap();
    let texels = voxlod::asset::texture::decode(&asset.images[slot.image]).unwrap();
    let (red, blue) = (Vec4::new(1.0, 0.0, 0.0, 1.0), Vec4::new(0.0, 0.0, 1.0, 1.0));
    let mut checked = 0;
    for (i, p) in asset.mesh.positions.iter().enumerate() {
        if p.x.abs() <= 0.2 {
            continue;
        }
        checked += 1;
        let c = texels.sample(slot, asset.mesh.uv[0][i]);
        let want = if p.x < 0.0 { red } else { blue };
        assert!((c - want).abs().max_element() < 0.05, "{what}: {p} has {c}");
    }
    assert!(checked > 0, "{what}: no vertex checked");
}

fn assert_within_budget(triangles: usize, budget: usize, what: &str) {
    assert!(
        triangles > 0 && triangles as f64 <= budget as f64 * 1.1,
        "{what}: {triangles} triangles for a budget of {budget}"
    );
}

fn assert_valid(path: &Path) {
    if let Some(v) = voxlod_testkit::gltf_validator::validate_gltf(path) {
        assert_eq!(
            (v.errors, v.warnings),
            (0, 0),
            "{}: {}",
            path.display(),
            v.report
        );
    }
}

fn budgets_arg() -> String {
    BUDGETS.map(|b| b.to_string()).join(",")
}

/// The report's levels: each says how it got its looks.
fn assert_report_looks(report: &Value) {
    let levels = report["levels"].as_array().unwrap();
    assert_eq!(levels.len(), BUDGETS.len(), "{report}");
    for (l, budget) in levels.iter().zip(BUDGETS) {
        let looks = l["looks"].as_str().unwrap();
        assert!(looks == "kept" || looks == "transferred", "{l}");
        assert_eq!(l["budget"].as_u64(), Some(budget as u64), "{l}");
    }
}

#[test]
fn msft_lod_chain_carries_every_level_with_its_looks() {
    let dir = tempfile::tempdir().unwrap();
    let input = sphere_glb(dir.path());
    let out = dir.path().join("sphere-lod.glb");
    let budgets = budgets_arg();
    let o = voxlod(&[
        "lod",
        arg(&input),
        "--triangles",
        &budgets,
        "-o",
        arg(&out),
        "--json",
    ]);
    let report = json(&o);
    assert_report_looks(&report);
    assert_eq!(report["layout"], "msft-lod");
    assert!(dir.path().join("sphere-lod-report.json").is_file());
    let doc = glb_json(&out);
    let lod = doc["nodes"][0]["extensions"]["MSFT_lod"]["ids"]
        .as_array()
        .unwrap();
    assert_eq!(lod.len(), BUDGETS.len() - 1, "{doc}");
    let nodes: Vec<usize> = std::iter::once(0)
        .chain(lod.iter().map(|i| i.as_u64().unwrap() as usize))
        .collect();
    for (k, (&node, budget)) in nodes.iter().zip(BUDGETS).enumerate() {
        let n = &doc["nodes"][node];
        let t = n["extras"]["voxlod"]["triangles"].as_u64().unwrap() as usize;
        assert_within_budget(t, budget, &format!("level {k}"));
        let mesh = n["mesh"].as_u64().unwrap() as usize;
        assert!(mesh_has_looks(&doc, mesh), "level {k} is grey: {doc}");
    }
    // The finest level as a reader without MSFT_lod sees it.
    let finest = read_scene(&out).unwrap().asset;
    assert_red_and_blue(&finest, "level 0");
    assert_valid(&out);
}

#[test]
fn lod_nodes_and_split_levels_carry_their_looks() {
    let dir = tempfile::tempdir().unwrap();
    let input = sphere_glb(dir.path());
    let out = dir.path().join("levels");
    let budgets = budgets_arg();
    let o = voxlod(&[
        "lod",
        arg(&input),
        "--triangles",
        &budgets,
        "-o",
        arg(&out),
        "--layout",
        "lod-nodes",
        "--split",
        "--json",
    ]);
    let report = json(&o);
    assert_report_looks(&report);
    assert_eq!(report["layout"], "lod-nodes");
    let chain = out.join("lod.glb");
    let doc = glb_json(&chain);
    let scene = doc["scenes"][0]["nodes"].as_array().unwrap();
    assert_eq!(scene.len(), BUDGETS.len(), "{doc}");
    for (k, (node, budget)) in scene.iter().zip(BUDGETS).enumerate() {
        let n = &doc["nodes"][node.as_u64().unwrap() as usize];
        assert_eq!(n["name"], format!("LOD{k}"));
        let t = n["extras"]["voxlod"]["triangles"].as_u64().unwrap() as usize;
        assert_within_budget(t, budget, &format!("LOD{k}"));
        assert!(mesh_has_looks(&doc, n["mesh"].as_u64().unwrap() as usize));
    }
    assert_valid(&chain);
    for (k, budget) in BUDGETS.iter().enumerate() {
        let path = out.join(format!("level-{k}.glb"));
        let level = read_scene(&path).unwrap().asset;
        assert_within_budget(
            level.mesh.triangles.len(),
            *budget,
            &path.display().to_string(),
        );
        assert_red_and_blue(&level, &path.display().to_string());
        assert_valid(&path);
        assert_eq!(
            report["levels"][k]["file"],
            format!("level-{k}.glb"),
            "{report}"
        );
    }
    assert!(out.join("report.json").is_file());
}

#[test]
fn the_pyramid_of_an_asset_is_not_grey() {
    let dir = tempfile::tempdir().unwrap();
    let input = sphere_glb(dir.path());
    let out = dir.path().join("pyramid");
    let o = voxlod(&[
        "lod",
        arg(&input),
        "--resolution",
        "32",
        "--levels",
        "2",
        "-o",
        arg(&out),
        "--split",
        "--json",
    ]);
    let report = json(&o);
    let levels = report["levels"].as_array().unwrap();
    assert_eq!(levels.len(), 2, "{report}");
    for (k, l) in levels.iter().enumerate() {
        // A voxel level shares no vertex with the input: baked from it.
        assert_eq!(l["looks"], "baked", "{l}");
        let level = read_scene(&out.join(format!("level-{k}.glb")))
            .unwrap()
            .asset;
        assert_red_and_blue(&level, &format!("pyramid level {k}"));
    }
}

#[test]
fn a_geometry_format_says_the_looks_were_dropped() {
    let dir = tempfile::tempdir().unwrap();
    let input = sphere_glb(dir.path());
    let out = dir.path().join("plys");
    let o = voxlod(&[
        "lod",
        arg(&input),
        "--triangles",
        "200",
        "--format",
        "stl",
        "-o",
        arg(&out),
        "--json",
    ]);
    let report = json(&o);
    assert!(out.join("level-0.stl").is_file());
    assert_eq!(report["levels"][0]["looks"], "dropped");
    let warnings = report["warnings"].as_array().unwrap();
    assert!(
        warnings
            .iter()
            .any(|w| w.as_str().unwrap().contains("looks")),
        "{report}"
    );
}

#[test]
fn a_required_extension_voxlod_does_not_read_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let input = sphere_glb(dir.path());
    let (mut doc, bin) = glb_chunks(&std::fs::read(&input).unwrap());
    doc["extensionsUsed"] = serde_json::json!(["KHR_materials_pbrSpecularGlossiness"]);
    doc["extensionsRequired"] = serde_json::json!(["KHR_materials_pbrSpecularGlossiness"]);
    let draco = dir.path().join("draco.glb");
    std::fs::write(&draco, voxlod::gltf::to_glb(&doc, bin).unwrap()).unwrap();
    let o = voxlod(&[
        "lod",
        arg(&draco),
        "--triangles",
        "200",
        "-o",
        arg(&dir.path().join("out")),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    common::assert_clean_failure(&o, "KHR_materials_pbrSpecularGlossiness");
    common::assert_clean_failure(&o, "draco.glb");
    let o = voxlod(&[
        "lod",
        arg(&dir.path().join("missing.glb")),
        "-o",
        arg(&dir.path().join("out")),
    ]);
    assert_eq!(o.status.code(), Some(4), "{}", stderr(&o));
}

#[test]
fn the_readers_warnings_reach_the_report() {
    let dir = tempfile::tempdir().unwrap();
    let input = sphere_glb(dir.path());
    let (mut doc, bin) = glb_chunks(&std::fs::read(&input).unwrap());
    doc["extensionsUsed"] = serde_json::json!(["EXT_made_up_for_the_test"]);
    let used = dir.path().join("used.glb");
    std::fs::write(&used, voxlod::gltf::to_glb(&doc, bin).unwrap()).unwrap();
    let out = dir.path().join("out");
    let o = voxlod(&[
        "lod",
        arg(&used),
        "--triangles",
        "200",
        "-o",
        arg(&out),
        "--json",
    ]);
    let report = json(&o);
    let warnings = report["warnings"].as_array().unwrap();
    assert!(
        warnings
            .iter()
            .any(|w| w.as_str().unwrap().contains("EXT_made_up_for_the_test")),
        "{report}"
    );
}

#[test]
fn a_mesh_with_budgets_and_format_glb_gets_its_chain_in_either_layout() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = common::write_mesh(dir.path(), "sphere.ply", &icosphere(3));
    let out = dir.path().join("chain");
    let o = voxlod(&[
        "lod",
        arg(&mesh),
        "--triangles",
        "400,100",
        "--format",
        "glb",
        "-o",
        arg(&out),
        "--json",
    ]);
    let report = json(&o);
    assert_eq!(report["glb"]["levels"], 2, "{report}");
    let chain = voxlod::gltf::read_glb(&out.join("lod.glb")).unwrap();
    assert!(!chain.mesh.triangles.is_empty());
    assert!(
        !out.join("level-0.ply").exists(),
        "level files only with --split"
    );
    assert_valid(&out.join("lod.glb"));
    let nodes = dir.path().join("nodes");
    let flags = [
        "--triangles",
        "400,100",
        "--format",
        "glb",
        "--layout",
        "lod-nodes",
    ];
    let report = lod_report(&mesh, &nodes, &flags);
    assert_eq!(report["glb"]["layout"], "lod-nodes", "{report}");
    let doc = glb_json(&nodes.join("lod.glb"));
    let names: Vec<&str> = doc["scenes"][0]["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| {
            doc["nodes"][n.as_u64().unwrap() as usize]["name"]
                .as_str()
                .unwrap()
        })
        .collect();
    assert_eq!(names, ["LOD0", "LOD1"]);
    assert_valid(&nodes.join("lod.glb"));

    // Compressed in the same layout: the same two nodes, both extensions required.
    let packed = dir.path().join("packed");
    let report = lod_report(
        &mesh,
        &packed,
        &[&flags[..], &["--compress", "meshopt"]].concat(),
    );
    assert_eq!(report["glb"]["compression"], "meshopt", "{report}");
    let doc = glb_json(&packed.join("lod.glb"));
    assert_eq!(doc["scenes"][0]["nodes"].as_array().unwrap().len(), 2);
    let required = doc["extensionsRequired"].to_string();
    assert!(required.contains("KHR_mesh_quantization"), "{doc}");
    let finest = read_scene(&packed.join("lod.glb")).unwrap().asset;
    assert_within_budget(finest.mesh.triangles.len(), 400, "LOD0");
    assert_valid(&packed.join("lod.glb"));
}

/// The textured sphere as `dir/sphere.obj` with `sphere.mtl` and `halves.png` beside it.
fn sphere_obj(dir: &Path) -> PathBuf {
    let a = textured_sphere(4);
    let mut obj = String::from("mtllib sphere.mtl\nusemtl halves\n");
    for p in &a.mesh.positions {
        obj += &format!("v {} {} {}\n", p.x, p.y, p.z);
    }
    // OBJ's v points up the image, glTF's down.
    for t in &a.mesh.uv[0] {
        obj += &format!("vt {} {}\n", t.x, 1.0 - t.y);
    }
    for t in &a.mesh.triangles {
        let [i, j, k] = t.map(|v| v + 1);
        obj += &format!("f {i}/{i} {j}/{j} {k}/{k}\n");
    }
    std::fs::write(dir.join("sphere.obj"), obj).unwrap();
    // MTL textures are read linearly with repeat: eight texels, so that only u within 1/16 of
    // the middle mixes red and blue (|x| < 0.125), and clamped at the sides.
    let mtl = "newmtl halves\nKd 1 1 1\nmap_Kd -clamp on halves.png\n";
    std::fs::write(dir.join("sphere.mtl"), mtl).unwrap();
    let img = image::RgbaImage::from_fn(8, 1, |x, _| {
        image::Rgba(if x < 4 {
            [255, 0, 0, 255]
        } else {
            [0, 0, 255, 255]
        })
    });
    img.save(dir.join("halves.png")).unwrap();
    dir.join("sphere.obj")
}

#[test]
fn an_obj_with_its_mtl_and_format_glb_keeps_its_looks() {
    let dir = tempfile::tempdir().unwrap();
    let obj = sphere_obj(dir.path());
    let out = dir.path().join("obj");
    let o = voxlod(&[
        "lod",
        arg(&obj),
        "--triangles",
        &budgets_arg(),
        "--format",
        "glb",
        "--layout",
        "lod-nodes",
        "--split",
        "-o",
        arg(&out),
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report = json(&o);
    assert_report_looks(&report);
    for (k, budget) in BUDGETS.into_iter().enumerate() {
        let level = read_scene(&out.join(format!("level-{k}.glb")))
            .unwrap()
            .asset;
        assert_within_budget(level.mesh.triangles.len(), budget, &format!("level {k}"));
        assert_red_and_blue(&level, &format!("obj level {k}"));
    }
    assert_valid(&out.join("lod.glb"));
}

/// The report's `files`: every file in `out` but the report, each listed once with what it
/// carries.
fn assert_files_listed(report: &Value, out: &Path) {
    let listed: Vec<&str> = report["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["file"].as_str().unwrap())
        .collect();
    let mut on_disk: Vec<String> = std::fs::read_dir(out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n != "report.json")
        .collect();
    on_disk.sort();
    let mut sorted: Vec<String> = listed.iter().map(|s| s.to_string()).collect();
    sorted.sort();
    assert_eq!(sorted, on_disk, "{report}");
    for f in report["files"].as_array().unwrap() {
        assert!(!f["carries"].as_array().unwrap().is_empty(), "{f}");
        let bytes = std::fs::metadata(out.join(f["file"].as_str().unwrap()))
            .unwrap()
            .len();
        assert_eq!(f["bytes"].as_u64(), Some(bytes), "{f}");
    }
}

/// `voxlod lod INPUT -o OUT --json FLAGS…`'s report (the run must succeed).
fn lod_report(input: &Path, out: &Path, flags: &[&str]) -> Value {
    let mut args = vec!["lod", arg(input), "-o", arg(out), "--json"];
    args.extend(flags);
    json(&voxlod(&args))
}

/// The OBJ or PLY level files of a run by [`BUDGETS`] read back with their looks: within their
/// budgets, as many triangles as the report says, red and blue where the input is, with the
/// texture where the level kept the input's looks; every file listed.
fn assert_level_files_keep_looks(report: &Value, out: &Path, format: &str) {
    assert_report_looks(report);
    assert_files_listed(report, out);
    for (k, budget) in BUDGETS.into_iter().enumerate() {
        let path = out.join(format!("level-{k}.{format}"));
        let read = voxlod::io::read_asset(&path).unwrap();
        assert!(read.warnings.is_empty(), "{path:?}: {:?}", read.warnings);
        let level = read.asset;
        let t = level.mesh.triangles.len();
        assert_within_budget(t, budget, &path.display().to_string());
        assert_eq!(report["levels"][k]["triangles"].as_u64(), Some(t as u64));
        assert_red_and_blue(&level, &path.display().to_string());
        let textured = report["levels"][k]["looks"] == "kept";
        assert_eq!(!level.images.is_empty(), textured, "{path:?}");
    }
    if format == "obj" {
        assert!(out.join("level-0.mtl").is_file());
    }
}

#[test]
fn obj_and_ply_levels_keep_their_looks() {
    let dir = tempfile::tempdir().unwrap();
    let input = sphere_glb(dir.path());
    for format in ["obj", "ply"] {
        let out = dir.path().join(format);
        let flags = ["--triangles", &budgets_arg(), "--format", format];
        let report = lod_report(&input, &out, &flags);
        assert_level_files_keep_looks(&report, &out, format);
        assert!(
            out.join("halves.png").is_file(),
            "the texture beside the levels"
        );
    }
}

#[test]
fn a_compressed_asset_chain_validates_and_reads_back() {
    let dir = tempfile::tempdir().unwrap();
    let input = sphere_glb(dir.path());
    let mut sizes = Vec::new();
    for compress in [false, true] {
        let out = dir.path().join(format!("compressed-{compress}"));
        let mut flags = vec!["--triangles", "2000,200", "--layout", "lod-nodes"];
        if compress {
            flags.extend(["--compress", "meshopt"]);
        }
        let report = lod_report(&input, &out, &flags);
        assert_files_listed(&report, &out);
        let chain = out.join("lod.glb");
        sizes.push(std::fs::metadata(&chain).unwrap().len());
        let doc = glb_json(&chain);
        let carries = report["files"][0]["carries"].to_string();
        if compress {
            assert_eq!(report["compression"], "meshopt");
            assert!(carries.contains("meshopt compression"), "{report}");
            let required = doc["extensionsRequired"].to_string();
            assert!(required.contains("EXT_meshopt_compression"), "{doc}");
        } else {
            assert!(report.get("compression").is_none(), "{report}");
        }
        let finest = read_scene(&chain).unwrap().asset;
        assert_within_budget(finest.mesh.triangles.len(), 2000, "LOD0");
        assert_red_and_blue(&finest, &format!("compressed {compress}"));
        assert_valid(&chain);
    }
    assert!(
        sizes[1] < sizes[0],
        "compressed {} bytes, plain {}",
        sizes[1],
        sizes[0]
    );
}

#[test]
fn compress_and_split_with_obj_or_ply_are_usage_errors_naming_the_flag() {
    let dir = tempfile::tempdir().unwrap();
    let input = sphere_glb(dir.path());
    let out = dir.path().join("refused");
    for (format, flags, named) in [
        ("obj", &["--compress", "meshopt"][..], "--compress"),
        ("ply", &["--compress", "meshopt"][..], "--compress"),
        ("ply", &["--split"][..], "--split"),
    ] {
        let mut args = vec!["lod", arg(&input), "--format", format, "-o", arg(&out)];
        args.extend(flags);
        let o = voxlod(&args);
        assert_eq!(
            o.status.code(),
            Some(2),
            "{format} {flags:?}: {}",
            stderr(&o)
        );
        common::assert_clean_failure(&o, named);
        assert!(!out.exists(), "nothing written");
    }
}

#[test]
fn an_obj_with_looks_and_format_ply_keeps_them_and_a_bare_mesh_takes_the_mesh_route() {
    let dir = tempfile::tempdir().unwrap();
    let obj = sphere_obj(dir.path());
    let out = dir.path().join("ply");
    let report = lod_report(
        &obj,
        &out,
        &["--triangles", &budgets_arg(), "--format", "ply"],
    );
    assert_level_files_keep_looks(&report, &out, "ply");
    // A mesh without looks: the mesh route's report (no `files`), plain level files.
    let mesh = common::write_mesh(dir.path(), "bare.obj", &icosphere(3));
    let bare = dir.path().join("bare");
    let report = lod_report(&mesh, &bare, &["--triangles", "400", "--format", "obj"]);
    assert!(report.get("files").is_none(), "{report}");
    assert!(bare.join("level-0.obj").is_file());
    assert!(!bare.join("level-0.mtl").exists());
}
