//! `voxlod proxy SCENE -o OUT.glb --triangles A,B,…`: one proxy for a whole scene
//! (`voxlod::proxy`): the scene's parts as one solid, levels by budget made by the voxel method
//! and the quadric stage, each baked with one material and one texture set, written as one
//! `.glb` in either level layout; the report gives per level its triangles, draw calls,
//! texture size, charts, texel utilisation and its appearance against the scene.

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::{Args, ValueEnum};
use serde::Serialize;
use voxlod::asset::{AlphaMode, Asset};
use voxlod::bake::ImageFormat;
use voxlod::core::glam::DVec3;
use voxlod::gltf::AssetGlbOptions;
use voxlod::io::OutputSet;
use voxlod::{Control, Progress, ProxyOptions};
use voxlod_eval::appearance::{AppearanceOptions, AppearanceReference};
use voxlod_eval::evaluate::draw_calls;

use super::common::{in_file, print_json, progress, say, CliError};
use super::lod_asset::LayoutArg;
use super::lod_glb::CompressArg;
use super::values::number;

/// One proxy for a whole scene, its looks baked: one mesh, one material, one draw call a level.
///
/// Every part and instance of a glTF scene (or of an OBJ, PLY or OFF asset, or of every mesh
/// and glTF file in a folder, placed as they are) is sampled as one solid and remeshed by the
/// voxel method at each triangle budget (parts merge, gaps narrower than a voxel close, what
/// is hidden inside goes, the genus drops), then given a UV atlas and textures cast from the
/// scene: base colour, tangent-space normals,
/// occlusion-roughness-metallic and emissive where the scene has them. Closed parts are
/// sampled as solids and open parts (leaf cards, fences, cloth) as thin shells around them,
/// so that they do not vanish; their alpha masks are baked.
///
/// Examples:
///   voxlod proxy street.glb -o street-proxy.glb --triangles 5000,1000,250
///   voxlod proxy machine.gltf -o proxy.glb --triangles 2000 --texture 2048 --layout lod-nodes
///   voxlod proxy yard.glb -o yard-proxy.glb --triangles 800 --close-gaps 0.5 --hard-edges 40
///   voxlod proxy spot.obj -o spot-proxy.glb --triangles 500 --json
///   voxlod proxy props/ -o props-proxy.glb --triangles 1000    # every mesh in the folder
///   voxlod proxy block.glb -o block-proxy.glb --triangles 4000,800 --screen-size 1200,300
///   voxlod proxy city.glb -o city-web.glb --triangles 3000 --images jpeg --jpeg-quality 85
#[derive(Args, Debug)]
#[command(verbatim_doc_comment)]
pub struct ProxyArgs {
    /// The scene: a glTF file (.glb, .gltf: every node, instance and material), an asset with
    /// its looks (.obj with .mtl, .ply or .off with vertex colours, .stl), or a folder of them
    /// (read in the order of their names, each in its own coordinates; subfolders are not read)
    pub input: PathBuf,
    /// The .glb to write, every level in it
    #[arg(short, long, value_name = "OUT.glb")]
    pub output: PathBuf,
    /// Triangle budgets, one level each (e.g. 5000,1000,250), each within 10 %
    #[arg(long, value_name = "N,N,...", value_delimiter = ',', required = true,
        value_parser = number::<usize>, allow_hyphen_values = true)]
    pub triangles: Vec<usize>,
    /// Texels a side of each level's textures (16 to 16384)
    #[arg(long, value_name = "TEXELS", default_value_t = 1024,
        value_parser = number::<u32>, allow_hyphen_values = true)]
    pub texture: u32,
    /// Texels per scene unit along the surface instead of a fixed --texture size: each
    /// level's texture is as large as its charts need at that density (at most 16384)
    #[arg(long, value_name = "TEXELS_PER_UNIT", conflicts_with = "texture",
        value_parser = number::<f32>, allow_hyphen_values = true)]
    pub texel_density: Option<f32>,
    /// Pixels across which each level is drawn, one per --triangles value (e.g.
    /// 800,200,60: the scene's bounding sphere that many pixels wide on screen), instead of
    /// a fixed --texture size: each level's textures get about one texel per pixel there,
    /// as large as its charts need
    #[arg(long, value_name = "PIXELS,...", value_delimiter = ',',
        conflicts_with_all = ["texture", "texel_density"],
        value_parser = number::<u32>, allow_hyphen_values = true)]
    pub screen_size: Vec<u32>,
    /// Close gaps between parts narrower than this distance (scene units): a fence's
    /// pickets or a shelf's books become one surface. By default only gaps under about a
    /// voxel of the level close
    #[arg(long, value_name = "DISTANCE", value_parser = number::<f64>,
        allow_hyphen_values = true)]
    pub close_gaps: Option<f64>,
    /// Edges of a level that bend by more than this angle (degrees, 0 to 180) are hard:
    /// split normals and a chart border there; smaller bends are shaded smooth
    #[arg(long, value_name = "DEGREES", default_value_t = 60.0,
        value_parser = number::<f32>, allow_hyphen_values = true)]
    pub hard_edges: f32,
    /// How the levels sit in the .glb. msft-lod: one node switching levels with MSFT_lod;
    /// lod-nodes: one node per level named LOD0, LOD1, … (Blender, Unity, Unreal, three.js)
    #[arg(long, value_enum, default_value = "msft-lod")]
    pub layout: LayoutArg,
    /// Compress the levels' geometry (textures stay as --images says)
    #[arg(long, value_enum, value_name = "METHOD")]
    pub compress: Option<CompressArg>,
    /// How the textures are stored: png (lossless), or jpeg (base colour, ORM and emissive as
    /// JPEG). JPEG is what web and game pipelines expect, and smaller where textures have
    /// grain (photographs, scans; flat colours are smaller as PNG); the normal map stays PNG,
    /// since JPEG's 8×8 blocks would show as shading faults, and so does a base colour whose
    /// alpha masks or blends
    #[arg(long, value_enum, default_value = "png")]
    pub images: ImagesArg,
    /// JPEG quality with --images jpeg, 1 (smallest) to 100 (closest); default 90, where
    /// block artefacts are hard to see on colour maps
    #[arg(long, value_name = "Q", value_parser = number::<u32>, allow_hyphen_values = true)]
    pub jpeg_quality: Option<u32>,
    /// Where the scene lets light through (leaf cards, fences: materials that mask or blend by
    /// alpha), each texel's opacity is measured by this many view rays through the level,
    /// and the level is drawn blended, showing the mean of what the scene shows through it.
    /// 0: a texel takes the alpha of the point its bake ray finds, masked as the scene is.
    /// Default 4; 0 to 256
    #[arg(long, value_name = "RAYS", value_parser = number::<u32>, allow_hyphen_values = true)]
    pub opacity_rays: Option<u32>,
    /// Keep the parts that none of 64 views around the scene sees (by default they are
    /// dropped, and levels are measured against what is seen)
    #[arg(long)]
    pub keep_hidden: bool,
    /// Let the genus rise from a level to the next
    #[arg(long)]
    pub no_monotone: bool,
    /// Leave each level's vertices where the voxel method put them (by default they are
    /// fitted to the scene's surface where that measures closer)
    #[arg(long)]
    pub no_fit: bool,
    /// Skip the appearance measure (the scene and every level rendered from 14 views)
    #[arg(long)]
    pub no_appearance: bool,
    /// Print the report as JSON on standard output (no progress bar)
    #[arg(long)]
    pub json: bool,
}

/// How `--images` stores the baked textures.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ImagesArg {
    /// Lossless PNG for every texture
    Png,
    /// JPEG for base colour, ORM and emissive; PNG for the normal map and a base colour with
    /// alpha
    Jpeg,
}

/// The JPEG quality `--images jpeg` takes without `--jpeg-quality`.
const JPEG_QUALITY: u8 = 90;

/// The report of a proxy run.
#[derive(Serialize)]
struct ProxyReport {
    input: String,
    output: String,
    bytes: usize,
    layout: &'static str,
    /// Draw calls of the scene: one per material its triangles use.
    input_draw_calls: usize,
    input_triangles: usize,
    /// Parts no view saw, dropped (0 with --keep-hidden).
    hidden_parts: usize,
    /// The world point the levels' positions are relative to, for a glTF scene far from the
    /// origin (absent otherwise); the `.glb`'s level nodes carry it as their translation.
    #[serde(skip_serializing_if = "Option::is_none")]
    origin: Option<[f64; 3]>,
    levels: Vec<LevelReport>,
    total_seconds: f64,
    /// Every warning, also printed on standard error without --json.
    warnings: Vec<String>,
}

#[derive(Serialize)]
struct LevelReport {
    level: usize,
    budget: usize,
    triangles: usize,
    draw_calls: usize,
    method: &'static str,
    resolution: Option<usize>,
    /// Two-sided Hausdorff distance to the scene's surface, and as a fraction of its diagonal.
    hausdorff: f64,
    hausdorff_fraction: f64,
    genus: Option<i64>,
    components: usize,
    /// Pixels across which the level is drawn, with --screen-size.
    #[serde(skip_serializing_if = "Option::is_none")]
    screen_size: Option<u32>,
    /// The bake: texture size, charts, texel utilisation, texels that hit the scene.
    bake: voxlod::bake::BakeReport,
    /// PSNR (dB) and SSIM from 14 views against the scene, without --no-appearance.
    #[serde(skip_serializing_if = "Option::is_none")]
    psnr: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    ssim: Option<f64>,
    /// The level's making and bake.
    seconds: f64,
}

/// Reads the scene, makes its proxy levels and writes them.
pub fn run(args: ProxyArgs) -> Result<(), CliError> {
    let start = Instant::now();
    check_values(&args)?;
    let images = image_format(&args)?;
    let mut out = OutputSet::protecting([&args.input]);
    out.check(&args.output)?;
    let (scene, mut warnings, origin) = read_scene(&args.input)?;
    let options = options_of(&args, images, &scene, &mut warnings);
    let bar = progress(args.triangles.len() as u64, "levels", args.json);
    let show = |p: Progress| {
        match p.event {
            voxlod::Event::Step {
                what: "atlases", ..
            } => bar.set_message("atlases"),
            voxlod::Event::Step { what: "bake", .. } => {
                bar.set_message("levels baked");
                bar.inc(1);
            }
            _ => {}
        }
        Control::Continue
    };
    let made = voxlod::proxy_with(&scene, &options, &show).map_err(|e| in_file(&args.input, e))?;
    bar.finish_and_clear();
    warnings.extend(made.warnings.iter().cloned());
    let measured = appearance(&args, &scene, &made)?;
    let levels: Vec<Asset> = made.levels.iter().map(|l| l.asset.clone()).collect();
    let glb = AssetGlbOptions {
        layout: args.layout.layout(),
        name: stem(&args.input),
        compression: CompressArg::compression(args.compress),
        origin,
        ..AssetGlbOptions::default()
    };
    let bytes = voxlod::gltf::asset_glb(&levels, &glb).map_err(|e| in_file(&args.output, e))?;
    out.bytes(&args.output, &bytes)?;
    out.commit()?;
    let report = ProxyReport {
        input: args.input.display().to_string(),
        output: args.output.display().to_string(),
        bytes: bytes.len(),
        layout: args.layout.name(),
        input_draw_calls: draw_calls(&scene),
        input_triangles: scene.mesh.triangles.len(),
        hidden_parts: made.input.hidden_parts,
        origin: (origin != DVec3::ZERO).then(|| origin.to_array()),
        levels: level_reports(&made, measured, &args.screen_size),
        total_seconds: start.elapsed().as_secs_f64(),
        warnings,
    };
    if args.json {
        return print_json(&report);
    }
    for w in &report.warnings {
        eprintln!("warning: {w}");
    }
    for l in &report.levels {
        say(describe(l));
    }
    say(format_args!(
        "{} levels ({} draw call each, the scene {}) in {:.2} s -> {}",
        report.levels.len(),
        1,
        report.input_draw_calls,
        report.total_seconds,
        report.output
    ));
    Ok(())
}

/// The library's options from the flags, for `scene`; a flag that does not apply to it is
/// said in `warnings`.
fn options_of(
    args: &ProxyArgs,
    images: ImageFormat,
    scene: &Asset,
    warnings: &mut Vec<String>,
) -> ProxyOptions {
    let mut options = ProxyOptions {
        monotone: !args.no_monotone,
        fit: (!args.no_fit).then(voxlod::FitOptions::quick),
        close_gaps: args.close_gaps,
        drop_hidden: !args.keep_hidden,
        ..ProxyOptions::for_triangles(&args.triangles, args.texture)
    };
    if let Some(density) = args.texel_density {
        options.bake.atlas.texture = voxlod::bake::TextureSize::Density(density);
    }
    options.screen_sizes = args.screen_size.clone();
    options.bake.atlas.crease_degrees = args.hard_edges;
    options.bake.images = images;
    if let Some(rays) = args.opacity_rays {
        options.bake.opacity_rays = rays;
        let see_through = (scene.materials.iter()).any(|m| m.alpha_mode != AlphaMode::Opaque);
        if !see_through {
            warnings.push(format!(
                "--opacity-rays {rays} does not apply: no material of {} masks or blends",
                args.input.display()
            ));
        }
    }
    options
}

/// Refuses flag values no run can honour (exit 2), before any work: an output that is not
/// `.glb`, a texture side, rays, angles, gap widths and densities out of range.
fn check_values(args: &ProxyArgs) -> Result<(), CliError> {
    let is_glb = (args.output.extension()).is_some_and(|e| e.eq_ignore_ascii_case("glb"));
    if !is_glb {
        return Err(CliError::usage(format!(
            "-o {}: a proxy is written as one .glb (its textures inside); name it OUT.glb",
            args.output.display()
        )));
    }
    if !(16..=16384).contains(&args.texture) {
        return Err(CliError::usage(format!(
            "--texture {}: a side of 16 to 16384 texels",
            args.texture
        )));
    }
    if let Some(rays) = args.opacity_rays.filter(|&r| r > 256) {
        return Err(CliError::usage(format!(
            "--opacity-rays {rays}: 0 to 256 rays a texel"
        )));
    }
    if !(0.0..=180.0).contains(&args.hard_edges) {
        let a = args.hard_edges;
        return Err(CliError::usage(format!(
            "--hard-edges {a}: an angle of 0 to 180 degrees"
        )));
    }
    if let Some(d) = args.texel_density.filter(|d| !(d.is_finite() && *d > 0.0)) {
        return Err(CliError::usage(format!(
            "--texel-density {d}: texels per scene unit, a positive number"
        )));
    }
    let sizes = &args.screen_size;
    if !sizes.is_empty() && sizes.len() != args.triangles.len() {
        let (n, m) = (sizes.len(), args.triangles.len());
        return Err(CliError::usage(format!(
            "--screen-size: {n} sizes for {m} budgets; give one per --triangles value"
        )));
    }
    if sizes.contains(&0) {
        return Err(CliError::usage(
            "--screen-size 0: a level is drawn at least one pixel across",
        ));
    }
    if let Some(g) = args.close_gaps.filter(|g| !(g.is_finite() && *g > 0.0)) {
        return Err(CliError::usage(format!(
            "--close-gaps {g}: a gap width, a positive distance in scene units"
        )));
    }
    Ok(())
}

/// The texture format `--images` and `--jpeg-quality` ask for; a quality outside 1 to 100, or
/// given without `--images jpeg` (it would be ignored), is a usage error naming the flags.
fn image_format(args: &ProxyArgs) -> Result<ImageFormat, CliError> {
    let quality = match args.jpeg_quality {
        Some(q) if !(1..=100).contains(&q) => {
            return Err(CliError::usage(format!(
                "--jpeg-quality {q}: a quality of 1 to 100"
            )));
        }
        q => q.map(|q| q as u8),
    };
    match (args.images, quality) {
        (ImagesArg::Png, None) => Ok(ImageFormat::Png),
        (ImagesArg::Png, Some(q)) => Err(CliError::usage(format!(
            "--jpeg-quality {q} applies to JPEG textures only: add --images jpeg, or leave \
             --jpeg-quality out"
        ))),
        (ImagesArg::Jpeg, q) => Ok(ImageFormat::Jpeg {
            quality: q.unwrap_or(JPEG_QUALITY),
        }),
    }
}

/// The scene as one asset ([`voxlod::read_scene`]: a glTF file, a folder of meshes, or one
/// mesh with its looks), with the readers' warnings and the world point its positions are
/// relative to.
fn read_scene(path: &Path) -> Result<(Asset, Vec<String>, DVec3), CliError> {
    let read = voxlod::read_scene(path)?;
    Ok((read.asset, read.warnings, read.origin))
}

/// PSNR and SSIM of each level against the scene from 14 views at 256², unless skipped.
fn appearance(
    args: &ProxyArgs,
    scene: &Asset,
    made: &voxlod::Proxy,
) -> Result<Vec<Measured>, CliError> {
    if args.no_appearance {
        return Ok(vec![None; made.levels.len()]);
    }
    let options = AppearanceOptions {
        views: 14,
        size: 256,
        supersample: 1,
    };
    let reference = AppearanceReference::new(scene, &options).map_err(measure_error)?;
    let compare = |asset: &Asset| {
        let r = reference.compare(asset).map_err(measure_error)?;
        Ok(Some((r.psnr, r.ssim)))
    };
    made.levels.iter().map(|l| compare(&l.asset)).collect()
}

/// A failure of the appearance measure, its class kept.
fn measure_error(e: voxlod::render::RenderError) -> CliError {
    CliError::Library(voxlod::Error::from(e).context("the appearance measure"))
}

/// PSNR and SSIM of a level, when measured.
type Measured = Option<(f64, f64)>;

fn level_reports(
    made: &voxlod::Proxy,
    measured: Vec<Measured>,
    screen_sizes: &[u32],
) -> Vec<LevelReport> {
    let levels = made.levels.iter().zip(measured).enumerate();
    let report = |(i, (l, m))| level_report(i, l, m, screen_sizes.get(i).copied());
    levels.map(report).collect()
}

fn level_report(
    i: usize,
    l: &voxlod::ProxyLevel,
    m: Measured,
    screen_size: Option<u32>,
) -> LevelReport {
    let r = &l.report;
    LevelReport {
        level: i,
        budget: r.budget,
        triangles: l.asset.mesh.triangles.len(),
        draw_calls: draw_calls(&l.asset),
        method: r.method.name(),
        resolution: r.resolution,
        hausdorff: r.hausdorff,
        hausdorff_fraction: r.hausdorff_fraction,
        genus: r.genus,
        components: r.components,
        screen_size,
        bake: l.bake.clone(),
        psnr: m.map(|m| m.0),
        ssim: m.map(|m| m.1),
        seconds: r.seconds + l.bake.seconds,
    }
}

fn stem(path: &Path) -> String {
    path.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// One line per level: budget, what came out, the bake, the appearance.
fn describe(l: &LevelReport) -> String {
    let b = &l.bake;
    let looks = match (l.psnr, l.ssim) {
        (Some(p), Some(s)) => format!(", PSNR {p:.2} dB, SSIM {s:.4}"),
        _ => String::new(),
    };
    format!(
        "level {}: budget {}: {} triangles ({} at resolution {}), Hausdorff {:.2} % of the \
         diagonal; {}×{} texels, {} charts, {:.0} % of the texels used{looks}",
        l.level,
        l.budget,
        l.triangles,
        l.method,
        l.resolution.map_or("-".into(), |r| r.to_string()),
        100.0 * l.hausdorff_fraction,
        b.width,
        b.height,
        b.charts,
        100.0 * b.utilisation,
    )
}
