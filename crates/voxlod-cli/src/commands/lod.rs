//! `voxlod lod`: the main job. A mesh or a scanned volume in, one closed mesh per level out.

use std::path::PathBuf;
use std::time::Instant;

use clap::{Args, ValueEnum};
use serde::Serialize;
use voxlod::io::OutputSet;
use voxlod::sampling::{DensityReport, Filter, PyramidOptions};

use super::common::{
    check_computed_mesh, count, describe_mesh, in_dir, in_file, print_json, progress, CliError,
    MeshExtension,
};
use super::envelope::{then_envelope, ThenEnvelope, ThenEnvelopeReport};
use super::source::{load, threshold_warning, Loaded, MeshSummary, Prepared, VolumeRoute};
use super::values::number;
use super::world::{frame_report, FrameArg};
use voxlod::lod::{build_level, plan, LodOptions};

/// Build levels of detail: a pyramid of filtered volumes, marching cubes on each (paper §2).
///
/// After He, Hong, Kaufman, Varshney and Wang, Voxel Based Object Simplification (1995).
///
/// Every level is filtered from the original object, never from the level above. Level k has
/// RESOLUTION/2^k samples across the longest side of the object's box and a filter radius of one
/// voxel of that level, as in the paper's tables. Writes DIR/level-0.ply, DIR/level-1.ply, …
/// and DIR/report.json, all at the end, and removes level files of an earlier run that this one
/// does not write.
///
/// Examples:
///   voxlod lod bunny.obj -o bunny-lods
///   voxlod lod part.stl -o out --resolutions 200,100,50,30,15,5 --filter gaussian
///   voxlod lod head.raw --dims 256,256,113 --dtype u16 --endian big --spacing 1,1,2 \
///       --threshold 1500 -o head-bone
#[derive(Args, Debug)]
#[command(verbatim_doc_comment)]
pub struct LodArgs {
    /// The input: a mesh (.obj .ply .stl .off .vtp .vtk) or a volume (.nrrd .nhdr .vti .vtk .nii
    /// .nii.gz .mha .mhd, or headerless raw with --dims)
    pub input: PathBuf,
    /// Folder for the level meshes and report.json (created if missing)
    #[arg(short, long, value_name = "DIR")]
    pub output: PathBuf,
    /// Samples across the longest side of the object at level 0
    #[arg(long, value_name = "N", default_value_t = 256,
        value_parser = number::<usize>, allow_hyphen_values = true)]
    pub resolution: usize,
    /// Number of levels, each half the resolution of the one before
    #[arg(long, value_name = "L", default_value_t = 6, conflicts_with = "resolutions",
        value_parser = number::<usize>, allow_hyphen_values = true)]
    pub levels: usize,
    /// Explicit resolutions, one per level, e.g. 200,100,50,30,15,5
    #[arg(long, value_name = "A,B,...", value_delimiter = ',',
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
    /// Format of the level meshes
    #[arg(long, value_enum, default_value = "ply")]
    pub format: MeshExtension,
    /// Quadrature lines per filter radius (accuracy against speed; 4 keeps the half-space
    /// profile within 0.01 of the paper's equation 5)
    #[arg(long, value_name = "Q", default_value_t = 4,
        value_parser = number::<usize>, allow_hyphen_values = true)]
    pub lines_per_radius: usize,
    /// Print the report as JSON on standard output (no progress bar)
    #[arg(long)]
    pub json: bool,
    /// Then simplify each level within E by simplification envelopes (genus and holes stay): a
    /// distance, a percentage of the level's diagonal (1%), or voxels of the level (1vox)
    #[arg(long, value_name = "E", value_parser = ThenEnvelope::parse_value,
        allow_hyphen_values = true)]
    pub then_envelope: Option<ThenEnvelope>,
    #[command(flatten)]
    pub route: VolumeRoute,
    #[command(flatten)]
    pub frame: FrameArg,
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
    seconds: f64,
    sample_seconds: f64,
    contour_seconds: f64,
    write_seconds: f64,
    density: Option<DensityReport>,
    #[serde(skip_serializing_if = "Option::is_none")]
    envelope: Option<ThenEnvelopeReport>,
}

#[derive(Serialize)]
struct LodReport {
    input: String,
    mesh: Option<MeshSummary>,
    route: &'static str,
    filter: Filter,
    iso: f32,
    /// For a volume: the frame of the meshes (lps, ras, unknown) and the input's index-to-world
    /// matrix in it.
    #[serde(skip_serializing_if = "Option::is_none")]
    frame: Option<voxlod::core::Frame>,
    #[serde(skip_serializing_if = "Option::is_none")]
    transform: Option<[[f64; 4]; 4]>,
    levels: Vec<LevelReport>,
    total_seconds: f64,
    /// Every warning printed without --json: levels the filter removed, stale level files
    /// removed from the output folder.
    warnings: Vec<String>,
}

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

pub fn run(args: LodArgs) -> Result<(), CliError> {
    let start = Instant::now();
    let loaded = load(&args.input, &args.route)?;
    if let Loaded::Volume(v) = &loaded {
        args.frame.check(v, &args.input)?;
    } else if args.frame.target().is_some() {
        return Err(CliError::usage(format!(
            "{}: --frame applies to volumes (a mesh has no anatomical frame)",
            args.input.display()
        )));
    }
    let prepared = Prepared::new(&loaded, &args.route, &args.input)?;
    let iso = prepared.iso(args.iso, &args.input)?;
    let envelope_eps = args.then_envelope;
    let mut pyramid = match &args.resolutions {
        Some(list) => PyramidOptions::with_resolutions(list.clone(), args.filter),
        None => {
            if args.levels == 0 {
                return Err(CliError::usage("--levels must be at least 1"));
            }
            PyramidOptions::halving(args.resolution, args.levels, args.filter)
        }
    };
    if args.resolution == 0 {
        return Err(CliError::usage("--resolution must be at least 1"));
    }
    pyramid.radius_voxels = args.radius;
    pyramid.lines_per_radius = args.lines_per_radius;
    let options = LodOptions {
        pyramid,
        iso,
        normals: true,
    };
    let source = prepared.source();
    let plans = plan(&source, &options).map_err(|e| in_file(&args.input, e))?;
    // Everything is written at the end, as one set; refuse now what it would refuse then.
    let mut out = OutputSet::protecting([&args.input]);
    let level_name = |level: usize| format!("level-{level}.{}", args.format.as_str());
    for p in &plans {
        out.check(&in_dir(&args.output, &level_name(p.level)))?;
    }
    out.create_dir(&args.output)?;
    if let Loaded::Mesh(_, summary) = &loaded {
        let p = &summary.preparation;
        let repairs: Vec<String> = [
            (p.welded_vertices, "coincident vertices welded"),
            (p.degenerate_triangles, "degenerate triangles dropped"),
            (p.duplicate_triangles, "duplicate triangles dropped"),
            (p.holes_closed, "holes closed"),
        ]
        .iter()
        .filter(|(n, _)| *n > 0)
        .map(|(n, what)| format!("{n} {what}"))
        .collect();
        if !args.json && !repairs.is_empty() {
            eprintln!("{}: {}", args.input.display(), repairs.join(", "));
        }
    }

    let finest = plans[0].voxel_size;
    let bar = progress(plans.len() as u64, "levels", args.json);
    let mut levels = Vec::new();
    let mut warnings: Vec<String> = threshold_warning(&loaded, &args.route)
        .into_iter()
        .collect();
    if let (false, Some(w)) = (args.json, warnings.first()) {
        eprintln!("warning: {w}");
    }
    for level_plan in &plans {
        let mut level = build_level(&source, level_plan, &options).map_err(|e| {
            let level = voxlod::Error::from(e).context(format!("level {}", level_plan.level));
            in_file(&args.input, level)
        })?;
        if let Loaded::Volume(v) = &loaded {
            args.frame.convert(v, &mut level.mesh);
        }
        check_computed_mesh(
            &level.mesh,
            &format!("{}: level {}", args.input.display(), level_plan.level),
            "the object's extent or position is too large for 32-bit coordinates",
        )?;
        let envelope = match envelope_eps {
            Some(eps) => {
                let what = format!("{}: level {}", args.input.display(), level_plan.level);
                let (mesh, report) = then_envelope(&level.mesh, eps, level_plan.voxel_size, &what)?;
                level.mesh = mesh;
                report
            }
            None => None,
        };
        let name = level_name(level_plan.level);
        let write_start = Instant::now();
        let file = (!level.mesh.is_empty()).then(|| name.clone());
        if file.is_some() {
            out.mesh(&in_dir(&args.output, &name), &level.mesh)?;
        }
        let write_seconds = write_start.elapsed().as_secs_f64();
        let t = &level.topology;
        levels.push(LevelReport {
            level: level_plan.level,
            resolution: level_plan.resolution,
            voxel_size: level_plan.voxel_size,
            radius: level_plan.radius,
            radius_in_finest_voxels: level_plan.radius / finest,
            grid: level_plan.grid.dims,
            file,
            vertices: level.mesh.positions.len(),
            triangles: level.mesh.triangles.len(),
            euler_characteristic: t.euler_characteristic,
            genus: t.genus,
            components: t.components,
            closed_manifold: t.is_closed_manifold() && t.is_consistently_oriented(),
            seconds: level.sample_seconds + level.contour_seconds + write_seconds,
            sample_seconds: level.sample_seconds,
            contour_seconds: level.contour_seconds,
            write_seconds,
            density: level.density,
            envelope,
        });
        bar.inc(1);
        if level.mesh.is_empty() {
            warnings.push(format!(
                "level {}: the filter of radius {:.4} removed the whole object (no density \
                 reaches {iso}); no file written. Use fewer levels, or a lower --iso for parts \
                 thinner than a voxel",
                level_plan.level, level_plan.radius
            ));
        }
        if !args.json {
            bar.suspend(|| {
                if let (true, Some(w)) = (level.mesh.is_empty(), warnings.last()) {
                    eprintln!("warning: {w}");
                } else {
                    println!(
                        "level {}: resolution {:>4}, radius {:.4}: {} -> {}",
                        level_plan.level,
                        level_plan.resolution,
                        level_plan.radius,
                        describe_mesh(&level.mesh),
                        name
                    );
                }
            });
        }
    }
    bar.finish_and_clear();
    if levels.iter().all(|l| l.file.is_none()) {
        return Err(no_surface(&args, &plans, iso));
    }
    out.remove_stale(&args.output, is_level_file);
    let written_warnings = out.warnings().len();
    warnings.extend(out.warnings().iter().cloned());
    let frame = match &loaded {
        Loaded::Volume(v) => Some(frame_report(v, args.frame.target())),
        Loaded::Mesh(..) => None,
    };
    let report = LodReport {
        frame: frame.as_ref().map(|f| f.frame),
        transform: frame.map(|f| f.transform),
        input: args.input.display().to_string(),
        mesh: match &loaded {
            Loaded::Mesh(_, summary) => Some(summary.clone()),
            Loaded::Volume(_) => None,
        },
        route: match prepared {
            Prepared::Mesh(_) => "mesh",
            Prepared::Threshold(_) => "threshold",
            Prepared::Direct(_) => "direct",
        },
        filter: args.filter,
        iso,
        levels,
        total_seconds: start.elapsed().as_secs_f64(),
        warnings,
    };
    let text = serde_json::to_string_pretty(&report)
        .map_err(|e| CliError::msg(format!("cannot encode the report: {e}")))?;
    out.text(&in_dir(&args.output, "report.json"), &text)?;
    out.commit()?;
    if args.json {
        print_json(&report)?;
    } else {
        // The level warnings were printed as the levels were made; the writing's come last.
        for w in &report.warnings[report.warnings.len() - written_warnings..] {
            eprintln!("warning: {w}");
        }
        println!(
            "{} in {:.2} s; report in {}",
            written_summary(&report.levels),
            report.total_seconds,
            in_dir(&args.output, "report.json").display()
        );
    }
    Ok(())
}

/// Why there is nothing to write: every level came out empty.
fn no_surface(args: &LodArgs, plans: &[voxlod::sampling::LevelPlan], iso: f32) -> CliError {
    let first = &plans[0];
    CliError::msg(format!(
        "{}: no level has a surface, so nothing was written: at every level the filtered density \
         stays below the isodensity {iso}. The object is thinner than the filter (level 0: voxel \
         {:.4}, radius {:.4}) or encloses no volume; use a higher --resolution, a smaller \
         --radius or a lower --iso",
        args.input.display(),
        first.voxel_size,
        first.radius
    ))
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
