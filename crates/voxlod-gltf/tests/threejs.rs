//! The asset `.glb` files as three.js's `GLTFLoader` reads them in headless Chromium (three
//! from npm in the peers' kit, `~/.cache/voxlod-peers/node_modules/three` or
//! `$VOXLOD_PEERS/node_modules/three`; Chromium at `/usr/bin/chromium` or `$VOXLOD_CHROMIUM`).
//! Skips with a printed reason when either is missing.
//!
//! Three levels of a sphere textured red on its −x half and blue on its +x half: the input
//! (textured), its collapse (textured, the same image) and a coarser sphere with the input's
//! looks transferred as vertex colours. Written in both layouts, served over HTTP from a thread
//! (ES modules do not load from `file://`), loaded by a page that posts a JSON summary back:
//! - `LodNodes`: the scene's children are `LOD0`, `LOD1`, `LOD2`, one per level, each drawing
//!   the level's triangles; the textured levels' materials have a `map` whose image is the
//!   2×1 PNG and the geometry has `uv`; the transferred level has `color` and its material
//!   `vertexColors`. Each level drawn alone is red left of centre and blue right of it.
//! - `MsftLod`: the file loads (three ignores the extension), the scene holds one node drawing
//!   the finest level, textured, red left and blue right.
//! - `LodNodes` compressed (`EXT_meshopt_compression`, `KHR_mesh_quantization`; three's
//!   `MeshoptDecoder` given to the loader): everything the plain `LodNodes` file shows.
//!
//! Any loader error, uncaught page error or console warning fails the test with its message.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::{Component, Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::mpsc::{channel, Sender};
use std::time::{Duration, Instant};
use voxlod_testkit::assets::textured_sphere;
use voxlod_testkit::browser::chromium;

use serde_json::Value;
use voxlod_asset::{collapse, transfer, Asset};
use voxlod_gltf::{asset_glb, AssetGlbOptions, Compression, Layout};
use voxlod_testkit::shapes::icosphere;
use voxlod_testkit::skips::skip;

/// How long the page may take to load and report, in real time.
const PAGE_TIMEOUT: Duration = Duration::from_secs(60);

fn three() -> Option<PathBuf> {
    let peers = std::env::var_os("VOXLOD_PEERS")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache/voxlod-peers")))
        .unwrap_or_else(|| PathBuf::from("~/.cache/voxlod-peers"));
    let dir = peers.join("node_modules/three");
    if dir.join("build/three.module.js").is_file() {
        Some(dir)
    } else {
        skip(format!(
            "no three.js: {} is missing (../shared/peers/setup.sh installs it)",
            dir.display()
        ));
        None
    }
}

/// The input, its collapse and a coarser sphere with the input's looks as vertex colours.
fn levels() -> Vec<Asset> {
    let input = textured_sphere(3);
    let collapsed = collapse(&input, 300).unwrap();
    let coloured = transfer(&input, &icosphere(1)).unwrap();
    assert!(coloured.warnings.is_empty(), "{:?}", coloured.warnings);
    let levels = vec![input, collapsed, coloured.asset];
    assert!(levels[1].materials[0].base_color_texture.is_some());
    assert!(!levels[2].mesh.colors.is_empty());
    levels
}

/// The page: loads each file with `GLTFLoader`, summarises its scene, draws each scene child
/// alone into a 64×64 target (orthographic, looking down −z, ambient light) and posts the
/// summary to `/result`.
fn page(files: &[&str]) -> String {
    let files = serde_json::to_string(files).unwrap();
    format!(
        r#"<!doctype html>
<html><head><meta charset="utf-8">
<script type="importmap">{{"imports": {{"three": "/three/build/three.module.js",
  "three/addons/": "/three/examples/jsm/"}}}}</script>
<script>
window.problems = [];
window.addEventListener('error', e => window.problems.push('page error: ' + e.message));
window.addEventListener('unhandledrejection', e => window.problems.push('rejection: ' + (e.reason && e.reason.message || e.reason)));
for (const level of ['warn', 'error']) {{
  const original = console[level];
  console[level] = (...args) => {{ window.problems.push(level + ': ' + args.map(String).join(' ')); original.apply(console, args); }};
}}
function post(text) {{
  document.getElementById('out').textContent = text;
  fetch('/result', {{method: 'POST', body: text}});
}}
window.addEventListener('load', () => setTimeout(() => {{
  if (!window.started) post(JSON.stringify({{files: {{}}, problems: window.problems.concat(['the module did not run'])}}));
}}, 5000));
</script>
<script type="module" onerror="window.problems.push('module script failed to load')">
window.started = true;
import * as THREE from 'three';
import {{ GLTFLoader }} from 'three/addons/loaders/GLTFLoader.js';
import {{ MeshoptDecoder }} from 'three/addons/libs/meshopt_decoder.module.js';
const files = {files};
const loader = new GLTFLoader();
loader.setMeshoptDecoder(MeshoptDecoder);
const canvas = document.createElement('canvas');
const renderer = new THREE.WebGLRenderer({{canvas}});
const target = new THREE.WebGLRenderTarget(64, 64);
const camera = new THREE.OrthographicCamera(-1.2, 1.2, 1.2, -1.2, 0.1, 10);
camera.position.set(0, 0, 3);
camera.lookAt(0, 0, 0);
function draw(scene, shown) {{
  const pixels = new Uint8Array(64 * 64 * 4);
  for (const child of scene.children) child.visible = child === shown;
  const light = new THREE.AmbientLight(0xffffff, 3);
  scene.add(light);
  renderer.setRenderTarget(target);
  renderer.setClearColor(0xffffff, 1);
  renderer.render(scene, camera);
  renderer.readRenderTargetPixels(target, 0, 0, 64, 64, pixels);
  renderer.setRenderTarget(null);
  scene.remove(light);
  for (const child of scene.children) child.visible = true;
  const at = (x, y) => Array.from(pixels.slice((y * 64 + x) * 4, (y * 64 + x) * 4 + 3));
  return {{left: at(16, 32), right: at(48, 32)}};
}}
function meshes(node) {{
  const list = [];
  node.traverse(o => {{
    if (!o.isMesh) return;
    const g = o.geometry, m = o.material;
    const image = m.map && m.map.image;
    list.push({{
      triangles: (g.index ? g.index.count : g.attributes.position.count) / 3,
      uv: !!g.attributes.uv,
      color: !!g.attributes.color,
      normal: !!g.attributes.normal,
      vertexColors: !!m.vertexColors,
      map: image ? [image.width, image.height] : null,
    }});
  }});
  return list;
}}
const out = {{files: {{}}, problems: window.problems}};
for (const file of files) {{
  try {{
    const gltf = await loader.loadAsync(file);
    const children = gltf.scene.children.map(child => ({{
      name: child.name,
      meshes: meshes(child),
      drawn: draw(gltf.scene, child),
    }}));
    out.files[file] = {{children, extensionsUsed: gltf.parser.json.extensionsUsed || []}};
  }} catch (e) {{
    out.files[file] = {{error: String(e && e.message || e)}};
  }}
}}
post(JSON.stringify(out));
</script></head>
<body><pre id="out">pending</pre></body></html>
"#
    )
}

fn content_type(path: &Path) -> &'static str {
    match path.extension().and_then(|e| e.to_str()) {
        Some("html") => "text/html; charset=utf-8",
        Some("js") => "text/javascript; charset=utf-8",
        Some("json") => "application/json",
        Some("glb") => "model/gltf-binary",
        _ => "application/octet-stream",
    }
}

/// One request: a GET of a file under `root` (or, under `/three/`, of three's package), or the
/// page's POST of its summary to `/result`, sent on `result`.
fn serve(stream: TcpStream, root: &Path, three: &Path, result: &Sender<String>) {
    let mut reader = BufReader::new(stream.try_clone().unwrap());
    let mut line = String::new();
    if reader.read_line(&mut line).is_err() {
        return;
    }
    let mut parts = line.split_whitespace();
    let (method, target) = (parts.next().unwrap_or(""), parts.next().unwrap_or("/"));
    let mut length = 0usize;
    loop {
        let mut header = String::new();
        if reader.read_line(&mut header).unwrap_or(0) == 0 || header.trim().is_empty() {
            break;
        }
        if let Some((name, value)) = header.split_once(':') {
            if name.eq_ignore_ascii_case("content-length") {
                length = value.trim().parse().unwrap_or(0);
            }
        }
    }
    let mut stream = stream;
    let respond = |stream: &mut TcpStream, status: &str, kind: &str, body: &[u8]| {
        let head = format!(
            "HTTP/1.1 {status}\r\nContent-Type: {kind}\r\nContent-Length: {}\r\nCache-Control: no-store\r\nConnection: close\r\n\r\n",
            body.len()
        );
        let _ = stream.write_all(head.as_bytes());
        let _ = stream.write_all(body);
    };
    if method == "POST" && target == "/result" {
        let mut body = vec![0; length];
        if reader.read_exact(&mut body).is_ok() {
            let _ = result.send(String::from_utf8_lossy(&body).into_owned());
        }
        respond(&mut stream, "204 No Content", "text/plain", b"");
        return;
    }
    let path = target.split(['?', '#']).next().unwrap_or("/");
    let (base, rest) = match path.strip_prefix("/three/") {
        Some(rest) => (three, rest),
        None => (root, path.trim_start_matches('/')),
    };
    let rest = Path::new(rest);
    let safe = rest.components().all(|c| matches!(c, Component::Normal(_)));
    let file = base.join(rest);
    match std::fs::read(&file) {
        Ok(bytes) if safe && method == "GET" => {
            respond(&mut stream, "200 OK", content_type(&file), &bytes)
        }
        _ => respond(&mut stream, "404 Not Found", "text/plain", b"not found"),
    }
}

/// Serves `root` and three's package on a local port; the page's summary arrives on the
/// returned receiver.
fn start_server(root: PathBuf, three: PathBuf) -> (u16, std::sync::mpsc::Receiver<String>) {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let port = listener.local_addr().unwrap().port();
    let (send, receive) = channel();
    std::thread::spawn(move || {
        for stream in listener.incoming().flatten() {
            let (root, three, send) = (root.clone(), three.clone(), send.clone());
            std::thread::spawn(move || serve(stream, &root, &three, &send));
        }
    });
    (port, receive)
}

/// Opens the page in headless Chromium and returns the summary it posts.
fn run_page(browser: &Path, url: &str, receive: &std::sync::mpsc::Receiver<String>) -> Value {
    let profile = tempfile::tempdir().unwrap();
    let mut child = Command::new(browser)
        .args(voxlod_testkit::browser::HEADLESS)
        .arg("--window-size=200,200")
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .arg(url)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("chromium starts");
    let start = Instant::now();
    let got = receive.recv_timeout(PAGE_TIMEOUT);
    let _ = child.kill();
    let out = child.wait_with_output().unwrap();
    let text = got.unwrap_or_else(|_| {
        panic!(
            "the page posted no summary within {PAGE_TIMEOUT:?}; chromium said:\n{}",
            String::from_utf8_lossy(&out.stderr)
        )
    });
    eprintln!("three.js summary after {:?}: {text}", start.elapsed());
    serde_json::from_str(&text).unwrap()
}

/// Red left of centre and blue right of it, as the two halves of the texture are.
fn assert_red_left_blue_right(what: &str, drawn: &Value) {
    let px = |side: &str| -> Vec<i64> {
        drawn[side]
            .as_array()
            .unwrap_or_else(|| panic!("{what}: no {side} pixel in {drawn}"))
            .iter()
            .map(|v| v.as_i64().unwrap())
            .collect()
    };
    let (left, right) = (px("left"), px("right"));
    assert!(
        left[0] > 100 && left[1] < 40 && left[2] < 40,
        "{what}: left of centre is {left:?}, not red"
    );
    assert!(
        right[2] > 100 && right[0] < 40 && right[1] < 40,
        "{what}: right of centre is {right:?}, not blue"
    );
}

#[test]
fn gltf_loader_reads_every_level_with_its_textures_and_colours() {
    let (Some(browser), Some(three)) = (chromium(), three()) else {
        return;
    };
    let levels = levels();
    let dir = tempfile::tempdir().unwrap();
    let files = [
        ("lod-nodes.glb", Layout::LodNodes, Compression::None),
        ("msft-lod.glb", Layout::MsftLod, Compression::None),
        (
            "lod-nodes-meshopt.glb",
            Layout::LodNodes,
            Compression::Meshopt,
        ),
    ];
    for (name, layout, compression) in files {
        let bytes = asset_glb(
            &levels,
            &AssetGlbOptions {
                layout,
                compression,
                ..AssetGlbOptions::default()
            },
        )
        .unwrap();
        std::fs::write(dir.path().join(name), bytes).unwrap();
    }
    let names: Vec<&str> = files.iter().map(|(n, _, _)| *n).collect();
    std::fs::write(dir.path().join("index.html"), page(&names)).unwrap();
    let (port, receive) = start_server(dir.path().to_path_buf(), three);
    let summary = run_page(
        &browser,
        &format!("http://127.0.0.1:{port}/index.html"),
        &receive,
    );

    let problems = summary["problems"].as_array().unwrap();
    assert!(problems.is_empty(), "the page reported {problems:?}");
    for name in &names {
        let file = &summary["files"][name];
        assert!(file.is_object(), "{name}: not in the page's summary");
        assert!(
            file["error"].is_null(),
            "{name}: GLTFLoader failed: {}",
            file["error"]
        );
    }
    let triangles: Vec<u64> = levels
        .iter()
        .map(|l| l.mesh.triangles.len() as u64)
        .collect();
    for file in ["lod-nodes.glb", "lod-nodes-meshopt.glb"] {
        assert_lod_nodes(&summary["files"][file], file, &triangles);
    }
    let used = summary["files"]["lod-nodes-meshopt.glb"]["extensionsUsed"].clone();
    assert!(
        used.as_array()
            .unwrap()
            .contains(&"EXT_meshopt_compression".into()),
        "extensionsUsed {used}"
    );

    let lod = &summary["files"]["msft-lod.glb"];
    let used = lod["extensionsUsed"].as_array().unwrap();
    assert!(used.contains(&"MSFT_lod".into()), "extensionsUsed {used:?}");
    let children = lod["children"].as_array().unwrap();
    assert_eq!(children.len(), 1, "the scene holds node 0 only");
    let meshes = children[0]["meshes"].as_array().unwrap();
    let drawn: u64 = meshes
        .iter()
        .map(|m| m["triangles"].as_u64().unwrap())
        .sum();
    assert_eq!(drawn, triangles[0], "node 0 draws the finest level");
    for m in meshes {
        assert_eq!(m["map"], serde_json::json!([2, 1]), "node 0's texture: {m}");
    }
    assert_red_left_blue_right("MSFT_lod node 0", &children[0]["drawn"]);
}

/// The `LodNodes` layout as three loaded it: `LOD0`…`LOD2`, each drawing its level's triangles,
/// the first two textured, the last with vertex colours, each red left and blue right.
fn assert_lod_nodes(nodes: &Value, file: &str, triangles: &[u64]) {
    let textured = |k: usize| k < 2;
    assert!(nodes["error"].is_null(), "{file}: {}", nodes["error"]);
    let children = nodes["children"].as_array().unwrap();
    let names: Vec<&str> = children
        .iter()
        .map(|c| c["name"].as_str().unwrap())
        .collect();
    assert_eq!(
        names,
        ["LOD0", "LOD1", "LOD2"],
        "{file}: one scene node per level"
    );
    for (k, child) in children.iter().enumerate() {
        let meshes = child["meshes"].as_array().unwrap();
        let drawn: u64 = meshes
            .iter()
            .map(|m| m["triangles"].as_u64().unwrap())
            .sum();
        assert_eq!(drawn, triangles[k], "{file} LOD{k}'s triangles");
        for m in meshes {
            assert_eq!(m["normal"], true, "{file} LOD{k}: {m}");
            if textured(k) {
                assert_eq!(
                    m["map"],
                    serde_json::json!([2, 1]),
                    "{file} LOD{k}'s texture: {m}"
                );
                assert_eq!(m["uv"], true, "{file} LOD{k}: {m}");
            } else {
                assert_eq!(m["color"], true, "{file} LOD{k}'s vertex colours: {m}");
                assert_eq!(m["vertexColors"], true, "{file} LOD{k}: {m}");
                assert!(m["map"].is_null(), "{file} LOD{k}: {m}");
            }
        }
        assert_red_left_blue_right(&format!("{file} LOD{k}"), &child["drawn"]);
    }
}
