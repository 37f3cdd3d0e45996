//! Assets written as OBJ + MTL (+ images) and as coloured PLY, read back by `read_asset` and by
//! an independent reader (trimesh, in the peers' Python, when it is there): counts exact
//! (triangles; vertices as the writer splits them, one block per material), positions exact,
//! other attributes within the float text's or the `u8`'s precision, materials and images as
//! written; a write that fails leaves no file.

use std::collections::HashSet;
use std::path::Path;
use std::process::Command;

use voxlod_asset::{Asset, Material};
use voxlod_core::glam::Vec4;
use voxlod_io::{linear_to_srgb, read_asset, write_asset};
use voxlod_testkit::assets::textured_sphere;

/// The textured sphere with vertex colours and a second, untextured green material on its
/// upper half (emissive, rough, half metallic), normal-mapped where textured.
fn asset() -> Asset {
    let mut a = textured_sphere(2);
    let m = &mut a.mesh;
    m.colors = m
        .positions
        .iter()
        .map(|p| Vec4::new(0.5 + 0.5 * p.x, 0.25 + 0.5 * p.z.abs(), 0.8, 1.0))
        .collect();
    m.material = m
        .triangles
        .iter()
        .map(|t| u32::from(m.positions[t[0] as usize].y > 0.0))
        .collect();
    a.materials[0].normal_texture = a.materials[0].base_color_texture.clone();
    a.materials[0].normal_scale = 0.5;
    a.materials.push(Material {
        name: "green".into(),
        base_color: [0.2, 0.6, 0.3, 1.0],
        metallic: 0.5,
        roughness: 0.75,
        emissive: [0.1, 0.0, 0.0],
        ..Material::default()
    });
    a
}

/// Vertices as the writers store them: one copy per material that uses it.
fn split_vertices(a: &Asset) -> usize {
    let m = &a.mesh;
    let mut used = HashSet::new();
    for (t, tri) in m.triangles.iter().enumerate() {
        for &v in tri {
            used.insert((m.material[t], v));
        }
    }
    used.len()
}

/// For every corner read back, the input's corner at the same position bits and material name
/// (the sphere's vertices are distinct points): `check` compares their attributes.
fn for_each_corner(input: &Asset, back: &Asset, check: impl Fn(usize, usize)) {
    let key = |a: &Asset, t: usize, v: usize| {
        let name = a.materials[a.mesh.material[t] as usize].name.clone();
        (a.mesh.positions[v].to_array().map(f32::to_bits), name)
    };
    let mut at = std::collections::HashMap::new();
    for (t, tri) in input.mesh.triangles.iter().enumerate() {
        for &v in tri {
            at.insert(key(input, t, v as usize), v as usize);
        }
    }
    assert_eq!(back.mesh.triangles.len(), input.mesh.triangles.len());
    for (t, tri) in back.mesh.triangles.iter().enumerate() {
        for &v in tri {
            let k = key(back, t, v as usize);
            let Some(&original) = at.get(&k) else {
                panic!("corner at {:?} of material {} is no input corner", k.0, k.1);
            };
            check(original, v as usize);
        }
    }
}

fn close(a: &[f32], b: &[f32], e: f32) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() <= e)
}

#[test]
fn obj_with_mtl_and_texture_reads_back_as_written() {
    let input = asset();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sphere.obj");
    let written = write_asset(&path, &input).unwrap();
    let names: Vec<String> = written
        .files
        .iter()
        .map(|f| f.path.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["sphere.obj", "sphere.mtl", "halves.png"]);
    assert_eq!(written.warnings.len(), 1, "{:?}", written.warnings);
    assert!(written.warnings[0].contains("without -clamp on"));
    for f in &written.files {
        assert_eq!(std::fs::read(&f.path).unwrap(), f.bytes, "{:?}", f.path);
    }
    let read = read_asset(&path).unwrap();
    assert!(read.warnings.is_empty(), "{:?}", read.warnings);
    let back = &read.asset;
    assert_eq!(back.mesh.positions.len(), split_vertices(&input));
    let (i, b) = (&input.mesh, &back.mesh);
    for_each_corner(&input, back, |o, v| {
        assert!(close(
            &i.normals[o].to_array(),
            &b.normals[v].to_array(),
            1e-6
        ));
        assert!(close(&i.uv[0][o].to_array(), &b.uv[0][v].to_array(), 1e-6));
        assert!(close(
            &i.colors[o].to_array(),
            &b.colors[v].to_array(),
            2e-6
        ));
    });
    assert_eq!(back.images.len(), 1);
    assert_eq!(back.images[0].bytes, input.images[0].bytes);
    let halves = back.materials.iter().find(|m| m.name == "halves").unwrap();
    let t = halves.base_color_texture.as_ref().unwrap();
    assert_eq!(
        t.sampler.wrap_u,
        voxlod_asset::Wrap::Repeat,
        "map_Kd has no options"
    );
    let normal = halves.normal_texture.as_ref().unwrap();
    assert_eq!(normal.image, t.image);
    assert_eq!(normal.sampler.wrap_u, voxlod_asset::Wrap::ClampToEdge);
    assert_eq!(halves.normal_scale, 0.5);
    let green = back.materials.iter().find(|m| m.name == "green").unwrap();
    assert_eq!(green.base_color, [0.2, 0.6, 0.3, 1.0]);
    assert_eq!((green.metallic, green.roughness), (0.5, 0.75));
    assert_eq!(green.emissive, [0.1, 0.0, 0.0]);
}

#[test]
fn ply_holds_srgb_byte_colours_texture_coordinates_and_its_texture() {
    let input = asset();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sphere.ply");
    let written = write_asset(&path, &input).unwrap();
    assert_eq!(written.files.len(), 2, "the PLY and its texture");
    assert!(
        written.warnings.iter().any(|w| w.contains("normalTexture")),
        "the normal map a PLY cannot name is a warning: {:?}",
        written.warnings
    );
    let read = read_asset(&path).unwrap();
    assert!(read.warnings.is_empty(), "{:?}", read.warnings);
    let back = &read.asset;
    assert_eq!(back.mesh.positions.len(), split_vertices(&input));
    assert_eq!(back.images[0].bytes, input.images[0].bytes);
    assert!(back.materials[0].base_color_texture.is_some());
    // The read-back asset has one material: compare by position alone.
    let factor: Vec<Vec4> = input
        .mesh
        .material
        .iter()
        .map(|&k| Vec4::from(input.materials[k as usize].base_color))
        .collect();
    let (i, b) = (&input.mesh, &back.mesh);
    let srgb = |c: Vec4| [c.x, c.y, c.z].map(linear_to_srgb);
    // Each corner's expected colour: its colour times its material's factor, in sRGB bytes.
    for (t, tri) in i.triangles.iter().enumerate() {
        for &v in tri {
            let want = srgb(i.colors[v as usize] * factor[t]);
            let found = b.positions.iter().enumerate().any(|(k, p)| {
                *p == i.positions[v as usize]
                    && close(&srgb(b.colors[k]), &want, 0.5 / 255.0 + 1e-6)
                    && close(
                        &b.normals[k].to_array(),
                        &i.normals[v as usize].to_array(),
                        0.0,
                    )
                    && close(
                        &b.uv[0][k].to_array(),
                        &i.uv[0][v as usize].to_array(),
                        1e-6,
                    )
            });
            assert!(
                found,
                "triangle {t}, vertex {v}: no vertex read back carries it"
            );
        }
    }
}

#[test]
fn what_a_format_cannot_hold_is_a_warning() {
    let mut a = asset();
    a.mesh.uv[1] = a.mesh.uv[0].iter().map(|t| *t * 2.0).collect();
    a.mesh.colors[0].w = 0.5;
    a.materials[0]
        .base_color_texture
        .as_mut()
        .unwrap()
        .tex_coord = 1;
    let dir = tempfile::tempdir().unwrap();
    let obj = write_asset(&dir.path().join("a.obj"), &a).unwrap();
    let said = |w: &[String], what: &str| w.iter().any(|x| x.contains(what));
    assert!(
        said(&obj.warnings, "set 1 was left out"),
        "{:?}",
        obj.warnings
    );
    assert!(said(&obj.warnings, "no alpha"), "{:?}", obj.warnings);
    assert!(
        said(&obj.warnings, "texture coordinate set 1"),
        "{:?}",
        obj.warnings
    );
    let ply = write_asset(&dir.path().join("a.ply"), &a).unwrap();
    assert!(
        said(&ply.warnings, "baseColorTexture"),
        "{:?}",
        ply.warnings
    );
    let read = read_asset(&dir.path().join("a.ply")).unwrap().asset;
    assert!(read
        .mesh
        .colors
        .iter()
        .any(|c| (c.w - 0.5).abs() < 1.0 / 255.0));
}

#[test]
fn a_failed_write_leaves_no_file() {
    let input = asset();
    let dir = tempfile::tempdir().unwrap();
    // The MTL's name is taken by a folder: nothing is written, the OBJ neither.
    std::fs::create_dir(dir.path().join("a.mtl")).unwrap();
    let e = write_asset(&dir.path().join("a.obj"), &input).unwrap_err();
    assert!(e.to_string().contains("a.mtl"), "{e}");
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(left.len(), 1, "only the folder: {left:?}");
    let mut broken = input.clone();
    broken.mesh.colors.pop();
    let e = write_asset(&dir.path().join("b.ply"), &broken).unwrap_err();
    assert!(e.to_string().contains("colours"), "{e}");
    assert!(!dir.path().join("b.ply").exists());
    let e = write_asset(&dir.path().join("c.stl"), &input).unwrap_err();
    assert!(e.to_string().contains(".obj"), "{e}");
}

/// trimesh's summary of the files (faces, texture size, colours), or `None` when the peers'
/// Python or trimesh is missing (a skip, with the reason printed).
fn trimesh(obj: &Path, ply: &Path, coloured: &Path) -> Option<serde_json::Value> {
    let python = voxlod_testkit::peers::python().or_else(|| {
        voxlod_testkit::skips::skip("no peers' Python at ~/.cache/voxlod-peers/bin/python");
        None
    })?;
    let has = Command::new(&python)
        .args(["-c", "import trimesh, PIL"])
        .output()
        .ok()?;
    if !has.status.success() {
        voxlod_testkit::skips::skip("the peers' Python has no trimesh");
        return None;
    }
    let script = r#"
import json, sys, trimesh
def summary(path):
    loaded = trimesh.load(path, process=False)
    meshes = list(loaded.geometry.values()) if isinstance(loaded, trimesh.Scene) else [loaded]
    out = {"faces": sum(len(m.faces) for m in meshes), "textures": [], "colors": None, "uv": 0}
    for m in meshes:
        material = getattr(m.visual, "material", None)
        image = getattr(material, "image", None) if material is not None else None
        if image is None and material is not None:
            image = getattr(material, "baseColorTexture", None)
        if image is not None:
            out["textures"].append(list(image.size))
        uv = getattr(m.visual, "uv", None)
        if uv is not None:
            out["uv"] += len(uv)
        if m.visual.kind == "vertex":
            out["colors"] = m.visual.vertex_colors[:, :3].tolist()
            out["vertices"] = m.vertices.tolist()
    return out
print(json.dumps({k: summary(p) for k, p in zip(["obj", "ply", "coloured"], sys.argv[1:])}))
"#;
    let out = Command::new(&python)
        .arg("-c")
        .arg(script)
        .args([obj, ply, coloured])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "trimesh failed on our files: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    Some(serde_json::from_slice(&out.stdout).unwrap())
}

#[test]
fn trimesh_reads_the_obj_with_its_texture_and_the_ply_with_its_colours() {
    let input = asset();
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("sphere.obj");
    let ply = dir.path().join("sphere.ply");
    write_asset(&obj, &input).unwrap();
    write_asset(&ply, &input).unwrap();
    // A PLY of colours only (a voxel level's looks): trimesh takes its vertex colours.
    let mut coloured = input.clone();
    coloured.mesh.uv[0].clear();
    coloured.materials = vec![Material::default()];
    coloured.images.clear();
    coloured.mesh.material.fill(0);
    let coloured_path = dir.path().join("coloured.ply");
    write_asset(&coloured_path, &coloured).unwrap();
    let Some(s) = trimesh(&obj, &ply, &coloured_path) else {
        return;
    };
    let triangles = input.mesh.triangles.len() as u64;
    for k in ["obj", "ply", "coloured"] {
        assert_eq!(s[k]["faces"], triangles, "{k}: {}", s[k]);
    }
    assert!(
        s["obj"]["textures"]
            .as_array()
            .unwrap()
            .contains(&serde_json::json!([2, 1])),
        "trimesh found no 2×1 texture in the OBJ: {}",
        s["obj"]
    );
    assert!(s["obj"]["uv"].as_u64().unwrap() > 0, "{}", s["obj"]);
    assert!(s["ply"]["uv"].as_u64().unwrap() > 0, "{}", s["ply"]);
    assert_eq!(
        s["ply"]["textures"],
        serde_json::json!([[2, 1]]),
        "{}",
        s["ply"]
    );
    let colours = s["coloured"]["colors"].as_array().unwrap();
    let vertices = s["coloured"]["vertices"].as_array().unwrap();
    assert_eq!(colours.len(), input.mesh.positions.len());
    for (c, p) in colours.iter().zip(vertices) {
        let p: Vec<f32> = p
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap() as f32)
            .collect();
        let v = input
            .mesh
            .positions
            .iter()
            .position(|q| q.to_array() == [p[0], p[1], p[2]])
            .expect("trimesh's vertex is one of ours");
        let want = [0, 1, 2].map(|k| (linear_to_srgb(input.mesh.colors[v][k]) * 255.0).round());
        let got: Vec<f32> = c
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap() as f32)
            .collect();
        assert_eq!(got, want, "vertex {v}'s colour");
    }
}
