//! The Khronos glTF validator on our chains (plain and meshopt-compressed, and a chain of
//! lines and points): no errors, no warnings. Runs the peers' kit when present
//! (`voxlod_testkit::gltf_validator`); skips with a printed reason otherwise.

mod common;

use common::{chain_levels, lines_and_points, sphere_chain, two_cluster_levels};
use voxlod_gltf::{write_chain_glb, ChainOptions};
use voxlod_testkit::gltf_validator::validate_gltf;

fn assert_clean(path: &std::path::Path) {
    if let Some(v) = validate_gltf(path) {
        assert_eq!(
            (v.errors, v.warnings),
            (0, 0),
            "{}: {}",
            path.display(),
            v.report
        );
    }
}

#[test]
fn chains_pass_the_khronos_validator() {
    let chain = sphere_chain();
    let dir = tempfile::tempdir().unwrap();
    for (name, options) in [
        ("plain.glb", ChainOptions::default()),
        ("meshopt.glb", ChainOptions::meshopt()),
    ] {
        let path = dir.path().join(name);
        write_chain_glb(&path, &chain_levels(&chain), &options).unwrap();
        assert_clean(&path);
    }
}

#[test]
fn chains_of_lines_and_points_pass_the_khronos_validator() {
    let parts = lines_and_points();
    let levels = two_cluster_levels(&parts);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cluster.glb");
    write_chain_glb(&path, &levels, &ChainOptions::default()).unwrap();
    assert_clean(&path);
}
