//! The main job as a library call: levels of detail of a mesh, each written to a PLY file.
//!
//!     cargo run --release -p voxlod --example lod_chain -- data/holed-block.obj /tmp/block-lods
//!
//! Builds six levels from 128 with the hyper-cone filter and prints each level's resolution,
//! triangle count and genus.

use std::path::PathBuf;

use voxlod::lod::{build_level, plan, LevelOptions, LodSource};
use voxlod::sampling::{Filter, MeshSolid, PyramidOptions};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let input = PathBuf::from(args.next().unwrap_or_else(|| "data/holed-block.obj".into()));
    let output = PathBuf::from(args.next().unwrap_or_else(|| "lod-chain".into()));
    std::fs::create_dir_all(&output)?;

    let mesh = voxlod::io::read_mesh(&input)?.mesh;
    let solid = MeshSolid::new(&mesh)?;
    let source = LodSource::Solid(&solid);
    let options = LevelOptions {
        pyramid: PyramidOptions::halving(128, 6, Filter::Hypercone),
        ..Default::default()
    };
    for level_plan in plan(&source, &options)? {
        let level = build_level(&source, &level_plan, &options)?;
        let path = output.join(format!("level-{}.ply", level_plan.level));
        if !level.mesh.is_empty() {
            voxlod::io::write_mesh(&path, &level.mesh)?;
        }
        println!(
            "level {} at {:>3}: {:>7} triangles, genus {:?}",
            level_plan.level,
            level_plan.resolution,
            level.mesh.triangles.len(),
            level.topology.genus
        );
    }
    Ok(())
}
