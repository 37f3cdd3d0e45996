//! [`write_layer`]: a complete precomputed segmentation layer, written so that a failure never
//! leaves a folder that looks complete.
//!
//! Everything is written into `DIR.partial` (the layer's `info` last), which then replaces
//! `DIR`: a reader sees the previous layer or the new one, never a half-written one. An existing
//! `DIR` is replaced only if it is empty or a precomputed layer (it has an `info` naming a
//! `neuroglancer_multiscale_volume`); anything else is refused. Labels are meshed in parallel
//! (rayon), and within a label the nodes of a level are simplified and encoded in parallel;
//! sharded layers one shard at a time, so memory holds one shard's output. Every file is put
//! together in a fixed order (labels by id, nodes in Morton order), so the bytes do not depend
//! on the number of threads, nor on the order of a mesh's vertices and triangles
//! (`canonical.rs`).

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use rayon::prelude::*;
use serde_json::json;
use voxlod_core::glam::DVec3;
use voxlod_core::{memory, LabelVolume, TriangleMesh};

use crate::canonical::{Compact, Compactor};
use crate::draco::{self, QuantizedFragment};
use crate::filtered::{self, LevelMesh};
use crate::lods::{self, Node, Octree, OctreeOptions};
use crate::manifest::Manifest;
use crate::quantize::{Lattice, StoredFrame};
use crate::sharding::{ShardWriter, ShardingSpec};
use crate::{volume, PrecomputedError, PrecomputedOptions, Sharding, SHARDING_THRESHOLD};

/// One level of detail of one label.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct LodReport {
    /// Octree nodes listed in the manifest (empty ones included).
    pub fragments: usize,
    /// Triangles over all its fragments.
    pub triangles: usize,
    /// Bytes of its Draco fragments.
    pub bytes: u64,
    /// The level had no triangle (a label thinner than that level's filter, or smaller than
    /// its simplification's error): it holds the finer level's surface instead.
    pub carried: bool,
}

/// What was written for one label.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct LabelReport {
    /// The segment id.
    pub label: u32,
    /// Per level of detail, finest first; empty for a label whose mesh has no triangle (no
    /// manifest is written for it).
    pub lods: Vec<LodReport>,
    /// Bytes of its manifest (before any shard encoding).
    pub manifest_bytes: u64,
}

/// What [`write_layer`] wrote.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LayerReport {
    /// The layer's folder.
    pub dir: PathBuf,
    /// Per label, in the order given.
    pub labels: Vec<LabelReport>,
    /// The sharding used, if the meshes are sharded.
    pub sharding: Option<ShardingSpec>,
    /// Bytes of the volume's chunks.
    pub volume_bytes: u64,
    /// Resolution of the scale, nm per voxel.
    pub resolution: [f64; 3],
    /// The scale's voxel offset.
    pub voxel_offset: [i64; 3],
}

/// A label's manifest and fragment data, ready to store.
struct Encoded {
    manifest: Vec<u8>,
    data: Vec<u8>,
    report: LabelReport,
}

/// Writes the precomputed segmentation layer of `map` with, for each `(label, mesh)`, its
/// multi-resolution mesh, into `dir` (see the crate docs for the layout): level 0 is the mesh,
/// each coarser level simplified from the finer one (`lods.rs`). Meshes are in the map's world
/// (`map.world()`). Fails before writing anything on invalid options, an oblique map, label 0
/// or a label given twice, or a mesh that is not well formed; fails naming the file on an I/O
/// error, leaving `dir` as it was. Cost: one pass over the labels, and per label the cut,
/// simplification and encoding of its mesh (`lods.rs`).
pub fn write_layer(
    dir: &Path,
    map: &LabelVolume,
    meshes: &[(u32, TriangleMesh)],
    options: &PrecomputedOptions,
) -> Result<LayerReport, PrecomputedError> {
    let labels: Vec<(u32, &[TriangleMesh])> = (meshes.iter())
        .map(|(label, mesh)| (*label, std::slice::from_ref(mesh)))
        .collect();
    write_labels(dir, map, &labels, options)
}

/// [`write_layer`] with each label's levels given, finest first, `options.lods` meshes per
/// label: the paper's filter pyramid, level k of the layer being level k of the pyramid, cut on
/// the octree's grid (`filtered.rs`; its docs say what meets between levels). A label whose
/// level 0 has no triangle gets no manifest; a coarser level without triangles (a label
/// thinner than that level's filter) holds the finer level's surface instead, so that the
/// label stays drawn when zoomed out and every level reads back as a mesh
/// ([`LodReport::carried`]). Fails as [`write_layer`] does, and on a label with
/// another number of meshes.
pub fn write_layer_filtered(
    dir: &Path,
    map: &LabelVolume,
    levels: &[(u32, Vec<TriangleMesh>)],
    options: &PrecomputedOptions,
) -> Result<LayerReport, PrecomputedError> {
    for (label, meshes) in levels {
        if meshes.len() != options.lods {
            return Err(PrecomputedError::Mesh {
                label: *label as u64,
                reason: format!(
                    "{} levels given for a layer of {} levels of detail",
                    meshes.len(),
                    options.lods
                ),
            });
        }
    }
    let labels: Vec<(u32, &[TriangleMesh])> = (levels.iter())
        .map(|(label, meshes)| (*label, meshes.as_slice()))
        .collect();
    write_labels(dir, map, &labels, options)
}

/// Each label with its meshes: its finest mesh alone (the coarser levels made by `lods.rs`), or
/// one mesh per level of detail (`filtered.rs`).
type Labels<'a> = [(u32, &'a [TriangleMesh])];

/// [`write_layer`] and [`write_layer_filtered`].
fn write_labels(
    dir: &Path,
    map: &LabelVolume,
    meshes: &Labels,
    options: &PrecomputedOptions,
) -> Result<LayerReport, PrecomputedError> {
    options.validate()?;
    let frame = StoredFrame::of(&map.world())?;
    check_meshes(meshes)?;
    check_memory(meshes, options)?;
    check_target(dir)?;
    let partial = partial_dir(dir)?;
    let result = write_into(&partial, map, meshes, options, &frame);
    match result {
        Ok(mut report) => {
            replace(&partial, dir)?;
            report.dir = dir.to_path_buf();
            Ok(report)
        }
        Err(e) => {
            let _ = std::fs::remove_dir_all(&partial);
            Err(e)
        }
    }
}

fn write_into(
    partial: &Path,
    map: &LabelVolume,
    meshes: &Labels,
    options: &PrecomputedOptions,
    frame: &StoredFrame,
) -> Result<LayerReport, PrecomputedError> {
    let resolution = volume::resolution(frame, options.nanometres_per_unit);
    let scale_dir = partial.join(volume::scale_key(resolution));
    let volume_bytes =
        volume::write_chunks(&scale_dir, map, frame, options.chunk, options.label_type)?;
    let mesh_dir = partial.join("mesh");
    mkdir(&mesh_dir)?;
    let meshed = meshes.iter().filter(|(_, m)| !m[0].is_empty()).count();
    let sharded = match options.sharding {
        Sharding::Never => false,
        Sharding::Always => true,
        Sharding::Auto => meshed > SHARDING_THRESHOLD,
    };
    let (labels, sharding) = if sharded {
        let spec = ShardingSpec::for_labels(
            meshed,
            options.shard_hash,
            options.minishard_index_encoding,
            options.data_encoding,
        );
        (
            write_sharded(&mesh_dir, meshes, frame, options, &spec)?,
            Some(spec),
        )
    } else {
        (write_unsharded(&mesh_dir, meshes, frame, options)?, None)
    };
    let mut mesh_info = json!({
        "@type": "neuroglancer_multilod_draco",
        "vertex_quantization_bits": options.quantization_bits,
        "transform": [resolution[0], 0, 0, 0, 0, resolution[1], 0, 0, 0, 0, resolution[2], 0],
        "lod_scale_multiplier": 1.0,
    });
    if let Some(spec) = &sharding {
        mesh_info["sharding"] = spec.to_json();
    }
    write_json(&mesh_dir.join("info"), &mesh_info)?;
    let info = volume::info(
        map,
        frame,
        resolution,
        options.chunk,
        options.label_type,
        "mesh",
    );
    write_json(&partial.join("info"), &info)?;
    Ok(LayerReport {
        dir: partial.to_path_buf(),
        labels,
        sharding,
        volume_bytes,
        resolution,
        voxel_offset: frame.voxel_offset,
    })
}

/// Refuses label 0, repeated labels and malformed meshes, naming the label.
fn check_meshes(meshes: &Labels) -> Result<(), PrecomputedError> {
    let mut seen = HashSet::with_capacity(meshes.len());
    for (label, levels) in meshes {
        let bad = |reason: String| PrecomputedError::Mesh {
            label: *label as u64,
            reason,
        };
        if *label == 0 {
            return Err(bad("label 0 is the background and has no mesh".into()));
        }
        if !seen.insert(*label) {
            return Err(bad("given twice".into()));
        }
        if levels.is_empty() {
            return Err(bad("no mesh given".into()));
        }
        for (k, mesh) in levels.iter().enumerate() {
            let at = |e: String| match levels.len() {
                1 => e,
                _ => format!("level {k}: {e}"),
            };
            mesh.validate().map_err(|e| bad(at(e.to_string())))?;
        }
    }
    Ok(())
}

/// Asks the memory limit for the octrees of the labels built at once: the largest ones, one
/// per thread.
fn check_memory(meshes: &Labels, options: &PrecomputedOptions) -> Result<(), PrecomputedError> {
    let bytes = |levels: &[TriangleMesh]| -> u64 {
        (levels.iter())
            .map(|m| lods::octree_bytes(m.positions.len(), m.triangles.len(), options.lods))
            .sum()
    };
    let mut sizes: Vec<u64> = meshes.iter().map(|(_, levels)| bytes(levels)).collect();
    sizes.sort_unstable_by(|a, b| b.cmp(a));
    let at_once = sizes.iter().take(rayon::current_num_threads()).sum();
    memory::check_allocation("the octrees of the labels meshed at once", at_once)?;
    Ok(())
}

/// One file per manifest and per fragment data, labels in parallel.
fn write_unsharded(
    mesh_dir: &Path,
    meshes: &Labels,
    frame: &StoredFrame,
    options: &PrecomputedOptions,
) -> Result<Vec<LabelReport>, PrecomputedError> {
    meshes
        .par_iter()
        .map(|(label, mesh)| {
            let Some(encoded) = encode_label(*label, mesh, frame, options)? else {
                return Ok(empty_report(*label));
            };
            write_file(&mesh_dir.join(format!("{label}.index")), &encoded.manifest)?;
            write_file(&mesh_dir.join(label.to_string()), &encoded.data)?;
            Ok(encoded.report)
        })
        .collect()
}

/// Shard files, one shard at a time, its labels encoded in parallel and stored in
/// (minishard, id) order.
fn write_sharded(
    mesh_dir: &Path,
    meshes: &Labels,
    frame: &StoredFrame,
    options: &PrecomputedOptions,
    spec: &ShardingSpec,
) -> Result<Vec<LabelReport>, PrecomputedError> {
    let mut order: Vec<(u64, u64, u32, usize)> = meshes
        .iter()
        .enumerate()
        .filter(|(_, (_, m))| !m[0].is_empty())
        .map(|(i, (label, _))| {
            let (shard, minishard) = spec.locate(*label as u64);
            (shard, minishard, *label, i)
        })
        .collect();
    order.sort_unstable();
    let mut reports: Vec<LabelReport> = meshes.iter().map(|(l, _)| empty_report(*l)).collect();
    for group in order.chunk_by(|a, b| a.0 == b.0) {
        let encoded: Vec<Option<Encoded>> = group
            .par_iter()
            .map(|&(_, _, label, i)| encode_label(label, meshes[i].1, frame, options))
            .collect::<Result<_, _>>()?;
        let path = mesh_dir.join(spec.file_name(group[0].0));
        let mut writer = ShardWriter::create(&path, *spec)?;
        for (&(_, _, label, i), e) in group.iter().zip(encoded) {
            if let Some(e) = e {
                writer.add(label as u64, &e.data, &e.manifest)?;
                reports[i] = e.report;
            }
        }
        writer.finish()?;
    }
    Ok(reports)
}

fn empty_report(label: u32) -> LabelReport {
    LabelReport {
        label,
        ..LabelReport::default()
    }
}

/// The octree's origin for a label: the volume's corner moved down by whole coarsest nodes
/// until it is at or below every vertex the levels' triangles use, so that node positions are
/// non-negative and every label's nodes lie on one global grid.
fn grid_origin(levels: &[StoredLevel], frame: &StoredFrame, coarsest: f64) -> DVec3 {
    let corner = DVec3::from_array(frame.voxel_offset.map(|v| v as f64));
    let low = (levels.iter())
        .flat_map(|(p, t)| t.iter().flatten().map(|&v| p[v as usize]))
        .fold(DVec3::INFINITY, |m, p| m.min(p));
    corner + ((low - corner) / coarsest).floor().min(DVec3::ZERO) * coarsest
}

/// A level's vertices in the stored model space, with its triangles.
type StoredLevel<'a> = (Vec<DVec3>, &'a [[u32; 3]]);

/// A label's octree, quantized and encoded: its manifest and fragment data, or `None` for a
/// label whose level 0 has no triangle. `levels` is its finest mesh alone (the octree of
/// `lods.rs`) or one mesh per level of detail (`filtered.rs`).
fn encode_label(
    label: u32,
    levels: &[TriangleMesh],
    frame: &StoredFrame,
    options: &PrecomputedOptions,
) -> Result<Option<Encoded>, PrecomputedError> {
    if levels[0].is_empty() {
        return Ok(None);
    }
    // A level given without triangles takes the finer level's surface.
    let mut stored: Vec<StoredLevel> = Vec::with_capacity(levels.len());
    let mut carried = vec![false; levels.len()];
    for (k, m) in levels.iter().enumerate() {
        let level = match stored.last() {
            Some(finer) if m.triangles.is_empty() => {
                carried[k] = true;
                finer.clone()
            }
            _ => {
                let p = m.positions.iter().map(|p| frame.to_stored(p.as_dvec3()));
                (p.collect(), m.triangles.as_slice())
            }
        };
        stored.push(level);
    }
    let chunk = DVec3::splat(options.fragment_voxels as f64);
    let coarsest = options.fragment_voxels as f64 * (1u64 << (options.lods - 1)) as f64;
    let octree_options = OctreeOptions {
        grid_origin: grid_origin(&stored, frame, coarsest),
        chunk,
        lods: options.lods,
        ratio: options.lod_ratio,
    };
    let octree = match stored.as_slice() {
        [(positions, triangles)] => lods::build_unchecked(positions, triangles, &octree_options),
        _ => {
            let meshes: Vec<LevelMesh> = (stored.iter())
                .map(|(positions, triangles)| LevelMesh {
                    positions,
                    triangles,
                })
                .collect();
            filtered::build_filtered(&meshes, &octree_options)
        }
    };
    let octree = octree.map_err(|e| match e {
        PrecomputedError::Mesh { reason, .. } => PrecomputedError::Mesh {
            label: label as u64,
            reason,
        },
        other => other,
    })?;
    let (manifest, data, mut lods) = encode_octree(&octree, options.quantization_bits)?;
    for (k, report) in lods.iter_mut().enumerate() {
        report.carried = carried.get(k).copied().unwrap_or(false) || octree.carried[k];
    }
    let manifest = manifest.to_bytes();
    Ok(Some(Encoded {
        report: LabelReport {
            label,
            lods,
            manifest_bytes: manifest.len() as u64,
        },
        manifest,
        data,
    }))
}

/// The manifest, the concatenated fragments (level 0 first, nodes in Z-curve order) and the
/// per-level report of an octree.
fn encode_octree(
    octree: &Octree,
    bits: u32,
) -> Result<(Manifest, Vec<u8>, Vec<LodReport>), PrecomputedError> {
    let lods = octree.levels.len();
    let mut manifest = Manifest {
        chunk_shape: octree.chunk.as_vec3().to_array(),
        grid_origin: octree.grid_origin.as_vec3().to_array(),
        lod_scales: (0..lods).map(|k| (1u64 << k) as f32).collect(),
        vertex_offsets: vec![[0.0; 3]; lods],
        ..Manifest::default()
    };
    let mut data = Vec::new();
    let mut reports = Vec::with_capacity(lods);
    for (k, level) in octree.levels.iter().enumerate() {
        let lattice = Lattice::new(octree.grid_origin, octree.chunk, k, bits);
        let nodes: Vec<&Node> = level.values().collect();
        // Fragments encoded in parallel, stored in the nodes' (Morton) order.
        let fragments: Vec<(usize, Vec<u8>)> = nodes
            .par_iter()
            .with_min_len(lods::NODES_PER_TASK)
            .map_init(
                || Compactor::new(octree.positions.len()),
                |compactor, node| {
                    let piece = compactor.compact(&node.triangles);
                    let fragment =
                        quantize_piece(&octree.positions, piece, &lattice, node.position);
                    Ok((fragment.triangles.len(), draco::encode(&fragment)?))
                },
            )
            .collect::<Result<_, PrecomputedError>>()?;
        let mut report = LodReport::default();
        let (mut positions, mut sizes) = (Vec::new(), Vec::new());
        for (node, (triangles, bytes)) in nodes.iter().zip(fragments) {
            positions.push(node.position);
            sizes.push(
                u32::try_from(bytes.len())
                    .map_err(|_| PrecomputedError::Draco("a fragment over 4 GiB".into()))?,
            );
            report.fragments += 1;
            report.triangles += triangles;
            report.bytes += bytes.len() as u64;
            data.extend_from_slice(&bytes);
        }
        manifest.fragment_positions.push(positions);
        manifest.fragment_sizes.push(sizes);
        reports.push(report);
    }
    Ok((manifest, data, reports))
}

/// A node's triangles with their own vertices, quantized on the level's lattice: the vertices
/// in increasing index order (position order in an [`Octree`]), the triangles as given.
pub fn quantize_node(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    lattice: &Lattice,
    cell: [u32; 3],
) -> QuantizedFragment {
    quantize_piece(positions, Compact::of(triangles), lattice, cell)
}

/// A piece on its own vertices, quantized on the level's lattice in the node at `cell`.
fn quantize_piece(
    positions: &[DVec3],
    piece: Compact,
    lattice: &Lattice,
    cell: [u32; 3],
) -> QuantizedFragment {
    QuantizedFragment {
        positions: piece
            .vertices
            .iter()
            .map(|&v| lattice.quantize(positions[v as usize], cell))
            .collect(),
        triangles: piece.triangles,
    }
}

fn mkdir(path: &Path) -> Result<(), PrecomputedError> {
    std::fs::create_dir_all(path).map_err(|e| PrecomputedError::io(path, e))
}

fn write_file(path: &Path, bytes: &[u8]) -> Result<(), PrecomputedError> {
    std::fs::write(path, bytes).map_err(|e| PrecomputedError::io(path, e))
}

fn write_json(path: &Path, value: &serde_json::Value) -> Result<(), PrecomputedError> {
    let text = serde_json::to_string_pretty(value).unwrap_or_default();
    write_file(path, text.as_bytes())
}

/// `DIR.partial`, emptied; fails if `dir` has no file name.
fn partial_dir(dir: &Path) -> Result<PathBuf, PrecomputedError> {
    let name = dir
        .file_name()
        .ok_or_else(|| PrecomputedError::Options(format!("{} names no folder", dir.display())))?;
    let mut partial_name = name.to_os_string();
    partial_name.push(".partial");
    let partial = dir.with_file_name(partial_name);
    if partial.exists() {
        std::fs::remove_dir_all(&partial).map_err(|e| PrecomputedError::io(&partial, e))?;
    }
    mkdir(&partial)?;
    Ok(partial)
}

/// Fails if `dir` exists and is neither empty nor a precomputed layer.
fn check_target(dir: &Path) -> Result<(), PrecomputedError> {
    if !dir.exists() {
        return Ok(());
    }
    let empty = std::fs::read_dir(dir)
        .map_err(|e| PrecomputedError::io(dir, e))?
        .next()
        .is_none();
    let info = std::fs::read_to_string(dir.join("info")).unwrap_or_default();
    if empty || info.contains("neuroglancer_multiscale_volume") {
        return Ok(());
    }
    Err(PrecomputedError::io(
        dir,
        std::io::Error::new(
            std::io::ErrorKind::AlreadyExists,
            "exists and is not a precomputed layer: refusing to replace it",
        ),
    ))
}

/// Moves the finished layer into place, replacing an empty folder or an earlier layer.
fn replace(partial: &Path, dir: &Path) -> Result<(), PrecomputedError> {
    if dir.exists() {
        if let Err(e) = check_target(dir) {
            let _ = std::fs::remove_dir_all(partial);
            return Err(e);
        }
        std::fs::remove_dir_all(dir).map_err(|e| PrecomputedError::io(dir, e))?;
    }
    std::fs::rename(partial, dir).map_err(|e| PrecomputedError::io(dir, e))
}
