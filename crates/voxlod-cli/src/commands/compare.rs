//! `voxlod compare`: how far apart the surfaces of two meshes are.

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;
use serde::Serialize;
use voxlod::core::TriangleMesh;
use voxlod::metrics::{mesh_distance, DistanceOptions, DistanceReport, MetricsError};

use super::common::say;
use super::common::{print_json, read_mesh_input, thousands, CliError};
use super::values::number;

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
    /// The first mesh (.obj .ply .stl .off .vtp .vtk)
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
    if args.samples == 0 {
        return Err(CliError::usage("--samples must be at least 1"));
    }
    let (a, b) = rayon::join(|| read_mesh_input(&args.a), || read_mesh_input(&args.b));
    let (a, b) = (a?.mesh, b?.mesh);
    let read_seconds = start.elapsed().as_secs_f64();
    let mut options = DistanceOptions::with_samples(args.samples);
    if let Some(seed) = args.seed {
        options.seed = seed;
    }
    let distance =
        mesh_distance(&a, &b, &options).map_err(|e| naming_the_file(e, &args.a, &args.b))?;
    let report = CompareReport {
        a: args.a.display().to_string(),
        b: args.b.display().to_string(),
        a_triangles: a.triangles.len(),
        b_triangles: b.triangles.len(),
        distance,
        read_seconds,
        total_seconds: start.elapsed().as_secs_f64(),
        warnings: frame_warnings(&a, &b),
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

/// The metrics' "first mesh: …" errors, with the file's name instead.
fn naming_the_file(error: MetricsError, a: &Path, b: &Path) -> CliError {
    match error {
        MetricsError::InMesh { which, source } => {
            let path = if which == "first" { a } else { b };
            CliError::msg(format!("{}: {source}", path.display()))
        }
        other => CliError::msg(other.to_string()),
    }
}

/// Signs that the two meshes are not in the same frame or units.
fn frame_warnings(a: &TriangleMesh, b: &TriangleMesh) -> Vec<String> {
    let (ba, bb) = (a.bounds(), b.bounds());
    let mut warnings = Vec::new();
    let disjoint = (0..3).any(|k| ba.max[k] < bb.min[k] || bb.max[k] < ba.min[k]);
    if disjoint {
        warnings.push(
            "the two meshes' bounding boxes do not overlap: are they in the same frame?".into(),
        );
    }
    let (da, db) = (ba.diagonal(), bb.diagonal());
    if da > 0.0 && db > 0.0 && (da / db).max(db / da) > 10.0 {
        warnings.push(format!(
            "the two meshes differ in size by a factor of {:.0} (diagonals {da:.4e} and \
             {db:.4e}): are they in the same units?",
            (da / db).max(db / da)
        ));
    }
    warnings
}
