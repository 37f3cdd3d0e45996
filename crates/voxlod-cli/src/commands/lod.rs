//! `voxlod lod`: the main job. A mesh or a scanned volume in, one closed mesh per level out.

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use indicatif::ProgressBar;
use serde::Serialize;
use voxlod::core::WorldTransform;
use voxlod::finest::FinestChoice;
use voxlod::io::OutputSet;
use voxlod::pyramid::{BlockwiseReason, Scan, ScanRoute};
use voxlod::sampling::{BandReport, DensityReport, Filter, PyramidOptions, TopologyRecord};
use voxlod::{
    Control, EnvelopeStep, Event, Finest, LevelEpsilon, Lod, LodLevel, LodOptions, Progress,
};

use super::common::say;
use super::common::{
    add_report, check_grid_reach, count, describe_mesh, in_dir, print_json, progress, read_input,
    CliError, Input, MeshExtension,
};
use super::lod_glb::{add_chain, GlbArgs, GlbReport, LodFormat, CHAIN_FILE};
use super::source::{MeshSummary, VolumeRoute};
use super::values::{in_flags, number};
use super::world::FrameArg;

/// Build levels of detail: a pyramid of filtered volumes, marching cubes on each (paper §2).
///
/// After He, Hong, Kaufman, Varshney and Wang, Voxel Based Object Simplification (1995).
///
/// Every level is filtered from the original object, never from the level above. Level k has
/// RESOLUTION/2^k samples across the longest side of the object's box and a filter radius of one
/// voxel of that level, as in the paper's tables. Without --resolution, a mesh starts where
/// marching cubes' estimated count is at most the input's triangles (at most 256, at least 16);
/// a volume starts at 256. The genus never rises from a level to the next (a thin wall closes
/// up instead of perforating; --no-monotone gives the plain pyramid), and every level is
/// cleaned of slivers, needles and self-intersections (--no-clean keeps plain marching cubes).
/// Writes DIR/level-0.ply, DIR/level-1.ply, … and DIR/report.json, all at the end, and removes
/// level files of an earlier run that this one does not write.
///
/// Examples:
///   voxlod lod bunny.obj -o bunny-lods
///   voxlod lod part.stl -o out --resolutions 200,100,50,30,15,5 --filter gaussian
///   voxlod lod head.raw --dims 256,256,113 --dtype u16 --endian big --spacing 1,1,2 \
///       --threshold 1500 -o head-bone
///
/// By triangle budget or error (paper §5: the voxel method first, then a geometric simplifier):
/// each budget gets the resolution that filters away what it cannot afford (handles, thin
/// parts, small pieces), then quadric collapse or simplification envelopes spend the triangles
/// where the shape needs them; candidates at isodensities 0.5, 0.25 and 0.15 compete by measured
/// distance, so thin walls close up instead of vanishing; an open scan keeps its holes (--closed
/// fills them):
///   voxlod lod bunny.obj -o chain --triangles 20000,5000,1000,250
///   voxlod lod part.stl -o fine --error 0.5%        # one level within 0.5 % of the diagonal
///   voxlod lod scan.ply -o out --triangles 2000 --then quadric --closed --json
///
/// A glTF asset (.glb, .gltf) keeps its looks: every level carries texture coordinates,
/// colours, normals and materials, the input's own where the level keeps its vertices, else
/// baked into new textures (or taken from its nearest points), in one .glb (--layout msft-lod
/// or lod-nodes; --split writes each level as its own .glb too; --compress meshopt quantizes
/// and compresses it). --format obj writes each level as OBJ with its MTL and textures,
/// --format ply as a coloured, textured PLY; an OBJ, PLY or OFF input with looks keeps them
/// when a --format is given:
///   voxlod lod model.glb --triangles 5000,1000,250 -o model-lod.glb
///   voxlod lod model.gltf -o out --layout lod-nodes --split --compress meshopt
///   voxlod lod spot.obj -o spot-lods --triangles 2000,500 --format obj
#[derive(Args, Debug)]
#[command(verbatim_doc_comment)]
pub struct LodArgs {
    /// The input: a mesh (.obj .ply .stl .off .vtp .vtu .vtk), a glTF asset with its looks (.glb
    /// .gltf) or a volume (.nrrd .nhdr .vti .vtk .nii .nii.gz .mha .mhd, or headerless raw with
    /// --dims)
    pub input: PathBuf,
    /// Folder for the level meshes and report.json (created if missing); for a glTF input also
    /// NAME.glb, the file with every level, with NAME-level-N.glb (--split) and
    /// NAME-report.json beside it
    #[arg(short, long, value_name = "DIR")]
    pub output: PathBuf,
    /// Samples across the longest side of the object at level 0 [default: for a mesh, from its
    /// triangle count, at most 256; for a volume, 256] (not with --triangles or --error, which
    /// choose the resolution of each level)
    #[arg(long, value_name = "N", value_parser = number::<usize>, allow_hyphen_values = true,
        conflicts_with_all = ["triangles", "error"])]
    pub resolution: Option<usize>,
    /// Number of levels, each half the resolution of the one before (not with --triangles or
    /// --error: one level per budget)
    #[arg(long, value_name = "L", default_value_t = 6,
        conflicts_with_all = ["resolutions", "triangles", "error"],
        value_parser = number::<usize>, allow_hyphen_values = true)]
    pub levels: usize,
    /// Explicit resolutions, one per level, e.g. 200,100,50,30,15,5 (not with --triangles or
    /// --error, which choose the resolution of each level)
    #[arg(long, value_name = "A,B,...", value_delimiter = ',',
        conflicts_with_all = ["triangles", "error"],
        value_parser = number::<usize>, allow_hyphen_values = true)]
    pub resolutions: Option<Vec<usize>>,
    /// Low-pass filter: hypercone (paper eq. 3) or gaussian (σ = R/3)
    #[arg(long, default_value = "hypercone")]
    pub filter: Filter,
    /// Filter support radius, in voxels of each level
    #[arg(long, value_name = "VOXELS", default_value_t = 1.0,
        value_parser = number::<f64>, allow_hyphen_values = true)]
    pub radius: f64,
    /// Isodensity of the surfaces: between 0 and 1 for meshes and --threshold (default 0.5);
    /// in data units with --direct (required)
    #[arg(long, value_name = "V", value_parser = number::<f32>, allow_hyphen_values = true)]
    pub iso: Option<f32>,
    /// Format of the level meshes, or glb: one DIR/lod.glb chaining every level (MSFT_lod)
    /// [default: ply; glb for a .glb or .gltf input, whose levels keep their looks]
    #[arg(long = "format", value_enum, value_name = "FORMAT")]
    pub format_given: Option<LodFormat>,
    #[command(flatten)]
    pub glb: GlbArgs,
    /// Quadrature lines per filter radius (accuracy against speed; 4 keeps the half-space
    /// profile within 0.01 of the paper's equation 5)
    #[arg(long, value_name = "Q", default_value_t = 4,
        value_parser = number::<usize>, allow_hyphen_values = true)]
    pub lines_per_radius: usize,
    /// Print the report as JSON on standard output (no progress bar)
    #[arg(long)]
    pub json: bool,
    /// Let the genus rise between levels as plain filtering makes it (the paper's pyramid);
    /// with --triangles, search every budget on its own instead of holding each level to the
    /// genus of the larger budget's level
    #[arg(long)]
    pub no_monotone: bool,
    /// Keep plain marching cubes (no cleaning of slivers, needles and self-intersections); not
    /// with --triangles or --error, whose levels are always cleaned
    #[arg(long, conflicts_with_all = ["triangles", "error"])]
    pub no_clean: bool,
    /// Then simplify each level within E by simplification envelopes (genus and holes stay): a
    /// distance, a percentage of the level's diagonal (1%), or voxels of the level (1vox). Not
    /// with --triangles or --error, whose geometric stage is chosen with --then envelope
    #[arg(long, value_name = "E", value_parser = parse_level_epsilon,
        conflicts_with_all = ["triangles", "error"], allow_hyphen_values = true)]
    pub then_envelope: Option<LevelEpsilon>,
    /// Levels by triangle budget, one per count (e.g. 20000,5000,1000,250): each within 10 %
    /// or the report says why; the resolutions are chosen per budget
    #[arg(long, value_name = "N,N,...", value_delimiter = ',', help_heading = "Budgets",
        value_parser = number::<usize>, allow_hyphen_values = true)]
    pub triangles: Option<Vec<usize>>,
    /// An error target, a distance or a percentage of the diagonal (0.5%): alone, one level
    /// within it; with --triangles, the bound of each level's geometric stage
    #[arg(
        long,
        value_name = "E",
        help_heading = "Budgets",
        allow_hyphen_values = true
    )]
    pub error: Option<voxlod::budget::ErrorTarget>,
    /// The geometric stage after the voxel stage: auto (quadric, and envelopes where it stalls
    /// above the budget, whichever is measured closer to the input), quadric (meshoptimizer,
    /// topology kept), envelope (simplification envelopes, ε-bounded) or none (the
    /// marching-cubes level nearest the budget). With auto or quadric, a budget that affords the
    /// input mesh's genus and components collapses the input itself (stage input-quadric)
    #[arg(
        long,
        value_name = "STAGE",
        default_value = "auto",
        help_heading = "Budgets"
    )]
    pub then: voxlod::budget::Then,
    /// Keep the caps that sampling puts over an open input's holes (watertight levels); by
    /// default they are cut away and the holes stay open
    #[arg(long, help_heading = "Budgets")]
    pub closed: bool,
    /// Leave each budget level as its geometric stage made it; by default its vertices are
    /// then fitted to the input mesh (triangles kept), where that measures closer
    #[arg(long, help_heading = "Budgets")]
    pub no_fit: bool,
    /// CPU seconds (all threads) each budget may spend per isodensity trying neighbouring
    /// resolutions for a smaller distance; CPU time, so that a busy machine gives the same levels
    #[arg(long, value_name = "SECONDS", default_value_t = 1.0, help_heading = "Budgets",
        value_parser = number::<f64>, allow_hyphen_values = true)]
    pub time_cap: f64,
    #[command(flatten)]
    pub route: VolumeRoute,
    /// Volumes with --threshold: read the scan blockwise, window by window, instead of whole
    /// (raw files, NRRD with raw encoding, MetaImage with uncompressed data; a Zarr array always
    /// is). Chosen by itself when the volume as 32-bit floats would take more than 1 GiB or not
    /// fit in memory; the levels are the same
    #[arg(long, alias = "bricked", help_heading = "Volumes")]
    pub blockwise: bool,
    #[command(flatten)]
    pub frame: FrameArg,
}

impl LodArgs {
    /// The format asked, else glb for a glTF input, else ply.
    pub fn format(&self) -> LodFormat {
        match self.format_given {
            Some(format) => format,
            None if super::lod_asset::is_gltf(&self.input) => LodFormat::Glb,
            None => LodFormat::Ply,
        }
    }
}

/// One level in the report.
#[derive(Serialize)]
struct LevelReport {
    level: usize,
    resolution: usize,
    voxel_size: f64,
    /// Support radius in world units, and in voxels of the finest level (the paper's tables).
    radius: f64,
    radius_in_finest_voxels: f64,
    grid: [usize; 3],
    /// None when the filter removed the whole object at this level (no file is written).
    file: Option<String>,
    vertices: usize,
    triangles: usize,
    euler_characteristic: i64,
    genus: Option<i64>,
    components: usize,
    closed_manifold: bool,
    /// Handles fewer than the level above (0 for the first level).
    handles_removed: u64,
    /// Surfaces (pieces and cavities) more (> 0) or fewer (< 0) than the level above.
    components_gained: i64,
    /// What keeping the genus from rising did here; absent with --no-monotone.
    #[serde(skip_serializing_if = "Option::is_none")]
    topology_change: Option<TopologyRecord>,
    seconds: f64,
    sample_seconds: f64,
    monotone_seconds: f64,
    contour_seconds: f64,
    write_seconds: f64,
    density: Option<DensityReport>,
    /// The bricks of the narrow band, for a level sampled through it.
    #[serde(skip_serializing_if = "Option::is_none")]
    band: Option<BandReport>,
    /// Bytes the plan expected the level to need at its peak (checked against the budget).
    estimated_bytes: u64,
    #[serde(skip_serializing_if = "Option::is_none")]
    envelope: Option<EnvelopeStep>,
}

#[derive(Serialize)]
struct LodReport {
    input: String,
    mesh: Option<MeshSummary>,
    route: &'static str,
    filter: Filter,
    iso: f32,
    /// How the finest resolution was chosen from the input's triangles (absent when given).
    #[serde(skip_serializing_if = "Option::is_none")]
    finest: Option<FinestChoice>,
    /// For a volume: the frame of the meshes (lps, ras, unknown) and the input's index-to-world
    /// matrix in it.
    #[serde(skip_serializing_if = "Option::is_none")]
    frame: Option<voxlod::core::Frame>,
    #[serde(skip_serializing_if = "Option::is_none")]
    transform: Option<[[f64; 4]; 4]>,
    /// Why a scan was read blockwise (absent when it was held whole).
    #[serde(skip_serializing_if = "Option::is_none")]
    blockwise: Option<BlockwiseReason>,
    levels: Vec<LevelReport>,
    /// The MSFT_lod chain file, with --format glb.
    #[serde(skip_serializing_if = "Option::is_none")]
    glb: Option<GlbReport>,
    total_seconds: f64,
    /// Every warning printed without --json: a threshold below every sample, levels the filter
    /// removed, stale level files removed from the output folder.
    warnings: Vec<String>,
}

/// The value parser of `--then-envelope` (the error without the flag's name).
fn parse_level_epsilon(text: &str) -> Result<LevelEpsilon, String> {
    text.parse()
}

/// The finest resolution of a volume, and the most a mesh's may be chosen from its triangles.
pub(super) const DEFAULT_RESOLUTION: usize = 256;

/// `level-N.EXT` for a mesh extension: the names `lod` writes, and the only ones it removes.
fn is_level_file(name: &str) -> bool {
    let Some((number, ext)) = name
        .strip_prefix("level-")
        .and_then(|rest| rest.split_once('.'))
    else {
        return false;
    };
    !number.is_empty()
        && number.bytes().all(|b| b.is_ascii_digit())
        && MeshExtension::value_variants()
            .iter()
            .any(|e| e.as_str() == ext)
}

/// The library's options from the flags.
pub(super) fn lod_options(args: &LodArgs) -> Result<LodOptions, CliError> {
    if args.resolution == Some(0) {
        return Err(CliError::usage("--resolution must be at least 1"));
    }
    let resolution = args.resolution.unwrap_or(DEFAULT_RESOLUTION);
    let mut pyramid = match &args.resolutions {
        Some(list) => PyramidOptions::for_resolutions(list.clone(), args.filter),
        None if args.levels == 0 => return Err(CliError::usage("--levels must be at least 1")),
        None => PyramidOptions::halving(resolution, args.levels, args.filter),
    };
    pyramid.radius_voxels = args.radius;
    pyramid.lines_per_radius = args.lines_per_radius;
    let defaults = LodOptions::default();
    let given = args.resolution.is_some() || args.resolutions.is_some();
    Ok(LodOptions {
        pyramid,
        iso: args.iso,
        normals: true,
        then_envelope: args.then_envelope.map(voxlod::ThenEnvelope::new),
        finest: if given {
            Finest::Given
        } else {
            defaults.finest
        },
        monotone: defaults.monotone.filter(|_| !args.no_monotone),
        clean: defaults.clean.filter(|_| !args.no_clean),
        frame: args.frame.target(),
    })
}

/// What was read: a mesh (with what its reader did) or a scan, held whole or read blockwise.
enum Loaded {
    Mesh(voxlod::io::LoadedMesh),
    Scan(Scan),
}

impl Loaded {
    /// The library's source for what was read.
    fn source(&self) -> voxlod::Source<'_> {
        match self {
            Loaded::Mesh(m) => voxlod::Source::Mesh(&m.mesh),
            Loaded::Scan(scan) => scan.source(),
        }
    }

    /// Where a scan's meshes are: its index-to-world transform in `frame` (none for a mesh).
    fn world(&self, frame: Option<voxlod::core::Frame>) -> Option<WorldTransform> {
        match self {
            Loaded::Mesh(_) => None,
            Loaded::Scan(scan) => Some(scan.world(frame)),
        }
    }
}

/// Reads the input: a scan blockwise where the library chooses so ([`Scan::open_blockwise`]:
/// asked with --blockwise, a Zarr array, or too large to hold), else whole; a volume needs a
/// route (--threshold or --direct) and samples within 32-bit mesh coordinates.
fn load(args: &LodArgs) -> Result<Loaded, CliError> {
    let (path, route) = (&args.input, &args.route);
    let layout = route.raw.layout()?;
    let opened = Scan::open_blockwise(path, layout.as_ref(), route.threshold, args.blockwise);
    let scan = match opened.map_err(|e| lod_error(args, e.into()))? {
        Some(scan) => scan,
        None => match read_input(path, &route.raw)? {
            Input::Mesh(mesh) => return Ok(Loaded::Mesh(mesh)),
            Input::Volume(volume) => {
                let to = ScanRoute::of(route.threshold, route.direct);
                Scan::whole(volume, to.map_err(|e| lod_error(args, e.into()))?)
            }
        },
    };
    check_grid_reach(&scan.grid(), path, route.raw.spacing_source())?;
    Ok(Loaded::Scan(scan))
}

/// The levels by resolution; `lod_budget.rs` makes them by budget or error
/// (`--triangles`, `--error`).
pub fn run(args: LodArgs) -> Result<(), CliError> {
    args.glb.check(args.format())?;
    let options = lod_options(&args)?;
    let loaded = load(&args)?;
    // Everything is written at the end, as one set; refuse now what it would refuse then.
    let mut out = OutputSet::protecting([&args.input]);
    for level in 0..options.pyramid.resolutions.len() {
        out.check(&in_dir(&args.output, &level_name(&args, level)))?;
    }
    if args.format() == LodFormat::Glb {
        out.check(&in_dir(&args.output, CHAIN_FILE))?;
    }
    out.create_dir(&args.output)?;
    let bar = progress(
        options.pyramid.resolutions.len() as u64,
        "levels",
        args.json,
    );
    let show = |p: Progress| show_level(&args, &bar, p);
    let lod =
        voxlod::lod_with(&loaded.source(), &options, &show).map_err(|e| lod_error(&args, e))?;
    bar.finish_and_clear();
    let mut levels = Vec::with_capacity(lod.levels.len());
    for (k, level) in lod.levels.iter().enumerate() {
        let previous = k.checked_sub(1).map(|above| &lod.levels[above]);
        levels.push(write_level(
            &args,
            &mut out,
            level,
            previous,
            lod.levels[0].plan.voxel_size,
        )?);
    }
    let glb = match args.format() {
        LodFormat::Glb => Some(add_chain(&mut out, &args.output, &lod, &args.glb)?),
        _ => None,
    };
    out.remove_stale(&args.output, is_level_file);
    let mut report = lod_report(&args, &loaded, &lod, levels, out.warnings());
    report.glb = glb;
    add_report(&mut out, &args.output, &report)?;
    out.commit()?;
    if args.json {
        return print_json(&report);
    }
    if let Some(m) = &report.mesh {
        print_repairs(&args, &m.preparation);
    }
    for w in &report.warnings {
        eprintln!("warning: {w}");
    }
    say(format_args!(
        "{} in {:.2} s; report in {}",
        written_summary(&report.levels),
        report.total_seconds,
        in_dir(&args.output, "report.json").display()
    ));
    Ok(())
}

/// `level-N.EXT`.
pub(super) fn level_name(args: &LodArgs, level: usize) -> String {
    format!("level-{level}.{}", args.format().level_extension().as_str())
}

/// Whether each level gets a file of its own (always, but for `--format glb` without `--split`).
fn level_files(args: &LodArgs) -> bool {
    args.format() != LodFormat::Glb || args.glb.split
}

/// The file a level is in: its own, or the chain.
fn level_file(args: &LodArgs, level: usize) -> String {
    if level_files(args) {
        level_name(args, level)
    } else {
        CHAIN_FILE.to_string()
    }
}

/// The progress callback: the bar, the preparation's warnings as the work starts, and a line
/// per finished level (or its warning when the filter removed the object).
fn show_level(args: &LodArgs, bar: &ProgressBar, p: Progress) -> Control {
    if args.json {
        return Control::Continue;
    }
    let Event::LodLevel(level) = p.event else {
        return Control::Continue;
    };
    bar.inc(1);
    let plan = &level.plan;
    let file = if level.mesh.is_empty() {
        "empty, no file (see the warnings)".to_string()
    } else {
        level_file(args, plan.level)
    };
    bar.println(format!(
        "level {}: resolution {:>4}, radius {:.4}: {} -> {file}",
        plan.level,
        plan.resolution,
        plan.radius,
        describe_mesh(&level.mesh),
    ));
    Control::Continue
}

/// What the mesh preparation repaired, in one line on standard error.
pub(super) fn print_repairs(args: &LodArgs, p: &voxlod::sampling::MeshPreparation) {
    if let Some(repairs) = p.repairs() {
        eprintln!("{}: {repairs}", args.input.display());
    }
}

/// The library's failure about the input, its options named as the flags (`--radius` for
/// `radius_voxels`) and its class, and so the exit status, kept.
pub(super) fn lod_error(args: &LodArgs, e: voxlod::Error) -> CliError {
    in_flags(e.in_file(&args.input), &[("radius_voxels", "--radius")])
}

/// Adds one level's mesh to the output set (none for an empty level) and reports it.
fn write_level(
    args: &LodArgs,
    out: &mut OutputSet,
    level: &LodLevel,
    previous: Option<&LodLevel>,
    finest_voxel: f64,
) -> Result<LevelReport, CliError> {
    let plan = &level.plan;
    let write_start = std::time::Instant::now();
    let file = (!level.mesh.is_empty()).then(|| level_file(args, plan.level));
    if file.is_some() && level_files(args) {
        out.mesh(
            &in_dir(&args.output, &level_name(args, plan.level)),
            &level.mesh,
        )?;
    }
    let write_seconds = write_start.elapsed().as_secs_f64();
    let t = &level.topology;
    let envelope_seconds = level.envelope.as_ref().map_or(0.0, |e| e.seconds);
    let (handles_removed, components_gained) = level.change_from(previous);
    Ok(LevelReport {
        level: plan.level,
        resolution: plan.resolution,
        voxel_size: plan.voxel_size,
        radius: plan.radius,
        radius_in_finest_voxels: plan.radius / finest_voxel,
        grid: plan.grid.dims,
        file,
        vertices: level.mesh.positions.len(),
        triangles: level.mesh.triangles.len(),
        euler_characteristic: t.euler_characteristic,
        genus: t.genus,
        components: t.components,
        closed_manifold: t.is_closed_manifold() && t.is_consistently_oriented(),
        handles_removed,
        components_gained,
        topology_change: level.monotone,
        seconds: level.sample_seconds
            + level.monotone_seconds
            + level.contour_seconds
            + envelope_seconds
            + write_seconds,
        sample_seconds: level.sample_seconds,
        monotone_seconds: level.monotone_seconds,
        contour_seconds: level.contour_seconds,
        write_seconds,
        density: level.density,
        band: level.band,
        estimated_bytes: plan.estimated_bytes,
        envelope: level.envelope.clone(),
    })
}

/// The report: the input, its preparation, every level, and every warning.
fn lod_report(
    args: &LodArgs,
    loaded: &Loaded,
    lod: &Lod,
    levels: Vec<LevelReport>,
    written_warnings: &[String],
) -> LodReport {
    let mesh = match (loaded, lod.preparation) {
        (Loaded::Mesh(m), Some(preparation)) => Some(MeshSummary::of(m, preparation)),
        _ => None,
    };
    let mut warnings = lod.warnings.clone();
    warnings.extend(written_warnings.iter().cloned());
    let world = loaded.world(args.frame.target());
    LodReport {
        frame: world.map(|w| w.frame),
        transform: world.map(|w| w.matrix()),
        blockwise: match loaded {
            Loaded::Scan(scan) => scan.blockwise_reason(),
            Loaded::Mesh(_) => None,
        },
        input: args.input.display().to_string(),
        mesh,
        route: lod.route.name(),
        filter: args.filter,
        iso: lod.iso,
        finest: lod.finest,
        levels,
        glb: None,
        total_seconds: lod.seconds,
        warnings,
    }
}

/// "6 levels written", or "5 of 6 levels written (level 5 is empty)": what is on disk.
fn written_summary(levels: &[LevelReport]) -> String {
    let empty: Vec<String> = levels
        .iter()
        .filter(|l| l.file.is_none())
        .map(|l| l.level.to_string())
        .collect();
    let written = levels.len() - empty.len();
    match empty.len() {
        0 => format!("{} written", count(written, "level", "levels")),
        1 => format!(
            "{written} of {} written (level {} is empty)",
            count(levels.len(), "level", "levels"),
            empty[0]
        ),
        _ => format!(
            "{written} of {} written (levels {} are empty)",
            count(levels.len(), "level", "levels"),
            empty.join(", ")
        ),
    }
}
