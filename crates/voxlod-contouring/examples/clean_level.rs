//! Times cleaning alone (`clean_mesh`) on one marching-cubes level of a mesh: the mesh is
//! sampled at one resolution (hyper-cone of one voxel, as `voxlod lod`'s level 0), contoured,
//! then cleaned several times; the best and median times are printed, with a checksum of the
//! cleaned mesh (positions, normals and triangles as bits) to compare two builds' outputs.
//!
//!     cargo run --release -p voxlod-contouring --example clean_level -- MESH.obj [RES] [RUNS]
//!
//! Without MESH (or if it is not an OBJ file that can be read) the sphereflake field at RES is
//! contoured instead. `RES` defaults to 256, `RUNS` to 5.

use std::hash::{Hash, Hasher};
use std::path::Path;
use std::time::Instant;

use voxlod_contouring::{clean_mesh, marching_cubes, CleanOptions, ContourOptions};
use voxlod_core::{TriangleMesh, Volume};
use voxlod_sampling::{filtered_density, plan_levels, Filter, MeshSolid, PyramidOptions, Solid};
use voxlod_testkit::fields::sphereflake_field;
use voxlod_testkit::readers::read_obj;

/// The level's density and iso value: the mesh sampled as `voxlod lod` samples a level, or the
/// sphereflake field.
fn level(mesh: Option<&str>, resolution: usize) -> (Volume, f32) {
    let Some(path) = mesh.filter(|p| p.ends_with(".obj") && Path::new(p).is_file()) else {
        return (sphereflake_field(resolution).expect("the field"), 0.0);
    };
    let solid = MeshSolid::new(&read_obj(Path::new(path))).expect("a mesh to sample");
    let pyramid = PyramidOptions::halving(resolution, 1, Filter::Hypercone);
    let plan = plan_levels(&solid.bounds(), &pyramid).expect("a plan")[0];
    let (volume, _) =
        filtered_density(&solid, &plan.grid, &plan.density_options(&pyramid)).expect("the density");
    (volume, 0.5)
}

/// A hash of every bit of the mesh.
fn checksum(mesh: &TriangleMesh) -> u64 {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    for p in mesh.positions.iter().chain(&mesh.normals) {
        p.to_array().map(f32::to_bits).hash(&mut h);
    }
    mesh.triangles.hash(&mut h);
    h.finish()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let resolution: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(256);
    let runs: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(5);
    let (volume, iso) = level(args.get(1).map(String::as_str), resolution);
    // With normals, as `voxlod lod` contours its levels (a merge averages them).
    let contour = ContourOptions {
        iso,
        normals: true,
        ..Default::default()
    };
    let mesh = marching_cubes(&volume, &contour).expect("marching cubes");
    let cell = volume.grid.spacing[0];
    let mut times = Vec::with_capacity(runs);
    let mut last = None;
    for _ in 0..runs.max(1) {
        let start = Instant::now();
        let cleaned = clean_mesh(&mesh, cell, &CleanOptions::default()).expect("cleaning");
        times.push(start.elapsed().as_secs_f64());
        last = Some(cleaned);
    }
    let (cleaned, report) = last.expect("one run at least");
    times.sort_by(f64::total_cmp);
    println!(
        "{} triangles -> {}; clean best {:.3} s, median {:.3} s over {} runs; checksum {:016x}",
        mesh.triangles.len(),
        cleaned.triangles.len(),
        times[0],
        times[times.len() / 2],
        times.len(),
        checksum(&cleaned)
    );
    println!("{report:?}");
}
