//! `voxlod contour`: marching cubes on any volume file.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use serde::Serialize;
use voxlod::contouring::{marching_cubes, ContourOptions};
use voxlod::core::mesh_topology;

use super::common::say;
use super::common::{
    check_computed_mesh, check_grid_range, describe_mesh, print_json, read_input, CliError, Input,
    RawArgs,
};
use super::source::iso_without_surface;
use super::values::number;

/// Extract the isosurface of a volume with marching cubes.
///
/// A sample is inside when its value is >= ISO, everywhere, once; every grid edge carries at most
/// one vertex, shared by all its triangles; normals come from the data's gradient. A surface
/// that does not touch the volume's boundary comes out closed and consistently oriented (use
/// --close to make it so even when it does).
///
/// Examples:
///   voxlod contour level.nrrd -o surface.ply --iso 0.5
///   voxlod contour tooth.nrrd -o tooth.vtp --iso 120 --json
#[derive(Args, Debug)]
#[command(verbatim_doc_comment)]
pub struct ContourArgs {
    /// The volume (.nrrd .nhdr .vti .vtk .nii .nii.gz .mha .mhd, or raw with --dims)
    pub volume: PathBuf,
    /// Output mesh (.ply .obj .stl .vtp .vtk)
    #[arg(short, long, value_name = "MESH")]
    pub output: PathBuf,
    /// The iso value, in the data's units
    #[arg(long, value_name = "V", value_parser = number::<f32>, allow_hyphen_values = true)]
    pub iso: f32,
    /// Skip normals (geometry only, as VTK's Flying Edges computes by default)
    #[arg(long)]
    pub no_normals: bool,
    /// Pad the volume with one layer of samples below the iso value, so that surfaces touching
    /// the boundary are closed there
    #[arg(long)]
    pub close: bool,
    /// Print the report as JSON on standard output
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub raw: RawArgs,
}

#[derive(Serialize)]
struct ContourReport {
    input: String,
    output: String,
    dims: [usize; 3],
    iso: f32,
    vertices: usize,
    triangles: usize,
    euler_characteristic: i64,
    genus: Option<i64>,
    closed_manifold: bool,
    read_seconds: f64,
    contour_seconds: f64,
    write_seconds: f64,
    warnings: Vec<String>,
}

pub fn run(args: ContourArgs) -> Result<(), CliError> {
    let start = Instant::now();
    let mut out = voxlod::io::OutputSet::protecting([&args.volume]);
    out.check(&args.output)?;
    let volume = match read_input(&args.volume, &args.raw)? {
        Input::Volume(v) => v,
        Input::Mesh(_) => {
            return Err(CliError::msg(format!(
                "{}: this is a mesh; contour takes a volume",
                args.volume.display()
            )))
        }
    };
    let mut warnings = Vec::new();
    check_grid_range(&volume, &args.volume, args.raw.spacing_source())?;
    match iso_without_surface(args.iso, &volume, &args.volume)? {
        // With --close, an iso at or below every sample is the volume's box: say so.
        Some(_) if args.close && volume.range().is_some_and(|(lo, _)| args.iso <= lo) => warnings
            .push(format!(
                "--iso {} is at or below every sample: all of the volume is inside, so the \
                 surface is the box --close puts around it",
                args.iso
            )),
        Some(why) => return Err(CliError::msg(why)),
        None => {}
    }
    let volume = if args.close {
        pad_below(&volume, args.iso)?
    } else {
        volume
    };
    let read_seconds = start.elapsed().as_secs_f64();
    let start = Instant::now();
    let options = ContourOptions {
        iso: args.iso,
        normals: !args.no_normals,
        ..ContourOptions::default()
    };
    let mesh = marching_cubes(&volume, &options)
        .map_err(|e| CliError::msg(format!("{}: {e}", args.volume.display())))?;
    let contour_seconds = start.elapsed().as_secs_f64();
    check_computed_mesh(
        &mesh,
        &args.volume.display().to_string(),
        "the volume's spacing or origin is too large",
    )?;
    let start = Instant::now();
    out.mesh(&args.output, &mesh)?;
    out.commit()?;
    let write_seconds = start.elapsed().as_secs_f64();
    let topology = mesh_topology(&mesh);
    let report = ContourReport {
        input: args.volume.display().to_string(),
        output: args.output.display().to_string(),
        dims: volume.grid.dims,
        iso: args.iso,
        vertices: mesh.positions.len(),
        triangles: mesh.triangles.len(),
        euler_characteristic: topology.euler_characteristic,
        genus: topology.genus,
        closed_manifold: topology.is_closed_manifold() && topology.is_consistently_oriented(),
        read_seconds,
        contour_seconds,
        write_seconds,
        warnings,
    };
    if args.json {
        print_json(&report)?;
    } else {
        for w in &report.warnings {
            eprintln!("warning: {w}");
        }
        say(format_args!(
            "{}: {} ({}) in {:.3} s -> {}",
            args.volume.display(),
            describe_mesh(&mesh),
            if report.closed_manifold {
                "closed"
            } else {
                "open at the volume's boundary"
            },
            contour_seconds,
            args.output.display()
        ));
    }
    Ok(())
}

/// The volume with one more sample on every side, all below `iso`.
fn pad_below(volume: &voxlod::core::Volume, iso: f32) -> Result<voxlod::core::Volume, CliError> {
    let g = volume.grid;
    let dims = g.dims.map(|d| d + 2);
    let origin = [0, 1, 2].map(|a| g.origin[a] - g.spacing[a]);
    let grid = voxlod::core::Grid::new(dims, g.spacing, origin)?;
    let (lo, _) = volume.range().unwrap_or((iso, iso));
    let below = lo.min(iso) - 1.0;
    let mut padded = voxlod::core::Volume::filled(grid, below, "the padded volume")?;
    for k in 0..g.dims[2] {
        for j in 0..g.dims[1] {
            for i in 0..g.dims[0] {
                padded.values[[k + 1, j + 1, i + 1]] = volume.get(i, j, k);
            }
        }
    }
    Ok(padded)
}
