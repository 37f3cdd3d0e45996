//! `voxlod envelope`: simplification envelopes (Varshney, Agarwal, Brooks, Wright, Weber 1995),
//! ε-bounded, topology-preserving levels of detail; and the `--then-envelope` step of `voxlod lod`.

use std::path::PathBuf;
use std::sync::Mutex;
use std::time::Instant;

use clap::Args;
use serde::Serialize;
use voxlod::core::TriangleMesh;
use voxlod::envelope::{
    EnvelopeLevel, EnvelopeOptions, EnvelopeReport, Epsilon, ManifoldRepair, OffsetRule,
    RegionEpsilon, RemovalOrder,
};
use voxlod::io::OutputSet;
use voxlod::{Control, EnvelopeSeries, EnvelopeSeriesOptions, Event, Progress};

use super::common::say;
use super::common::{level_path, print_json, progress, read_mesh_input, thousands, CliError};
use super::values::{in_flags, number};

/// Simplify a mesh within ε by simplification envelopes, keeping its topology.
///
/// Every point of a level lies within ε of the input and every point of the input within ε of
/// the level; genus, components and holes stay; the level's vertices are input vertices. The
/// input is offset by up to ε outwards and inwards along its normals (shrunk where an offset
/// would cross itself), and vertices are removed, largest covering triangle first, as long as
/// the retriangulated hole stays between the two offsets (paper §4, §6, §7).
///
/// ε is a distance in the mesh's units (0.5) or a percentage of its bounding-box diagonal (1%).
/// With --levels, level i simplifies level i-1, each within its own ε of the input, and OUT's
/// name gets the level: out.ply -> out-0.ply, out-1.ply, ...
///
/// Border vertices are kept (the border stays exact). The input must be a consistently
/// oriented manifold; the error names the edges that are not, and --repair cuts the mesh into
/// one without moving any point.
///
/// Examples:
///   voxlod envelope bunny.obj -o bunny-1.ply --epsilon 1%
///   voxlod envelope part.stl -o part.ply --levels 1%,2%,4%,8% --keep-sharp 60 --json
///   voxlod envelope bunny.obj -o bunny-lod.ply --levels 1%,2%,4%,8% --preset tight
///   voxlod envelope scan.ply -o scan-lod.ply --epsilon 0.2 --region 0,0,0,1,1,1:0.25
#[derive(Args, Debug)]
#[command(verbatim_doc_comment)]
pub struct EnvelopeArgs {
    /// The input mesh
    pub input: PathBuf,
    /// Output mesh (.ply .obj .stl .vtp .vtk)
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    /// ε of a single level: a distance, or a percentage of the bounding-box diagonal (1%)
    #[arg(long, value_name = "E", required_unless_present = "levels", conflicts_with = "levels",
        value_parser = epsilon_value, allow_hyphen_values = true)]
    pub epsilon: Option<Epsilon>,
    /// A series of levels with growing ε, each simplifying the one before, e.g. 1%,2%,4%,8%
    #[arg(long, value_name = "E,E,...", value_delimiter = ',',
        value_parser = epsilon_value, allow_hyphen_values = true)]
    pub levels: Option<Vec<Epsilon>>,
    /// Keep every edge whose dihedral angle exceeds DEG degrees (sharp features)
    #[arg(long, value_name = "DEG", value_parser = number::<f64>, allow_hyphen_values = true)]
    pub keep_sharp: Option<f64>,
    /// A box whose ε is SCALE times the level's (repeatable; the last box containing a vertex
    /// wins), e.g. -0.2,-0.2,0,0.2,0.2,1:0.25
    #[arg(long, value_name = "X0,Y0,Z0,X1,Y1,Z1:SCALE",
        value_parser = |s: &str| s.parse::<RegionEpsilon>(), allow_hyphen_values = true)]
    pub region: Vec<RegionEpsilon>,
    /// Cut a non-manifold or inconsistently oriented input into a manifold first
    #[arg(long)]
    pub repair: bool,
    /// paper (the default: the paper's order and offsets) or tight (offsets along smoothed
    /// normals, shrunk only where they cross, smallest deviation first: same guarantees, far
    /// fewer triangles at coarse levels, faster)
    #[arg(long, default_value = "paper", value_parser = ["paper", "tight"])]
    pub preset: String,
    /// Which removal first: coverage (the paper's: the new triangle covering the most input
    /// vertices) or deviation (the smallest distance from the input); overrides the preset
    #[arg(long, value_parser = ["coverage", "deviation"])]
    pub order: Option<String>,
    /// Offsets limited by the Voronoi test of §4.3 (voronoi) or only where they cross
    /// themselves (crossings); overrides the preset
    #[arg(long, value_parser = ["voronoi", "crossings"])]
    pub offsets: Option<String>,
    /// Rounds of smoothing of the normals the offsets follow (0: raw); overrides the preset
    #[arg(long, value_name = "ROUNDS", value_parser = number::<usize>, allow_hyphen_values = true)]
    pub smooth_normals: Option<usize>,
    /// Points per side for measuring each level's two-sided distance to the input (0: skip)
    #[arg(long, value_name = "N", default_value_t = 100_000,
        value_parser = number::<usize>, allow_hyphen_values = true)]
    pub samples: usize,
    /// Print the report as JSON on standard output
    #[arg(long)]
    pub json: bool,
}

#[derive(Serialize)]
struct LevelOut {
    #[serde(flatten)]
    report: EnvelopeReport,
    /// ε in percent of the bounding-box diagonal.
    epsilon_percent: f64,
    file: String,
    write_seconds: f64,
}

#[derive(Serialize)]
struct Report {
    input: String,
    input_vertices: usize,
    input_triangles: usize,
    repair: Option<ManifoldRepair>,
    options: EnvelopeOptions,
    levels: Vec<LevelOut>,
    total_seconds: f64,
    /// Every warning printed without --json (what --repair changed).
    warnings: Vec<String>,
}

/// The value parser of ε flags: a distance or a percentage (the error without the flag).
pub fn epsilon_value(text: &str) -> Result<Epsilon, String> {
    text.parse::<Epsilon>().map_err(|_| {
        format!(
            "'{text}': ε must be a positive distance (0.5) or percentage of the bounding-box \
             diagonal (1%)"
        )
    })
}

/// The library's options from the flags, refused before any work when out of range.
fn envelope_options(args: &EnvelopeArgs) -> Result<EnvelopeSeriesOptions, CliError> {
    let epsilons: Vec<Epsilon> = match (args.epsilon, &args.levels) {
        (Some(e), _) => vec![e],
        (None, Some(list)) => list.clone(),
        (None, None) => return Err(CliError::usage("give --epsilon E or --levels E,E,...")),
    };
    let mut options = match args.preset.as_str() {
        "tight" => EnvelopeOptions::tight(),
        _ => EnvelopeOptions::paper(),
    };
    if let Some(order) = &args.order {
        options.order = match order.as_str() {
            "deviation" => RemovalOrder::Deviation,
            _ => RemovalOrder::Coverage,
        };
    }
    if let Some(offsets) = &args.offsets {
        options.offsets = match offsets.as_str() {
            "crossings" => OffsetRule::CrossingsOnly,
            _ => OffsetRule::Voronoi,
        };
    }
    if let Some(rounds) = args.smooth_normals {
        options.normal_smoothing = rounds;
    }
    options.keep_sharp = args.keep_sharp;
    options.regions = args.region.clone();
    options.measure_samples = args.samples;
    let options = EnvelopeSeriesOptions {
        epsilons,
        options,
        repair: args.repair,
    };
    voxlod::check_envelope_options(&options).map_err(|e| in_flags(e, &[]))?;
    Ok(options)
}

/// The series, each level added to the output set as soon as it is made; the first failure
/// to add one stops the series and is returned.
fn simplify(
    args: &EnvelopeArgs,
    out: &mut OutputSet,
    mesh: &TriangleMesh,
    options: &EnvelopeSeriesOptions,
) -> Result<(EnvelopeSeries, Vec<LevelOut>), CliError> {
    let count = options.epsilons.len();
    let bar = progress(count as u64, "levels", args.json);
    let written = Mutex::new((out, Vec::new(), None));
    let on_progress = |p: Progress| {
        let Event::EnvelopeLevel(level) = p.event else {
            return Control::Continue;
        };
        let mut guard = written.lock().unwrap_or_else(|e| e.into_inner());
        let (out, levels, failure) = &mut *guard;
        match write_level(&args.output, count, out, level) {
            Ok(l) => {
                bar.inc(1);
                levels.push(l);
                Control::Continue
            }
            Err(e) => {
                *failure = Some(e);
                Control::Stop
            }
        }
    };
    let series = voxlod::envelope_with(mesh, options, &on_progress);
    bar.finish_and_clear();
    let (_, levels, failure) = written.into_inner().unwrap_or_else(|e| e.into_inner());
    if let Some(e) = failure {
        return Err(e.into());
    }
    let series = series.map_err(|e| in_flags(e.in_file(&args.input), &[]))?;
    Ok((series, levels))
}

/// Adds one level to the output set.
fn write_level(
    output: &std::path::Path,
    count: usize,
    out: &mut OutputSet,
    level: &EnvelopeLevel,
) -> Result<LevelOut, voxlod::io::IoError> {
    let path = level_path(output, level.report.level, count);
    let t = Instant::now();
    out.mesh(&path, &level.mesh)?;
    Ok(LevelOut {
        epsilon_percent: level.report.epsilon_fraction * 100.0,
        report: level.report.clone(),
        file: path.display().to_string(),
        write_seconds: t.elapsed().as_secs_f64(),
    })
}

pub fn run(args: EnvelopeArgs) -> Result<(), CliError> {
    let start = Instant::now();
    let options = envelope_options(&args)?;
    let count = options.epsilons.len();
    // Refuse an output format we cannot write before any work.
    voxlod::io::mesh_format_of(&args.output)?;
    let mut out = OutputSet::protecting([&args.input]);
    for level in 0..count {
        out.check(&level_path(&args.output, level, count))?;
    }
    let mesh = read_mesh_input(&args.input)?.mesh;
    let (series, levels) = simplify(&args, &mut out, &mesh, &options)?;
    out.commit()?;
    let input = args.input.display();
    let report = Report {
        input: input.to_string(),
        input_vertices: series.input_vertices,
        input_triangles: series.input_triangles,
        repair: series.repair,
        options: options.options,
        levels,
        total_seconds: start.elapsed().as_secs_f64(),
        warnings: series
            .warnings
            .iter()
            .map(|w| format!("{input}: {w}"))
            .collect(),
    };
    if args.json {
        return print_json(&report);
    }
    for w in &report.warnings {
        eprintln!("warning: {w}");
    }
    print_report(&report);
    Ok(())
}

/// A line per level and a summary on standard output.
fn print_report(report: &Report) {
    for l in &report.levels {
        let r = &l.report;
        let distance = r.distance.map_or(String::new(), |d| {
            format!(
                ", measured distance {:.4} ({:.2} ε)",
                d.hausdorff, d.hausdorff_over_epsilon
            )
        });
        say(format_args!(
            "level {}: ε {:.4} ({:.2}% of the diagonal): {} triangles ({:.1}% fewer) in {:.2} s{distance} -> {}",
            r.level,
            r.epsilon,
            l.epsilon_percent,
            thousands(r.triangles),
            r.reduction_percent,
            r.seconds,
            l.file
        ));
    }
    say(format_args!(
        "{} triangles in, {} levels in {:.2} s",
        thousands(report.input_triangles),
        report.levels.len(),
        report.total_seconds
    ));
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    #[test]
    fn level_names_and_epsilon_parsing() {
        assert_eq!(
            level_path(Path::new("a/out.ply"), 2, 4),
            PathBuf::from("a/out-2.ply")
        );
        assert_eq!(
            level_path(Path::new("out.ply"), 0, 1),
            PathBuf::from("out.ply")
        );
        assert!(epsilon_value("0").is_err());
        assert!(epsilon_value("-1%").is_err());
        assert_eq!(
            epsilon_value("2%").unwrap(),
            Epsilon::DiagonalFraction(0.02)
        );
    }
}
