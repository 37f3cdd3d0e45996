//! A build that cannot fit in the memory allowed is refused before it allocates. (Its own test
//! binary: the limit is read from the process environment.)

mod common;

use voxlod_metrics::{mesh_distance, DistanceOptions, MeshDistance};

#[test]
fn refuses_a_search_structure_beyond_the_memory_limit() {
    std::env::set_var("VOXLOD_MAX_MEMORY", "1K");
    let torus = common::torus(40, 20); // 1600 triangles: about 320 KB to build
    let message = MeshDistance::new(&torus).err().unwrap().to_string();
    assert!(
        message.starts_with("the closest-point search structure for 1600 triangles would need"),
        "{message}"
    );
    let message = mesh_distance(&torus, &torus, &DistanceOptions::quick())
        .unwrap_err()
        .to_string();
    assert!(
        message.starts_with("first mesh: the closest-point"),
        "{message}"
    );
}
