//! The page without a browser: self-contained, the data inlined intact, bad files refused with
//! an error that names the file and the problem (an image outside the file, an attribute of the
//! wrong shape, a required extension the page does not read), and the `LOD0, LOD1, …` layout
//! counted as a chain.

mod common;

use base64::Engine;
use common::{edit_glb, write_sphere_chain, write_two_layers};
use serde_json::json;
use voxlod_gltf::{asset_glb, AssetGlbOptions, ChainOptions, Layout};
use voxlod_io::IoErrorKind;
use voxlod_view::{check_glb, page_html, read_model, write_page, ViewError, ViewOptions};

#[test]
fn the_page_inlines_everything_and_the_data_round_trips() {
    let dir = tempfile::tempdir().unwrap();
    let glb = dir.path().join("chain.glb");
    write_sphere_chain(&glb, &ChainOptions::default());
    let layers = dir.path().join("layers.glb");
    write_two_layers(&layers, 0.0);
    let page = dir.path().join("page.html");
    let mut models = write_page(&[glb.clone(), layers], &page, &ViewOptions::default()).unwrap();
    assert_eq!(models[0].glb.levels, 3);
    assert!(!models[0].glb.layered);
    assert!(models[1].glb.layered);
    assert_eq!(models[1].glb.triangles, 4);
    let on_disk = std::fs::read_to_string(&page).unwrap();
    assert_eq!(
        on_disk,
        page_html(&models, &ViewOptions::default()).unwrap()
    );
    models[1].name = "layers</script>.glb".into();
    let html = page_html(&models, &ViewOptions::default()).unwrap();
    for external in ["http://", "https://", "src=", "href=", "import "] {
        assert!(
            !html.contains(external),
            "the page refers to something outside: {external}"
        );
    }
    assert_eq!(
        html.matches("</script>").count(),
        2,
        "a name must not end a script block"
    );
    let start = html.find("id=\"voxlod-data\">").unwrap() + "id=\"voxlod-data\">".len();
    let end = start + html[start..].find("</script>").unwrap();
    let data: serde_json::Value = serde_json::from_str(&html[start..end]).unwrap();
    let bytes = base64::engine::general_purpose::STANDARD
        .decode(data[0]["glb"].as_str().unwrap())
        .unwrap();
    assert_eq!(bytes, std::fs::read(&glb).unwrap());
    assert_eq!(data[1]["name"], "layers</script>.glb");
}

#[test]
fn compressed_chains_are_embedded_decoded() {
    let dir = tempfile::tempdir().unwrap();
    let glb = dir.path().join("packed.glb");
    write_sphere_chain(&glb, &ChainOptions::meshopt());
    let model = read_model(&glb).unwrap();
    let doc = gltf::binary::Glb::from_slice(&model.glb.bytes).unwrap();
    let json = String::from_utf8_lossy(&doc.json).to_string();
    assert!(!json.contains("EXT_meshopt_compression"));
    assert!(json.contains("KHR_mesh_quantization"));
    assert_eq!(model.glb.levels, 3);
    assert_eq!(model.glb.triangles, 20 * (64 + 16 + 4));
}

#[test]
fn corrupt_files_are_refused_with_the_file_and_the_problem() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("good.glb");
    write_sphere_chain(&good, &ChainOptions::default());
    let bytes = std::fs::read(&good).unwrap();
    let cases: Vec<(&str, Vec<u8>)> = vec![
        ("empty.glb", vec![]),
        ("text.glb", b"not a glb at all".to_vec()),
        ("truncated.glb", bytes[..bytes.len() / 2].to_vec()),
        ("header-only.glb", bytes[..20].to_vec()),
        ("bad-json.glb", {
            let mut b = bytes.clone();
            b[24] = b'#';
            b
        }),
    ];
    for (name, data) in cases {
        let path = dir.path().join(name);
        std::fs::write(&path, data).unwrap();
        let e = read_model(&path).unwrap_err();
        assert!(
            matches!(&e, ViewError::Io(io) if io.kind == IoErrorKind::Malformed),
            "{name}: {e:?}"
        );
        let text = e.to_string();
        assert!(text.starts_with(&path.display().to_string()), "{text}");
        assert!(!text.contains("panicked"), "{text}");
    }
    let missing = dir.path().join("missing.glb");
    assert!(matches!(
        read_model(&missing),
        Err(ViewError::Io(io)) if io.kind == IoErrorKind::Access && io.path == missing
    ));
    let page = dir.path().join("page.html");
    assert!(write_page(
        &[dir.path().join("text.glb")],
        &page,
        &ViewOptions::default()
    )
    .is_err());
    assert!(!page.exists(), "no page is left after a failure");
}

#[test]
fn an_index_beyond_the_vertices_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("layers.glb");
    write_two_layers(&good, 0.0);
    let mut bytes = std::fs::read(&good).unwrap();
    // The binary chunk starts after the 12-byte header, the JSON chunk and the 8-byte chunk
    // header; the layer indices start 192 bytes into it.
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let at = 12 + 8 + json_len + 8 + 192;
    bytes[at..at + 4].copy_from_slice(&77u32.to_le_bytes());
    let bad = dir.path().join("bad-index.glb");
    std::fs::write(&bad, bytes).unwrap();
    let e = read_model(&bad).unwrap_err().to_string();
    assert!(e.contains("index 77 beyond its 4 vertices"), "{e}");
}

#[test]
fn textured_levels_are_checked_and_lod_nodes_count_as_levels() {
    let dir = tempfile::tempdir().unwrap();
    let levels = [4, 2, 1].map(voxlod_testkit::assets::textured_sphere);
    let options = AssetGlbOptions {
        layout: Layout::LodNodes,
        ..AssetGlbOptions::default()
    };
    let bytes = asset_glb(&levels, &options).unwrap();
    let glb = dir.path().join("lod-nodes.glb");
    std::fs::write(&glb, &bytes).unwrap();
    let model = read_model(&glb).unwrap();
    assert_eq!(model.glb.levels, 3);
    assert_eq!(model.glb.triangles, 20 * (256 + 16 + 4));
    // Two nodes named LOD0: no chain, one model of every node.
    let twice = edit_glb(&bytes, |doc| doc["nodes"][1]["name"] = json!("LOD0"));
    assert_eq!(check_glb(&twice).unwrap().levels, 1);

    let refused =
        |edit: &dyn Fn(&mut serde_json::Value)| check_glb(&edit_glb(&bytes, edit)).unwrap_err();
    let e = refused(&|doc| doc["images"][0] = json!({"uri": "halves.png"}));
    assert!(
        e.contains("image 0 is the file \"halves.png\" outside the .glb"),
        "{e}"
    );
    let e = refused(&|doc| {
        let uv = doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"].clone();
        doc["accessors"][uv.as_u64().unwrap() as usize]["type"] = json!("SCALAR");
    });
    assert!(
        e.contains("TexCoords(0)") && e.contains("must be of type VEC2"),
        "{e}"
    );
    let e =
        refused(&|doc| doc["extensionsRequired"] = json!(["KHR_materials_pbrSpecularGlossiness"]));
    assert!(e.contains("KHR_materials_pbrSpecularGlossiness"), "{e}");
    // Required extensions the page reads are accepted.
    let transform = edit_glb(&bytes, |doc| {
        doc["extensionsUsed"] = json!(["KHR_texture_transform"]);
        doc["extensionsRequired"] = json!(["KHR_texture_transform"]);
    });
    assert!(check_glb(&transform).is_ok());
}
