//! Reading glTF assets as scenes: a hand-built scene of two instances of a textured unit cube
//! (one mirrored) and a vertex-coloured triangle under a rotated parent, written as `.gltf`
//! with files beside it, as `.glb`, quantized (`KHR_mesh_quantization`), meshopt-compressed
//! (`EXT_meshopt_compression`), Draco-compressed (`KHR_draco_mesh_compression`, by draco-core
//! and by C++ Draco through DracoPy), instanced (`EXT_mesh_gpu_instancing`) and through
//! gltfpack; each reads back to the same asset, with positions, winding, normals, materials and
//! image bytes checked against what was written. Broken and mutated files give errors, never
//! panics.

use std::path::Path;

use serde_json::{json, Value};
use voxlod_core::glam::{DVec3, Vec2, Vec3, Vec4};
use voxlod_gltf::{parse_scene, read_scene, SceneRead};

/// The unit cube's 24 vertices (4 per face, outward normals, texture coordinates 0..1) and 12
/// counter-clockwise triangles.
fn cube() -> (Vec<Vec3>, Vec<Vec3>, Vec<Vec2>, Vec<u16>) {
    let (mut p, mut n, mut t, mut i) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let normal =
                Vec3::from_array(std::array::from_fn(|k| if k == axis { sign } else { 0.0 }));
            let u = Vec3::from_array(std::array::from_fn(|k| {
                if k == (axis + 1) % 3 {
                    1.0
                } else {
                    0.0
                }
            }));
            let v = normal.cross(u);
            let base = p.len() as u16;
            for (a, b) in [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)] {
                p.push(normal * 0.5 + u * a + v * b);
                n.push(normal);
                t.push(Vec2::new(a + 0.5, b + 0.5));
            }
            i.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
        }
    }
    (p, n, t, i)
}

/// A 2 × 2 PNG.
fn png() -> Vec<u8> {
    let img = image::RgbaImage::from_fn(2, 2, |x, y| {
        image::Rgba([200 * x as u8, 100 * y as u8, 50, 255])
    });
    let mut bytes = Vec::new();
    img.write_to(
        &mut std::io::Cursor::new(&mut bytes),
        image::ImageFormat::Png,
    )
    .unwrap();
    bytes
}

/// Builds the binary buffer and its views and accessors.
#[derive(Default)]
struct Bin {
    bytes: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Bin {
    fn view(&mut self, data: &[u8], target: Option<u32>) -> usize {
        while !self.bytes.len().is_multiple_of(4) {
            self.bytes.push(0);
        }
        let mut v = json!({"buffer": 0, "byteOffset": self.bytes.len(), "byteLength": data.len()});
        if let Some(t) = target {
            v["target"] = json!(t);
        }
        self.bytes.extend_from_slice(data);
        self.views.push(v);
        self.views.len() - 1
    }

    fn accessor(
        &mut self,
        data: &[u8],
        component: u32,
        kind: &str,
        count: usize,
        extra: Value,
    ) -> usize {
        let view = self.view(data, None);
        let mut a =
            json!({"bufferView": view, "componentType": component, "type": kind, "count": count});
        for (k, v) in extra.as_object().unwrap() {
            a[k] = v.clone();
        }
        self.accessors.push(a);
        self.accessors.len() - 1
    }
}

fn f32s(values: impl IntoIterator<Item = f32>) -> Vec<u8> {
    values.into_iter().flat_map(f32::to_le_bytes).collect()
}

/// How the cube's attributes are stored.
#[derive(Clone, Copy, PartialEq)]
enum Storage {
    Float,
    Quantized,
}

/// The scene's JSON and binary buffer; the image goes in a view when `image_in_view`.
fn scene(storage: Storage, image_in_view: bool) -> (Value, Vec<u8>) {
    let (p, n, t, i) = cube();
    let mut bin = Bin::default();
    let bounds = json!({"min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5]});
    let (pos, nrm, uv) = match storage {
        Storage::Float => (
            bin.accessor(
                &f32s(p.iter().flat_map(|v| v.to_array())),
                5126,
                "VEC3",
                24,
                bounds,
            ),
            bin.accessor(
                &f32s(n.iter().flat_map(|v| v.to_array())),
                5126,
                "VEC3",
                24,
                json!({}),
            ),
            bin.accessor(
                &f32s(t.iter().flat_map(|v| v.to_array())),
                5126,
                "VEC2",
                24,
                json!({}),
            ),
        ),
        Storage::Quantized => {
            // Positions as unsigned shorts 0 or 2 (dequantized by the parent's transform),
            // padded to 8 bytes; normals as normalized bytes; coordinates as normalized shorts.
            let q: Vec<u8> = p
                .iter()
                .flat_map(|v| {
                    let c = v.to_array().map(|x| if x > 0.0 { 2u16 } else { 0 });
                    [c[0], c[1], c[2], 0].into_iter().flat_map(u16::to_le_bytes)
                })
                .collect();
            let nq: Vec<u8> = n
                .iter()
                .flat_map(|v| {
                    let c = v.to_array().map(|x| (x * 127.0) as i8 as u8);
                    [c[0], c[1], c[2], 0]
                })
                .collect();
            let tq: Vec<u8> = t
                .iter()
                .flat_map(|v| v.to_array().map(|x| (x * 65535.0) as u16))
                .flat_map(u16::to_le_bytes)
                .collect();
            let pv = bin.view(&q, Some(34962));
            bin.views[pv]["byteStride"] = json!(8);
            bin.accessors.push(json!({"bufferView": pv, "componentType": 5123, "type": "VEC3", "count": 24, "min": [0, 0, 0], "max": [2, 2, 2]}));
            let nv = bin.view(&nq, Some(34962));
            bin.views[nv]["byteStride"] = json!(4);
            bin.accessors.push(json!({"bufferView": nv, "componentType": 5120, "type": "VEC3", "count": 24, "normalized": true}));
            let uv = bin.accessor(&tq, 5123, "VEC2", 24, json!({"normalized": true}));
            (bin.accessors.len() - 3, bin.accessors.len() - 2, uv)
        }
    };
    let idx = bin.accessor(
        &i.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<_>>(),
        5123,
        "SCALAR",
        36,
        json!({}),
    );
    let tri = bin.accessor(
        &f32s([0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]),
        5126,
        "VEC3",
        3,
        json!({"min": [0, 0, 0], "max": [1, 1, 0]}),
    );
    let col = bin.accessor(
        &[255, 0, 0, 0, 0, 255, 0, 0, 0, 0, 51, 0],
        5121,
        "VEC3",
        3,
        json!({"normalized": true}),
    );
    bin.views.last_mut().unwrap()["byteStride"] = json!(4);
    let image = if image_in_view {
        let v = bin.view(&png(), None);
        json!({"bufferView": v, "mimeType": "image/png"})
    } else {
        json!({"uri": "tex%20ture.png"})
    };
    let cube_node = |translation: [f32; 3], scale: [f32; 3]| json!({"mesh": 0, "translation": translation, "scale": scale});
    let quantized = storage == Storage::Quantized;
    let (inner_scale, inner_shift) = if quantized {
        ([0.5; 3], [-0.5; 3])
    } else {
        ([1.0; 3], [0.0; 3])
    };
    let nodes = json!([
        {"name": "right", "children": [3], "translation": [2.0, 0.0, 0.0]},
        {"name": "left", "children": [4], "translation": [-2.0, 0.0, 0.0], "scale": [-1.0, 1.0, 1.0]},
        {"name": "tilted", "children": [5], "rotation": [0.0, 0.0, 0.70710677, 0.70710677]},
        cube_node(inner_shift, inner_scale),
        cube_node(inner_shift, inner_scale),
        {"mesh": 1, "name": "coloured"}
    ]);
    let doc = json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": if quantized { json!(["KHR_texture_transform", "KHR_mesh_quantization"]) } else { json!(["KHR_texture_transform"]) },
        "extensionsRequired": if quantized { json!(["KHR_mesh_quantization"]) } else { json!([]) },
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 2]}],
        "nodes": nodes,
        "meshes": [
            {"name": "cube", "primitives": [{"attributes": {"POSITION": pos, "NORMAL": nrm, "TEXCOORD_0": uv}, "indices": idx, "material": 0}]},
            {"primitives": [{"attributes": {"POSITION": tri, "COLOR_0": col}, "material": 1}]}
        ],
        "materials": [
            {"name": "checker", "pbrMetallicRoughness": {"baseColorFactor": [1.0, 0.5, 1.0, 1.0], "baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform": {"offset": [0.5, 0.0], "scale": [2.0, 2.0]}}}, "metallicFactor": 0.0}},
            {"name": "plain", "doubleSided": true, "emissiveFactor": [1.0, 0.0, 0.0], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}}}
        ],
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"magFilter": 9728, "wrapS": 33071}],
        "images": [image],
        "bufferViews": bin.views,
        "accessors": bin.accessors,
        "buffers": [{"byteLength": bin.bytes.len()}]
    });
    (doc, bin.bytes)
}

/// A GLB of the JSON and buffer.
fn glb(doc: &Value, bin: Vec<u8>) -> Vec<u8> {
    let json = serde_json::to_vec(doc).unwrap();
    let header = gltf::binary::Header {
        magic: *b"glTF",
        version: 2,
        length: 0,
    };
    gltf::binary::Glb {
        header,
        json: json.into(),
        bin: Some(bin.into()),
    }
    .to_vec()
    .unwrap()
}

/// Signed volume of the triangles `range` of the asset's mesh.
fn volume(read: &SceneRead, range: std::ops::Range<usize>) -> f32 {
    let m = &read.asset.mesh;
    m.triangles[range]
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| m.positions[v as usize]);
            a.dot(b.cross(c)) / 6.0
        })
        .sum()
}

/// What every storage of the scene must read back as.
fn check(read: &SceneRead) {
    let a = &read.asset;
    let m = &a.mesh;
    assert_eq!(m.triangles.len(), 25);
    assert_eq!(
        a.parts.iter().map(|p| p.name.as_str()).collect::<Vec<_>>(),
        ["cube", "cube", "coloured"]
    );
    // Both cubes are unit cubes facing out, mirrored or not, where their nodes put them.
    for (part, centre) in [
        (0, Vec3::new(2.0, 0.0, 0.0)),
        (1, Vec3::new(-2.0, 0.0, 0.0)),
    ] {
        let p = &a.parts[part];
        let range = p.first_triangle as usize..(p.first_triangle + p.triangle_count) as usize;
        assert!(
            (volume(read, range.clone()) - 1.0).abs() < 1e-5,
            "part {part}"
        );
        for t in &m.triangles[range] {
            for &v in t {
                let (q, n) = (m.positions[v as usize], m.normals[v as usize]);
                assert!(((q - centre).abs().max_element() - 0.5).abs() < 1e-6, "{q}");
                assert!(n.dot(q - centre) > 0.49, "normal {n} at {q}");
            }
        }
    }
    // The triangle under a quarter turn about z: (1, 0, 0) went to (0, 1, 0).
    let last = m.triangles[24].map(|v| m.positions[v as usize]);
    assert!((last[1] - Vec3::Y).length() < 1e-6, "{:?}", last);
    let colours = m.triangles[24].map(|v| m.colors[v as usize]);
    assert_eq!(
        colours,
        [
            Vec4::new(1.0, 0.0, 0.0, 1.0),
            Vec4::new(0.0, 1.0, 0.0, 1.0),
            Vec4::new(0.0, 0.0, 0.2, 1.0)
        ]
    );
    // Materials: the cube's textured with its transform and sampler, the triangle's emissive.
    assert_eq!(m.material, [vec![0; 24], vec![1]].concat());
    let checker = &a.materials[0];
    let slot = checker.base_color_texture.as_ref().unwrap();
    assert_eq!(
        (checker.base_color, checker.metallic),
        ([1.0, 0.5, 1.0, 1.0], 0.0)
    );
    assert_eq!(slot.transform.unwrap().offset, [0.5, 0.0]);
    assert!(!slot.sampler.linear);
    assert_eq!(slot.sampler.wrap_u, voxlod_asset::Wrap::ClampToEdge);
    let plain = &a.materials[1];
    assert_eq!((plain.emissive_strength, plain.double_sided), (4.0, true));
    assert_eq!(a.images.len(), 1);
    assert_eq!(
        (a.images[0].mime.as_str(), a.images[0].bytes.as_slice()),
        ("image/png", png().as_slice())
    );
    // Texture coordinates as written (quantized ones are exact at 0 and 1).
    let corners: Vec<Vec2> = m.uv[0][..4].to_vec();
    assert_eq!(corners, [Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y]);
}

#[test]
fn a_gltf_with_files_beside_it_reads_as_the_scene_written() {
    let dir = tempfile::tempdir().unwrap();
    let (mut doc, bin) = scene(Storage::Float, false);
    doc["buffers"][0]["uri"] = json!("cube%20data.bin");
    std::fs::write(dir.path().join("cube data.bin"), &bin).unwrap();
    std::fs::write(dir.path().join("tex ture.png"), png()).unwrap();
    let path = dir.path().join("scene.gltf");
    std::fs::write(&path, serde_json::to_vec(&doc).unwrap()).unwrap();
    let read = read_scene(&path).unwrap();
    check(&read);
    assert!(read.warnings.is_empty(), "{:?}", read.warnings);
    assert_eq!(read.asset.images[0].name, "tex%20ture.png");
}

#[test]
fn a_glb_and_a_gltf_of_data_uris_read_the_same() {
    let (doc, bin) = scene(Storage::Float, true);
    let from_glb = parse_scene(&glb(&doc, bin.clone()), None).unwrap();
    check(&from_glb);
    let mut embedded = doc.clone();
    use base64::Engine;
    let data = base64::engine::general_purpose::STANDARD.encode(&bin);
    embedded["buffers"][0]["uri"] = json!(format!("data:application/octet-stream;base64,{data}"));
    let from_json = parse_scene(&serde_json::to_vec(&embedded).unwrap(), None).unwrap();
    assert_eq!(from_json.asset, from_glb.asset);
}

#[test]
fn quantized_attributes_read_as_the_floats() {
    let (doc, bin) = scene(Storage::Quantized, true);
    let read = parse_scene(&glb(&doc, bin), None).unwrap();
    check(&read);
}

/// The scene with every vertex and index view meshopt-encoded into a second buffer, the first
/// a fallback without data, as gltfpack writes it.
fn meshopt_scene() -> Vec<u8> {
    let (mut doc, bin) = scene(Storage::Float, true);
    let mut packed = Vec::new();
    let views = doc["bufferViews"].as_array().unwrap().clone();
    let accessors = doc["accessors"].as_array().unwrap().clone();
    for (v, view) in views.iter().enumerate() {
        let Some(a) = accessors.iter().find(|a| a["bufferView"] == json!(v)) else {
            continue;
        };
        let (offset, length) = (
            view["byteOffset"].as_u64().unwrap() as usize,
            view["byteLength"].as_u64().unwrap() as usize,
        );
        let data = &bin[offset..offset + length];
        let count = a["count"].as_u64().unwrap() as usize;
        let (mode, stride, encoded) = if a["type"] == "SCALAR" {
            let i: Vec<u32> = data
                .chunks_exact(2)
                .map(|c| u16::from_le_bytes([c[0], c[1]]) as u32)
                .collect();
            (
                "TRIANGLES",
                2,
                meshopt::encode_index_buffer(&i, 24).unwrap(),
            )
        } else {
            let stride = length / count;
            let enc = match stride {
                4 => meshopt::encode_vertex_buffer(
                    &data
                        .chunks_exact(4)
                        .map(|c| <[u8; 4]>::try_from(c).unwrap())
                        .collect::<Vec<_>>(),
                ),
                8 => meshopt::encode_vertex_buffer(
                    &data
                        .chunks_exact(8)
                        .map(|c| <[u8; 8]>::try_from(c).unwrap())
                        .collect::<Vec<_>>(),
                ),
                _ => meshopt::encode_vertex_buffer(
                    &data
                        .chunks_exact(12)
                        .map(|c| <[u8; 12]>::try_from(c).unwrap())
                        .collect::<Vec<_>>(),
                ),
            };
            ("ATTRIBUTES", stride, enc.unwrap())
        };
        while !packed.len().is_multiple_of(4) {
            packed.push(0);
        }
        doc["bufferViews"][v]["buffer"] = json!(1);
        doc["bufferViews"][v]["byteStride"] = if mode == "TRIANGLES" {
            Value::Null
        } else {
            json!(stride)
        };
        doc["bufferViews"][v]["extensions"] = json!({"EXT_meshopt_compression": {
            "buffer": 0, "byteOffset": packed.len(), "byteLength": encoded.len(),
            "byteStride": stride, "count": count, "mode": mode}});
        packed.extend_from_slice(&encoded);
    }
    // The GLB's chunk holds the encoded data and the image; the declared buffer 1 is a fallback.
    let image_view = doc["images"][0]["bufferView"].as_u64().unwrap() as usize;
    let (offset, length) = (
        doc["bufferViews"][image_view]["byteOffset"]
            .as_u64()
            .unwrap() as usize,
        doc["bufferViews"][image_view]["byteLength"]
            .as_u64()
            .unwrap() as usize,
    );
    while !packed.len().is_multiple_of(4) {
        packed.push(0);
    }
    doc["bufferViews"][image_view]["byteOffset"] = json!(packed.len());
    packed.extend_from_slice(&bin[offset..offset + length]);
    doc["buffers"] = json!([{"byteLength": packed.len()}, {"byteLength": bin.len(), "extensions": {"EXT_meshopt_compression": {"fallback": true}}}]);
    doc["extensionsUsed"] = json!(["KHR_texture_transform", "EXT_meshopt_compression"]);
    doc["extensionsRequired"] = json!(["EXT_meshopt_compression"]);
    glb(&doc, packed)
}

#[test]
fn meshopt_compressed_views_read_as_the_plain_ones() {
    let read = parse_scene(&meshopt_scene(), None).unwrap();
    check(&read);
    let (doc, bin) = scene(Storage::Float, true);
    assert_eq!(
        read.asset,
        parse_scene(&glb(&doc, bin), None).unwrap().asset
    );
}

#[test]
fn a_required_extension_not_read_is_refused_by_name_and_one_only_used_is_a_warning() {
    let (mut doc, bin) = scene(Storage::Float, true);
    doc["extensionsUsed"] = json!(["KHR_materials_pbrSpecularGlossiness", "KHR_materials_sheen"]);
    doc["extensionsRequired"] = json!(["KHR_materials_pbrSpecularGlossiness"]);
    let e = parse_scene(&glb(&doc, bin.clone()), None)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("requires KHR_materials_pbrSpecularGlossiness, which voxlod does not read"),
        "{e}"
    );
    doc["extensionsRequired"] = json!([]);
    let read = parse_scene(&glb(&doc, bin), None).unwrap();
    assert_eq!(read.warnings.len(), 2, "{:?}", read.warnings);
    assert!(read.warnings[1].contains("KHR_materials_sheen"));
}

#[test]
fn broken_files_are_errors_that_say_what_is_wrong() {
    let (doc, bin) = scene(Storage::Float, true);
    let whole = glb(&doc, bin.clone());
    let cases: Vec<(Vec<u8>, &str)> = vec![
        (whole[..whole.len() / 2].to_vec(), "not a GLB"),
        (b"{\"asset\": ".to_vec(), "JSON does not parse"),
        (glb(&doc, bin[..100].to_vec()), "declares"),
        (
            {
                let mut d = doc.clone();
                d["accessors"][0]["count"] = json!(1000);
                glb(&d, bin.clone())
            },
            "beyond",
        ),
        (
            {
                let mut d = doc.clone();
                d["meshes"][0]["primitives"][0]["indices"] = json!(99);
                glb(&d, bin.clone())
            },
            "not a valid glTF",
        ),
        (
            {
                let mut d = doc.clone();
                d["images"][0] = json!({"uri": "../secret.png"});
                glb(&d, bin.clone())
            },
            "not a file beside",
        ),
    ];
    for (bytes, words) in cases {
        let e = parse_scene(&bytes, Some(Path::new("/nonexistent")))
            .unwrap_err()
            .to_string();
        assert!(e.contains(words), "{words}: {e}");
    }
}

#[test]
fn a_scene_without_triangles_says_so() {
    // No mesh at all (and so no buffers, which glTF leaves out), and points only.
    let empty = json!({"asset": {"version": "2.0"}, "scenes": [{"nodes": []}], "scene": 0});
    let (mut points, bin) = scene(Storage::Float, true);
    for mesh in points["meshes"].as_array_mut().unwrap() {
        for primitive in mesh["primitives"].as_array_mut().unwrap() {
            primitive["mode"] = json!(0);
        }
    }
    let files = [serde_json::to_vec(&empty).unwrap(), glb(&points, bin)];
    for bytes in files {
        let e = parse_scene(&bytes, None).unwrap_err();
        assert!(matches!(e, voxlod_gltf::GltfError::NoTriangles), "{e}");
    }
}

#[test]
fn mutated_files_never_panic() {
    let files = [
        meshopt_scene(),
        {
            let (d, b) = scene(Storage::Quantized, true);
            glb(&d, b)
        },
        draco_scene(),
        instanced_scene(),
    ];
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    for file in &files {
        for _ in 0..400 {
            let mut bytes = file.clone();
            for _ in 0..1 + next() % 4 {
                let at = (next() as usize) % bytes.len();
                bytes[at] = next() as u8;
            }
            let outcome = std::panic::catch_unwind(|| {
                let _ = voxlod_gltf::decompress_glb(&bytes);
                parse_scene(&bytes, None).map(|r| r.asset.mesh.triangles.len())
            });
            assert!(outcome.is_ok(), "a mutated file panicked");
        }
    }
}

/// The scene `doc` and `bin` written as a GLB and packed by gltfpack with `flags`, whose output
/// must name each of `extensions`: the folder that holds them (dropped last), the input's path
/// and the packed file's. `None`, recorded as a skip, without the peers' gltfpack.
fn gltfpacked(
    doc: &Value,
    bin: Vec<u8>,
    flags: &[&str],
    extensions: &[&str],
) -> Option<(tempfile::TempDir, std::path::PathBuf, std::path::PathBuf)> {
    let Some(gltfpack) = std::env::var_os("HOME")
        .map(|h| Path::new(&h).join(".cache/voxlod-peers/node_modules/.bin/gltfpack"))
        .filter(|p| p.is_file())
    else {
        voxlod_testkit::skips::skip(
            "no gltfpack in ~/.cache/voxlod-peers (../shared/peers/setup.sh)",
        );
        return None;
    };
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("scene.glb");
    std::fs::write(&input, glb(doc, bin)).unwrap();
    let packed = dir.path().join("packed.glb");
    let out = std::process::Command::new(gltfpack)
        .args([
            "-i".as_ref(),
            input.as_os_str(),
            "-o".as_ref(),
            packed.as_os_str(),
        ])
        .args(flags)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&std::fs::read(&packed).unwrap()).into_owned();
    for e in extensions {
        assert!(text.contains(e), "gltfpack's output has no {e}");
    }
    Some((dir, input, packed))
}

#[test]
fn a_file_gltfpack_compressed_reads_as_the_scene_it_packed() {
    let (doc, bin) = scene(Storage::Float, true);
    let meshopt = ["EXT_meshopt_compression", "KHR_mesh_quantization"];
    let Some((_dir, _, packed)) = gltfpacked(&doc, bin, &["-cc", "-kn"], &meshopt) else {
        return;
    };
    let read = read_scene(&packed).unwrap();
    let m = &read.asset.mesh;
    assert_eq!(m.triangles.len(), 25);
    let b = voxlod_core::TriangleMesh::new(m.positions.clone(), m.triangles.clone()).bounds();
    assert!(
        (b.min - voxlod_core::glam::DVec3::new(-2.5, -0.5, -0.5))
            .abs()
            .max_element()
            < 1e-3,
        "{:?}",
        b
    );
    assert!(
        (b.max - voxlod_core::glam::DVec3::new(2.5, 1.0, 0.5))
            .abs()
            .max_element()
            < 1e-3,
        "{:?}",
        b
    );
    let textured = read
        .asset
        .materials
        .iter()
        .filter(|m| m.base_color_texture.is_some())
        .count();
    assert_eq!(textured, 1);
    assert_eq!(read.asset.images[0].mime, "image/png");
}

/// Every number in the JSON, by path, so that a mutation can change one of them.
fn number_paths(v: &Value, path: &mut Vec<Value>, out: &mut Vec<Vec<Value>>) {
    match v {
        Value::Number(_) => out.push(path.clone()),
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                path.push(json!(i));
                number_paths(x, path, out);
                path.pop();
            }
        }
        Value::Object(o) => {
            for (k, x) in o {
                path.push(json!(k));
                number_paths(x, path, out);
                path.pop();
            }
        }
        _ => {}
    }
}

#[test]
fn documents_with_a_changed_number_never_panic() {
    let parts = |file: Vec<u8>| {
        let g = gltf::binary::Glb::from_slice(&file).unwrap();
        let doc: Value = serde_json::from_slice(&g.json).unwrap();
        (doc, g.bin.unwrap().into_owned())
    };
    let (d, b) = scene(Storage::Quantized, true);
    for (doc, bin) in [(d, b), parts(draco_scene()), parts(instanced_scene())] {
        numbers_changed_never_panic(&doc, &bin);
    }
}

/// [`documents_with_a_changed_number_never_panic`] for one document.
fn numbers_changed_never_panic(doc: &Value, bin: &[u8]) {
    let mut paths = Vec::new();
    number_paths(doc, &mut Vec::new(), &mut paths);
    let values = [
        json!(0),
        json!(1),
        json!(3),
        json!(-1),
        json!(7),
        json!(1e9),
        json!(4294967295u64),
        json!(0.5),
    ];
    for path in &paths {
        for value in &values {
            let mut d = doc.clone();
            let mut at = &mut d;
            for key in path {
                at = match key {
                    Value::String(k) => &mut at[k.as_str()],
                    k => &mut at[k.as_u64().unwrap() as usize],
                };
            }
            *at = value.clone();
            let bytes = glb(&d, bin.to_vec());
            let outcome = std::panic::catch_unwind(|| {
                parse_scene(&bytes, None).map(|r| r.asset.mesh.triangles.len())
            });
            assert!(outcome.is_ok(), "{path:?} = {value} panicked");
        }
    }
}

/// Every triangle corner with its attributes, as bits, sorted: equal for two meshes that draw
/// the same triangles with the same looks, whatever their vertex order and primitives.
fn corners(read: &SceneRead) -> Vec<Vec<u32>> {
    let a = &read.asset;
    let m = &a.mesh;
    let mut out: Vec<Vec<u32>> = m
        .triangles
        .iter()
        .enumerate()
        .flat_map(|(t, tri)| {
            let material = a.materials[m.material[t] as usize].name.len() as u32;
            tri.map(|v| {
                let v = v as usize;
                let mut c: Vec<f32> = m.positions[v].to_array().to_vec();
                c.extend(m.normals[v].to_array());
                c.extend(m.uv[0].get(v).map_or([0.0; 2], |t| t.to_array()));
                c.extend(m.colors.get(v).map_or([1.0; 4], |c| c.to_array()));
                // -0 and 0 are one value (a transform on reading turns one into the other).
                let mut bits: Vec<u32> = c.into_iter().map(|x| (x + 0.0).to_bits()).collect();
                bits.push(material);
                bits
            })
        })
        .collect();
    out.sort();
    out
}

#[test]
fn an_asset_written_and_read_back_is_the_same_in_both_layouts() {
    let (doc, bin) = scene(Storage::Float, true);
    let input = parse_scene(&glb(&doc, bin), None).unwrap();
    let dir = tempfile::tempdir().unwrap();
    for layout in [voxlod_gltf::Layout::MsftLod, voxlod_gltf::Layout::LodNodes] {
        // Two levels: the asset and its first cube alone; read back, the finest is the asset.
        let mut coarse = input.asset.clone();
        coarse.mesh.triangles.truncate(12);
        coarse.mesh.material.truncate(12);
        coarse.parts.clear();
        let options = voxlod_gltf::AssetGlbOptions {
            layout,
            ..Default::default()
        };
        let bytes = voxlod_gltf::asset_glb(&[input.asset.clone(), coarse], &options).unwrap();
        let back = parse_scene(&bytes, None).unwrap();
        assert!(back.warnings.is_empty(), "{:?}", back.warnings);
        assert_eq!(corners(&back), corners(&input), "{layout:?}");
        assert_eq!(back.asset.images, input.asset.images);
        let textured = &back
            .asset
            .materials
            .iter()
            .find(|m| m.name == "checker")
            .unwrap();
        assert_eq!(**textured, input.asset.materials[0]);
        let path = dir.path().join(format!("{layout:?}.glb"));
        std::fs::write(&path, &bytes).unwrap();
        if let Some(v) = voxlod_testkit::gltf_validator::validate_gltf(&path) {
            assert_eq!((v.errors, v.warnings), (0, 0), "{layout:?}: {}", v.report);
        }
    }
}

#[test]
fn writing_refuses_what_cannot_make_a_file() {
    let (doc, bin) = scene(Storage::Float, true);
    let asset = parse_scene(&glb(&doc, bin), None).unwrap().asset;
    let options = voxlod_gltf::AssetGlbOptions::default();
    let e = voxlod_gltf::asset_glb(&[], &options)
        .unwrap_err()
        .to_string();
    assert!(e.contains("no level"), "{e}");
    let mut broken = asset.clone();
    broken.mesh.colors.pop();
    let e = voxlod_gltf::asset_glb(&[broken], &options)
        .unwrap_err()
        .to_string();
    assert!(e.contains("level 0") && e.contains("colours"), "{e}");
    let wrong = voxlod_gltf::AssetGlbOptions {
        coverages: vec![0.5],
        ..Default::default()
    };
    let e = voxlod_gltf::asset_glb(&[asset.clone(), asset], &wrong)
        .unwrap_err()
        .to_string();
    assert!(e.contains("one per level"), "{e}");
}

#[test]
fn an_untextured_chain_declares_msft_lod_and_validates() {
    let (doc, bin) = scene(Storage::Float, true);
    let mut asset = parse_scene(&glb(&doc, bin), None).unwrap().asset;
    asset.materials = asset.materials.iter().map(|m| m.untextured()).collect();
    asset.images.clear();
    let bytes = voxlod_gltf::asset_glb(&[asset.clone(), asset], &Default::default()).unwrap();
    let json = gltf::binary::Glb::from_slice(&bytes)
        .unwrap()
        .json
        .into_owned();
    let root: Value = serde_json::from_slice(&json).unwrap();
    assert_eq!(
        root["extensionsUsed"],
        json!(["KHR_materials_emissive_strength", "MSFT_lod"])
    );
    assert_eq!(
        root["nodes"][0]["extensions"]["MSFT_lod"]["ids"],
        json!([1])
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("plain.glb");
    std::fs::write(&path, &bytes).unwrap();
    if let Some(v) = voxlod_testkit::gltf_validator::validate_gltf(&path) {
        assert_eq!((v.errors, v.warnings), (0, 0), "{}", v.report);
    }
}

/// A textured sphere of radius `r` about its centre `at`, written with `origin` as its nodes'
/// translation (`compression` as given).
fn far_sphere(r: f32, origin: DVec3, compression: voxlod_gltf::Compression) -> Vec<u8> {
    let mut asset = voxlod_testkit::assets::textured_sphere(3);
    for p in &mut asset.mesh.positions {
        *p *= r;
    }
    let options = voxlod_gltf::AssetGlbOptions {
        origin,
        compression,
        ..Default::default()
    };
    voxlod_gltf::asset_glb(&[asset], &options).unwrap()
}

#[test]
fn a_scene_at_map_coordinates_keeps_its_detail_relative_to_an_origin_near_it() {
    // At 4·10⁶, f32 world coordinates step by half a unit: a sphere of radius 0.4 would be
    // crushed onto a few lattice points.
    let at = DVec3::new(4_000_000.25, 5_500_000.5, 120.0);
    for compression in [
        voxlod_gltf::Compression::None,
        voxlod_gltf::Compression::Meshopt,
    ] {
        let read = parse_scene(&far_sphere(0.4, at, compression), None).unwrap();
        assert_ne!(read.origin, DVec3::ZERO, "{compression:?}");
        assert!((read.origin - at).length() < 1.0, "{:?}", read.origin);
        assert!(read
            .warnings
            .iter()
            .any(|w| w.contains("far from the origin")));
        let centre = (at - read.origin).as_vec3();
        for p in &read.asset.mesh.positions {
            let r = (*p - centre).length();
            assert!((r - 0.4).abs() < 2e-4, "{compression:?}: radius {r}");
        }
        // Written back with its origin, it reads the same.
        let options = voxlod_gltf::AssetGlbOptions {
            origin: read.origin,
            ..Default::default()
        };
        let bytes = voxlod_gltf::asset_glb(std::slice::from_ref(&read.asset), &options).unwrap();
        let back = parse_scene(&bytes, None).unwrap();
        assert_eq!(back.origin, read.origin);
        for (p, q) in back
            .asset
            .mesh
            .positions
            .iter()
            .zip(&read.asset.mesh.positions)
        {
            assert!((*p - *q).length() < 1e-6, "{p} against {q}");
        }
    }
}

#[test]
fn a_scene_near_the_origin_keeps_world_coordinates() {
    // 1 000 diagonals away is still near: f32 keeps its detail there.
    let at = DVec3::new(500.0, 0.0, 0.0);
    let read = parse_scene(&far_sphere(0.4, at, voxlod_gltf::Compression::None), None).unwrap();
    assert_eq!(read.origin, DVec3::ZERO);
    assert!(read.warnings.is_empty(), "{:?}", read.warnings);
    let lowest = read
        .asset
        .mesh
        .positions
        .iter()
        .map(|p| p.x)
        .fold(f32::INFINITY, f32::min);
    assert!((lowest - 499.6).abs() < 1e-3, "{lowest}");
}

/// `data` appended to the GLB buffer `bin` as a new view of `doc` (4-byte aligned); its index.
fn append_view(doc: &mut Value, bin: &mut Vec<u8>, data: &[u8]) -> usize {
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let views = doc["bufferViews"].as_array_mut().unwrap();
    views.push(json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": data.len()}));
    let view = views.len() - 1;
    bin.extend_from_slice(data);
    doc["buffers"][0]["byteLength"] = json!(bin.len());
    view
}

/// `data` appended as a view and a float accessor of `count` elements of `kind`; its index.
fn append_floats(doc: &mut Value, bin: &mut Vec<u8>, data: &[f32], kind: &str) -> usize {
    let width = match kind {
        "VEC3" => 3,
        _ => 4,
    };
    let view = append_view(doc, bin, &f32s(data.iter().copied()));
    let accessors = doc["accessors"].as_array_mut().unwrap();
    accessors.push(json!({"bufferView": view, "componentType": 5126, "type": kind, "count": data.len() / width}));
    accessors.len() - 1
}

/// Names `extension` as used and required.
fn require(doc: &mut Value, extension: &str) {
    for key in ["extensionsUsed", "extensionsRequired"] {
        doc[key].as_array_mut().unwrap().push(json!(extension));
    }
}

/// The cube encoded by Draco (draco-core's encoder, as exporters configure C++ Draco: positions
/// at 14 bits, normals at 10, texture coordinates at 12), and the unique ids of its position,
/// normal and texture coordinate attributes.
fn draco_cube() -> (Vec<u8>, [u32; 3]) {
    use draco_core::{
        DataType, EncoderBuffer, EncoderOptions, GeometryAttributeType as Kind, Mesh, MeshEncoder,
        PointAttribute,
    };
    let (p, n, t, i) = cube();
    let mut mesh = Mesh::new();
    mesh.set_num_points(p.len());
    let mut add = |kind: Kind, components: u8, values: Vec<f32>| {
        let mut a = PointAttribute::new();
        a.init(kind, components, DataType::Float32, false, p.len());
        a.buffer_mut().write(0, &f32s(values));
        mesh.add_attribute(a)
    };
    let flat = |v: &[Vec3]| v.iter().flat_map(|x| x.to_array()).collect::<Vec<f32>>();
    let ids = [
        add(Kind::Position, 3, flat(&p)),
        add(Kind::Normal, 3, flat(&n)),
        add(
            Kind::TexCoord,
            2,
            t.iter().flat_map(|x| x.to_array()).collect(),
        ),
    ];
    mesh.set_num_faces(i.len() / 3);
    mesh.set_faces_from_flat_indices(&i.iter().map(|&x| u32::from(x)).collect::<Vec<_>>());
    let mut options = EncoderOptions::new();
    for (id, bits) in ids.iter().zip([14, 10, 12]) {
        options.set_attribute_quantization(*id, bits);
    }
    let unique = ids.map(|id| mesh.attribute(id).unique_id());
    let mut encoder = MeshEncoder::new();
    encoder.set_mesh(mesh);
    let mut buffer = EncoderBuffer::new();
    encoder.encode(&options, &mut buffer).unwrap();
    (buffer.data().to_vec(), unique)
}

/// The scene with its cube's primitive Draco-compressed: the extension names the stream's view
/// and attribute ids, and the primitive's accessors keep their counts but lose their data.
fn draco_scene() -> Vec<u8> {
    let (mut doc, mut bin) = scene(Storage::Float, true);
    let (stream, ids) = draco_cube();
    let view = append_view(&mut doc, &mut bin, &stream);
    let primitive = doc["meshes"][0]["primitives"][0].clone();
    for key in ["POSITION", "NORMAL", "TEXCOORD_0"] {
        let a = primitive["attributes"][key].as_u64().unwrap() as usize;
        doc["accessors"][a]
            .as_object_mut()
            .unwrap()
            .remove("bufferView");
    }
    let indices = primitive["indices"].as_u64().unwrap() as usize;
    doc["accessors"][indices]
        .as_object_mut()
        .unwrap()
        .remove("bufferView");
    doc["meshes"][0]["primitives"][0]["extensions"] = json!({"KHR_draco_mesh_compression": {
        "bufferView": view,
        "attributes": {"POSITION": ids[0], "NORMAL": ids[1], "TEXCOORD_0": ids[2]}
    }});
    require(&mut doc, "KHR_draco_mesh_compression");
    glb(&doc, bin)
}

/// [`corners`] with every value rounded to `step`: equal for two meshes that differ by less
/// than a quantization step (on values that are multiples of 10 steps, as the cube's are).
fn rounded_corners(read: &SceneRead, step: f32) -> Vec<Vec<i64>> {
    let mut out: Vec<Vec<i64>> = (corners(read).into_iter())
        .map(|c| {
            let (values, material) = c.split_at(c.len() - 1);
            let mut r: Vec<i64> = (values.iter())
                .map(|&b| (f32::from_bits(b) / step).round() as i64)
                .collect();
            r.push(i64::from(material[0]));
            r
        })
        .collect();
    out.sort();
    out
}

#[test]
fn a_draco_compressed_primitive_reads_as_the_plain_one_within_its_quantization() {
    let (doc, bin) = scene(Storage::Float, true);
    let plain = parse_scene(&glb(&doc, bin), None).unwrap();
    let read = parse_scene(&draco_scene(), None).unwrap();
    assert!(read.warnings.is_empty(), "{:?}", read.warnings);
    assert_eq!(read.asset.mesh.triangles.len(), 25);
    assert_eq!(read.asset.parts, plain.asset.parts);
    assert_eq!(rounded_corners(&read, 1e-3), rounded_corners(&plain, 1e-3));
    // Both cubes (one mirrored) still enclose a unit volume, facing out.
    for p in &read.asset.parts[..2] {
        let range = p.first_triangle as usize..(p.first_triangle + p.triangle_count) as usize;
        assert!((volume(&read, range) - 1.0).abs() < 1e-3);
    }
}

#[test]
fn a_broken_draco_stream_is_an_error_that_names_the_primitive() {
    let good = draco_scene();
    let (json, bin) = {
        let g = gltf::binary::Glb::from_slice(&good).unwrap();
        let json: Value = serde_json::from_slice(&g.json).unwrap();
        (json, g.bin.unwrap().into_owned())
    };
    let stream = json["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]
        ["bufferView"]
        .as_u64()
        .unwrap() as usize;
    // Half the stream, then the stream with its body overwritten, then an attribute id it lacks.
    let mut half = json.clone();
    let length = half["bufferViews"][stream]["byteLength"].as_u64().unwrap();
    half["bufferViews"][stream]["byteLength"] = json!(length / 2);
    let mut scrambled = bin.clone();
    let at = json["bufferViews"][stream]["byteOffset"].as_u64().unwrap() as usize;
    for (k, b) in scrambled[at + 12..at + length as usize]
        .iter_mut()
        .enumerate()
    {
        *b = (k * 37 % 251) as u8;
    }
    let mut missing = json.clone();
    missing["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]
        ["attributes"]["NORMAL"] = json!(9);
    let here = "mesh 0, primitive 0 (KHR_draco_mesh_compression): ";
    let e = parse_scene(&glb(&half, bin.clone()), None)
        .unwrap_err()
        .to_string();
    assert!(e.contains(&format!("{here}Draco cannot decode it")), "{e}");
    let e = parse_scene(&glb(&missing, bin), None)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains(&format!("{here}NORMAL: the stream has no attribute 9")),
        "{e}"
    );
    // A scrambled body may still decode to some mesh: then a valid one.
    match parse_scene(&glb(&json, scrambled), None) {
        Err(e) => assert!(e.to_string().contains(here), "{e}"),
        Ok(read) => assert!(read.asset.validate().is_ok()),
    }
}

/// The cube drawn by one node under three instances: moved by (3, 0, 0); turned a quarter about
/// z and moved by (0, 3, 0); mirrored in x and scaled by 2, at the node's origin.
fn instanced_scene() -> Vec<u8> {
    let (mut doc, mut bin) = scene(Storage::Float, true);
    let t = append_floats(
        &mut doc,
        &mut bin,
        &[3.0, 0.0, 0.0, 0.0, 3.0, 0.0, 0.0, 0.0, 0.0],
        "VEC3",
    );
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let r = append_floats(
        &mut doc,
        &mut bin,
        &[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, s, s, 0.0, 0.0, 0.0, 1.0],
        "VEC4",
    );
    let k = append_floats(
        &mut doc,
        &mut bin,
        &[1.0, 1.0, 1.0, 1.0, 1.0, 1.0, -2.0, 2.0, 2.0],
        "VEC3",
    );
    doc["nodes"] = json!([{"name": "crates", "mesh": 0, "translation": [10.0, 0.0, 0.0],
        "extensions": {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": t, "ROTATION": r, "SCALE": k}}}}]);
    doc["scenes"] = json!([{"nodes": [0]}]);
    require(&mut doc, "EXT_mesh_gpu_instancing");
    glb(&doc, bin)
}

#[test]
fn gpu_instances_are_each_placed_under_their_node() {
    let read = parse_scene(&instanced_scene(), None).unwrap();
    let a = &read.asset;
    assert!(read.warnings.is_empty(), "{:?}", read.warnings);
    assert_eq!(a.mesh.triangles.len(), 36);
    let names: Vec<&str> = a.parts.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "crates, instance 0",
            "crates, instance 1",
            "crates, instance 2"
        ]
    );
    for (p, (centre, size)) in a.parts.iter().zip([
        (Vec3::new(13.0, 0.0, 0.0), 1.0),
        (Vec3::new(10.0, 3.0, 0.0), 1.0),
        (Vec3::new(10.0, 0.0, 0.0), 2.0),
    ]) {
        let range = p.first_triangle as usize..(p.first_triangle + p.triangle_count) as usize;
        // Facing out under the mirror too: the volume is the cube's, positive.
        assert!(
            (volume(&read, range.clone()) - size * size * size).abs() < 1e-4,
            "{}",
            p.name
        );
        for t in &a.mesh.triangles[range] {
            for &v in t {
                let q = a.mesh.positions[v as usize];
                assert!(
                    ((q - centre).abs().max_element() - size / 2.0).abs() < 1e-5,
                    "{q}"
                );
            }
        }
    }
    // The quarter turn took the cube's +x face (texture coordinates as written) to +y.
    let turned = &a.parts[1];
    let first = turned.first_triangle as usize;
    let plus_x = (first..first + 12)
        .flat_map(|t| a.mesh.triangles[t])
        .filter(|&v| a.mesh.normals[v as usize].y > 0.99)
        .count();
    assert_eq!(plus_x, 6);
}

#[test]
fn broken_instancing_is_an_error_that_names_the_node() {
    let good = gltf::binary::Glb::from_slice(&instanced_scene())
        .unwrap()
        .bin
        .unwrap()
        .into_owned();
    let json: Value = serde_json::from_slice(
        &gltf::binary::Glb::from_slice(&instanced_scene())
            .unwrap()
            .json,
    )
    .unwrap();
    let attributes = "/nodes/0/extensions/EXT_mesh_gpu_instancing/attributes";
    let mut short = json.clone();
    let translation = short
        .pointer(&format!("{attributes}/TRANSLATION"))
        .unwrap()
        .as_u64()
        .unwrap();
    short["accessors"][translation as usize]["count"] = json!(2);
    let mut none = json.clone();
    *none.pointer_mut(attributes).unwrap() = json!({});
    let mut dangling = json.clone();
    *dangling
        .pointer_mut(&format!("{attributes}/SCALE"))
        .unwrap() = json!(99);
    for (doc, why) in [
        (short, "different counts"),
        (none, "no TRANSLATION, ROTATION or SCALE"),
        (dangling, "SCALE names no accessor"),
    ] {
        let e = parse_scene(&glb(&doc, good.clone()), None)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("node 0 (EXT_mesh_gpu_instancing)") && e.contains(why),
            "{e}"
        );
    }
}

/// Writes a GLB of a UV sphere of radius 1 whose one primitive C++ Draco compressed (DracoPy,
/// positions at 14 bits, normals at 10, as Blender's exporter does by default), and prints the
/// triangle count and the polyhedron's volume.
const DRACOPY_SPHERE: &str = r#"
import sys, json, struct, numpy as np, DracoPy
rings, segments = 24, 48
points = [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]]
for i in range(1, rings):
    t = np.pi * i / rings
    for j in range(segments):
        f = 2 * np.pi * j / segments
        points.append([np.sin(t) * np.cos(f), np.sin(t) * np.sin(f), np.cos(t)])
points = np.array(points, dtype=np.float32)
at = lambda i, j: 2 + (i - 1) * segments + j % segments
faces = [[0, at(1, j), at(1, j + 1)] for j in range(segments)]
for i in range(1, rings - 1):
    for j in range(segments):
        faces += [[at(i, j), at(i + 1, j), at(i + 1, j + 1)], [at(i, j), at(i + 1, j + 1), at(i, j + 1)]]
faces += [[1, at(rings - 1, j + 1), at(rings - 1, j)] for j in range(segments)]
faces = np.array(faces, dtype=np.uint32)
stream = DracoPy.encode(points, faces, quantization_bits=14, compression_level=7,
                        normals=points.astype(np.float64), normal_quantization_bits=10)
back = DracoPy.decode(stream)
ids = {"POSITION": 0, "NORMAL": 1}
while len(stream) % 4: stream += b"\0"
doc = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
       "extensionsUsed": ["KHR_draco_mesh_compression"], "extensionsRequired": ["KHR_draco_mesh_compression"],
       "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2,
            "extensions": {"KHR_draco_mesh_compression": {"bufferView": 0, "attributes": ids}}}]}],
       "accessors": [
           {"componentType": 5126, "count": len(back.points), "type": "VEC3", "min": [-1, -1, -1], "max": [1, 1, 1]},
           {"componentType": 5126, "count": len(back.points), "type": "VEC3"},
           {"componentType": 5125, "count": 3 * len(faces), "type": "SCALAR"}],
       "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(stream)}],
       "buffers": [{"byteLength": len(stream)}]}
text = json.dumps(doc).encode()
while len(text) % 4: text += b" "
glb = struct.pack("<4sII", b"glTF", 2, 28 + len(text) + len(stream))
glb += struct.pack("<I4s", len(text), b"JSON") + text + struct.pack("<I4s", len(stream), b"BIN\0") + stream
open(sys.argv[1], "wb").write(glb)
p = points[faces]
print(len(faces), np.einsum("ij,ij->i", p[:, 0], np.cross(p[:, 1], p[:, 2])).sum() / 6)
"#;

#[test]
fn a_primitive_that_cpp_draco_compressed_reads_as_its_sphere() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sphere.glb");
    let Some(out) = voxlod_testkit::peers::run_python(DRACOPY_SPHERE, &[path.as_os_str()]) else {
        return;
    };
    let numbers: Vec<f64> = out.split_whitespace().map(|x| x.parse().unwrap()).collect();
    let (triangles, volume_written) = (numbers[0] as usize, numbers[1]);
    let read = read_scene(&path).unwrap();
    let m = &read.asset.mesh;
    assert_eq!(m.triangles.len(), triangles);
    // 14 bits over a span of 2: a step of 1.2·10⁻⁴.
    for (p, n) in m.positions.iter().zip(&m.normals) {
        assert!((p.length() - 1.0).abs() < 3e-4, "{p}");
        assert!(n.dot(*p) > 0.99, "normal {n} at {p}");
    }
    let whole = volume(&read, 0..m.triangles.len()) as f64;
    assert!(
        (whole - volume_written).abs() < 1e-3 * volume_written,
        "{whole} {volume_written}"
    );
}

#[test]
fn a_scene_gltfpack_instanced_reads_as_the_scene_it_packed() {
    // Five nodes of the cube in a row, one turned: gltfpack -mi draws them as instances of one
    // node.
    let (mut doc, bin) = scene(Storage::Float, true);
    doc["nodes"] = json!([
        {"mesh": 0, "translation": [0.0, 0.0, 0.0]},
        {"mesh": 0, "translation": [2.0, 0.0, 0.0]},
        {"mesh": 0, "translation": [4.0, 0.0, 0.0], "rotation": [0.0, 0.0, 0.38268343, 0.9238795]},
        {"mesh": 0, "translation": [6.0, 0.0, 0.0], "scale": [1.0, 2.0, 1.0]},
        {"mesh": 0, "translation": [8.0, 0.0, 0.0]}
    ]);
    doc["scenes"] = json!([{"nodes": [0, 1, 2, 3, 4]}]);
    let instancing = ["EXT_mesh_gpu_instancing"];
    let Some((_dir, input, packed)) = gltfpacked(&doc, bin, &["-mi"], &instancing) else {
        return;
    };
    let (original, read) = (read_scene(&input).unwrap(), read_scene(&packed).unwrap());
    assert_eq!(read.asset.mesh.triangles.len(), 60);
    // Positions and normals (gltfpack folds the material's texture transform into the
    // coordinates, so those differ as stored).
    let placed = |read: &SceneRead| {
        let m = &read.asset.mesh;
        let mut corners: Vec<[i64; 6]> = (m.triangles.iter().flatten())
            .map(|&v| {
                let (p, n) = (m.positions[v as usize], m.normals[v as usize]);
                let r = |x: f32| (x * 1000.0).round() as i64;
                [r(p.x), r(p.y), r(p.z), r(n.x), r(n.y), r(n.z)]
            })
            .collect();
        corners.sort();
        corners
    };
    assert_eq!(placed(&read), placed(&original));
}

/// `file` through `decompress_glb`: its JSON, after checking that it requires no extension,
/// has one buffer, reads with the `gltf` crate (which decodes nothing) and draws the corners
/// `file` draws.
fn decompressed(file: &[u8]) -> Value {
    let plain = voxlod_gltf::decompress_glb(file).unwrap();
    let g = gltf::binary::Glb::from_slice(&plain).unwrap();
    let doc: Value = serde_json::from_slice(&g.json).unwrap();
    assert_eq!(
        doc["extensionsRequired"],
        json!([]),
        "{}",
        doc["extensionsRequired"]
    );
    assert_eq!(doc["buffers"].as_array().unwrap().len(), 1);
    gltf::Gltf::from_slice(&plain).unwrap();
    let (read, given) = (
        parse_scene(&plain, None).unwrap(),
        parse_scene(file, None).unwrap(),
    );
    assert_eq!(corners(&read), corners(&given));
    doc
}

#[test]
fn a_draco_file_decompressed_needs_no_extension_and_draws_the_same() {
    decompressed(&draco_scene());
}

#[test]
fn gpu_instances_decompressed_become_nodes_that_draw_the_same() {
    let doc = decompressed(&instanced_scene());
    assert_eq!(doc["nodes"][0]["children"], json!([1, 2, 3]));
}
