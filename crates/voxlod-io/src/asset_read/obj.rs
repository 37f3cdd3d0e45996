//! An OBJ file with its MTL libraries as an asset, through `tobj`.
//!
//! `tobj` loads with a single index: each distinct (position, texture coordinate, normal)
//! triple of a group's corners becomes one vertex, so a position on a texture seam or a normal
//! crease is split into one vertex per side, as [`voxlod_asset::AssetMesh`] wants. Each
//! `usemtl` (and each `o`/`g`) starts a new `tobj` model, and each model becomes one
//! [`Part`] whose triangles all take its material; vertices are not shared between parts.
//! Polygons are kept as polygons by `tobj` and ear-clipped here ([`crate::ear_clipping`]),
//! which, unlike `tobj`'s fan, is right for non-convex faces. Lines and points are left out.
//!
//! Texture coordinates: OBJ's v points up the image and glTF's down, so v becomes `1 - v`.
//! Texture coordinates and normals are kept when every corner of the file has them; a file
//! where only some parts have them keeps them with zeros for the others (texture coordinates,
//! with a warning) or drops them (normals, with a warning: the pipeline recomputes them).
//! Vertex colours (`v x y z r g b`) are sRGB and made linear. MTL files are read from the
//! OBJ's folder (several may share an `mtllib` line), their materials by [`super::mtl`]; a
//! missing one is a warning, and the faces that use its materials take the `default` material.
//! Bytes that are not UTF-8 (a comment or name in another encoding) are read as U+FFFD, with a
//! warning, rather than refused.
//!
//! Unlike the geometry reader (`obj.rs`), unreferenced vertices are dropped: an asset's
//! vertices are corners of its triangles.
//!
//! Cost: one pass of `tobj` over the file (a hash lookup per corner), then one over its
//! models; memory the file, `tobj`'s models (about the asset's size) and the asset.

use std::borrow::Cow;
use std::cell::RefCell;
use std::io::Cursor;
use std::path::{Path, PathBuf};

use voxlod_asset::{Asset, AssetMesh, Part};
use voxlod_core::glam::{DVec3, Vec2, Vec3, Vec4};

use super::mtl::{self, Images};
use super::{default_material, srgba_to_linear};
use crate::{budget, ear_clipping, guard, IoError, IoErrorKind};

/// Bytes of memory per byte of OBJ text that reading may take: `tobj` holds a face line of 8
/// bytes (`f 1 2 3\n`) as 3 corner triples of 24 bytes each, and the asset then has up to 3
/// vertices of 48 bytes for it.
const BYTES_PER_FILE_BYTE: u64 = 32;

/// The MTL files `tobj` asked for, in order: each one's folder and how many materials it gave
/// (so that material `k` of `tobj`'s list is known to come from which folder).
#[derive(Default)]
struct Libraries {
    loaded: Vec<(PathBuf, usize)>,
    warnings: Vec<String>,
    error: Option<IoError>,
}

/// Reads the OBJ at `path` (checked readable) as an asset; warnings are appended.
pub(crate) fn read(path: &Path, warnings: &mut Vec<String>) -> Result<Asset, IoError> {
    let bytes = crate::read_file(path)?;
    budget::check_bytes(
        path,
        "the asset of the OBJ file",
        (bytes.len() as u64).saturating_mul(BYTES_PER_FILE_BYTE),
    )?;
    let folder = path.parent().unwrap_or(Path::new("")).to_path_buf();
    let libraries = RefCell::new(Libraries::default());
    // tobj's `merging` and `reordering` features add fields (off, hence the default).
    #[allow(clippy::needless_update)]
    let options = tobj::LoadOptions {
        single_index: true,
        triangulate: false,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    // tobj reads lines as UTF-8 and fails on any other byte: a comment or name in another
    // encoding gets replacement characters instead.
    let text = String::from_utf8_lossy(&bytes);
    if matches!(text, Cow::Owned(_)) {
        warnings.push("the file is not valid UTF-8: its other bytes were read as \u{FFFD}".into());
    }
    let loader = |name: &Path| load_library(&folder, name, &libraries);
    let mut reader = Cursor::new(text.as_bytes());
    let loaded = guard::quietly(|| tobj::load_obj_buf(&mut reader, &options, loader))
        .ok_or_else(|| IoError::malformed(path, "the OBJ data cannot be decoded"))?;
    let libraries = libraries.into_inner();
    if let Some(error) = libraries.error {
        return Err(error);
    }
    let (models, materials) = loaded.map_err(|e| from_tobj(path, e))?;
    drop(text);
    drop(bytes);
    warnings.extend(libraries.warnings);
    // tobj gives an error instead of the materials when none loaded; the libraries' own
    // warnings say why.
    let materials = materials.unwrap_or_default();

    let mut images = Images::default();
    let mut converted = Vec::with_capacity(materials.len() + 1);
    let mut first = 0;
    for (dir, count) in &libraries.loaded {
        for m in materials.iter().skip(first).take(*count) {
            converted.push(mtl::material(m, dir, &mut images, warnings)?);
        }
        first += count;
    }
    // Materials tobj has beyond those counted (none, unless it changes how it merges).
    for m in materials.iter().skip(first) {
        converted.push(mtl::material(m, &folder, &mut images, warnings)?);
    }
    let mut asset = assemble(path, &models, warnings)?;
    let default = converted.len() as u32;
    let mut uses_default = false;
    for (model, part) in models.iter().zip(&asset.parts) {
        let k = match model.mesh.material_id {
            Some(k) if k < converted.len() => k as u32,
            _ => {
                uses_default = true;
                default
            }
        };
        let range =
            part.first_triangle as usize..(part.first_triangle + part.triangle_count) as usize;
        asset.mesh.material[range].fill(k);
    }
    if uses_default {
        converted.push(default_material());
    }
    asset.parts.retain(|p| p.triangle_count > 0);
    asset.materials = converted;
    asset.images = images.images;
    Ok(asset)
}

/// `tobj`'s material loader: the MTL file `name` relative to the OBJ's `folder` or, when no
/// file has that name and it has spaces, each of the files it lists (`mtllib a.mtl b.mtl`,
/// which `tobj` passes whole), their materials merged in order. Each is read within the memory
/// limit; a missing or unreadable one is a warning (and no materials); one too large for the
/// memory limit stops the read with that error. Cost: the MTL files' sizes.
fn load_library(folder: &Path, name: &Path, libraries: &RefCell<Libraries>) -> tobj::MTLLoadResult {
    let name = name.to_string_lossy().replace('\\', "/");
    let files: Vec<&str> = if folder.join(&name).is_file() || !name.contains(' ') {
        vec![name.as_str()]
    } else {
        name.split_whitespace().collect()
    };
    let mut libraries = libraries.borrow_mut();
    let mut merged: tobj::MTLLoadResult = Err(tobj::LoadError::OpenFileFailed);
    for file in files {
        let file = folder.join(file);
        let Ok((materials, names)) = load_one_library(&file, &mut libraries) else {
            continue;
        };
        let dir = file.parent().unwrap_or(Path::new("")).to_path_buf();
        libraries.loaded.push((dir, materials.len()));
        match &mut merged {
            Ok((all, all_names)) => {
                for (name, k) in names {
                    all_names.insert(name, k + all.len());
                }
                all.extend(materials);
            }
            Err(_) => merged = Ok((materials, names)),
        }
    }
    merged
}

/// The materials of one MTL file and their index by name, or an error after a warning (or,
/// when it is too large for the memory limit, after recording that error).
fn load_one_library(file: &Path, libraries: &mut Libraries) -> tobj::MTLLoadResult {
    let missing = Err(tobj::LoadError::OpenFileFailed);
    let len = match std::fs::metadata(file) {
        Ok(meta) if meta.is_file() => meta.len(),
        _ => {
            libraries.warnings.push(format!(
                "material library {} not found: its materials are left out",
                file.display()
            ));
            return missing;
        }
    };
    if let Err(e) = budget::check_bytes(file, "reading the material library", len) {
        libraries.error.get_or_insert(e);
        return missing;
    }
    let bytes = match std::fs::read(file) {
        Ok(bytes) => bytes,
        Err(e) => {
            libraries.warnings.push(format!(
                "material library {} cannot be read ({e}): its materials are left out",
                file.display()
            ));
            return missing;
        }
    };
    let text = String::from_utf8_lossy(&bytes);
    match tobj::load_mtl_buf(&mut Cursor::new(text.as_bytes())) {
        Ok(library) => Ok(library),
        Err(e) => {
            libraries.warnings.push(format!(
                "material library {} is not valid MTL ({}): its materials are left out",
                file.display(),
                mtl_problem(e)
            ));
            Err(e)
        }
    }
}

/// What a `tobj` failure on an MTL file means, in words.
fn mtl_problem(e: tobj::LoadError) -> &'static str {
    match e {
        tobj::LoadError::InvalidObjectName => "a newmtl statement without a name",
        tobj::LoadError::ReadError => "it is not text",
        _ => "a statement has missing or non-numeric values",
    }
}

/// A `tobj` failure on the OBJ file, in words.
fn from_tobj(path: &Path, e: tobj::LoadError) -> IoError {
    use tobj::LoadError as E;
    let message = match e {
        E::OpenFileFailed | E::ReadError => "the file cannot be read as text",
        E::PositionParseError => "a vertex (v) has a coordinate that is not a number",
        E::ScalingByZeroError => "a vertex (v) has a weight w of zero",
        E::ColorParseError => {
            "a vertex (v) has neither 3 coordinates, 4 (with w) nor 6 (with a colour)"
        }
        E::NormalParseError => "a normal (vn) has fewer than 3 numbers",
        E::TexcoordParseError => "a texture coordinate (vt) has fewer than 2 numbers",
        E::FaceParseError => "a face (f) or line (l) has a corner that is not an index",
        E::MaterialParseError => "a usemtl statement without a material name",
        E::InvalidObjectName => "an object or group has an invalid name",
        E::InvalidPolygon => "a face has too few corners",
        E::FaceVertexOutOfBounds => "a face refers to a vertex that does not exist",
        E::FaceTexCoordOutOfBounds => "a face refers to a texture coordinate that does not exist",
        E::FaceNormalOutOfBounds => "a face refers to a normal that does not exist",
        E::FaceColorOutOfBounds => "some vertices have colours and others do not",
        E::UnrecognizedCharacter | E::InvalidLoadOptionConfig | E::GenericFailure => {
            "the OBJ data cannot be decoded"
        }
    };
    IoError::malformed(path, message)
}

/// The models' geometry and attributes as one mesh with a part per model, in order, empty ones
/// included (materials filled with 0, set by the caller). Cost: linear in the models, plus the ear clipping of polygons.
fn assemble(
    path: &Path,
    models: &[tobj::Model],
    warnings: &mut Vec<String>,
) -> Result<Asset, IoError> {
    let vertices: usize = models.iter().map(|m| m.mesh.positions.len() / 3).sum();
    let corners: usize = models.iter().map(|m| m.mesh.indices.len()).sum();
    budget::check_count(path, "the vertices of the asset", vertices as u64, 64)?;
    budget::check_count(path, "the triangles of the asset", corners as u64, 8)?;
    let vertex_count = |m: &tobj::Model| m.mesh.positions.len() / 3;
    let complete =
        |m: &tobj::Model, data: &[f32], width: usize| data.len() == vertex_count(m) * width;

    let (with_uv, keep_normals, with_colors) = attribute_presence(models, warnings);

    let mut mesh = AssetMesh::default();
    mesh.positions.reserve(vertices);
    if with_uv > 0 {
        mesh.uv[0].reserve(vertices);
    }
    let mut parts = Vec::with_capacity(models.len());
    let mut polygon: Vec<DVec3> = Vec::new();
    for model in models {
        let m = &model.mesh;
        let base = mesh.positions.len() as u32;
        let n = vertex_count(model);
        let first_triangle = mesh.triangles.len() as u32;
        mesh.positions.extend(
            m.positions
                .chunks_exact(3)
                .map(|p| Vec3::new(p[0], p[1], p[2])),
        );
        if with_uv > 0 {
            if complete(model, &m.texcoords, 2) {
                mesh.uv[0].extend(
                    m.texcoords
                        .chunks_exact(2)
                        .map(|t| Vec2::new(t[0], 1.0 - t[1])),
                );
            } else {
                mesh.uv[0].extend(std::iter::repeat_n(Vec2::ZERO, n));
            }
        }
        if keep_normals {
            mesh.normals.extend(
                m.normals
                    .chunks_exact(3)
                    .map(|v| Vec3::new(v[0], v[1], v[2]).normalize_or_zero()),
            );
        }
        if with_colors > 0 {
            if complete(model, &m.vertex_color, 3) {
                mesh.colors.extend(
                    m.vertex_color
                        .chunks_exact(3)
                        .map(|c| srgba_to_linear([c[0], c[1], c[2], 1.0])),
                );
            } else {
                mesh.colors.extend(std::iter::repeat_n(Vec4::ONE, n));
            }
        }
        add_faces(path, m, base, n, &mut mesh, &mut polygon)?;
        parts.push(Part {
            name: model.name.clone(),
            first_triangle,
            triangle_count: mesh.triangles.len() as u32 - first_triangle,
        });
    }
    if let Some(i) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err(IoError::new(
            path,
            IoErrorKind::NonFinite,
            format!(
                "vertex {i} of the asset is not finite: {}",
                mesh.positions[i]
            ),
        ));
    }
    mesh.material = vec![0; mesh.triangles.len()];
    Ok(Asset {
        mesh,
        materials: Vec::new(),
        images: Vec::new(),
        parts,
    })
}

/// How many models have texture coordinates, whether every corner has a normal (else none are
/// kept), and how many models have vertex colours; warnings for attributes given in part.
fn attribute_presence(models: &[tobj::Model], warnings: &mut Vec<String>) -> (usize, bool, usize) {
    let vertex_count = |m: &tobj::Model| m.mesh.positions.len() / 3;
    let complete =
        |m: &tobj::Model, data: &[f32], width: usize| data.len() == vertex_count(m) * width;
    let with_uv = models
        .iter()
        .filter(|m| !m.mesh.texcoords.is_empty())
        .count();
    let with_normals = models.iter().filter(|m| !m.mesh.normals.is_empty()).count();
    let with_colors = models
        .iter()
        .filter(|m| !m.mesh.vertex_color.is_empty())
        .count();
    let partial =
        |m: &tobj::Model, data: &[f32], width: usize| !data.is_empty() && !complete(m, data, width);
    if models.iter().any(|m| partial(m, &m.mesh.texcoords, 2)) {
        warnings.push(
            "some corners of a part have texture coordinates and others do not: that part's texture coordinates are zero"
                .into(),
        );
    } else if with_uv > 0 && with_uv < models.len() {
        warnings.push(format!(
            "{} of {} parts have no texture coordinates: theirs are zero",
            models.len() - with_uv,
            models.len()
        ));
    }
    let keep_normals =
        with_normals == models.len() && models.iter().all(|m| complete(m, &m.mesh.normals, 3));
    if with_normals > 0 && !keep_normals {
        warnings.push("normals are given for some corners only: all are left out".into());
    }

    (with_uv, keep_normals, with_colors)
}

/// The faces of one model appended to `mesh` as triangles (its vertices start at `base`, `n`
/// of them), polygons ear-clipped. Refuses a face naming a vertex the model lacks.
fn add_faces(
    path: &Path,
    m: &tobj::Mesh,
    base: u32,
    n: usize,
    mesh: &mut AssetMesh,
    polygon: &mut Vec<DVec3>,
) -> Result<(), IoError> {
    let index = |i: u32| -> Result<u32, IoError> {
        if (i as usize) < n {
            Ok(base + i)
        } else {
            Err(IoError::new(
                path,
                IoErrorKind::Malformed,
                "a face refers to a vertex that does not exist",
            ))
        }
    };
    if m.face_arities.is_empty() {
        for t in m.indices.chunks_exact(3) {
            mesh.triangles
                .push([index(t[0])?, index(t[1])?, index(t[2])?]);
        }
    } else {
        let mut start = 0usize;
        for &arity in &m.face_arities {
            let end = start + arity as usize;
            let face = m
                .indices
                .get(start..end)
                .ok_or_else(|| IoError::malformed(path, "the OBJ data cannot be decoded"))?;
            start = end;
            match face.len() {
                0..=2 => {}
                3 => mesh
                    .triangles
                    .push([index(face[0])?, index(face[1])?, index(face[2])?]),
                _ => {
                    let local: Vec<u32> =
                        face.iter().map(|&i| index(i)).collect::<Result<_, _>>()?;
                    polygon.clear();
                    polygon.extend(local.iter().map(|&v| mesh.positions[v as usize].as_dvec3()));
                    mesh.triangles.extend(
                        ear_clipping::triangulate(polygon)
                            .into_iter()
                            .map(|t| t.map(|i| local[i])),
                    );
                }
            }
        }
    }
    Ok(())
}
