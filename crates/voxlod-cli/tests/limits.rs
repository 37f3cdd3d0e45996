//! Limits end to end: no panic on triangles collapsed to a point in any mesh format, a clean
//! refusal (not an abort) under an address-space limit and for sizes stated in files, no hang
//! on extreme spacing or sample counts. Each test feeds an input that could make a careless
//! reader panic, abort or run forever.
//!
//! Runs that could hang are watched: a run still going after [`WATCHDOG`] is killed and the
//! test fails. That is a hang detector with a generous margin, not a speed test.

mod common;

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use common::*;
use voxlod::core::{mesh_topology, weld::weld_vertices, TriangleMesh};

/// How long a run may take before it counts as hung.
const WATCHDOG: Duration = Duration::from_secs(120);

/// Runs `command`, killing it and failing the test if it outlives [`WATCHDOG`].
fn run_watched(mut command: Command) -> Output {
    let mut child = command
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the command starts");
    let drain = |mut pipe: Box<dyn Read + Send>| {
        std::thread::spawn(move || {
            let mut bytes = Vec::new();
            pipe.read_to_end(&mut bytes).map(|_| bytes)
        })
    };
    let out = drain(Box::new(child.stdout.take().unwrap()));
    let err = drain(Box::new(child.stderr.take().unwrap()));
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if start.elapsed() > WATCHDOG {
            child.kill().unwrap();
            child.wait().unwrap();
            panic!("{command:?} still running after {WATCHDOG:?}: a hang");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    Output {
        status,
        stdout: out.join().unwrap().unwrap(),
        stderr: err.join().unwrap().unwrap(),
    }
}

fn voxlod_watched(args: &[&str]) -> Output {
    let mut command = Command::new(env!("CARGO_BIN_EXE_voxlod"));
    command.args(args);
    run_watched(command)
}

// ---------------------------------------------------------------------------------------------
// Triangles collapsed to a point, in every mesh format voxlod reads.

/// A mesh as a file states it: corners and index triples.
struct Soup {
    positions: Vec<[f32; 3]>,
    triangles: Vec<[u32; 3]>,
}

/// `v 0 0 0` / `f 1 1 1`: one triangle collapsed to a point.
fn lone_point() -> Soup {
    Soup {
        positions: vec![[0.0; 3]],
        triangles: vec![[0, 0, 0]],
    }
}

/// A closed unit cube and one facet collapsed to a point that no real triangle shares.
fn cube_and_point() -> Soup {
    let cube = voxlod_testkit::shapes::unit_cube();
    let mut positions: Vec<[f32; 3]> = cube.positions.iter().map(|p| p.to_array()).collect();
    positions.push([5.0; 3]);
    let mut triangles = cube.triangles.clone();
    triangles.push([8, 8, 8]);
    Soup {
        positions,
        triangles,
    }
}

fn text_lines<T>(items: &[T], line: impl Fn(&T) -> String) -> String {
    items.iter().map(|x| line(x) + "\n").collect()
}

fn xyz(p: &[f32; 3]) -> String {
    format!("{} {} {}", p[0], p[1], p[2])
}

fn obj(m: &Soup) -> Vec<u8> {
    let v = text_lines(&m.positions, |p| format!("v {}", xyz(p)));
    let f = text_lines(&m.triangles, |t| {
        format!("f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1)
    });
    (v + &f).into_bytes()
}

fn ply_header(m: &Soup, format: &str) -> String {
    format!(
        "ply\nformat {format} 1.0\nelement vertex {}\nproperty float x\nproperty float y\n\
         property float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        m.positions.len(),
        m.triangles.len()
    )
}

fn ply_ascii(m: &Soup) -> Vec<u8> {
    let body = text_lines(&m.positions, xyz)
        + &text_lines(&m.triangles, |t| format!("3 {} {} {}", t[0], t[1], t[2]));
    (ply_header(m, "ascii") + &body).into_bytes()
}

fn ply_binary(m: &Soup) -> Vec<u8> {
    let mut bytes = ply_header(m, "binary_little_endian").into_bytes();
    for p in &m.positions {
        p.iter().for_each(|x| bytes.extend(x.to_le_bytes()));
    }
    for t in &m.triangles {
        bytes.push(3);
        t.iter()
            .for_each(|&v| bytes.extend((v as i32).to_le_bytes()));
    }
    bytes
}

fn corners(m: &Soup, t: &[u32; 3]) -> [[f32; 3]; 3] {
    t.map(|v| m.positions[v as usize])
}

fn stl_ascii(m: &Soup) -> Vec<u8> {
    let facets = text_lines(&m.triangles, |t| {
        let c = corners(m, t);
        format!(
            "facet normal 0 0 0\nouter loop\nvertex {}\nvertex {}\nvertex {}\nendloop\nendfacet",
            xyz(&c[0]),
            xyz(&c[1]),
            xyz(&c[2])
        )
    });
    format!("solid collapsed\n{facets}endsolid collapsed\n").into_bytes()
}

fn stl_binary(m: &Soup) -> Vec<u8> {
    let mut bytes = vec![0u8; 80];
    bytes.extend((m.triangles.len() as u32).to_le_bytes());
    for t in &m.triangles {
        bytes.extend([0u8; 12]);
        for c in corners(m, t) {
            c.iter().for_each(|x| bytes.extend(x.to_le_bytes()));
        }
        bytes.extend([0u8; 2]);
    }
    bytes
}

fn off(m: &Soup) -> Vec<u8> {
    let head = format!("OFF\n{} {} 0\n", m.positions.len(), m.triangles.len());
    let body = text_lines(&m.positions, xyz)
        + &text_lines(&m.triangles, |t| format!("3 {} {} {}", t[0], t[1], t[2]));
    (head + &body).into_bytes()
}

fn joined<T: ToString>(items: impl IntoIterator<Item = T>) -> String {
    items
        .into_iter()
        .map(|x| x.to_string())
        .collect::<Vec<_>>()
        .join(" ")
}

fn vtp(m: &Soup) -> Vec<u8> {
    let points = joined(m.positions.iter().flatten());
    let connectivity = joined(m.triangles.iter().flatten());
    let offsets = joined((1..=m.triangles.len()).map(|i| 3 * i));
    format!(
        r#"<?xml version="1.0"?>
<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian" header_type="UInt64">
  <PolyData>
    <Piece NumberOfPoints="{}" NumberOfVerts="0" NumberOfLines="0" NumberOfStrips="0" NumberOfPolys="{}">
      <Points>
        <DataArray type="Float32" NumberOfComponents="3" format="ascii">{points}</DataArray>
      </Points>
      <Polys>
        <DataArray type="Int64" Name="connectivity" format="ascii">{connectivity}</DataArray>
        <DataArray type="Int64" Name="offsets" format="ascii">{offsets}</DataArray>
      </Polys>
    </Piece>
  </PolyData>
</VTKFile>
"#,
        m.positions.len(),
        m.triangles.len()
    )
    .into_bytes()
}

fn legacy_vtk(m: &Soup) -> Vec<u8> {
    format!(
        "# vtk DataFile Version 3.0\ncollapsed\nASCII\nDATASET POLYDATA\nPOINTS {} float\n{}\
         POLYGONS {} {}\n{}",
        m.positions.len(),
        text_lines(&m.positions, xyz),
        m.triangles.len(),
        4 * m.triangles.len(),
        text_lines(&m.triangles, |t| format!("3 {} {} {}", t[0], t[1], t[2]))
    )
    .into_bytes()
}

/// A binary glTF with one triangle primitive: positions, then u32 indices, in one buffer.
fn glb(m: &Soup) -> Vec<u8> {
    let mut bin: Vec<u8> = Vec::new();
    m.positions
        .iter()
        .flatten()
        .for_each(|x| bin.extend(x.to_le_bytes()));
    let position_bytes = bin.len();
    m.triangles
        .iter()
        .flatten()
        .for_each(|v| bin.extend(v.to_le_bytes()));
    let (min, max) = (0..3).fold((vec![], vec![]), |(mut lo, mut hi), a| {
        let axis = m.positions.iter().map(|p| p[a]);
        lo.push(axis.clone().fold(f32::INFINITY, f32::min));
        hi.push(axis.fold(f32::NEG_INFINITY, f32::max));
        (lo, hi)
    });
    let json = serde_json::json!({
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": position_bytes},
            {"buffer": 0, "byteOffset": position_bytes, "byteLength": bin.len() - position_bytes}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": m.positions.len(), "type": "VEC3",
             "min": min, "max": max},
            {"bufferView": 1, "componentType": 5125, "count": 3 * m.triangles.len(),
             "type": "SCALAR"}
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}],
        "scene": 0
    });
    glb_container(serde_json::to_vec(&json).unwrap(), bin)
}

/// The GLB container around a JSON chunk and a binary chunk, each padded to 4 bytes.
fn glb_container(mut json: Vec<u8>, mut bin: Vec<u8>) -> Vec<u8> {
    json.resize(json.len().next_multiple_of(4), b' ');
    bin.resize(bin.len().next_multiple_of(4), 0);
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    for (chunk, kind) in [(&json, b"JSON"), (&bin, b"BIN\0")] {
        out.extend((chunk.len() as u32).to_le_bytes());
        out.extend(kind);
        out.extend(chunk.iter());
    }
    out
}

/// The eight formats `voxlod::io::read_mesh` reads, by file name, with their writers.
type Writer = fn(&Soup) -> Vec<u8>;
const IO_FORMATS: [(&str, Writer); 8] = [
    ("mesh.obj", obj),
    ("ascii.ply", ply_ascii),
    ("binary.ply", ply_binary),
    ("ascii.stl", stl_ascii),
    ("binary.stl", stl_binary),
    ("mesh.off", off),
    ("mesh.vtp", vtp),
    ("legacy.vtk", legacy_vtk),
];

/// The topology of `mesh` after welding, as `inspect` counts it.
fn welded_topology(mut mesh: TriangleMesh) -> voxlod::core::Topology {
    weld_vertices(&mut mesh);
    mesh_topology(&mesh)
}

#[test]
fn collapsed_triangles_in_every_mesh_format_are_counted_not_panicked_on() {
    let dir = tempfile::tempdir().unwrap();
    for (soup, label, components) in [(lone_point(), "point", 1), (cube_and_point(), "cube", 2)] {
        let triangles = soup.triangles.len() as u64;
        for (name, write) in IO_FORMATS {
            let path = dir.path().join(format!("{label}-{name}"));
            std::fs::write(&path, write(&soup)).unwrap();
            let what = path.display().to_string();
            // The library: read, weld, count.
            let mesh = voxlod::io::read_mesh(&path)
                .unwrap_or_else(|e| panic!("{what}: {e}"))
                .mesh;
            let t = welded_topology(mesh);
            assert_eq!(t.degenerate_triangles, 1, "{what}");
            assert_eq!(t.triangles as u64, triangles, "{what}");
            assert_eq!(t.components, components, "{what}");
            assert_eq!(t.non_manifold_vertices, 0, "{what}");
            assert_eq!(t.genus, None, "{what}");
            // The command line.
            let report = json(&voxlod(&["inspect", arg(&path), "--json"]));
            assert_eq!(report["triangles"], triangles, "{what}");
            assert_eq!(report["degenerate_triangles"], 1, "{what}");
            assert_eq!(report["components"], components, "{what}");
        }
    }
}

#[test]
fn collapsed_triangles_in_the_glb_that_render_reads() {
    let dir = tempfile::tempdir().unwrap();
    for (soup, label, components) in [(lone_point(), "point", 1), (cube_and_point(), "cube", 2)] {
        let path = dir.path().join(format!("{label}.glb"));
        std::fs::write(&path, glb(&soup)).unwrap();
        let scene = voxlod_gltf::read_glb(&path).unwrap();
        let t = welded_topology(scene.mesh);
        assert_eq!(t.degenerate_triangles, 1, "{label}");
        assert_eq!(t.components, components, "{label}");
        let png = dir.path().join(format!("{label}.png"));
        let o = voxlod(&["render", arg(&path), "-o", arg(&png), "--size", "32x32"]);
        assert!(o.status.success(), "{label}: {}", stderr(&o));
        assert!(png.exists());
    }
}

#[test]
fn evaluate_takes_a_mesh_with_a_collapsed_facet_in_every_format() {
    let dir = tempfile::tempdir().unwrap();
    for (name, write) in IO_FORMATS {
        let input = dir.path().join(name);
        std::fs::write(&input, write(&cube_and_point())).unwrap();
        let out = dir.path().join(format!("eval-{name}"));
        let o = voxlod(&[
            "evaluate",
            arg(&input),
            "-o",
            arg(&out),
            "--budgets",
            "8",
            "--views",
            "0",
            "--samples",
            "2000",
            "--methods",
            "rossignac-borrel",
        ]);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        let report: serde_json::Value =
            serde_json::from_slice(&std::fs::read(out.join("report.json")).unwrap()).unwrap();
        assert_eq!(report["input"]["triangles"], 13, "{name}: {report}");
        // The lone point has nothing to simplify: a clean refusal.
        std::fs::write(&input, write(&lone_point())).unwrap();
        let o = voxlod(&["evaluate", arg(&input), "-o", arg(&out), "--views", "0"]);
        assert_clean_failure(&o, "no area");
    }
}

// ---------------------------------------------------------------------------------------------
// The memory budget.

/// Runs voxlod under `ulimit -v` (KiB) through the shell.
fn voxlod_under_ulimit_v(kib: u64, args: &[&str]) -> Output {
    let mut command = Command::new("sh");
    command
        .arg("-c")
        .arg(format!("ulimit -v {kib} && exec \"$0\" \"$@\""))
        .arg(env!("CARGO_BIN_EXE_voxlod"))
        .args(args)
        .env_remove("VOXLOD_MAX_MEMORY");
    run_watched(command)
}

#[test]
fn an_address_space_limit_is_a_clean_refusal_not_an_abort() {
    let dir = tempfile::tempdir().unwrap();
    let input = write_mesh(dir.path(), "block.obj", &holed_block());
    let out = dir.path().join("block.nrrd");
    let voxelize = |resolution: &str| {
        let args = [
            "voxelize",
            arg(&input),
            "-o",
            arg(&out),
            "--resolution",
            resolution,
        ];
        voxlod_under_ulimit_v(2_000_000, &args)
    };
    // Resolution 1000 takes a 4 GB volume: within the memory of many machines, beyond 2 GB of
    // address space, where allocating it would abort. The narrow band fits; the dense volume
    // that voxelize writes (1.9 GiB) does not, and is refused before allocating.
    let o = voxelize("1000");
    // Exit status 3: would not fit in memory.
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    assert_clean_failure(&o, "would need 1.9 GiB");
    assert!(stderr(&o).contains("bytes) but only"), "{}", stderr(&o));
    assert!(!out.exists());
    // Small work still runs under the limit.
    let o = voxelize("20");
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn a_malformed_memory_limit_names_the_variable_and_the_value() {
    let dir = tempfile::tempdir().unwrap();
    let input = write_mesh(dir.path(), "block.obj", &holed_block());
    for value in ["4Q", "lots"] {
        let o = Command::new(env!("CARGO_BIN_EXE_voxlod"))
            .args(["inspect", arg(&input)])
            .env("VOXLOD_MAX_MEMORY", value)
            .output()
            .unwrap();
        assert_clean_failure(&o, &format!("VOXLOD_MAX_MEMORY=\"{value}\" is not a size"));
    }
    let o = Command::new(env!("CARGO_BIN_EXE_voxlod"))
        .args(["inspect", arg(&input)])
        .env("VOXLOD_MAX_MEMORY", "64M")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
}

// ---------------------------------------------------------------------------------------------
// Sizes stated in files.

/// A layered `.glb` written by `voxlod layers`, with the volume grid of its scene extras
/// replaced by `dims`.
fn layered_glb_with_grid(dir: &Path, dims: [u64; 3]) -> PathBuf {
    let input = write_mesh(dir, "block.obj", &holed_block());
    let glb = dir.join("layers.glb");
    if !glb.exists() {
        let o = voxlod(&[
            "layers",
            arg(&input),
            "-o",
            arg(&glb),
            "--error",
            "0.05",
            "--resolution",
            "12",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let bytes = std::fs::read(&glb).unwrap();
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let mut json: serde_json::Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    let scene = json["scene"].as_u64().unwrap_or(0) as usize;
    let grid = &mut json["scenes"][scene]["extras"]["voxlod"]["grid"];
    assert!(grid["dims"].is_array(), "voxlod layers records its grid");
    grid["dims"] = serde_json::json!(dims);
    let bin_start = 20 + json_len;
    let bin_len = u32::from_le_bytes(bytes[bin_start..bin_start + 4].try_into().unwrap()) as usize;
    let bin = bytes[bin_start + 8..bin_start + 8 + bin_len].to_vec();
    let path = dir.join(format!("grid-{}x{}x{}.glb", dims[0], dims[1], dims[2]));
    std::fs::write(
        &path,
        glb_container(serde_json::to_vec(&json).unwrap(), bin),
    )
    .unwrap();
    path
}

#[test]
fn render_of_a_glb_stating_a_huge_grid_does_not_abort() {
    let dir = tempfile::tempdir().unwrap();
    // 3.6 billion rows of cells: the order must not allocate 14 GB for them.
    let rows = layered_glb_with_grid(dir.path(), [2, 60_000, 60_000]);
    let png = dir.path().join("rows.png");
    let o = voxlod_watched(&["render", arg(&rows), "-o", arg(&png), "--perspective"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(png.exists());
    // More cells than 32-bit cell numbers name: refused, naming the grid.
    let cells = layered_glb_with_grid(dir.path(), [3, 100_000, 100_000]);
    let png = dir.path().join("cells.png");
    let o = voxlod_watched(&["render", arg(&cells), "-o", arg(&png), "--perspective"]);
    assert_clean_failure(&o, "2x99999x99999 cells");
    assert!(!png.exists());
}

// ---------------------------------------------------------------------------------------------
// Work that must not run forever.

/// A 16³ u8 volume: a ball of 200 (radius 5 samples) in 10.
fn ball_volume(dir: &Path) -> PathBuf {
    let mut data = Vec::with_capacity(16 * 16 * 16);
    for k in 0..16 {
        for j in 0..16 {
            for i in 0..16 {
                let r2 = [i, j, k]
                    .map(|x| (x as f64 - 7.5).powi(2))
                    .iter()
                    .sum::<f64>();
                data.push(if r2 < 25.0 { 200u8 } else { 10 });
            }
        }
    }
    let path = dir.join("ball.raw");
    std::fs::write(&path, data).unwrap();
    path
}

fn direct_lod(input: &Path, spacing: &str, out: &Path) -> Output {
    voxlod_watched(&[
        "lod",
        arg(input),
        "--dims",
        "16,16,16",
        "--dtype",
        "u8",
        "--spacing",
        spacing,
        "--direct",
        "--iso",
        "100",
        "-o",
        arg(out),
        "--json",
    ])
}

#[test]
fn direct_filtering_finishes_on_extreme_spacing() {
    let dir = tempfile::tempdir().unwrap();
    let input = ball_volume(dir.path());
    // 1:1:1e9: the support spans billions of samples across x and y; the levels see only air.
    let o = direct_lod(&input, "1,1,1e9", &dir.path().join("far"));
    let err = stderr(&o);
    assert!(!err.contains("panicked"), "{err}");
    assert!(
        o.status.success() || err.contains("voxlod: error:"),
        "neither a result nor a clean refusal: {err}"
    );
    // 1:1:127: the fine levels keep the ball as closed surfaces.
    let out = dir.path().join("tall");
    let report = json(&direct_lod(&input, "1,1,127", &out));
    let levels = report["levels"].as_array().unwrap();
    assert_eq!(levels.len(), 6);
    for level in &levels[..2] {
        assert!(level["triangles"].as_u64().unwrap() > 0, "{level}");
        let mesh = voxlod::io::read_mesh(&out.join(level["file"].as_str().unwrap()))
            .unwrap()
            .mesh;
        assert!(mesh_topology(&mesh).is_closed_manifold(), "{level}");
    }
}

#[test]
fn compare_refuses_a_sample_count_that_would_run_for_hours() {
    let dir = tempfile::tempdir().unwrap();
    let input = write_mesh(dir.path(), "block.obj", &holed_block());
    let o = voxlod_watched(&[
        "compare",
        arg(&input),
        arg(&input),
        "--samples",
        "100000000000",
    ]);
    assert_clean_failure(
        &o,
        "100000000000 samples per surface is more than the 100000000 allowed",
    );
}
