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
    std::fs::write(
        &info_path,
        info.replace("\"raw\"", "\"compressed_segmentation\""),
    )
    .unwrap();
    let error = read_labels(&layer).unwrap_err();
    assert!(
        error
            .to_string()
            .contains("encoding \"compressed_segmentation\": only raw chunks"),
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
