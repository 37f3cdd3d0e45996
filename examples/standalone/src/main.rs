//! Levels of detail of a mesh file with the library's one call, printed one line per level.
//!
//! Usage: `cargo run --release -- path/to/mesh.obj`

use std::process::ExitCode;

fn main() -> ExitCode {
    let Some(path) = std::env::args_os().nth(1) else {
        eprintln!("usage: voxlod-standalone MESH (.obj .ply .stl .off .vtp .vtk)");
        return ExitCode::from(2);
    };
    match run(path.as_ref()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e} ({:?})", e.class());
            ExitCode::FAILURE
        }
    }
}

fn run(path: &std::path::Path) -> Result<(), voxlod::Error> {
    let mesh = voxlod::read_mesh(path)?;
    println!("{}: {} triangles", path.display(), mesh.triangle_count());
    let lod = voxlod::lod(
        &voxlod::Source::Mesh(&mesh),
        &voxlod::LodOptions::default(),
    )?;
    for (k, level) in lod.levels.iter().enumerate() {
        let genus = level
            .topology
            .genus
            .map_or("-".to_string(), |g| g.to_string());
        println!(
            "level {k}: resolution {:>3}, {:>8} triangles, genus {genus}",
            level.resolution,
            level.mesh.triangle_count(),
        );
    }
    Ok(())
}
