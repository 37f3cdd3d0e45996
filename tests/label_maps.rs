//! The facade's label maps call and its glTF errors keep their class: a label asked for that
//! the map lacks is a usage error, a map of background alone bad input naming the file, a
//! corrupt `.glb` bad input and a missing one an I/O error, as for any other input file.

use voxlod::core::{Grid, Volume};
use voxlod::gltf::GltfError;
use voxlod::labels::LabelOptions;
use voxlod::{run_to_end, Error, ErrorClass};

/// A 6 × 6 × 6 map holding the 2 × 2 × 2 block of label 7 at indices 2..=3.
fn block_map() -> Volume {
    let grid = Grid::new([6, 6, 6], [1.0; 3], [0.0; 3]).unwrap();
    let values = (0..grid.len())
        .map(|n| [n % 6, n / 6 % 6, n / 36])
        .map(|at| {
            if at.iter().all(|a| (2..4).contains(a)) {
                7.0
            } else {
                0.0
            }
        })
        .collect();
    Volume::from_vec(grid, values).unwrap()
}

#[test]
fn labels_meshes_the_map_and_its_failures_keep_their_class() {
    let map = block_map();
    let meshes = voxlod::labels(&map, &LabelOptions::default(), &run_to_end).unwrap();
    assert_eq!(meshes.labels.len(), 1);
    assert_eq!(
        (meshes.labels[0].label.value, meshes.labels[0].label.voxels),
        (7, 8)
    );
    assert!(meshes.labels[0].levels[0].topology.is_closed_manifold());

    let missing = LabelOptions {
        labels: Some(vec![7, 9]),
        ..LabelOptions::default()
    };
    let e = voxlod::labels(&map, &missing, &run_to_end).unwrap_err();
    assert_eq!(e.class(), ErrorClass::Usage, "{e}");
    assert!(
        matches!(e.root(), Error::InvalidOption(o) if o.option == "labels"),
        "{e:?}"
    );

    let grid = Grid::new([4, 4, 4], [1.0; 3], [0.0; 3]).unwrap();
    let background = Volume::filled(grid, 0.0, "background").unwrap();
    let path = std::path::Path::new("empty.nrrd");
    let e = voxlod::labels(&background, &LabelOptions::default(), &run_to_end)
        .map_err(|e| e.in_file(path))
        .unwrap_err();
    assert_eq!(e.class(), ErrorClass::BadInput);
    assert_eq!(
        e.to_string(),
        "empty.nrrd: the map holds no label other than 0"
    );
}

#[test]
fn a_corrupt_glb_is_bad_input_and_a_missing_one_an_io_error_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let corrupt = dir.path().join("corrupt.glb");
    std::fs::write(&corrupt, b"glTF not really").unwrap();
    let e = voxlod::read_glb(&corrupt).unwrap_err();
    assert_eq!(e.class(), ErrorClass::BadInput, "{e}");
    assert!(e.to_string().contains("corrupt.glb"), "{e}");

    let missing = dir.path().join("missing.glb");
    let e = voxlod::read_glb(&missing).unwrap_err();
    assert_eq!(e.class(), ErrorClass::Io, "{e}");
    assert!(matches!(&e, Error::Io(io) if io.path == missing), "{e:?}");

    let e = Error::from(GltfError::InvalidParameter {
        what: "pixel size",
        value: -1.0,
    });
    assert_eq!(e.class(), ErrorClass::Usage);
    let e = Error::from(GltfError::Invalid("no buffer".into()));
    assert_eq!(e.class(), ErrorClass::BadInput);
}
