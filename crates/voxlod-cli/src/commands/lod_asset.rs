//! `voxlod lod MODEL.glb|MODEL.gltf`, or an OBJ (with its MTL), PLY or OFF file that has looks
//! with `--format glb`: levels of an asset with its looks (`voxlod::asset_lod`).
//! The levels by resolution, by triangle budget or by error, as for a mesh, are made on the
//! asset's geometry; each then carries the asset's texture coordinates, colours, normals and
//! materials, kept or taken from the nearest input points. Written as one `.glb` with every
//! level (`--layout msft-lod` or `lod-nodes`; `--compress meshopt` quantizes and encodes it),
//! and each level as its own `.glb` with `--split`; or, with `--format obj`, each level as an
//! OBJ with its MTL and textures beside it, with `--format ply` as a PLY with vertex colours,
//! texture coordinates and its texture (`voxlod::io::asset_files`). Another `--format` writes
//! the geometry only, and the report says that the looks were dropped. The report lists every
//! file written with what it carries.
//!
//! Files: with `-o DIR`, `DIR/lod.glb`, `DIR/level-N.EXT` (with `.mtl` and textures for OBJ)
//! and `DIR/report.json`; with `-o NAME.glb`, `NAME.glb`, `NAME-level-N.glb` and
//! `NAME-report.json` beside it.

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::ValueEnum;
use serde::Serialize;
use voxlod::budget::BudgetLevel;
use voxlod::core::glam::DVec3;
use voxlod::gltf::{AssetGlbOptions, Compression, Layout};
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
    pub(super) fn layout(self) -> Layout {
        match self {
            LayoutArg::MsftLod => Layout::MsftLod,
            LayoutArg::LodNodes => Layout::LodNodes,
        }
    }

    pub(super) fn name(self) -> &'static str {
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
/// whose levels go to a format that holds them (`--format glb`, or `obj` or `ply` given).
pub fn may_have_looks(args: &LodArgs) -> bool {
    let mesh = args.input.extension().is_some_and(|e| {
        ["obj", "ply", "off"]
            .iter()
            .any(|x| e.eq_ignore_ascii_case(x))
    });
    let keeps = matches!(
        args.format_given,
        Some(LodFormat::Glb | LodFormat::Obj | LodFormat::Ply)
    );
    mesh && (keeps || args.format() == LodFormat::Glb)
}

/// Whether `format` writes each level with its looks as OBJ + MTL or coloured PLY.
fn writes_looks_as_mesh(format: LodFormat) -> bool {
    matches!(format, LodFormat::Obj | LodFormat::Ply)
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
    /// `meshopt` for compressed `.glb` files (absent otherwise).
    #[serde(skip_serializing_if = "Option::is_none")]
    compression: Option<&'static str>,
    /// The world point the levels' positions are relative to, for a glTF scene far from the
    /// origin (absent otherwise); the `.glb` files' nodes carry it as their translation.
    #[serde(skip_serializing_if = "Option::is_none")]
    origin: Option<[f64; 3]>,
    levels: Vec<AssetLevelReport>,
    /// Every file written (the report aside), with what it carries.
    files: Vec<FileReport>,
    total_seconds: f64,
    /// Every warning: the reader's (extensions ignored, images left out), the levels', the
    /// looks' (images that could not be decoded, looks dropped by a geometry-only format, what
    /// OBJ or PLY cannot hold).
    warnings: Vec<String>,
}

/// One file written and what it carries.
#[derive(Serialize)]
struct FileReport {
    /// Its name in the output folder.
    file: String,
    /// The level it holds; absent for the file with every level, and for a texture or MTL
    /// library (`level` then names the first level that uses it).
    #[serde(skip_serializing_if = "Option::is_none")]
    level: Option<usize>,
    /// Its size; absent for a geometry-only level file (written by the mesh writer).
    #[serde(skip_serializing_if = "Option::is_none")]
    bytes: Option<usize>,
    /// `triangles`, `normals`, `texture coordinates`, `vertex colours`, `materials`,
    /// `texture`, `meshopt compression`, …
    carries: Vec<String>,
}

/// What the run has written so far, and what the writers warned of.
#[derive(Default)]
struct Written {
    files: Vec<FileReport>,
    warnings: Vec<String>,
}

impl Written {
    fn add(
        &mut self,
        path: &Path,
        level: Option<usize>,
        bytes: Option<usize>,
        carries: Vec<String>,
    ) {
        let file = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        if self.files.iter().any(|f| f.file == file) {
            return; // a texture several levels share
        }
        self.files.push(FileReport {
            file,
            level,
            bytes,
            carries,
        });
    }

    /// A `.glb` of `levels` staged in `out` and listed.
    fn glb(
        &mut self,
        out: &mut OutputSet,
        path: &Path,
        levels: &[voxlod::asset::Asset],
        level: Option<usize>,
        options: &AssetGlbOptions,
    ) -> Result<(), CliError> {
        let bytes = voxlod::gltf::asset_glb(levels, options).map_err(|e| in_file(path, e))?;
        out.bytes(path, &bytes)?;
        let mut carries = vec![format!("{} levels", levels.len())];
        if levels.len() == 1 {
            carries.clear();
        }
        carries.extend(carried(levels));
        if options.compression == Compression::Meshopt {
            carries.push("meshopt compression".into());
        }
        self.add(path, level, Some(bytes.len()), carries);
        Ok(())
    }
}

/// What a `.glb` of `levels` carries besides triangles.
fn carried(levels: &[voxlod::asset::Asset]) -> Vec<String> {
    let any = |f: &dyn Fn(&voxlod::asset::Asset) -> bool| levels.iter().any(f);
    [
        (true, "triangles"),
        (any(&|a| !a.mesh.normals.is_empty()), "normals"),
        (any(&|a| !a.mesh.tangents.is_empty()), "tangents"),
        (any(&|a| !a.mesh.uv[0].is_empty()), "texture coordinates"),
        (any(&|a| !a.mesh.colors.is_empty()), "vertex colours"),
        (any(&|a| !a.materials.is_empty()), "materials"),
        (any(&|a| !a.images.is_empty()), "textures"),
    ]
    .into_iter()
    .filter(|(present, _)| *present)
    .map(|(_, what)| what.to_string())
    .collect()
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
    let names = Names::of(args, format)?;
    let by_budget = args.triangles.is_some() || args.error.is_some();
    let pyramid = if by_budget {
        None
    } else {
        Some(lod_options(args)?)
    };
    let (scene, origin) = read_input(args, read)?;
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
        looks: glb || writes_looks_as_mesh(format),
    };
    plan.check(&mut out, &made)?;
    let glb_options = AssetGlbOptions {
        compression: args.glb.compression(),
        layout: args.glb.layout.layout(),
        coverages: Vec::new(),
        name: args
            .input
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default(),
        origin,
    };
    if origin != DVec3::ZERO && plan.level_files && !glb {
        warnings.push(format!(
            "the {} level files are relative to the scene's origin ({}, {}, {}); \
             --format glb keeps their place",
            ext.to_uppercase(),
            origin.x,
            origin.y,
            origin.z
        ));
    }
    let mut written = Written::default();
    let levels = plan.write_levels(&mut out, &made, &glb_options, &mut written)?;
    let chain: Vec<_> = made.assets.iter().filter_map(|l| l.asset.clone()).collect();
    warnings.append(&mut written.warnings);
    if glb {
        let path = in_dir(&names.dir, &names.chain);
        written.glb(&mut out, &path, &chain, None, &glb_options)?;
    } else if !plan.looks {
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
        compression: (glb && args.glb.compress.is_some()).then_some("meshopt"),
        origin: (origin != DVec3::ZERO).then(|| origin.to_array()),
        levels,
        files: written.files,
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

/// The input as an asset: the one read already, or the glTF file read now, and the world point
/// its positions are relative to (zero but for a glTF scene far from the origin). A missing or
/// unreadable file is an I/O failure (exit 4), as for the other readers.
fn read_input(args: &LodArgs, read: Option<AssetRead>) -> Result<(AssetRead, DVec3), CliError> {
    std::fs::File::open(&args.input).map_err(|e| {
        IoError::new(
            &args.input,
            IoErrorKind::Access,
            format!("cannot open: {e}"),
        )
    })?;
    Ok(match read {
        Some(read) => (read, DVec3::ZERO),
        None => {
            let s = voxlod::gltf::read_scene(&args.input).map_err(|e| in_file(&args.input, e))?;
            let read = AssetRead {
                asset: s.asset,
                warnings: s.warnings,
            };
            (read, s.origin)
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
    /// Whether the levels' files keep their looks (`.glb`, OBJ + MTL, coloured PLY).
    looks: bool,
}

impl Plan<'_> {
    /// Refuses outputs that would overwrite what they must not, before anything is written,
    /// and makes the folder.
    fn check(&self, out: &mut OutputSet, made: &voxlod::AssetLod) -> Result<(), CliError> {
        let names = self.names;
        for (k, level) in made.assets.iter().enumerate() {
            if self.level_files && level.asset.is_some() {
                out.check(&in_dir(&names.dir, &names.level(k, self.ext)))?;
                if self.ext == "obj" && self.looks {
                    out.check(&in_dir(&names.dir, &names.level(k, "mtl")))?;
                }
            }
        }
        if self.glb {
            out.check(&in_dir(&names.dir, &names.chain))?;
        }
        out.check(&in_dir(&names.dir, &names.report()))?;
        out.create_dir(&names.dir)?;
        Ok(())
    }

    /// Writes each level's own file where it gets one (with the files beside it: an OBJ's
    /// MTL and textures, a PLY's texture), lists them in `written`, and reports every level.
    fn write_levels(
        &self,
        out: &mut OutputSet,
        made: &voxlod::AssetLod,
        glb_options: &AssetGlbOptions,
        written: &mut Written,
    ) -> Result<Vec<AssetLevelReport>, CliError> {
        let (names, ext) = (self.names, self.ext);
        let mut levels = Vec::with_capacity(made.assets.len());
        let mut looks_files = Vec::new();
        for (k, (level, lod_level)) in made.assets.iter().zip(&made.lod.levels).enumerate() {
            let path = in_dir(&names.dir, &names.level(k, ext));
            let file = match (&level.asset, self.glb, self.looks) {
                (None, _, _) => None,
                (Some(asset), true, _) if self.level_files => {
                    let one = std::slice::from_ref(asset);
                    written.glb(out, &path, one, Some(k), glb_options)?;
                    Some(names.level(k, ext))
                }
                (Some(_), true, _) => Some(names.chain.clone()),
                (Some(asset), false, true) => {
                    let files = voxlod::io::asset_files(&path, asset)?;
                    for f in &files.files {
                        written.add(&f.path, Some(k), Some(f.bytes.len()), f.carries.clone());
                    }
                    let said = files.warnings.iter().map(|w| format!("level {k}: {w}"));
                    written.warnings.extend(said);
                    looks_files.push(files);
                    Some(names.level(k, ext))
                }
                (Some(_), false, false) => {
                    out.mesh(&path, &lod_level.mesh)?;
                    let mut carries = vec!["triangles".to_string()];
                    if !lod_level.mesh.normals.is_empty() {
                        carries.push("normals".into());
                    }
                    written.add(&path, Some(k), None, carries);
                    Some(names.level(k, ext))
                }
            };
            let budget = made.lod.budgets.get(k).cloned();
            levels.push(AssetLevelReport {
                level: k,
                file,
                vertices: lod_level.mesh.positions.len(),
                triangles: budget.is_none().then_some(lod_level.mesh.triangles.len()),
                looks: match (self.looks, level.looks) {
                    (false, _) => "dropped",
                    (true, Looks::Kept) => "kept",
                    (true, Looks::Transferred) => "transferred",
                    (true, Looks::Baked) => "baked",
                },
                materials: level.asset.as_ref().map_or(0, |a| a.materials.len()),
                budget,
            });
        }
        let staged: Vec<&voxlod::io::AssetFiles> = looks_files.iter().collect();
        voxlod::io::stage_assets(out, &staged)?;
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
