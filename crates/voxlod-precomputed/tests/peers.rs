//! The layer read back by independent tools in the peers' Python: cloud-volume (meshes at
//! every level of detail, plain and sharded, and the labels) and DracoPy (the fragments).
//! Each test skips, with the reason recorded, when the peers are absent.

mod common;

use std::ffi::OsStr;
use std::path::Path;

use serde_json::Value;
use voxlod_precomputed::read::read_mesh;
use voxlod_precomputed::{
    sharding, write_layer_filtered, LabelType, PrecomputedOptions, ShardEncoding, ShardHash,
    Sharding,
};
use voxlod_testkit::peers::run_python;

/// Prints, per label and level, cloud-volume's triangles as global lattice indices (9 integers
/// each: the stored position over the level's quantization step), and writes the labels it
/// reads, x fastest, to argv[4].
const CLOUD_VOLUME: &str = r#"
import sys, json, numpy as np
from cloudvolume import CloudVolume
d, labels, bits, out = sys.argv[1], [int(x) for x in sys.argv[2].split(',')], int(sys.argv[3]), sys.argv[4]
cv = CloudVolume('file://' + d, progress=False)
M = 2 ** bits - 1
res = np.array(cv.resolution, dtype=float)
result = {}
for label in labels:
    man = cv.mesh.get_manifest(label)
    origin = np.array(man.grid_origin, float)
    chunk = np.array(man.chunk_shape, float)
    per = {}
    for k in range(man.num_lods):
        m = cv.mesh.get(label, lod=k)[label]
        stored = np.asarray(m.vertices, float) / res
        n = np.rint((stored - origin) / (chunk * 2 ** k) * M).astype(np.int64)
        per[k] = n[np.asarray(m.faces)].reshape(-1, 9).tolist()
    result[label] = per
vol = np.asarray(cv[:, :, :])[..., 0]
open(out, 'wb').write(vol.tobytes(order='F'))
print(json.dumps({'triangles': result, 'dtype': str(vol.dtype)}))
"#;

/// A triangle as its corners' global lattice indices, rotated to start at its least corner.
fn canonical(t: [[u64; 3]; 3]) -> [u64; 9] {
    let r = (0..3).min_by_key(|&i| t[i]).unwrap_or(0);
    let c = [t[r], t[(r + 1) % 3], t[(r + 2) % 3]];
    std::array::from_fn(|i| c[i / 3][i % 3])
}

/// Our own reading of a label's level `lod`, as canonical sorted triangles.
fn ours(layer: &Path, label: u32, lod: usize) -> Vec<[u64; 9]> {
    let stored = read_mesh(layer, label as u64).unwrap();
    let max = (1u64 << stored.bits) - 1;
    let mut out: Vec<[u64; 9]> = Vec::new();
    for f in stored.fragments().unwrap().iter().filter(|f| f.lod == lod) {
        for t in &f.fragment.triangles {
            let corner = |v: u32| -> [u64; 3] {
                std::array::from_fn(|a| {
                    f.node[a] as u64 * max + f.fragment.positions[v as usize][a] as u64
                })
            };
            out.push(canonical(t.map(corner)));
        }
    }
    out.sort_unstable();
    out
}

/// Reads the layer back with cloud-volume and checks every label's every level and the labels.
fn check_with_cloud_volume(layer: &Path, options: &PrecomputedOptions) {
    let labels: Vec<String> = common::meshes()
        .iter()
        .map(|(l, _)| l.to_string())
        .collect();
    let volume = layer.with_extension("labels");
    let bits = options.quantization_bits.to_string();
    let labels = labels.join(",");
    let args: [&OsStr; 4] = [
        layer.as_os_str(),
        OsStr::new(&labels),
        OsStr::new(&bits),
        volume.as_os_str(),
    ];
    let Some(out) = run_python(CLOUD_VOLUME, &args) else {
        return;
    };
    let json: Value = serde_json::from_str(&out).unwrap();
    for (label, _) in common::meshes() {
        let per = &json["triangles"][label.to_string()];
        for lod in 0..options.lods {
            let theirs = per[lod.to_string()].as_array().unwrap();
            let mut theirs: Vec<[u64; 9]> = theirs
                .iter()
                .map(|t| {
                    let v: Vec<u64> = t
                        .as_array()
                        .unwrap()
                        .iter()
                        .map(|x| x.as_u64().unwrap())
                        .collect();
                    canonical([[v[0], v[1], v[2]], [v[3], v[4], v[5]], [v[6], v[7], v[8]]])
                })
                .collect();
            theirs.sort_unstable();
            let mine = ours(layer, label, lod);
            assert!(
                mine.len() > 100,
                "label {label} lod {lod}: {} triangles",
                mine.len()
            );
            assert_eq!(theirs.len(), mine.len(), "label {label} lod {lod}");
            assert!(
                theirs == mine,
                "label {label} lod {lod}: cloud-volume's triangles differ"
            );
        }
    }
    let bytes = std::fs::read(&volume).unwrap();
    let map = common::map();
    let read: Vec<u64> = match options.label_type {
        LabelType::Uint32 => bytes
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes(c.try_into().unwrap()) as u64)
            .collect(),
        LabelType::Uint64 => bytes
            .chunks_exact(8)
            .map(|c| u64::from_le_bytes(c.try_into().unwrap()))
            .collect(),
    };
    let expected: Vec<u64> = map.values.iter().map(|&v| v as u64).collect();
    assert!(read == expected, "cloud-volume reads other labels");
    let dtype = match options.label_type {
        LabelType::Uint32 => "uint32",
        LabelType::Uint64 => "uint64",
    };
    assert_eq!(json["dtype"], dtype);
}

#[test]
fn cloud_volume_reads_the_plain_layer_at_every_level() {
    let dir = tempfile::tempdir().unwrap();
    let layer = dir.path().join("layer");
    let options = PrecomputedOptions {
        sharding: Sharding::Never,
        ..common::options()
    };
    common::write(&layer, &options);
    check_with_cloud_volume(&layer, &options);
}

#[test]
fn cloud_volume_reads_a_layer_of_given_levels_at_every_level() {
    let dir = tempfile::tempdir().unwrap();
    let layer = dir.path().join("layer");
    let options = common::options();
    let levels = common::filtered_levels(options.lods as u32);
    write_layer_filtered(&layer, &common::map(), &levels, &options).unwrap();
    check_with_cloud_volume(&layer, &options);
}

#[test]
fn cloud_volume_reads_sharded_layers_with_either_hash_and_encoding() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            ShardHash::Murmurhash3X86_128,
            ShardEncoding::Gzip,
            LabelType::Uint32,
            16,
        ),
        (
            ShardHash::Identity,
            ShardEncoding::Raw,
            LabelType::Uint64,
            10,
        ),
    ];
    for (n, (hash, encoding, label_type, bits)) in cases.into_iter().enumerate() {
        let layer = dir.path().join(format!("layer{n}"));
        let options = PrecomputedOptions {
            sharding: Sharding::Always,
            shard_hash: hash,
            minishard_index_encoding: encoding,
            data_encoding: encoding,
            label_type,
            quantization_bits: bits,
            ..common::options()
        };
        let report = common::write(&layer, &options);
        assert!(report.sharding.is_some());
        check_with_cloud_volume(&layer, &options);
    }
}

/// Prints each fragment of a plain layer's label decoded by DracoPy: points and faces.
const DRACOPY: &str = r#"
import sys, json, numpy as np, DracoPy
from cloudvolume import CloudVolume
d, label = sys.argv[1], int(sys.argv[2])
man = CloudVolume('file://' + d, progress=False).mesh.get_manifest(label)
data = open(d + '/mesh/' + str(label), 'rb').read()
out, at = [], 0
for sizes in man.fragment_offsets:
    for s in sizes:
        s = int(s)
        if s == 0:
            out.append(None)
            continue
        m = DracoPy.decode(data[at:at + s])
        at += s
        out.append({'points': np.asarray(m.points).tolist(), 'faces': np.asarray(m.faces).tolist()})
print(json.dumps(out))
"#;

#[test]
fn dracopy_decodes_the_same_quantized_positions() {
    let dir = tempfile::tempdir().unwrap();
    let layer = dir.path().join("layer");
    common::write(&layer, &common::options());
    let Some(out) = run_python(DRACOPY, &[layer.as_os_str(), OsStr::new("7")]) else {
        return;
    };
    let theirs: Vec<Value> = serde_json::from_str(&out).unwrap();
    let mine = read_mesh(&layer, 7).unwrap().fragments().unwrap();
    assert_eq!(theirs.len(), mine.len());
    for (t, m) in theirs.iter().zip(&mine) {
        if t.is_null() {
            assert!(m.fragment.triangles.is_empty());
            continue;
        }
        let points: Vec<[u32; 3]> = t["points"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| std::array::from_fn(|a| p[a].as_f64().unwrap() as u32))
            .collect();
        let faces: Vec<[u32; 3]> = t["faces"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| std::array::from_fn(|a| f[a].as_u64().unwrap() as u32))
            .collect();
        assert_eq!(points, m.fragment.positions);
        assert_eq!(faces, m.fragment.triangles);
    }
}

#[test]
fn the_shard_hash_is_cloud_volume_s_murmurhash3() {
    let ids: [u64; 6] = [0, 1, 7, 300, (1 << 40) + 5, u64::MAX];
    let script = "
import numpy as np
from cloudvolume.datasource.precomputed import mmh3
for i in [0, 1, 7, 300, (1 << 40) + 5, 2 ** 64 - 1]:
    print(int(np.uint64(mmh3.hash64(np.uint64(i).tobytes(), x64arch=False)[0] % 2 ** 64)))
";
    let Some(out) = run_python(script, &[]) else {
        return;
    };
    let theirs: Vec<u64> = out.lines().map(|l| l.trim().parse().unwrap()).collect();
    let mine: Vec<u64> = ids.iter().map(|&i| sharding::murmur_hash(i)).collect();
    assert_eq!(theirs, mine);
}
