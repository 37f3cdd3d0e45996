//! Assets with their looks for Python: `read_scene` gives a glTF file's asset as NumPy arrays
//! (vertices, faces, normals, tangents, two texture coordinate sets, colours, a material per
//! face) with its materials as JSON (the serde form of `voxlod_asset::Material`) and its images
//! as bytes; `write_scene` writes levels given the same way as one `.glb`
//! (`voxlod_gltf::asset_glb`, `MSFT_lod` or `LOD0`, `LOD1`, … nodes).

use std::path::PathBuf;
use std::sync::Arc;

use glam::{DVec3, Vec2, Vec3, Vec4};
use numpy::{PyArray1, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use voxlod::gltf::{asset_glb, AssetGlbOptions, Compression, Layout};
use voxlod_asset::{Asset, AssetMesh, Image, Material};

use crate::arrays::{faces_i32, rows};
use crate::errors::{usage, Failure};

/// An image as Python gives and takes it: name, media type, encoded bytes.
type ImageTuple = (String, String, Vec<u8>);

/// `read_scene(path)` ([`voxlod::read_scene`]: a glTF file, a mesh with its looks, or a folder
/// of them): a dict of arrays (`vertices`, `faces`, `normals`, and `tangents`,
/// `uv0`, `uv1`, `colors` or None), `material` (one per face), `materials_json`, `parts_json`,
/// `images` as (name, mime, bytes), `warnings` and `origin` (the world point the vertices are
/// relative to: zeros but for a scene far from the origin).
#[pyfunction]
pub fn read_scene(py: Python<'_>, path: PathBuf) -> PyResult<Bound<'_, PyDict>> {
    let read = py.detach(|| voxlod::read_scene(&path).map_err(Failure::from))?;
    let a = read.asset;
    let m = a.mesh;
    let d = PyDict::new(py);
    let v3 = |v: Vec<Vec3>| {
        v.into_iter()
            .map(|p| p.to_array())
            .collect::<Vec<[f32; 3]>>()
    };
    d.set_item("vertices", rows(py, v3(m.positions)))?;
    d.set_item("faces", rows(py, faces_i32(m.triangles, false)))?;
    d.set_item("normals", rows(py, v3(m.normals)))?;
    let opt4 = |v: Vec<Vec4>| {
        (!v.is_empty()).then(|| {
            v.into_iter()
                .map(|p| p.to_array())
                .collect::<Vec<[f32; 4]>>()
        })
    };
    let opt2 = |v: Vec<Vec2>| {
        (!v.is_empty()).then(|| {
            v.into_iter()
                .map(|p| p.to_array())
                .collect::<Vec<[f32; 2]>>()
        })
    };
    d.set_item("tangents", opt4(m.tangents).map(|t| rows(py, t)))?;
    let [uv0, uv1] = m.uv;
    d.set_item("uv0", opt2(uv0).map(|t| rows(py, t)))?;
    d.set_item("uv1", opt2(uv1).map(|t| rows(py, t)))?;
    d.set_item("colors", opt4(m.colors).map(|t| rows(py, t)))?;
    d.set_item("material", PyArray1::from_vec(py, m.material))?;
    d.set_item("materials_json", to_json(&a.materials)?)?;
    d.set_item("parts_json", to_json(&a.parts)?)?;
    let images: Vec<(String, String, Bound<'_, PyBytes>)> = a
        .images
        .iter()
        .map(|i| (i.name.clone(), i.mime.clone(), PyBytes::new(py, &i.bytes)))
        .collect();
    d.set_item("images", images)?;
    d.set_item("warnings", read.warnings)?;
    d.set_item("origin", read.origin.to_array())?;
    Ok(d)
}

fn to_json<T: serde::Serialize>(value: &T) -> PyResult<String> {
    serde_json::to_string(value).map_err(|e| usage(format!("cannot encode: {e}")))
}

/// One level from Python: vertices, faces, normals, tangents, uv0, uv1, colors, material,
/// materials as JSON, images.
type LevelIn<'py> = (
    PyReadonlyArray2<'py, f32>,
    PyReadonlyArray2<'py, u32>,
    Option<PyReadonlyArray2<'py, f32>>,
    Option<PyReadonlyArray2<'py, f32>>,
    Option<PyReadonlyArray2<'py, f32>>,
    Option<PyReadonlyArray2<'py, f32>>,
    Option<PyReadonlyArray2<'py, f32>>,
    Option<PyReadonlyArray1<'py, u32>>,
    String,
    Vec<ImageTuple>,
);

/// `write_scene(path, levels, layout, compress, origin)`: the levels (finest first) as one
/// `.glb`; `layout` is `"msft-lod"` or `"lod-nodes"`; with `compress`, every attribute
/// quantized and meshopt-encoded (`EXT_meshopt_compression`, `KHR_mesh_quantization`; texture
/// coordinates outside 0..1 stay float); `origin`, the world point the vertices are relative
/// to, goes to the level nodes' translation. The file replaces `path` only when complete.
#[pyfunction]
#[pyo3(signature = (path, levels, layout, compress = false, origin = [0.0; 3]))]
pub fn write_scene(
    py: Python<'_>,
    path: PathBuf,
    levels: Vec<LevelIn<'_>>,
    layout: &str,
    compress: bool,
    origin: [f64; 3],
) -> PyResult<()> {
    if !origin.iter().all(|x| x.is_finite()) {
        return Err(usage(format!("origin {origin:?} is not finite")));
    }
    let layout = match layout {
        "msft-lod" => Layout::MsftLod,
        "lod-nodes" => Layout::LodNodes,
        other => {
            return Err(usage(format!(
                "layout {other:?}: use \"msft-lod\" or \"lod-nodes\""
            )))
        }
    };
    let assets: Vec<Asset> = levels.iter().map(asset_from).collect::<PyResult<_>>()?;
    py.detach(|| {
        let options = AssetGlbOptions {
            layout,
            compression: if compress {
                Compression::Meshopt
            } else {
                Compression::None
            },
            origin: DVec3::from_array(origin),
            ..AssetGlbOptions::default()
        };
        let bytes =
            asset_glb(&assets, &options).map_err(|e| Failure::from(voxlod::Error::from(e)))?;
        voxlod::io::atomic::write_atomically(&path, |w| std::io::Write::write_all(w, &bytes))
            .map_err(|e| Failure::from(voxlod::Error::from(e)))
    })?;
    Ok(())
}

/// A level's asset from its arrays (checked by the writer).
fn asset_from(level: &LevelIn<'_>) -> PyResult<Asset> {
    let (v, f, normals, tangents, uv0, uv1, colors, material, materials, images) = level;
    let columns = |a: &PyReadonlyArray2<'_, f32>, n: usize, what: &str| -> PyResult<Vec<f32>> {
        let a = a.as_array();
        if a.ncols() != n {
            return Err(usage(format!("{what} must have {n} columns")));
        }
        Ok(a.iter().copied().collect())
    };
    let vec3 = |x: Vec<f32>| x.chunks_exact(3).map(Vec3::from_slice).collect::<Vec<_>>();
    let vec2 = |x: Vec<f32>| x.chunks_exact(2).map(Vec2::from_slice).collect::<Vec<_>>();
    let vec4 = |x: Vec<f32>| x.chunks_exact(4).map(Vec4::from_slice).collect::<Vec<_>>();
    let faces = f.as_array();
    if faces.ncols() != 3 {
        return Err(usage("faces must have 3 columns"));
    }
    let opt = |a: &Option<PyReadonlyArray2<'_, f32>>, n: usize, what: &str| {
        a.as_ref().map(|a| columns(a, n, what)).transpose()
    };
    let materials: Vec<Material> =
        serde_json::from_str(materials).map_err(|e| usage(format!("materials_json: {e}")))?;
    Ok(Asset {
        mesh: AssetMesh {
            positions: vec3(columns(v, 3, "vertices")?),
            triangles: faces
                .rows()
                .into_iter()
                .map(|r| [r[0], r[1], r[2]])
                .collect(),
            normals: opt(normals, 3, "normals")?.map(vec3).unwrap_or_default(),
            tangents: opt(tangents, 4, "tangents")?.map(vec4).unwrap_or_default(),
            uv: [
                opt(uv0, 2, "uv0")?.map(vec2).unwrap_or_default(),
                opt(uv1, 2, "uv1")?.map(vec2).unwrap_or_default(),
            ],
            colors: opt(colors, 4, "colors")?.map(vec4).unwrap_or_default(),
            material: material
                .as_ref()
                .map(|m| m.as_array().iter().copied().collect())
                .unwrap_or_default(),
        },
        materials,
        images: images
            .iter()
            .map(|(name, mime, bytes)| Image {
                name: name.clone(),
                mime: mime.clone(),
                bytes: Arc::new(bytes.clone()),
            })
            .collect(),
        parts: Vec::new(),
    })
}
