//! A layer's labels read back as they were written (`read_labels`), placed in nanometres, and
//! what cannot be read refused naming the file.

mod common;

use voxlod_precomputed::{read_labels, LabelType, PrecomputedError};

#[test]
fn a_written_layer_reads_back_its_labels_in_nanometres() {
    let dir = tempfile::tempdir().unwrap();
    let layer = dir.path().join("layer");
    for label_type in [LabelType::Uint32, LabelType::Uint64] {
        let mut options = common::options();
        options.label_type = label_type;
        options.chunk = [7, 5, 6]; // chunks cut short at the map's far sides
        options.nanometres_per_unit = 4.0;
        let map = common::map();
        voxlod_precomputed::write_layer(&layer, &map, &common::meshes(), &options).unwrap();
        let back = read_labels(&layer).unwrap();
        assert_eq!(back.values, map.values);
        assert_eq!(back.grid.dims, map.grid.dims);
        let nm = map.grid.spacing.map(|s| s * 4.0);
        assert_eq!(back.grid.spacing, nm);
        // The origin: the voxel offset (the map's origin in voxels, rounded) in nanometres.
        let origin: [f64; 3] =
            std::array::from_fn(|a| (map.grid.origin[a] / map.grid.spacing[a]).round() * nm[a]);
        assert_eq!(back.grid.origin, origin);
    }
}

#[test]
fn other_encodings_and_missing_chunks_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let layer = dir.path().join("layer");
    voxlod_precomputed::write_layer(
        &layer,
        &common::map(),
        &common::meshes(),
        &common::options(),
    )
    .unwrap();
    let info_path = layer.join("info");
    let info = std::fs::read_to_string(&info_path).unwrap();
    std::fs::write(&info_path, info.replace("\"raw\"", "\"jpeg\"")).unwrap();
    let error = read_labels(&layer).unwrap_err();
    assert!(
        error
            .to_string()
            .contains("encoding \"jpeg\": labels are read from raw or compressed_segmentation"),
        "{error}"
    );
    std::fs::write(&info_path, info).unwrap();
    let scale = std::fs::read_dir(&layer)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.is_dir() && !p.ends_with("mesh"))
        .unwrap();
    let chunk = std::fs::read_dir(&scale)
        .unwrap()
        .next()
        .unwrap()
        .unwrap()
        .path();
    std::fs::remove_file(&chunk).unwrap();
    match read_labels(&layer).unwrap_err() {
        PrecomputedError::Io { path, .. } => assert_eq!(path, chunk),
        other => panic!("{other}"),
    }
}

#[test]
fn a_compressed_segmentation_layer_written_by_cloud_volume_reads_back() {
    let dir = tempfile::tempdir().unwrap();
    let layer = dir.path().join("cseg");
    // A 20 x 17 x 9 map of labels (some above 2^24) in 8 x 8 x 8 chunks of 4 x 4 2 blocks
    // (uint64, as connectomics layers hold them), written by cloud-volume; its labels printed.
    let script = r#"
import sys, numpy as np
from cloudvolume import CloudVolume
x, y, z = np.mgrid[0:20, 0:17, 0:9]
labels = ((x // 3) * 7 + (y // 5) * 20_000_000 + (z // 4)).astype(np.uint64)
labels[x + y < 6] = 0
info = CloudVolume.create_new_info(num_channels=1, layer_type="segmentation", data_type="uint64",
    encoding="compressed_segmentation", resolution=[4, 4, 40], voxel_offset=[3, -2, 5],
    chunk_size=[8, 8, 8], volume_size=[20, 17, 9], compressed_segmentation_block_size=[4, 4, 2])
cv = CloudVolume("file://" + sys.argv[1], info=info, progress=False)
cv.commit_info()
cv[:, :, :] = labels[..., None]
print(" ".join(str(v) for v in labels.ravel(order="F")))
"#;
    let Some(out) = voxlod_testkit::peers::run_python(script, &[layer.as_os_str()]) else {
        return;
    };
    let expected: Vec<u32> = out.split_whitespace().map(|v| v.parse().unwrap()).collect();
    let back = read_labels(&layer).unwrap();
    assert_eq!(back.grid.dims, [20, 17, 9]);
    assert_eq!(back.grid.origin, [12.0, -8.0, 200.0]);
    assert_eq!(back.values, expected);
}
