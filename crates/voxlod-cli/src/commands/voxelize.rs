//! `voxlod voxelize`: one level's filtered density, written as a volume.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use serde::Serialize;
use voxlod::io::{OutputSet, VolumeWriteOptions};
use voxlod::sampling::Filter;
use voxlod::VoxelizeOptions;

use super::common::say;
use super::common::{in_file, print_json, CliError};
use super::source::{in_flag_words, VolumeRoute};
use super::values::number;

/// Sample the input into a filtered density volume (paper §2, equations 1–3).
///
/// The inside function of a mesh (or of a thresholded volume) is low-pass filtered with the
/// hyper-cone or the Gaussian and sampled on a grid of RESOLUTION samples across the object's
/// longest side, padded so that the density is zero on the boundary. With --direct, a volume's
/// own values are filtered instead. The result can be contoured at any isodensity with
/// `voxlod contour`.
///
/// Examples:
///   voxlod voxelize bunny.obj -o bunny-128.nrrd --resolution 128
///   voxlod voxelize part.stl -o part.vti --resolution 200 --filter gaussian --radius 2
#[derive(Args, Debug)]
#[command(verbatim_doc_comment)]
pub struct VoxelizeArgs {
    /// The input mesh or volume
    pub input: PathBuf,
    /// Output volume (.nrrd .nhdr .vti .vtk .mha .mhd .raw)
    #[arg(short, long, value_name = "VOLUME")]
    pub output: PathBuf,
    /// Samples across the longest side of the object
    #[arg(long, value_name = "N", value_parser = number::<usize>, allow_hyphen_values = true)]
    pub resolution: usize,
    /// Low-pass filter: hypercone or gaussian
    #[arg(long, default_value = "hypercone")]
    pub filter: Filter,
    /// Filter support radius, in voxels
    #[arg(long, value_name = "VOXELS", default_value_t = 1.0,
        value_parser = number::<f64>, allow_hyphen_values = true)]
    pub radius: f64,
    /// Quadrature lines per filter radius
    #[arg(long, value_name = "Q", default_value_t = 4,
        value_parser = number::<usize>, allow_hyphen_values = true)]
    pub lines_per_radius: usize,
    /// Compress the output (gzip for NRRD, zlib for VTI and MetaImage)
    #[arg(long)]
    pub compress: bool,
    /// Print the report as JSON on standard output
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub route: VolumeRoute,
}

#[derive(Serialize)]
struct VoxelizeReport {
    input: String,
    output: String,
    /// Every file written: the volume, and the data file of a `.nhdr` or `.mhd`.
    files: Vec<String>,
    dims: [usize; 3],
    spacing: f64,
    radius: f64,
    filter: Filter,
    sample_seconds: f64,
    write_seconds: f64,
    /// Every warning printed without --json: an object the filter removed, a data file written
    /// under another name than usual.
    warnings: Vec<String>,
}

/// The library's options from the flags.
fn voxelize_options(args: &VoxelizeArgs) -> Result<VoxelizeOptions, CliError> {
    if args.resolution == 0 {
        return Err(CliError::usage("--resolution must be at least 1"));
    }
    if !(args.radius.is_finite() && args.radius > 0.0) {
        return Err(CliError::usage(
            "--radius must be a positive number of voxels",
        ));
    }
    Ok(VoxelizeOptions {
        resolution: args.resolution,
        filter: args.filter,
        radius_voxels: args.radius,
        lines_per_radius: args.lines_per_radius,
    })
}

pub fn run(args: VoxelizeArgs) -> Result<(), CliError> {
    let options = voxelize_options(&args)?;
    let mut out = OutputSet::protecting([&args.input]);
    out.check(&args.output)?;
    let input = args.route.read(&args.input)?;
    let voxelized = voxlod::voxelize(&args.route.source(&input), &options)
        .map_err(|e| in_file(&args.input, e))?;
    let start = Instant::now();
    out.volume(
        &args.output,
        &voxelized.volume,
        &VolumeWriteOptions {
            compress: args.compress,
        },
    )?;
    let files = out
        .files()
        .iter()
        .map(|f| f.display().to_string())
        .collect();
    let mut warnings: Vec<String> = voxelized
        .warnings
        .iter()
        .map(|w| in_flag_words(w))
        .collect();
    warnings.extend(out.warnings().iter().cloned());
    out.commit()?;
    let report = VoxelizeReport {
        input: args.input.display().to_string(),
        output: args.output.display().to_string(),
        files,
        dims: voxelized.plan.grid.dims,
        spacing: voxelized.plan.voxel_size,
        radius: voxelized.plan.radius,
        filter: args.filter,
        sample_seconds: voxelized.seconds,
        write_seconds: start.elapsed().as_secs_f64(),
        warnings,
    };
    if args.json {
        return print_json(&report);
    }
    print_report(&args, &report);
    Ok(())
}

/// The warnings on standard error and one line on standard output.
fn print_report(args: &VoxelizeArgs, report: &VoxelizeReport) {
    for w in &report.warnings {
        eprintln!("warning: {w}");
    }
    say(format_args!(
        "{}: {}x{}x{} samples of spacing {:.5}, {} radius {:.5}, in {:.2} s -> {}",
        args.input.display(),
        report.dims[0],
        report.dims[1],
        report.dims[2],
        report.spacing,
        args.filter.name(),
        report.radius,
        report.sample_seconds,
        args.output.display()
    ));
}
