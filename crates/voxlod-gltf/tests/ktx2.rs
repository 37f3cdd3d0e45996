//! KTX2 textures (`KHR_texture_basisu`) pass through: written with the extension (required),
//! accepted by the Khronos validator, read back with their bytes unchanged, written again
//! byte for byte; a texture with a PNG fallback reads the fallback; sampling the looks of a
//! KTX2-textured asset warns and keeps the factor.

use std::sync::Arc;

use serde_json::Value;
use voxlod_asset::{Asset, Image};
use voxlod_gltf::{asset_glb, parse_scene, AssetGlbOptions};
use voxlod_testkit::assets::textured_sphere;
use voxlod_testkit::gltf_validator::validate_gltf;
use voxlod_testkit::skips::skip;

/// A 1×1 uncompressed `VK_FORMAT_R8G8B8A8_SRGB` (43) KTX2 file of one texel (KTX 2.0 §3:
/// identifier, header, index, one level; §4 the data format descriptor's basic block with
/// four 8-bit samples, alpha linear).
fn ktx2_rgba8(texel: [u8; 4]) -> Vec<u8> {
    let u32s = |out: &mut Vec<u8>, v: &[u32]| v.iter().for_each(|x| out.extend(x.to_le_bytes()));
    let mut dfd = Vec::new();
    let block_size = 24 + 16 * 4;
    u32s(&mut dfd, &[4 + block_size]); // dfdTotalSize
    u32s(&mut dfd, &[0]); // vendor Khronos, descriptor type basic
    u32s(&mut dfd, &[2 | (block_size << 16)]); // version 2, block size
    dfd.extend([1, 1, 2, 0]); // RGBSDA, BT.709 primaries, sRGB transfer, straight alpha
    dfd.extend([0, 0, 0, 0]); // texel block 1×1×1×1
    dfd.extend([4, 0, 0, 0, 0, 0, 0, 0]); // bytes per plane
    for (k, channel) in [0u8, 1, 2, 15 | 0x80].into_iter().enumerate() {
        dfd.extend(((k * 8) as u16).to_le_bytes());
        dfd.extend([7, channel, 0, 0, 0, 0]);
        u32s(&mut dfd, &[0, 255]);
    }
    let header_len = 12 + 9 * 4 + 4 * 4 + 2 * 8 + 3 * 8;
    let dfd_at = header_len as u32;
    let data_at = (header_len + dfd.len()).next_multiple_of(4) as u64;
    let mut out = b"\xABKTX 20\xBB\r\n\x1A\n".to_vec();
    // vkFormat, typeSize, width, height, depth, layers, faces, levels, supercompression.
    u32s(&mut out, &[43, 1, 1, 1, 0, 0, 1, 1, 0]);
    u32s(&mut out, &[dfd_at, dfd.len() as u32, 0, 0]);
    out.extend([0u64, 0].iter().flat_map(|x| x.to_le_bytes()));
    out.extend([data_at, 4, 4].iter().flat_map(|x| x.to_le_bytes()));
    assert_eq!(out.len(), header_len);
    out.extend(dfd);
    out.resize(data_at as usize, 0);
    out.extend(texel);
    out
}

/// The textured sphere with its base colour texture replaced by a KTX2 image.
fn ktx2_sphere() -> Asset {
    let mut asset = textured_sphere(2);
    asset.materials[0].base_color = [0.5, 0.75, 1.0, 1.0];
    asset.images = vec![Image {
        name: "swatch.ktx2".into(),
        mime: "image/ktx2".into(),
        bytes: Arc::new(ktx2_rgba8([200, 100, 50, 255])),
    }];
    asset
}

/// The JSON chunk of a `.glb`.
fn json_of(glb: &[u8]) -> Value {
    let glb = gltf::binary::Glb::from_slice(glb).unwrap();
    serde_json::from_slice(&glb.json).unwrap()
}

/// The Khronos validator (2.0.0-dev.3.10, the kit's) finds no error. It does not know
/// `KHR_texture_basisu`, so its only warnings may be the two that follow from that: the
/// `image/ktx2` media type not in its list, and the image's format not recognised.
fn assert_valid(path: &std::path::Path) {
    let Some(v) = validate_gltf(path) else { return };
    assert_eq!(v.errors, 0, "{}", v.report);
    let report: Value = serde_json::from_str(&v.report).unwrap();
    for m in report["messages"].as_array().unwrap() {
        if m["severity"].as_u64() > Some(1) {
            continue;
        }
        let (code, at) = (m["code"].as_str().unwrap(), m["pointer"].as_str().unwrap());
        let expected = match code {
            "VALUE_NOT_IN_LIST" => at == "/images/0/mimeType",
            "IMAGE_UNRECOGNIZED_FORMAT" => at == "/images/0",
            _ => false,
        };
        assert!(expected, "{}: {}", path.display(), v.report);
    }
}

#[test]
fn a_ktx2_texture_is_written_validated_read_and_written_again_unchanged() {
    let asset = ktx2_sphere();
    let ktx2 = asset.images[0].bytes.clone();
    let glb = asset_glb(std::slice::from_ref(&asset), &AssetGlbOptions::default()).unwrap();
    let json = json_of(&glb);
    assert_eq!(
        json["extensionsUsed"],
        serde_json::json!(["KHR_texture_basisu"])
    );
    assert_eq!(
        json["extensionsRequired"],
        serde_json::json!(["KHR_texture_basisu"])
    );
    let texture = &json["textures"][0];
    assert!(texture.get("source").is_none(), "{texture}");
    assert_eq!(texture["extensions"]["KHR_texture_basisu"]["source"], 0);
    assert_eq!(json["images"][0]["mimeType"], "image/ktx2");

    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("ktx2.glb");
    std::fs::write(&path, &glb).unwrap();
    assert_valid(&path);

    let back = voxlod_gltf::read_scene(&path).unwrap();
    assert!(back.warnings.is_empty(), "{:?}", back.warnings);
    assert_eq!(back.asset.images.len(), 1);
    assert_eq!(back.asset.images[0].mime, "image/ktx2");
    assert_eq!(*back.asset.images[0].bytes, *ktx2);
    assert_eq!(
        back.asset.materials[0].base_color_texture,
        asset.materials[0].base_color_texture
    );

    let again = asset_glb(
        std::slice::from_ref(&back.asset),
        &AssetGlbOptions::meshopt(),
    )
    .unwrap();
    let read = parse_scene(&again, None).unwrap();
    assert_eq!(*read.asset.images[0].bytes, *ktx2);
    let required = json_of(&again)["extensionsRequired"].clone();
    assert!(
        required
            .as_array()
            .unwrap()
            .contains(&"KHR_texture_basisu".into()),
        "{required}"
    );
    let path = dir.path().join("ktx2-meshopt.glb");
    std::fs::write(&path, &again).unwrap();
    assert_valid(&path);
}

#[test]
fn a_texture_with_a_png_fallback_reads_the_fallback_and_warns_of_the_ktx2_image() {
    let mut asset = textured_sphere(1);
    let png = asset.images[0].clone();
    asset.images.push(Image {
        name: String::new(),
        mime: "image/ktx2".into(),
        bytes: Arc::new(ktx2_rgba8([1, 2, 3, 255])),
    });
    let glb = asset_glb(&[asset], &AssetGlbOptions::default()).unwrap();
    // The writer wrote the PNG only (the KTX2 image is used by no texture); add the KTX2
    // image as the texture's KHR_texture_basisu source beside its PNG fallback.
    let parsed = gltf::binary::Glb::from_slice(&glb).unwrap();
    let mut json: Value = serde_json::from_slice(&parsed.json).unwrap();
    let mut bin = parsed.bin.unwrap().into_owned();
    let ktx2 = ktx2_rgba8([1, 2, 3, 255]);
    let at = bin.len();
    bin.extend(&ktx2);
    bin.resize(bin.len().next_multiple_of(4), 0);
    json["buffers"][0]["byteLength"] = bin.len().into();
    let views = json["bufferViews"].as_array_mut().unwrap();
    views.push(serde_json::json!({"buffer": 0, "byteOffset": at, "byteLength": ktx2.len()}));
    let view = views.len() - 1;
    json["images"]
        .as_array_mut()
        .unwrap()
        .push(serde_json::json!({"bufferView": view, "mimeType": "image/ktx2"}));
    json["textures"][0]["extensions"] = serde_json::json!({"KHR_texture_basisu": {"source": 1}});
    json["extensionsUsed"] = serde_json::json!(["KHR_texture_basisu"]);
    let text = serde_json::to_vec(&json).unwrap();
    let glb = gltf::binary::Glb {
        header: gltf::binary::Header {
            magic: *b"glTF",
            version: 2,
            length: 0,
        },
        json: text.into(),
        bin: Some(bin.into()),
    };
    let bytes = glb.to_vec().unwrap();
    let read = parse_scene(&bytes, None).unwrap();
    assert_eq!(
        read.asset.materials[0]
            .base_color_texture
            .as_ref()
            .unwrap()
            .image,
        0
    );
    assert_eq!(read.asset.images[0].bytes, png.bytes);
    assert_eq!(*read.asset.images[1].bytes, ktx2);
    assert_eq!(read.asset.images[1].mime, "image/ktx2");
    assert_eq!(read.warnings.len(), 1, "{:?}", read.warnings);
    assert!(
        read.warnings[0].contains("KTX2 image 1"),
        "{:?}",
        read.warnings
    );
}

#[test]
fn looks_taken_from_a_ktx2_textured_asset_keep_the_factor_with_a_warning() {
    let asset = ktx2_sphere();
    let level = textured_sphere(1).mesh.geometry();
    let t = voxlod_asset::transfer::transfer(&asset, &level).unwrap();
    assert_eq!(t.warnings.len(), 1, "{:?}", t.warnings);
    assert!(t.warnings[0].contains("swatch.ktx2"), "{:?}", t.warnings);
    for c in &t.asset.mesh.colors {
        assert_eq!(c.to_array(), [0.5, 0.75, 1.0, 1.0]);
    }
}

#[test]
fn an_unnamed_ktx2_image_is_named_by_its_index_in_the_warning() {
    let mut asset = ktx2_sphere();
    asset.images[0].name.clear();
    let level = textured_sphere(1).mesh.geometry();
    let t = voxlod_asset::transfer::transfer(&asset, &level).unwrap();
    assert_eq!(t.warnings.len(), 1, "{:?}", t.warnings);
    assert!(
        t.warnings[0].starts_with("image 0 (image/ktx2)"),
        "{:?}",
        t.warnings
    );
}

#[test]
fn a_bake_from_a_ktx2_textured_asset_keeps_the_factor_with_a_warning() {
    let asset = ktx2_sphere();
    let level = textured_sphere(1).mesh.geometry();
    let options = voxlod::bake::BakeOptions::for_texture(64);
    let baked = voxlod::bake::bake(&asset, &level, &options).unwrap();
    let named: Vec<&String> = baked
        .report
        .warnings
        .iter()
        .filter(|w| w.contains("swatch.ktx2"))
        .collect();
    assert_eq!(named.len(), 1, "{:?}", baked.report.warnings);
}

/// three.js's KTX2 parser (`ktx-parse`, from the peers' kit) on `file`: its format, size,
/// first level's bytes and samples' channels, as JSON; `None` (skipped) without node or three.
fn ktx_parse(file: &std::path::Path) -> Option<Value> {
    let peers = std::env::var_os("VOXLOD_PEERS")
        .map(std::path::PathBuf::from)
        .or_else(|| {
            std::env::var_os("HOME").map(|h| std::path::Path::new(&h).join(".cache/voxlod-peers"))
        })?;
    let module = peers.join("node_modules/three/examples/jsm/libs/ktx-parse.module.js");
    if !module.is_file() {
        skip(format!("no ktx-parse: {} is missing", module.display()));
        return None;
    }
    let script = format!(
        "import {{ read }} from {module:?}; import fs from 'fs';\n\
         const c = read(new Uint8Array(fs.readFileSync(process.argv[1])));\n\
         console.log(JSON.stringify({{vkFormat: c.vkFormat, size: [c.pixelWidth, c.pixelHeight],\n\
           level: Array.from(c.levels[0].levelData),\n\
           channels: c.dataFormatDescriptor[0].samples.map(s => s.channelType)}}));",
        module = module.display().to_string()
    );
    let out = match std::process::Command::new("node")
        .args(["--input-type=module", "-e", &script])
        .arg(file)
        .output()
    {
        Ok(out) => out,
        Err(e) => {
            skip(format!("no node: {e}"));
            return None;
        }
    };
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    Some(serde_json::from_slice(&out.stdout).unwrap())
}

#[test]
fn the_ktx2_image_read_back_parses_with_three_js_ktx_parse() {
    let asset = ktx2_sphere();
    let glb = asset_glb(&[asset], &AssetGlbOptions::default()).unwrap();
    let image = parse_scene(&glb, None).unwrap().asset.images[0].clone();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("swatch.ktx2");
    std::fs::write(&path, image.bytes.as_slice()).unwrap();
    let Some(parsed) = ktx_parse(&path) else {
        return;
    };
    assert_eq!(
        parsed,
        serde_json::json!({"vkFormat": 43, "size": [1, 1], "level": [200, 100, 50, 255],
            "channels": [0, 1, 2, 143]})
    );
}
