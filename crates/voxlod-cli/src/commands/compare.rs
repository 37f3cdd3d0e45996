//! `voxlod compare`: how far apart the surfaces of two meshes are.

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;
use serde::Serialize;
use voxlod::metrics::{DistanceReport, MetricsError};
use voxlod::CompareOptions;

use super::common::say;
use super::common::{print_json, read_mesh_input, thousands, CliError};
use super::values::{in_flags, number};

/// Measure the two-sided distance between the surfaces of two meshes.
///
/// Both surfaces are sampled area-uniformly (stratified, seeded: the same files give the same
/// figures on any machine and thread count) and every sample's exact distance to the other mesh
/// is found through a BVH. Prints the Hausdorff distance (the largest sample distance in either
/// direction, a lower bound of the true one that tightens with --samples), the mean and the RMS
/// distance over the samples of both sides, each also as a percentage of the diagonal of the
/// box enclosing both meshes, and the two one-sided maxima.
///
/// Examples:
///   voxlod compare bunny.obj bunny-lods/level-2.ply
///   voxlod compare a.ply b.ply --samples 1000000 --json
#[derive(Args, Debug)]
#[command(verbatim_doc_comment)]
pub struct CompareArgs {
    /// The first mesh (.obj .ply .stl .off .vtp .vtu .vtk; a glTF file .glb .gltf as its scene's
    /// geometry)
    pub a: PathBuf,
    /// The second mesh
    pub b: PathBuf,
    /// Points sampled on each surface
    #[arg(long, value_name = "N", default_value_t = 100_000,
        value_parser = number::<usize>, allow_hyphen_values = true)]
    pub samples: usize,
    /// Seed of the samples (the second surface uses the next one)
    #[arg(long, value_name = "S", value_parser = number::<u64>, allow_hyphen_values = true)]
    pub seed: Option<u64>,
    /// Print the report as JSON on standard output
    #[arg(long)]
    pub json: bool,
}

#[derive(Serialize)]
struct CompareReport {
    a: String,
    b: String,
    a_triangles: usize,
    b_triangles: usize,
    #[serde(flatten)]
    distance: DistanceReport,
    /// Reading both files (in parallel).
    read_seconds: f64,
    /// Reading and measuring.
    total_seconds: f64,
    warnings: Vec<String>,
}

pub fn run(args: CompareArgs) -> Result<(), CliError> {
    let start = Instant::now();
    let (a, b) = rayon::join(|| read_mesh_input(&args.a), || read_mesh_input(&args.b));
    let (a, b) = (a?.mesh, b?.mesh);
    let read_seconds = start.elapsed().as_secs_f64();
    let mut options = CompareOptions::for_samples(args.samples);
    if let Some(seed) = args.seed {
        options.distance.seed = seed;
    }
    let comparison =
        voxlod::compare(&a, &b, &options).map_err(|e| naming_the_file(e, &args.a, &args.b))?;
    let report = CompareReport {
        a: args.a.display().to_string(),
        b: args.b.display().to_string(),
        a_triangles: a.triangles.len(),
        b_triangles: b.triangles.len(),
        distance: comparison.distance,
        read_seconds,
        total_seconds: start.elapsed().as_secs_f64(),
        warnings: comparison.warnings,
    };
    if args.json {
        return print_json(&report);
    }
    for w in &report.warnings {
        eprintln!("warning: {w}");
    }
    say(format_args!(
        "{} ({} triangles) and {} ({} triangles):",
        report.a,
        thousands(report.a_triangles),
        report.b,
        thousands(report.b_triangles)
    ));
    say(format_args!("{}", report.distance));
    Ok(())
}

/// The library's failure with the file's name in place of the metrics' "first mesh" or
/// "second mesh", and `--samples` for its option.
fn naming_the_file(error: voxlod::Error, a: &Path, b: &Path) -> CliError {
    match error {
        voxlod::Error::Metrics(MetricsError::InMesh { which, source }) => {
            let path = if which == "first" { a } else { b };
            CliError::Library(voxlod::Error::Metrics(*source).in_file(path))
        }
        other => in_flags(other, &[("samples_per_side", "--samples")]),
    }
}
