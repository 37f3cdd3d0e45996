//! The paper's Table 2 on real meshes: simplification envelopes at 1, 2, 4 and 8 % of the
//! bounding-box diagonal, each level simplifying the one before, with timings and the measured
//! two-sided distance. Reads ../shared/data/meshes (skips, saying why, when it is absent).
//!
//!     cargo run --release -p voxlod-envelope --example envelope_table2 -- \
//!         [--order coverage|deviation] [--offsets voronoi|crossings] [--levels 1,2,4,8] \
//!         [--smooth ROUNDS] [--preset paper|tight] [--keep-sharp DEG] [--samples N] [MESH ...]
//!
//! Without MESH arguments it runs rocker-arm.obj, fandisk.obj and stanford-bunny.obj.

use std::path::{Path, PathBuf};
use std::time::Instant;

use voxlod_core::mesh_topology;
use voxlod_envelope::{envelope_series_with, OffsetRule, RemovalOrder};
use voxlod_envelope::{EnvelopeOptions, EnvelopeReport, Epsilon};
use voxlod_testkit::data::shared_data_or_skip;

/// The paper's Table 2 reductions (%), at 1, 2, 4 and 8 % of the diagonal.
const PAPER: [(f64, f64); 4] = [(1.0, 37.8), (2.0, 54.6), (4.0, 63.7), (8.0, 68.7)];

fn main() {
    let (options, levels, mut files) = parse_args();
    if files.is_empty() {
        for name in ["rocker-arm.obj", "fandisk.obj", "stanford-bunny.obj"] {
            if let Some(p) = shared_data_or_skip(&format!("meshes/{name}"), "envelope_table2") {
                files.push(p);
            }
        }
    }
    let epsilons: Vec<Epsilon> = levels.iter().map(|&p| Epsilon::percent(p)).collect();
    println!(
        "order {:?}, offsets {:?}, normals smoothed {} rounds, keep sharp {:?}, {} rayon threads",
        options.order,
        options.offsets,
        options.normal_smoothing,
        options.keep_sharp,
        rayon::current_num_threads()
    );
    for path in files {
        table(&path, &epsilons, &options);
    }
}

/// The options, the levels (percent of the diagonal) and the meshes the arguments name.
fn parse_args() -> (EnvelopeOptions, Vec<f64>, Vec<PathBuf>) {
    let mut options = EnvelopeOptions::paper();
    let mut levels: Vec<f64> = PAPER.iter().map(|p| p.0).collect();
    let mut files: Vec<PathBuf> = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--order" => {
                options.order = match args.next().as_deref() {
                    Some("deviation") => RemovalOrder::Deviation,
                    _ => RemovalOrder::Coverage,
                }
            }
            "--offsets" => {
                options.offsets = match args.next().as_deref() {
                    Some("crossings") => OffsetRule::CrossingsOnly,
                    _ => OffsetRule::Voronoi,
                }
            }
            "--levels" => {
                levels = args
                    .next()
                    .expect("--levels A,B,...")
                    .split(',')
                    .map(|x| x.parse().expect("a percentage"))
                    .collect()
            }
            "--smooth" => {
                options.normal_smoothing = args.next().expect("--smooth ROUNDS").parse().unwrap()
            }
            "--preset" => {
                let samples = options.measure_samples;
                options = match args.next().as_deref() {
                    Some("tight") => EnvelopeOptions::tight(),
                    _ => EnvelopeOptions::paper(),
                };
                options.measure_samples = samples;
            }
            "--keep-sharp" => {
                options.keep_sharp = Some(args.next().expect("--keep-sharp DEG").parse().unwrap())
            }
            "--samples" => {
                options.measure_samples = args.next().expect("--samples N").parse().unwrap()
            }
            _ => files.push(PathBuf::from(a)),
        }
    }
    (options, levels, files)
}

/// One mesh's table: its topology, then a row per level as it is made.
fn table(path: &Path, epsilons: &[Epsilon], options: &EnvelopeOptions) {
    let mesh = voxlod_io::read_mesh(path).expect("readable mesh").mesh;
    let topo = mesh_topology(&mesh);
    println!(
        "\n{}: {} triangles, genus {:?}, {} components, {} border loops",
        path.file_name().unwrap().to_string_lossy(),
        mesh.triangles.len(),
        topo.genus,
        topo.components,
        topo.boundary_loops
    );
    println!(
        "{:>6} {:>9} {:>9} {:>7} {:>8} {:>8} {:>10} {:>7} {:>6} {:>5} {:>7}",
        "ε %",
        "triangles",
        "reduction",
        "paper",
        "seconds",
        "offset s",
        "hausdorff/ε",
        "ε kept",
        "genus",
        "comp",
        "loops"
    );
    let check_crossings = std::env::var_os("ENVELOPE_CHECK_CROSSINGS").is_some();
    if check_crossings {
        let pairs = voxlod_envelope::self_intersections(&mesh).unwrap();
        println!("input self-intersections: {} pairs", pairs.len());
    }
    let start = Instant::now();
    envelope_series_with(&mesh, epsilons, options, |level| {
        row(&level.report);
        if check_crossings {
            let pairs = voxlod_envelope::self_intersections(&level.mesh).unwrap();
            println!("       output self-intersections: {} pairs", pairs.len());
        }
        eprintln!("    {:?}", level.report.removal);
        eprintln!("    {:?}", level.report.offsets);
    })
    .expect("simplification");
    println!("total {:.2} s", start.elapsed().as_secs_f64());
}

/// One level's row, beside the paper's reduction at the same ε.
fn row(r: &EnvelopeReport) {
    let paper = PAPER
        .iter()
        .find(|p| (p.0 / 100.0 - r.epsilon_fraction).abs() < 1e-9)
        .map_or("-".to_string(), |p| format!("{:.1}", p.1));
    println!(
        "{:>6.2} {:>9} {:>8.1}% {:>7} {:>8.2} {:>8.2} {:>10} {:>7.3} {:>6} {:>5} {:>7}",
        r.epsilon_fraction * 100.0,
        r.triangles,
        r.reduction_percent,
        paper,
        r.seconds,
        r.offsets.seconds,
        r.distance
            .map_or("-".into(), |d| format!("{:.3}", d.hausdorff_over_epsilon)),
        r.offsets.mean_fraction,
        r.topology.genus.map_or("-".into(), |g| g.to_string()),
        r.topology.components,
        r.topology.boundary_loops,
    );
}
