//! `voxlod voxelize`: one level's filtered density, written as a volume.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use serde::Serialize;
use voxlod::sampling::{DensityOptions, Filter};

use super::common::{print_json, CliError};
use super::source::{load, threshold_warning, Prepared, VolumeRoute};
use super::values::number;
use voxlod::lod::LodSource;

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

pub fn run(args: VoxelizeArgs) -> Result<(), CliError> {
    if args.resolution == 0 {
        return Err(CliError::usage("--resolution must be at least 1"));
    }
    if !(args.radius.is_finite() && args.radius > 0.0) {
        return Err(CliError::msg(
            "--radius must be a positive number of voxels",
        ));
    }
    let mut out = voxlod::io::OutputSet::protecting([&args.input]);
    out.check(&args.output)?;
    let loaded = load(&args.input, &args.route)?;
    let prepared = Prepared::new(&loaded, &args.route, &args.input)?;
    let source = prepared.source();
    let bounds = source.bounds();
    let in_file = |e: voxlod::sampling::SamplingError| super::common::in_file(&args.input, e);
    let plans = voxlod::sampling::plan_levels(
        &bounds,
        &voxlod::sampling::PyramidOptions {
            resolutions: vec![args.resolution],
            radius_voxels: args.radius,
            filter: args.filter,
            lines_per_radius: args.lines_per_radius,
        },
    )
    .map_err(in_file)?;
    let (grid, voxel, radius) = (plans[0].grid, plans[0].voxel_size, plans[0].radius);
    let start = Instant::now();
    let density = match source {
        LodSource::Solid(solid) => {
            let options = DensityOptions {
                filter: args.filter,
                radius,
                lines_per_radius: args.lines_per_radius,
            };
            voxlod::sampling::filtered_density(solid, &grid, &options)
                .map_err(in_file)?
                .0
        }
        LodSource::Direct(volume) => {
            voxlod::sampling::direct_density(volume, &grid, args.filter, radius).map_err(in_file)?
        }
    };
    let sample_seconds = start.elapsed().as_secs_f64();
    let mut warnings: Vec<String> = threshold_warning(&loaded, &args.route)
        .into_iter()
        .collect();
    let solid = matches!(source, LodSource::Solid(_));
    if solid && density.range().is_none_or(|(_, hi)| hi < 0.5) {
        warnings.push(format!(
            "the filter of radius {radius:.4} removed the whole object: no sample reaches the \
             density 0.5 of its surface (the object is thinner than the filter; use a higher \
             --resolution)"
        ));
    }
    let start = Instant::now();
    out.volume(
        &args.output,
        &density,
        &voxlod::io::VolumeWriteOptions {
            compress: args.compress,
        },
    )?;
    let files = out
        .files()
        .iter()
        .map(|f| f.display().to_string())
        .collect();
    warnings.extend(out.warnings().iter().cloned());
    out.commit()?;
    let report = VoxelizeReport {
        input: args.input.display().to_string(),
        output: args.output.display().to_string(),
        files,
        dims: grid.dims,
        spacing: voxel,
        radius,
        filter: args.filter,
        sample_seconds,
        write_seconds: start.elapsed().as_secs_f64(),
        warnings,
    };
    if args.json {
        print_json(&report)?;
    } else {
        for w in &report.warnings {
            eprintln!("warning: {w}");
        }
        println!(
            "{}: {}x{}x{} samples of spacing {:.5}, {} radius {:.5}, in {:.2} s -> {}",
            args.input.display(),
            grid.dims[0],
            grid.dims[1],
            grid.dims[2],
            voxel,
            args.filter.name(),
            radius,
            sample_seconds,
            args.output.display()
        );
    }
    Ok(())
}
