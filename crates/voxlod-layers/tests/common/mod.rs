//! Shared inputs of the layers tests: the bolt and (when the shared data is there) the bunny,
//! filtered and layered.

#![allow(dead_code)]

use voxlod_layers::bolt;
use voxlod_layers::{layer_solid, Layered, LayersOptions};
use voxlod_sampling::{CsgSolid, MeshSolid};

pub fn layered_bolt(resolution: usize) -> Layered {
    let solid = CsgSolid::new(bolt()).unwrap();
    layer_solid(
        &solid,
        &LayersOptions {
            resolution,
            ..Default::default()
        },
    )
    .unwrap()
}

pub fn bunny_solid(test: &str) -> Option<MeshSolid> {
    let path = voxlod_testkit::data::shared_data_or_skip("meshes/stanford-bunny.obj", test)?;
    let mesh = voxlod_io::read_mesh(&path).unwrap().mesh;
    Some(MeshSolid::new(&mesh).unwrap())
}

pub fn layered_bunny(resolution: usize, test: &str) -> Option<Layered> {
    let solid = bunny_solid(test)?;
    Some(
        layer_solid(
            &solid,
            &LayersOptions {
                resolution,
                ..Default::default()
            },
        )
        .unwrap(),
    )
}
