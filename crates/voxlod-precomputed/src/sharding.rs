//! The sharded layout `neuroglancer_uint64_sharded_v1` (neuroglancer `sharded.md`) for
//! multi-resolution meshes: chunk ids are segment ids, hashed to a shard and a minishard; a
//! shard file is the shard index (`2^minishard_bits` pairs of u64 offsets), then the chunks, then
//! the minishard indices (`[3, n]` u64: id deltas, offset deltas from the end of the previous
//! chunk, sizes). For meshes a segment's chunk is its manifest, and its fragment data come just
//! before it in the same file (`meshes.md`). Cost: linear in the bytes written; a shard's
//! minishard indices are held in memory until the shard is finished.

use std::io::{Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use flate2::read::GzDecoder;
use flate2::write::GzEncoder;
use serde_json::json;

use crate::PrecomputedError;

/// How a chunk id becomes its hashed id.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ShardHash {
    /// The id itself (ids spread evenly when they are dense).
    Identity,
    /// MurmurHash3_x86_128 of its 8 little-endian bytes, low 64 bits.
    #[default]
    Murmurhash3X86_128,
}

/// The sharded format's hash of a chunk id: the low 64 bits of MurmurHash3_x86_128 (seed 0)
/// of its 8 little-endian bytes, as neuroglancer and cloud-volume compute it. The hash is the
/// `murmur3` crate's; the low 64 bits of its `u128` are the digest's first 8 bytes read little
/// endian, `h1 | h2 << 32`.
pub fn murmur_hash(id: u64) -> u64 {
    let mut bytes: &[u8] = &id.to_le_bytes();
    // Reading from a byte slice never fails; the fallback is never taken.
    murmur3::murmur3_x86_128(&mut bytes, 0).map_or(0, |h| h as u64)
}

/// How minishard indices or chunk data are encoded.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ShardEncoding {
    /// As they are.
    Raw,
    /// gzip.
    #[default]
    Gzip,
}

impl ShardEncoding {
    fn name(self) -> &'static str {
        match self {
            ShardEncoding::Raw => "raw",
            ShardEncoding::Gzip => "gzip",
        }
    }

    /// `bytes` encoded.
    pub fn encode(self, bytes: &[u8]) -> Vec<u8> {
        match self {
            ShardEncoding::Raw => bytes.to_vec(),
            ShardEncoding::Gzip => {
                let mut gz = GzEncoder::new(Vec::new(), flate2::Compression::default());
                // Writing into a Vec cannot fail.
                let _ = gz.write_all(bytes);
                gz.finish().unwrap_or_default()
            }
        }
    }

    /// `bytes` decoded; `None` if they are not valid gzip.
    pub fn decode(self, bytes: &[u8]) -> Option<Vec<u8>> {
        match self {
            ShardEncoding::Raw => Some(bytes.to_vec()),
            ShardEncoding::Gzip => {
                let mut out = Vec::new();
                std::io::Read::read_to_end(&mut GzDecoder::new(bytes), &mut out).ok()?;
                Some(out)
            }
        }
    }
}

/// A sharding specification.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShardingSpec {
    /// Low bits of the id dropped before hashing.
    pub preshift_bits: u32,
    /// The hash.
    pub hash: ShardHash,
    /// Bits of the hashed id that pick the minishard.
    pub minishard_bits: u32,
    /// Bits above those that pick the shard.
    pub shard_bits: u32,
    /// Encoding of the minishard indices.
    pub minishard_index_encoding: ShardEncoding,
    /// Encoding of the chunks (the manifests).
    pub data_encoding: ShardEncoding,
}

/// At most about this many segments per shard, and per minishard, when the bits are chosen.
const PER_SHARD: usize = 2048;
const PER_MINISHARD: usize = 32;

fn ceil_log2(n: usize) -> u32 {
    n.max(1).next_power_of_two().trailing_zeros()
}

impl ShardingSpec {
    /// A specification for `labels` segments: no preshift, enough shards for about 2048
    /// segments each and enough minishards for about 32 each (a minishard index of under a
    /// kilobyte, a shard index of at most 1 KiB), with the given hash and encodings.
    pub fn for_labels(
        labels: usize,
        hash: ShardHash,
        minishard_index_encoding: ShardEncoding,
        data_encoding: ShardEncoding,
    ) -> ShardingSpec {
        let shard_bits = ceil_log2(labels.div_ceil(PER_SHARD));
        let per_shard = labels.div_ceil(1 << shard_bits);
        ShardingSpec {
            preshift_bits: 0,
            hash,
            minishard_bits: ceil_log2(per_shard.div_ceil(PER_MINISHARD)),
            shard_bits,
            minishard_index_encoding,
            data_encoding,
        }
    }

    /// The `"sharding"` JSON member.
    pub fn to_json(&self) -> serde_json::Value {
        json!({
            "@type": "neuroglancer_uint64_sharded_v1",
            "preshift_bits": self.preshift_bits,
            "hash": match self.hash {
                ShardHash::Identity => "identity",
                ShardHash::Murmurhash3X86_128 => "murmurhash3_x86_128",
            },
            "minishard_bits": self.minishard_bits,
            "shard_bits": self.shard_bits,
            "minishard_index_encoding": self.minishard_index_encoding.name(),
            "data_encoding": self.data_encoding.name(),
        })
    }

    fn hashed(&self, id: u64) -> u64 {
        let shifted = id.checked_shr(self.preshift_bits).unwrap_or(0);
        match self.hash {
            ShardHash::Identity => shifted,
            ShardHash::Murmurhash3X86_128 => murmur_hash(shifted),
        }
    }

    fn bits(value: u64, from: u32, count: u32) -> u64 {
        let shifted = value.checked_shr(from).unwrap_or(0);
        if count >= 64 {
            shifted
        } else {
            shifted & ((1u64 << count) - 1)
        }
    }

    /// The shard and minishard of a chunk id.
    pub fn locate(&self, id: u64) -> (u64, u64) {
        let h = self.hashed(id);
        (
            Self::bits(h, self.minishard_bits, self.shard_bits),
            Self::bits(h, 0, self.minishard_bits),
        )
    }

    /// The file name of a shard: lower-case hexadecimal, `ceil(shard_bits / 4)` digits.
    pub fn file_name(&self, shard: u64) -> String {
        let width = self.shard_bits.div_ceil(4) as usize;
        format!("{shard:0width$x}.shard")
    }

    fn index_bytes(&self) -> u64 {
        16u64 << self.minishard_bits
    }
}

/// Writes one shard file chunk by chunk; chunks must come in (minishard, id) order.
pub struct ShardWriter {
    spec: ShardingSpec,
    path: PathBuf,
    file: std::io::BufWriter<std::fs::File>,
    /// Per minishard: (id, start relative to the index's end, size).
    entries: Vec<Vec<(u64, u64, u64)>>,
    /// Bytes written after the shard index.
    written: u64,
}

impl ShardWriter {
    /// Creates the file and reserves its shard index.
    pub fn create(path: &Path, spec: ShardingSpec) -> Result<ShardWriter, PrecomputedError> {
        let io = |e| PrecomputedError::io(path, e);
        let mut file = std::io::BufWriter::new(std::fs::File::create(path).map_err(io)?);
        file.write_all(&vec![0u8; spec.index_bytes() as usize])
            .map_err(io)?;
        Ok(ShardWriter {
            spec,
            path: path.to_path_buf(),
            file,
            entries: vec![Vec::new(); 1 << spec.minishard_bits],
            written: 0,
        })
    }

    /// Appends a segment: `prefix` (its fragment data, stored as is) then `chunk` (its manifest,
    /// stored in the data encoding), which the minishard index points at. Fails on a chunk out
    /// of (minishard, id) order.
    pub fn add(&mut self, id: u64, prefix: &[u8], chunk: &[u8]) -> Result<(), PrecomputedError> {
        let (_, minishard) = self.spec.locate(id);
        let later = self.entries[minishard as usize + 1..]
            .iter()
            .any(|e| !e.is_empty());
        let last = self.entries[minishard as usize].last().map(|e| e.0);
        if later || last.is_some_and(|l| l >= id) {
            return Err(PrecomputedError::Format {
                path: self.path.clone(),
                reason: format!("segment {id} added out of (minishard, id) order"),
            });
        }
        let encoded = self.spec.data_encoding.encode(chunk);
        let io = |e| PrecomputedError::io(&self.path, e);
        self.file.write_all(prefix).map_err(io)?;
        self.file.write_all(&encoded).map_err(io)?;
        let start = self.written + prefix.len() as u64;
        self.entries[minishard as usize].push((id, start, encoded.len() as u64));
        self.written = start + encoded.len() as u64;
        Ok(())
    }

    /// Writes the minishard indices and the shard index, and closes the file.
    pub fn finish(mut self) -> Result<(), PrecomputedError> {
        let mut index = Vec::with_capacity(self.spec.index_bytes() as usize);
        for entries in &self.entries {
            let begin = self.written;
            if !entries.is_empty() {
                let raw = minishard_index(entries);
                let encoded = self.spec.minishard_index_encoding.encode(&raw);
                self.file
                    .write_all(&encoded)
                    .map_err(|e| PrecomputedError::io(&self.path, e))?;
                self.written += encoded.len() as u64;
            }
            index.extend_from_slice(&begin.to_le_bytes());
            index.extend_from_slice(&self.written.to_le_bytes());
        }
        let io = |e| PrecomputedError::io(&self.path, e);
        self.file.seek(SeekFrom::Start(0)).map_err(io)?;
        self.file.write_all(&index).map_err(io)?;
        self.file.flush().map_err(io)?;
        Ok(())
    }
}

/// The raw `[3, n]` minishard index of entries (id, start, size) sorted by id.
fn minishard_index(entries: &[(u64, u64, u64)]) -> Vec<u8> {
    let mut ids = Vec::with_capacity(entries.len());
    let mut offsets = Vec::with_capacity(entries.len());
    let (mut prev_id, mut prev_end) = (0u64, 0u64);
    for &(id, start, size) in entries {
        ids.push(id - prev_id);
        offsets.push(start - prev_end);
        prev_id = id;
        prev_end = start + size;
    }
    let sizes = entries.iter().map(|e| e.2);
    ids.into_iter()
        .chain(offsets)
        .chain(sizes)
        .flat_map(u64::to_le_bytes)
        .collect()
}

/// Finds a chunk in a shard file's bytes: its start in the file and its decoded bytes, or
/// `None` when the shard does not hold it. Fails on indices that do not follow the format.
pub fn read_chunk(
    spec: &ShardingSpec,
    shard: &[u8],
    id: u64,
    path: &Path,
) -> Result<Option<(u64, Vec<u8>)>, PrecomputedError> {
    let bad = |reason: &str| PrecomputedError::Format {
        path: path.to_path_buf(),
        reason: reason.to_string(),
    };
    let u64_at = |bytes: &[u8], i: usize| -> Result<u64, PrecomputedError> {
        let w = bytes
            .get(8 * i..8 * i + 8)
            .ok_or_else(|| bad("index truncated"))?;
        Ok(u64::from_le_bytes(
            w.try_into().map_err(|_| bad("index truncated"))?,
        ))
    };
    let (_, minishard) = spec.locate(id);
    let base = spec.index_bytes();
    let begin = base + u64_at(shard, 2 * minishard as usize)?;
    let end = base + u64_at(shard, 2 * minishard as usize + 1)?;
    if begin == end {
        return Ok(None);
    }
    let raw = shard
        .get(begin as usize..end as usize)
        .ok_or_else(|| bad("minishard index beyond the file"))?;
    let index = spec
        .minishard_index_encoding
        .decode(raw)
        .ok_or_else(|| bad("minishard index is not valid gzip"))?;
    let n = index.len() / 24;
    let (mut cur_id, mut cur_end) = (0u64, base);
    for i in 0..n {
        cur_id = cur_id.wrapping_add(u64_at(&index, i)?);
        let start = cur_end + u64_at(&index, n + i)?;
        let size = u64_at(&index, 2 * n + i)?;
        cur_end = start + size;
        if cur_id == id {
            let bytes = shard
                .get(start as usize..cur_end as usize)
                .ok_or_else(|| bad("chunk beyond the file"))?;
            let data = spec
                .data_encoding
                .decode(bytes)
                .ok_or_else(|| bad("chunk is not valid gzip"))?;
            return Ok(Some((start, data)));
        }
    }
    Ok(None)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_hash_is_the_one_cloud_volume_computes() {
        // Printed by cloud-volume's mmh3.hash64(np.uint64(id).tobytes(), x64arch=False)[0]
        // (tests/peers.rs runs the same comparison live when the peers are installed).
        let expected: [(u64, u64); 6] = [
            (0, 5148371408780832321),
            (1, 16770674756601302682),
            (7, 15959679207757848918),
            (300, 10283220358353951676),
            ((1 << 40) + 5, 2274969156372510802),
            (u64::MAX, 6291360166951214362),
        ];
        for (id, hash) in expected {
            assert_eq!(murmur_hash(id), hash, "id {id}");
        }
    }

    #[test]
    fn bits_grow_with_the_labels() {
        let spec = |n| {
            ShardingSpec::for_labels(
                n,
                ShardHash::Identity,
                ShardEncoding::Raw,
                ShardEncoding::Raw,
            )
        };
        assert_eq!((spec(1).shard_bits, spec(1).minishard_bits), (0, 0));
        assert_eq!((spec(513).shard_bits, spec(513).minishard_bits), (0, 5));
        assert_eq!(
            (spec(100_000).shard_bits, spec(100_000).minishard_bits),
            (6, 6)
        );
        assert_eq!(spec(513).file_name(0), "0.shard");
        assert_eq!(spec(100_000).file_name(10), "0a.shard");
    }

    #[test]
    fn chunks_are_found_where_they_were_written() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("0.shard");
        let spec = ShardingSpec {
            preshift_bits: 0,
            hash: ShardHash::Identity,
            minishard_bits: 1,
            shard_bits: 0,
            minishard_index_encoding: ShardEncoding::Gzip,
            data_encoding: ShardEncoding::Gzip,
        };
        let mut w = ShardWriter::create(&path, spec).unwrap();
        for id in [2u64, 8, 3, 5] {
            w.add(id, &[id as u8; 3], format!("manifest {id}").as_bytes())
                .unwrap();
        }
        assert!(w.add(1, b"", b"late").is_err());
        w.finish().unwrap();
        let bytes = std::fs::read(&path).unwrap();
        for id in [2u64, 8, 3, 5] {
            let (start, data) = read_chunk(&spec, &bytes, id, &path).unwrap().unwrap();
            assert_eq!(data, format!("manifest {id}").as_bytes());
            assert_eq!(&bytes[start as usize - 3..start as usize], &[id as u8; 3]);
        }
        assert!(read_chunk(&spec, &bytes, 4, &path).unwrap().is_none());
    }
}
