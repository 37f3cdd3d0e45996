//! `voxlod lod MODEL.glb|MODEL.gltf`, or an OBJ (with its MTL), PLY or OFF file that has looks
//! with `--format glb`: levels of an asset with its looks (`voxlod::asset_lod`).
//! The levels by resolution, by triangle budget or by error, as for a mesh, are made on the
//! asset's geometry; each then carries the asset's texture coordinates, colours, normals and
//! materials, kept or taken from the nearest input points. Written as one `.glb` with every
//! level (`--layout msft-lod` or `lod-nodes`), and each level as its own `.glb` with `--split`.
//! Another `--format` writes the geometry only, and the report says that the looks were dropped.
//!
//! Files: with `-o DIR`, `DIR/lod.glb`, `DIR/level-N.EXT` and `DIR/report.json`; with
//! `-o NAME.glb`, `NAME.glb`, `NAME-level-N.glb` and `NAME-report.json` beside it.

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::ValueEnum;
use serde::Serialize;
use voxlod::budget::BudgetLevel;
use voxlod::gltf::{AssetGlbOptions, Layout};
use voxlod::io::{AssetRead, IoError, IoErrorKind, OutputSet};
use voxlod::portfolio::Looks;
use voxlod::run_to_end;

use super::common::{describe_mesh, in_dir, in_file, print_json, say, CliError};
use super::lod::{lod_error, lod_options, LodArgs};
use super::lod_glb::{LodFormat, CHAIN_FILE};

/// How the levels sit in the `.glb`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum LayoutArg {
    /// One node switching levels with MSFT_lod and MSFT_screencoverage, for engines with the
    /// extension (others draw the finest level)
    #[default]
    MsftLod,
    /// One scene node per level named LOD0, LOD1, …: the names Blender's, Unity's and Unreal's
    /// importers turn into LOD groups, and what three.js users pick levels by
    LodNodes,
}

impl LayoutArg {
    fn layout(self) -> Layout {
        match self {
            LayoutArg::MsftLod => Layout::MsftLod,
            LayoutArg::LodNodes => Layout::LodNodes,
        }
    }

    fn name(self) -> &'static str {
        match self {
            LayoutArg::MsftLod => "msft-lod",
            LayoutArg::LodNodes => "lod-nodes",
        }
    }
}

/// Whether `path` is a glTF file (`.glb` or `.gltf`), read as an asset with its looks.
pub fn is_gltf(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb") || e.eq_ignore_ascii_case("gltf"))
}

/// Whether the input may carry looks worth keeping: an OBJ (with its MTL), PLY or OFF file
/// whose levels go to a `.glb` (`--format glb`).
pub fn may_have_looks(args: &LodArgs) -> bool {
    let mesh = args.input.extension().is_some_and(|e| {
        ["obj", "ply", "off"]
            .iter()
            .any(|x| e.eq_ignore_ascii_case(x))
    });
    mesh && args.format() == LodFormat::Glb
}

/// The input read as an asset when it has looks (texture coordinates, colours, or materials
/// other than one plain white one); `None` for bare geometry, which the mesh route takes.
pub fn looks_of(args: &LodArgs) -> Result<Option<AssetRead>, CliError> {
    let read = voxlod::io::read_asset(&args.input)?;
    let a = &read.asset;
    let plain = |m: &voxlod::asset::Material| m.textures().count() == 0 && m.base_color == [1.0; 4];
    let looks = !a.mesh.uv[0].is_empty()
        || !a.mesh.colors.is_empty()
        || a.materials.len() > 1
        || a.materials.iter().any(|m| !plain(m));
    Ok(looks.then_some(read))
}

/// The report of an asset's levels.
#[derive(Serialize)]
struct AssetReport {
    input: String,
    route: &'static str,
    /// The layout of the `.glb` files (absent for other formats).
    #[serde(skip_serializing_if = "Option::is_none")]
    layout: Option<&'static str>,
    /// The file with every level (absent for other formats).
    #[serde(skip_serializing_if = "Option::is_none")]
    glb: Option<String>,
    levels: Vec<AssetLevelReport>,
    total_seconds: f64,
    /// Every warning: the reader's (extensions ignored, images left out), the levels', the
    /// looks' (images that could not be decoded, looks dropped by a geometry-only format).
    warnings: Vec<String>,
}

#[derive(Serialize)]
struct AssetLevelReport {
    level: usize,
    /// The level's own file, or the file with every level; none for an empty level.
    file: Option<String>,
    vertices: usize,
    /// With a budget, the budget report's `triangles`.
    #[serde(skip_serializing_if = "Option::is_none")]
    triangles: Option<usize>,
    /// `kept` (the input's vertices with their attributes) or `transferred` (from the nearest
    /// input points); `dropped` for a geometry-only format.
    looks: &'static str,
    materials: usize,
    /// The level's report by budget or error.
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    budget: Option<BudgetLevel>,
}

/// Where the files go: the folder, the chain's name, and the prefix of the level files and
/// the report.
struct Names {
    dir: PathBuf,
    chain: String,
    prefix: String,
}

impl Names {
    fn of(args: &LodArgs, format: LodFormat) -> Result<Names, CliError> {
        if !is_glb_name(&args.output) {
            return Ok(Names {
                dir: args.output.clone(),
                chain: CHAIN_FILE.into(),
                prefix: String::new(),
            });
        }
        if format != LodFormat::Glb {
            return Err(CliError::usage(format!(
                "-o {} names a .glb file; --format {} writes level files into a folder",
                args.output.display(),
                format_name(format)
            )));
        }
        let dir = match args.output.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let name = |p: Option<&std::ffi::OsStr>| p.map(|s| s.to_string_lossy().into_owned());
        Ok(Names {
            dir,
            chain: name(args.output.file_name()).unwrap_or_default(),
            prefix: name(args.output.file_stem()).unwrap_or_default() + "-",
        })
    }

    fn level(&self, level: usize, ext: &str) -> String {
        format!("{}level-{level}.{ext}", self.prefix)
    }

    fn report(&self) -> String {
        format!("{}report.json", self.prefix)
    }
}

/// Whether `-o` names a `.glb` file rather than a folder.
pub fn is_glb_name(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"))
}

fn format_name(format: LodFormat) -> String {
    format
        .to_possible_value()
        .map(|v| v.get_name().to_string())
        .unwrap_or_default()
}

/// Reads the asset, makes its levels as `args` ask and writes them with their looks.
pub fn run(args: &LodArgs, read: Option<AssetRead>) -> Result<(), CliError> {
    let start = Instant::now();
    let format = args.format();
    args.glb.check(format)?;
    if args.glb.compress.is_some() {
        return Err(CliError::usage(
            "--compress applies to meshes' chains; an asset's levels are written uncompressed",
        ));
    }
    let names = Names::of(args, format)?;
    let by_budget = args.triangles.is_some() || args.error.is_some();
    let pyramid = if by_budget {
        None
    } else {
        Some(lod_options(args)?)
    };
    let scene = read_input(args, read)?;
    let made = match &pyramid {
        Some(options) => voxlod::asset_lod(&scene.asset, options, &run_to_end),
        None => {
            let options = super::lod_budget::options(args);
            voxlod::asset_lod_by_budget(&scene.asset, &options, &run_to_end)
        }
    }
    .map_err(|e| lod_error(args, e.into()))?;
    let mut warnings = scene.warnings.clone();
    warnings.extend(made.lod.warnings.iter().cloned());
    let glb = format == LodFormat::Glb;
    let ext = if glb {
        "glb".to_string()
    } else {
        format_name(format)
    };
    let mut out = OutputSet::protecting([&args.input]);
    let level_files = !glb || args.glb.split;
    let plan = Plan {
        names: &names,
        glb,
        level_files,
        ext: &ext,
    };
    plan.check(&mut out, &made)?;
    let glb_options = AssetGlbOptions {
        layout: args.glb.layout.layout(),
        coverages: Vec::new(),
        name: args
            .input
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default(),
        ..Default::default()
    };
    let levels = plan.write_levels(&mut out, &made, &glb_options)?;
    let chain: Vec<_> = made.assets.iter().filter_map(|l| l.asset.clone()).collect();
    if glb {
        let path = in_dir(&names.dir, &names.chain);
        let bytes = voxlod::gltf::asset_glb(&chain, &glb_options).map_err(|e| in_file(&path, e))?;
        out.bytes(&path, &bytes)?;
    } else {
        warnings.push(format!(
            "the levels' looks (texture coordinates, colours, normals, materials) were dropped: \
             {} files hold geometry only; --format glb keeps them",
            ext.to_uppercase()
        ));
    }
    warnings.extend(out.warnings().iter().cloned());
    let report = AssetReport {
        input: args.input.display().to_string(),
        route: made.lod.route.name(),
        layout: glb.then(|| args.glb.layout.name()),
        glb: glb.then(|| names.chain.clone()),
        levels,
        total_seconds: start.elapsed().as_secs_f64(),
        warnings,
    };
    let text = serde_json::to_string_pretty(&report)
        .map_err(|e| CliError::msg(format!("cannot encode the report: {e}")))?;
    out.text(&in_dir(&names.dir, &names.report()), &text)?;
    out.commit()?;
    if args.json {
        return print_json(&report);
    }
    print_text(&report, &made, &names);
    Ok(())
}

/// The input as an asset: the one read already, or the glTF file read now. A missing or
/// unreadable file is an I/O failure (exit 4), as for the other readers.
fn read_input(args: &LodArgs, read: Option<AssetRead>) -> Result<AssetRead, CliError> {
    std::fs::File::open(&args.input).map_err(|e| {
        IoError::new(
            &args.input,
            IoErrorKind::Access,
            format!("cannot open: {e}"),
        )
    })?;
    Ok(match read {
        Some(read) => read,
        None => {
            let s = voxlod::gltf::read_scene(&args.input).map_err(|e| in_file(&args.input, e))?;
            AssetRead {
                asset: s.asset,
                warnings: s.warnings,
            }
        }
    })
}

/// What files a run writes: the names, whether the levels go to a `.glb`, whether each level
/// gets its own file, and their extension.
struct Plan<'a> {
    names: &'a Names,
    glb: bool,
    level_files: bool,
    ext: &'a str,
}

impl Plan<'_> {
    /// Refuses outputs that would overwrite what they must not, before anything is written,
    /// and makes the folder.
    fn check(&self, out: &mut OutputSet, made: &voxlod::AssetLod) -> Result<(), CliError> {
        let names = self.names;
        for (k, level) in made.assets.iter().enumerate() {
            if self.level_files && level.asset.is_some() {
                out.check(&in_dir(&names.dir, &names.level(k, self.ext)))?;
            }
        }
        if self.glb {
            out.check(&in_dir(&names.dir, &names.chain))?;
        }
        out.check(&in_dir(&names.dir, &names.report()))?;
        out.create_dir(&names.dir)?;
        Ok(())
    }

    /// Writes each level's own file where it gets one, and reports every level.
    fn write_levels(
        &self,
        out: &mut OutputSet,
        made: &voxlod::AssetLod,
        glb_options: &AssetGlbOptions,
    ) -> Result<Vec<AssetLevelReport>, CliError> {
        let (names, ext) = (self.names, self.ext);
        let mut levels = Vec::with_capacity(made.assets.len());
        for (k, (level, lod_level)) in made.assets.iter().zip(&made.lod.levels).enumerate() {
            let file = match (&level.asset, self.glb, self.level_files) {
                (None, _, _) => None,
                (Some(asset), true, true) => {
                    let path = in_dir(&names.dir, &names.level(k, ext));
                    let bytes = voxlod::gltf::asset_glb(std::slice::from_ref(asset), glb_options)
                        .map_err(|e| in_file(&path, e))?;
                    out.bytes(&path, &bytes)?;
                    Some(names.level(k, ext))
                }
                (Some(_), true, false) => Some(names.chain.clone()),
                (Some(_), false, _) => {
                    let path = in_dir(&names.dir, &names.level(k, ext));
                    out.mesh(&path, &lod_level.mesh)?;
                    Some(names.level(k, ext))
                }
            };
            let budget = made.lod.budgets.get(k).cloned();
            levels.push(AssetLevelReport {
                level: k,
                file,
                vertices: lod_level.mesh.positions.len(),
                triangles: budget.is_none().then_some(lod_level.mesh.triangles.len()),
                looks: match (self.glb, level.looks) {
                    (false, _) => "dropped",
                    (true, Looks::Kept) => "kept",
                    (true, Looks::Transferred) => "transferred",
                },
                materials: level.asset.as_ref().map_or(0, |a| a.materials.len()),
                budget,
            });
        }
        Ok(levels)
    }
}

/// The warnings on standard error; the levels and the report's file on standard output.
fn print_text(report: &AssetReport, made: &voxlod::AssetLod, names: &Names) {
    for w in &report.warnings {
        eprintln!("warning: {w}");
    }
    for (l, level) in report.levels.iter().zip(&made.lod.levels) {
        say(format_args!(
            "level {}: {}, looks {} -> {}",
            l.level,
            describe_mesh(&level.mesh),
            l.looks,
            l.file.as_deref().unwrap_or("(empty, not written)")
        ));
    }
    say(format_args!(
        "{} levels in {:.2} s; report in {}",
        report.levels.len(),
        report.total_seconds,
        in_dir(&names.dir, &names.report()).display()
    ));
}
