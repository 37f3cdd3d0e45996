//! `voxlod contour`: marching cubes on any volume file, through the library's
//! [`voxlod::contour`]: the flags in, the volume read, the surface written in the scan's world
//! (its spacing, origin and orientation, as `lod` places its levels) and reported.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use serde::Serialize;
use voxlod::core::Volume;
use voxlod::io::OutputSet;
use voxlod::ContourOptions;

use super::common::say;
use super::common::{
    check_grid_range, describe_mesh, in_file, print_json, read_input, CliError, Input, RawArgs,
};
use super::values::number;
use super::world::{frame_report, FrameArg, FrameReport};

/// Extract the isosurface of a volume with marching cubes.
///
/// A sample is inside when its value is >= ISO, everywhere, once; every grid edge carries at most
/// one vertex, shared by all its triangles; normals come from the data's gradient. A surface
/// that does not touch the volume's boundary comes out closed and consistently oriented (use
/// --close to make it so even when it does). The mesh is in the scan's world, in millimetres
/// for a CT, oblique and flipped scans included, in the file's own frame (--frame converts).
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
    #[command(flatten)]
    pub frame: FrameArg,
}

#[derive(Serialize)]
struct ContourReport {
    input: String,
    output: String,
    /// Samples contoured (the padded volume's with --close).
    dims: [usize; 3],
    iso: f32,
    /// The frame of the mesh (lps, ras, unknown) and the input's index-to-world matrix in it.
    #[serde(flatten)]
    frame: FrameReport,
    vertices: usize,
    triangles: usize,
    euler_characteristic: i64,
    genus: Option<i64>,
    closed_manifold: bool,
    read_seconds: f64,
    /// The whole contouring: checks of the data and the mesh, marching cubes, topology.
    contour_seconds: f64,
    /// Marching cubes alone.
    marching_cubes_seconds: f64,
    write_seconds: f64,
    /// Every warning printed without --json: an iso value at or below every sample with --close.
    warnings: Vec<String>,
}

pub fn run(args: ContourArgs) -> Result<(), CliError> {
    let start = Instant::now();
    let mut out = OutputSet::protecting([&args.volume]);
    out.check(&args.output)?;
    let volume = read_volume(&args)?;
    let read_seconds = start.elapsed().as_secs_f64();
    let options = ContourOptions {
        iso: args.iso,
        normals: !args.no_normals,
        close: args.close,
    };
    let mut surface = voxlod::contour(&volume, &options).map_err(|e| contour_error(&args, e))?;
    args.frame.convert(&volume, &mut surface.mesh);
    let start = Instant::now();
    out.mesh(&args.output, &surface.mesh)?;
    out.commit()?;
    let write_seconds = start.elapsed().as_secs_f64();
    let topology = &surface.topology;
    let report = ContourReport {
        input: args.volume.display().to_string(),
        output: args.output.display().to_string(),
        dims: surface.dims,
        iso: args.iso,
        frame: frame_report(volume.world(), args.frame.target()),
        vertices: surface.mesh.positions.len(),
        triangles: surface.mesh.triangles.len(),
        euler_characteristic: topology.euler_characteristic,
        genus: topology.genus,
        closed_manifold: topology.is_closed_manifold() && topology.is_consistently_oriented(),
        read_seconds,
        contour_seconds: surface.seconds,
        marching_cubes_seconds: surface.marching_cubes_seconds,
        write_seconds,
        warnings: surface.warnings.iter().map(|w| in_flag_words(w)).collect(),
    };
    if args.json {
        return print_json(&report);
    }
    for w in &report.warnings {
        eprintln!("warning: {w}");
    }
    say(format_args!(
        "{}: {} ({}) in {:.3} s -> {}",
        args.volume.display(),
        describe_mesh(&surface.mesh),
        if report.closed_manifold {
            "closed"
        } else {
            "open at the volume's boundary"
        },
        report.contour_seconds,
        args.output.display()
    ));
    Ok(())
}

/// Reads the input volume, refusing a mesh, samples beyond 32-bit mesh coordinates (blaming the
/// header or the raw flags) and a --frame the file cannot be converted to.
fn read_volume(args: &ContourArgs) -> Result<Volume, CliError> {
    let volume = match read_input(&args.volume, &args.raw)? {
        Input::Volume(v) => v,
        Input::Mesh(_) => {
            return Err(CliError::msg(format!(
                "{}: this is a mesh; contour takes a volume",
                args.volume.display()
            )))
        }
    };
    check_grid_range(&volume, &args.volume, args.raw.spacing_source())?;
    args.frame.check(volume.orientation.frame, &args.volume)?;
    Ok(volume)
}

/// A library failure about the input, with its options named as the flags (`--iso`,
/// `--close`), keeping its class and so its exit status.
fn contour_error(args: &ContourArgs, e: voxlod::Error) -> CliError {
    match e {
        voxlod::Error::Pyramid(voxlod::PyramidError::IsoOutsideData { .. }) => {
            CliError::msg(format!(
                "{}: {}",
                args.volume.display(),
                in_flag_words(&e.to_string())
            ))
        }
        e => in_file(&args.volume, e),
    }
}

/// A library message in the command line's words: the options of [`ContourOptions`] named as
/// the flags.
fn in_flag_words(text: &str) -> String {
    text.replace("`iso`", "--iso").replace("`close`", "--close")
}
