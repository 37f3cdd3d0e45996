//! Reading a label's multi-resolution mesh back from a layer written by [`crate::write_layer`]
//! (or any precomputed layer of the same format): its manifest and fragment data, plain or
//! sharded, and its fragments decoded and placed. For checks and tests; cost: one read of the
//! label's files (of its whole shard when sharded).

use std::path::Path;

use voxlod_core::glam::DVec3;

use crate::draco;
use crate::manifest::Manifest;
use crate::quantize::Lattice;
use crate::sharding::{read_chunk, ShardEncoding, ShardHash, ShardingSpec};
use crate::PrecomputedError;

/// A label's manifest and its fragment data.
#[derive(Clone, Debug, PartialEq)]
pub struct StoredMesh {
    /// The manifest.
    pub manifest: Manifest,
    /// The fragments, concatenated in the manifest's order.
    pub data: Vec<u8>,
    /// The mesh info's `vertex_quantization_bits`.
    pub bits: u32,
}

/// One decoded fragment with its node.
#[derive(Clone, Debug, PartialEq)]
pub struct PlacedFragment {
    /// Level of detail.
    pub lod: usize,
    /// Node position at that level.
    pub node: [u32; 3],
    /// The quantized fragment as stored.
    pub fragment: draco::QuantizedFragment,
    /// Its vertices in the stored model space.
    pub positions: Vec<DVec3>,
}

fn read(path: &Path) -> Result<Vec<u8>, PrecomputedError> {
    std::fs::read(path).map_err(|e| PrecomputedError::io(path, e))
}

/// The sharding of a mesh `info`, if any; fails on a malformed one.
fn sharding_of(
    info: &serde_json::Value,
    path: &Path,
) -> Result<Option<ShardingSpec>, PrecomputedError> {
    let Some(s) = info.get("sharding") else {
        return Ok(None);
    };
    let bad = |what: &str| PrecomputedError::Format {
        path: path.to_path_buf(),
        reason: format!("sharding: bad or missing {what}"),
    };
    let int = |k: &str| {
        s.get(k)
            .and_then(|v| v.as_u64())
            .map(|v| v as u32)
            .ok_or_else(|| bad(k))
    };
    let encoding = |k: &str| match s.get(k).and_then(|v| v.as_str()).unwrap_or("raw") {
        "raw" => Ok(ShardEncoding::Raw),
        "gzip" => Ok(ShardEncoding::Gzip),
        _ => Err(bad(k)),
    };
    Ok(Some(ShardingSpec {
        preshift_bits: int("preshift_bits")?,
        hash: match s.get("hash").and_then(|v| v.as_str()) {
            Some("identity") => ShardHash::Identity,
            Some("murmurhash3_x86_128") => ShardHash::Murmurhash3X86_128,
            _ => return Err(bad("hash")),
        },
        minishard_bits: int("minishard_bits")?,
        shard_bits: int("shard_bits")?,
        minishard_index_encoding: encoding("minishard_index_encoding")?,
        data_encoding: encoding("data_encoding")?,
    }))
}

/// Reads `label`'s manifest and fragment data from the layer at `dir` (its `mesh` folder).
pub fn read_mesh(dir: &Path, label: u64) -> Result<StoredMesh, PrecomputedError> {
    let mesh_dir = dir.join("mesh");
    let info_path = mesh_dir.join("info");
    let info: serde_json::Value =
        serde_json::from_slice(&read(&info_path)?).map_err(|e| PrecomputedError::Format {
            path: info_path.clone(),
            reason: e.to_string(),
        })?;
    let bits = info["vertex_quantization_bits"].as_u64().unwrap_or(0) as u32;
    let Some(spec) = sharding_of(&info, &info_path)? else {
        let index = mesh_dir.join(format!("{label}.index"));
        let manifest = Manifest::from_bytes(&read(&index)?, &index)?;
        let data = read(&mesh_dir.join(label.to_string()))?;
        return Ok(StoredMesh {
            manifest,
            data,
            bits,
        });
    };
    let path = mesh_dir.join(spec.file_name(spec.locate(label).0));
    let shard = read(&path)?;
    let missing = || PrecomputedError::Format {
        path: path.clone(),
        reason: format!("no segment {label}"),
    };
    let (start, chunk) = read_chunk(&spec, &shard, label, &path)?.ok_or_else(missing)?;
    let manifest = Manifest::from_bytes(&chunk, &path)?;
    let begin = start
        .checked_sub(manifest.data_size())
        .ok_or_else(missing)?;
    let data = shard[begin as usize..start as usize].to_vec();
    Ok(StoredMesh {
        manifest,
        data,
        bits,
    })
}

impl StoredMesh {
    /// Every fragment decoded, level 0 first, with its vertices placed by neuroglancer's
    /// formula. Fails on a fragment Draco cannot decode or sizes beyond the data.
    pub fn fragments(&self) -> Result<Vec<PlacedFragment>, PrecomputedError> {
        let m = &self.manifest;
        let origin = DVec3::from_array(m.grid_origin.map(|v| v as f64));
        let chunk = DVec3::from_array(m.chunk_shape.map(|v| v as f64));
        let mut out = Vec::new();
        let mut at = 0usize;
        for lod in 0..m.num_lods() {
            let lattice = Lattice::new(origin, chunk, lod, self.bits);
            let offset = DVec3::from_array(m.vertex_offsets[lod].map(|v| v as f64));
            for (node, &size) in m.fragment_positions[lod].iter().zip(&m.fragment_sizes[lod]) {
                let bytes = self.data.get(at..at + size as usize).ok_or_else(|| {
                    PrecomputedError::Draco("fragment sizes run past the data".into())
                })?;
                at += size as usize;
                let fragment = draco::decode(bytes)?;
                let positions = fragment
                    .positions
                    .iter()
                    .map(|&x| lattice.dequantize(x, *node) + offset)
                    .collect();
                out.push(PlacedFragment {
                    lod,
                    node: *node,
                    fragment,
                    positions,
                });
            }
        }
        Ok(out)
    }
}
