//! `voxlod layers`: multi-layer translucent shells (paper §3) as a layered `.glb` (or PLY/VTK).

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;
use glam::DVec3;
use serde::Serialize;
use voxlod::asset::Asset;
use voxlod::core::TriangleMesh;
use voxlod::io::OutputSet;
use voxlod::layers::{
    bake_layers, has_base_colour, BakedLayers, Blending, GlbOptions, Layered, LayersOptions,
    LooksOptions, PlanOptions, DEFAULT_TEXTURE, ORDER_NAMES,
};
use voxlod::sampling::Filter;

use super::camera::CameraArgs;
use super::common::say;
use super::common::{in_file, print_json, progress, thousands, CliError, Input};
use super::layers_lod::{ChainReport, LodArgs};
use super::lod_asset::is_gltf;
use super::source::{in_flag_words, VolumeRoute};
use super::values::{in_flags, number};

/// The library's options whose flags are not their names with hyphens.
const FLAGS: &[(&str, &str)] = &[("radius_voxels", "--radius")];

/// Build multi-layer translucent shells for antialiased rendering (He et al. 1995, §3).
///
/// Filters the input into one volume, chooses the fewest layers whose piecewise constant
/// profile is within --error of the filter's density profile (∫₀^R |p − d| dx ≤ E, x in units
/// of the filter radius R: the optimum, equations 4–6), extracts every layer as an isosurface
/// of the volume, each more translucent than the one inside it, and orders all triangles back
/// to front by traversing the volume's cells, for each of the eight octants of view direction.
///
/// OUT.glb holds one mesh per layer (innermost first) with an alpha-blended material, and the
/// eight orders as index accessors named order+x+y+z … order-x-y-z (see the README). OUT.ply,
/// .vtp or .vtk hold all layers in one mesh with per-vertex `opacity` and `layer`, triangles in
/// the back-to-front order of --view's octant.
///
/// An asset with looks (.glb or .gltf, an OBJ with its MTL and textures, a PLY or OFF with
/// vertex colours) gives its base colour to the layers of a .glb: each layer gets a texture
/// atlas and a base colour texture of --texture texels a side baked from the asset (a ray from
/// each texel finds the asset's surface), and its material is that texture with the layer's
/// alpha; with --lod, every level's layers. The paper's layers carry one colour; the bake is
/// voxlod's. A .ply/.vtp/.vtk output carries no looks (a warning says so).
///
/// With --lod, OUT.glb holds the layered shells at several resolutions (--levels halvings of
/// --resolution, or --resolutions) as one MSFT_lod chain: one mesh per level with a primitive
/// per layer and the level's eight orders (accessors "level K order+x+y+z" …); its
/// MSFT_screencoverage switches to the coarsest level whose filter radius spans at most 0.45 px
/// on screen, where the layers were measured to beat the single surface (BENCHMARKS.md).
///
/// Examples:
///   voxlod layers bunny.obj -o bunny.glb --error 0.025 --preview bunny.png
///   voxlod layers part.stl -o part.glb --error 0.01 --filter gaussian --resolution 200 --json
///   voxlod layers tooth.nrrd --threshold 120 -o tooth.vtp --error 0.05
///   voxlod layers bunny.obj -o bunny-chain.glb --lod --resolutions 256,128,64,32
///   voxlod layers statue.glb -o statue-layers.glb --error 0.05 --texture 1024
#[derive(Args, Debug)]
#[command(verbatim_doc_comment)]
pub struct LayersArgs {
    /// The input: a mesh (.obj .ply .stl .off .vtp .vtu .vtk), an asset with looks (.glb .gltf, or
    /// an OBJ, PLY or OFF with materials or colours), or a volume with --threshold
    pub input: PathBuf,
    /// Output: .glb (layers and the eight orders), or .ply .vtp .vtk (opacity, layer)
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    /// Error bound ε on ∫₀^R |p − d| dx in units of R (0.01 to 0.2 typical; smaller means more
    /// layers; the hyper-cone needs 5 layers for 0.025, 10 for 0.0104)
    #[arg(long, value_name = "E", default_value_t = 0.025,
        value_parser = number::<f64>, allow_hyphen_values = true)]
    pub error: f64,
    /// Samples across the longest side of the object
    #[arg(long, value_name = "N", default_value_t = 128,
        value_parser = number::<usize>, allow_hyphen_values = true)]
    pub resolution: usize,
    /// Low-pass filter: hypercone (paper eq. 3) or gaussian (σ = R/3)
    #[arg(long, default_value = "hypercone")]
    pub filter: Filter,
    /// Filter support radius R, in voxels
    #[arg(long, value_name = "VOXELS", default_value_t = 1.0,
        value_parser = number::<f64>, allow_hyphen_values = true)]
    pub radius: f64,
    /// Blend alphas: composited (the shells' back-to-front composite has translucency 1 − d/m
    /// along every ray) or direct (alpha = 1 − translucency for each layer on its own)
    #[arg(long, default_value = "composited")]
    pub blending: Blending,
    /// With an input that has looks and a .glb output: texels a side of each layer's baked
    /// base colour texture, 8 to 16384 [default: 512]
    #[arg(long, value_name = "N", value_parser = number::<u32>, allow_hyphen_values = true)]
    pub texture: Option<u32>,
    /// Also draw the layered shells to this PNG (one sample per pixel, stored order)
    #[arg(long, value_name = "PNG")]
    pub preview: Option<PathBuf>,
    // The preview's camera; its view direction also picks the octant of a PLY/VTK file's order.
    #[command(flatten)]
    pub camera: CameraArgs,
    /// Quadrature lines per filter radius
    #[arg(long, value_name = "Q", default_value_t = 4,
        value_parser = number::<usize>, allow_hyphen_values = true)]
    pub lines_per_radius: usize,
    /// Print the report as JSON on standard output
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub chain: LodArgs,
    #[command(flatten)]
    pub route: VolumeRoute,
}

#[derive(Serialize)]
struct LayerReport {
    index: usize,
    isodensity: f64,
    translucency: f64,
    alpha: f64,
    /// Distance of the layer outside the object's surface, in units of R.
    offset: f64,
    vertices: usize,
    triangles: usize,
}

#[derive(Serialize)]
struct LayersReport {
    input: String,
    output: String,
    preview: Option<String>,
    filter: Filter,
    radius_voxels: f64,
    resolution: usize,
    grid: [usize; 3],
    error_bound: f64,
    achieved_error: f64,
    blending: Blending,
    layers: Vec<LayerReport>,
    vertices: usize,
    triangles: usize,
    orders: [&'static str; 8],
    sample_seconds: f64,
    extract_seconds: f64,
    order_seconds: f64,
    total_seconds: f64,
    /// With --lod: the chain's levels, coverages and size (the fields above describe level 0).
    lod: Option<ChainReport>,
    /// With an input that has looks and a single .glb: each layer's baked base colour (the
    /// layers' `vertices` above are then the baked layers', split at chart seams).
    texture: Option<TextureReport>,
    /// Every warning printed without --json.
    warnings: Vec<String>,
}

/// The layers' baked base colour, for the report.
#[derive(Serialize)]
struct TextureReport {
    /// Texels a side of each layer's base colour texture.
    size: u32,
    /// Seconds of all the bakes.
    seconds: f64,
    /// Per layer with triangles.
    layers: Vec<BakedLayerReport>,
}

#[derive(Serialize)]
struct BakedLayerReport {
    index: usize,
    /// Charts of the layer's atlas.
    charts: usize,
    /// Covered texels over all texels.
    utilisation: f64,
    /// Covered texels whose ray missed the asset (its nearest point stood in).
    texels_fallback: usize,
    /// Seconds of the atlas (most of the bake).
    atlas_seconds: f64,
}

/// The kind of output, by extension.
#[derive(Clone, Copy)]
enum OutKind {
    Glb,
    Mesh,
}

fn out_kind(path: &Path) -> Result<OutKind, CliError> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "glb" => Ok(OutKind::Glb),
        "ply" | "vtp" | "vtk" => Ok(OutKind::Mesh),
        other => Err(CliError::usage(format!(
            "{}: '{}' is not a layers output: use .glb, .ply, .vtp or .vtk",
            path.display(),
            if other.is_empty() {
                "no extension"
            } else {
                other
            }
        ))),
    }
}

/// Refuses now the outputs the set would refuse at the end: the kind of OUT, the preview's, a
/// chain into another file than a .glb.
fn check_outputs(args: &LayersArgs, out: &mut OutputSet) -> Result<OutKind, CliError> {
    let kind = out_kind(&args.output)?;
    if args.chain.lod && matches!(kind, OutKind::Mesh) {
        return Err(CliError::usage(format!(
            "--lod writes an MSFT_lod chain: {} must be a .glb",
            args.output.display()
        )));
    }
    out.check(&args.output)?;
    if let Some(preview) = &args.preview {
        voxlod::io::check_image_path(preview)?;
        out.check(preview)?;
    }
    Ok(kind)
}

/// Refuses --texture out of range or where it can never apply (a mesh file or a chain).
fn check_texture(args: &LayersArgs, kind: OutKind) -> Result<(), CliError> {
    let Some(n) = args.texture else {
        return Ok(());
    };
    if !(8..=voxlod::bake::atlas::MAX_TEXTURE).contains(&n) {
        let max = voxlod::bake::atlas::MAX_TEXTURE;
        return Err(CliError::usage(format!(
            "--texture {n}: must be 8 to {max} texels"
        )));
    }
    if matches!(kind, OutKind::Mesh) {
        return Err(CliError::usage(format!(
            "--texture: {} holds no textures; bake the layers' looks into a .glb",
            args.output.display()
        )));
    }
    Ok(())
}

/// What the layers are made from: their geometry, and the asset whose base colour they take
/// when it has one.
struct LayersInput {
    geometry: Geometry,
    /// The asset, when it has a base colour to bake (`voxlod::layers::has_base_colour`).
    looks: Option<Asset>,
    /// What the asset's reader warned of.
    warnings: Vec<String>,
}

/// The input's geometry.
enum Geometry {
    /// A mesh or a volume, read as the other commands read them.
    Read(Input),
    /// A glTF asset's triangles.
    Asset(TriangleMesh),
}

impl LayersInput {
    /// The library's source of the layers' solid.
    fn source<'a>(&'a self, route: &VolumeRoute) -> voxlod::Source<'a> {
        match &self.geometry {
            Geometry::Read(input) => route.source(input),
            Geometry::Asset(mesh) => voxlod::Source::Mesh(mesh),
        }
    }
}

/// Reads the layers' input: a glTF file as an asset; anything else as the other commands read
/// it, and an OBJ, PLY or OFF mesh also as an asset for its looks (where that reader fails, a
/// warning says so and the layers carry one colour). Cost: an OBJ, PLY or OFF is read twice.
fn read_layers_input(args: &LayersArgs) -> Result<LayersInput, CliError> {
    let path = &args.input;
    if is_gltf(path) {
        if let Err(e) = std::fs::metadata(path) {
            let kind = voxlod::io::IoErrorKind::Access;
            return Err(voxlod::io::IoError::new(path, kind, format!("cannot open: {e}")).into());
        }
        let mut read = voxlod::gltf::read_scene(path).map_err(|e| in_file(path, e))?;
        if read.origin != voxlod::core::glam::DVec3::ZERO {
            let [x, y, z] = read.origin.to_array();
            read.warnings.push(format!(
                "the layers are written relative to the scene's origin ({x}, {y}, {z}): \
                 place them there"
            ));
        }
        return Ok(LayersInput {
            geometry: Geometry::Asset(read.asset.mesh.geometry()),
            looks: has_base_colour(&read.asset).then_some(read.asset),
            warnings: read.warnings,
        });
    }
    let input = args.route.read(path)?;
    let mesh_with_looks = matches!(input, Input::Mesh(_))
        && path.extension().is_some_and(|e| {
            let e = e.to_ascii_lowercase();
            e == "obj" || e == "ply" || e == "off"
        });
    let mut out = LayersInput {
        geometry: Geometry::Read(input),
        looks: None,
        warnings: Vec::new(),
    };
    if mesh_with_looks {
        match voxlod::io::read_asset(path) {
            Ok(read) if has_base_colour(&read.asset) => {
                out.looks = Some(read.asset);
                out.warnings = read.warnings;
            }
            Ok(_) => {}
            Err(e) => out.warnings.push(format!(
                "its looks could not be read ({e}): the layers carry one colour"
            )),
        }
    }
    Ok(out)
}

/// The warning for looks that the output does not carry, or --texture without looks.
fn looks_warning(args: &LayersArgs, has_looks: bool, kind: OutKind) -> Option<String> {
    let input = args.input.display();
    match (has_looks, kind) {
        (false, _) => args.texture.map(|_| {
            format!(
                "--texture: {input} has no base colour to bake (no vertex colours, base colour \
                 texture or coloured material): the layers carry one colour"
            )
        }),
        (true, OutKind::Mesh) => Some(format!(
            "{} holds no textures: the layers carry none of {input}'s looks (a .glb output \
             bakes them)",
            args.output.display()
        )),
        (true, OutKind::Glb) => args.preview.as_ref().map(|_| {
            "--preview draws the layers in one colour, without their baked textures".to_string()
        }),
    }
}

/// The layers baked with the input's looks, when they have looks and go to a single layered
/// .glb (a chain's levels are baked as the chain is made, [`looks_options`]); with the seconds
/// the bakes took.
fn bake(
    args: &LayersArgs,
    input: &LayersInput,
    kind: OutKind,
    layered: &Layered,
) -> Result<Option<(BakedLayers, f64)>, voxlod::Error> {
    let Some(asset) = &input.looks else {
        return Ok(None);
    };
    if args.chain.lod || matches!(kind, OutKind::Mesh) {
        return Ok(None);
    }
    let start = Instant::now();
    let baked = bake_layers(asset, &layered.mesh, &looks_options(args))?;
    Ok(Some((baked, start.elapsed().as_secs_f64())))
}

/// How the layers' looks are baked: --texture texels a side, rays as far as the filter.
fn looks_options(args: &LayersArgs) -> LooksOptions {
    LooksOptions {
        texture: args.texture.unwrap_or(DEFAULT_TEXTURE),
        radius_voxels: args.radius,
    }
}

/// The bakes in the report: each baked layer's atlas, and the layers' vertices as written.
fn add_texture(report: &mut LayersReport, (baked, seconds): &(BakedLayers, f64), size: u32) {
    let mut layers = Vec::new();
    for (index, (layer, look)) in baked.mesh.layers.iter().zip(&baked.looks).enumerate() {
        report.layers[index].vertices = layer.mesh.positions.len();
        if let Some(look) = look {
            layers.push(BakedLayerReport {
                index,
                charts: look.report.charts,
                utilisation: look.report.utilisation,
                texels_fallback: look.report.texels_fallback,
                atlas_seconds: look.report.atlas_seconds,
            });
        }
    }
    report.vertices = baked.mesh.vertex_count();
    report.warnings.extend(baked.warnings.iter().cloned());
    report.texture = Some(TextureReport {
        size,
        seconds: *seconds,
        layers,
    });
}

/// The library's options from the flags, refused before any work when out of range (with
/// --lod, at every level's resolution).
fn layers_options(
    args: &LayersArgs,
    resolutions: Option<&[usize]>,
) -> Result<LayersOptions, CliError> {
    let options = LayersOptions {
        resolution: args.resolution,
        radius_voxels: args.radius,
        plan: PlanOptions {
            blending: args.blending,
            ..PlanOptions::new(args.filter, args.error)
        },
        lines_per_radius: args.lines_per_radius,
        extract: Default::default(),
    };
    match resolutions {
        Some(list) => voxlod::check_layers_levels(&options, list),
        None => voxlod::check_layers_options(&options).map(|_| ()),
    }
    .map_err(|e| in_flags(e, FLAGS))?;
    Ok(options)
}

/// The library's failure to make `path`, in the flags' words.
fn failed_on(path: &Path) -> impl Fn(voxlod::Error) -> CliError + '_ {
    move |e| in_flags(e.in_file(path), FLAGS)
}

/// Adds the shells (or the chain's bytes, with --lod) and the preview to the output set, all
/// encoded before anything is written.
fn write_outputs(
    args: &LayersArgs,
    out: &mut OutputSet,
    (kind, chain): (OutKind, Option<Vec<u8>>),
    view: DVec3,
    (layered, baked): (&Layered, Option<&BakedLayers>),
) -> Result<(), CliError> {
    let bytes = match (kind, chain, baked) {
        (_, Some(chain), _) => Some(chain),
        (OutKind::Glb, None, Some(baked)) => {
            let options = GlbOptions {
                radius: Some(voxlod::layers_radius(layered, args.radius)),
                ..Default::default()
            };
            let bytes = voxlod::layers::baked_glb_bytes(baked, &layered.orders, &options);
            Some(bytes.map_err(|e| failed_on(&args.output)(e.into()))?)
        }
        (OutKind::Glb, None, None) => {
            Some(voxlod::layered_glb(layered, args.radius).map_err(failed_on(&args.output))?)
        }
        (OutKind::Mesh, None, _) => None,
    };
    let preview = match &args.preview {
        Some(path) => {
            let size = args.camera.size;
            let png = voxlod::layered_preview(layered, view, size.width, size.height)
                .and_then(|image| Ok(image.to_png()?))
                .map_err(failed_on(path))?;
            Some((path, png))
        }
        None => None,
    };
    // The shells and the preview appear together or not at all.
    match bytes {
        Some(b) => out.bytes(&args.output, &b)?,
        None => {
            let poly = voxlod::layered_poly_mesh(layered, view).map_err(failed_on(&args.output))?;
            out.poly_mesh(&args.output, &poly)?
        }
    }
    if let Some((path, png)) = &preview {
        out.png(path, png)?;
    }
    Ok(())
}

pub fn run(args: LayersArgs) -> Result<(), CliError> {
    let start = Instant::now();
    // Everything that can be refused is refused before any work.
    let mut out = OutputSet::protecting([&args.input]);
    let kind = check_outputs(&args, &mut out)?;
    check_texture(&args, kind)?;
    let view = DVec3::from(args.camera.view);
    voxlod::view_direction(view).map_err(|e| in_flags(e, FLAGS))?;
    let resolutions = args.chain.resolutions(args.resolution)?;
    let mut options = layers_options(&args, resolutions.as_deref())?;
    let input = read_layers_input(&args)?;
    let bar = progress(3, "layers", args.json);
    let source = input.source(&args.route);
    let failed = |e: voxlod::Error| in_flags(e.in_file(&args.input), FLAGS);
    let mut chain_warnings = Vec::new();
    let (shells, chain, lod) = match &resolutions {
        Some(list) => {
            let looks = looks_options(&args);
            let looks = input.looks.as_ref().map(|asset| (asset, &looks));
            let mut chain = voxlod::layers_chain(&source, &options, list, looks).map_err(failed)?;
            chain_warnings.extend(chain.baked.iter().enumerate().flat_map(|(k, b)| {
                let warnings = b.iter().flat_map(|b| b.warnings.iter());
                warnings.map(move |w| format!("chain level {k}: {w}"))
            }));
            let report = ChainReport::of(&chain, list);
            options.resolution = list[0];
            let bytes = std::mem::take(&mut chain.bytes);
            (chain.levels.swap_remove(0), Some(bytes), Some(report))
        }
        None => (
            voxlod::layers(&source, &options).map_err(failed)?,
            None,
            None,
        ),
    };
    bar.inc(2);
    if input.looks.is_some() {
        bar.set_message("baking looks");
    }
    let baked = bake(&args, &input, kind, &shells.layered).map_err(failed)?;
    let layers = (&shells.layered, baked.as_ref().map(|b| &b.0));
    write_outputs(&args, &mut out, (kind, chain), view, layers)?;
    out.commit()?;
    bar.finish_and_clear();
    let mut warnings: Vec<String> = shells.warnings.iter().map(|w| in_flag_words(w)).collect();
    warnings.extend(
        input
            .warnings
            .iter()
            .map(|w| format!("{}: {w}", args.input.display())),
    );
    warnings.extend(looks_warning(&args, input.looks.is_some(), kind));
    warnings.extend(chain_warnings);
    let mut report = LayersReport {
        warnings,
        resolution: options.resolution,
        lod,
        ..report(&args, &shells.layered, start.elapsed().as_secs_f64())
    };
    if let Some(baked) = &baked {
        add_texture(&mut report, baked, args.texture.unwrap_or(DEFAULT_TEXTURE));
    }
    if args.json {
        return print_json(&report);
    }
    print_report(&args, &report);
    Ok(())
}

/// The warnings on standard error; the layers and the files on standard output.
fn print_report(args: &LayersArgs, report: &LayersReport) {
    for w in &report.warnings {
        eprintln!("warning: {w}");
    }
    say(format_args!(
        "{}: {} layers (achieved error {:.5} ≤ {}), {} triangles -> {}",
        args.input.display(),
        report.layers.len(),
        report.achieved_error,
        report.error_bound,
        thousands(report.triangles),
        args.output.display()
    ));
    for l in &report.layers {
        say(format_args!(
            "  layer {}: isodensity {:.4}, translucency {:.3}, alpha {:.3}, {} triangles",
            l.index,
            l.isodensity,
            l.translucency,
            l.alpha,
            thousands(l.triangles)
        ));
    }
    if let Some(chain) = &report.lod {
        for l in &chain.levels {
            say(format_args!(
                "  chain level {}: resolution {}, filter radius {:.4}, {} layers, {} triangles",
                l.level,
                l.resolution,
                l.radius,
                l.layers,
                thousands(l.triangles)
            ));
        }
    }
    if let Some(t) = &report.texture {
        let charts: usize = t.layers.iter().map(|l| l.charts).sum();
        say(format_args!(
            "  base colour baked onto {} layers: {}² texels each, {charts} charts, {:.2} s",
            t.layers.len(),
            t.size,
            t.seconds
        ));
    }
    if let Some(p) = &report.preview {
        say(format_args!("preview -> {p}"));
    }
}

fn report(args: &LayersArgs, layered: &Layered, total_seconds: f64) -> LayersReport {
    let layers = layered
        .plan
        .layers
        .iter()
        .zip(&layered.mesh.layers)
        .enumerate()
        .map(|(index, (p, l))| LayerReport {
            index,
            isodensity: p.isodensity,
            translucency: p.translucency,
            alpha: p.alpha,
            offset: p.offset,
            vertices: l.mesh.positions.len(),
            triangles: l.mesh.triangles.len(),
        })
        .collect();
    let t = &layered.timings;
    LayersReport {
        input: args.input.display().to_string(),
        output: args.output.display().to_string(),
        preview: args.preview.as_ref().map(|p| p.display().to_string()),
        filter: layered.plan.filter,
        radius_voxels: args.radius,
        resolution: args.resolution,
        grid: layered.mesh.grid.dims,
        error_bound: args.error,
        achieved_error: layered.plan.achieved_error,
        blending: layered.plan.blending,
        layers,
        vertices: layered.mesh.vertex_count(),
        triangles: layered.mesh.triangle_count(),
        orders: ORDER_NAMES,
        sample_seconds: t.sample_seconds,
        extract_seconds: t.extract_seconds,
        order_seconds: t.order_seconds,
        total_seconds,
        lod: None,
        texture: None,
        warnings: Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use clap::Parser;

    use crate::commands::{run, Cli};

    /// A closed input mesh: the bolt's surface at a coarse resolution.
    fn input(dir: &Path) -> std::path::PathBuf {
        let solid = voxlod::sampling::CsgSolid::new(voxlod::layers::bolt()).unwrap();
        let options = voxlod::layers::LayersOptions {
            resolution: 24,
            ..Default::default()
        };
        let l = voxlod::layers::layer_solid(&solid, &options).unwrap();
        let path = dir.join("bolt.ply");
        voxlod::io::write_mesh(&path, &l.mesh.layers[0].mesh).unwrap();
        path
    }

    fn voxlod(args: &[&str]) -> Result<(), crate::commands::CliError> {
        let mut all = vec!["voxlod"];
        all.extend_from_slice(args);
        run(Cli::try_parse_from(all).map_err(|e| crate::commands::CliError::msg(e.to_string()))?)
    }

    #[test]
    fn layers_then_render_write_what_they_say() {
        let dir = tempfile::tempdir().unwrap();
        let mesh = input(dir.path());
        let d = |n: &str| dir.path().join(n).display().to_string();
        voxlod(&[
            "layers",
            &mesh.display().to_string(),
            "-o",
            &d("bolt.glb"),
            "--resolution",
            "32",
            "--error",
            "0.05",
            "--preview",
            &d("preview.png"),
            "--size",
            "64x48",
            "--json",
        ])
        .unwrap();
        let scene = voxlod_gltf::read_glb(&dir.path().join("bolt.glb")).unwrap();
        assert!(scene.is_layered());
        // ε = 0.05: three hyper-cone layers (0.0559 > 0.05 ≥ 0.0361).
        assert_eq!(scene.parts.len(), 3);
        let png = std::fs::read(dir.path().join("preview.png")).unwrap();
        let img = image::load_from_memory(&png).unwrap();
        assert_eq!((img.width(), img.height()), (64, 48));
        voxlod(&[
            "layers",
            &mesh.display().to_string(),
            "-o",
            &d("bolt.vtp"),
            "--resolution",
            "24",
        ])
        .unwrap();
        let poly = voxlod::io::read_poly_mesh(&dir.path().join("bolt.vtp")).unwrap();
        assert!(poly.vertex_attributes.iter().any(|a| a.name == "opacity"));
        let (glb, r) = (d("bolt.glb"), d("r.png"));
        for extra in [&[][..], &["--perspective"][..]] {
            let mut args = vec![
                "render",
                &glb,
                mesh.to_str().unwrap(),
                "-o",
                &r,
                "--size",
                "50x40",
                "--view",
                "0.3,-1,0.2",
            ];
            args.extend_from_slice(extra);
            voxlod(&args).unwrap();
            let img =
                image::load_from_memory(&std::fs::read(dir.path().join("r.png")).unwrap()).unwrap();
            assert_eq!((img.width(), img.height()), (50, 40));
        }
    }

    #[test]
    fn bad_input_fails_in_one_line_and_writes_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let mesh = input(dir.path());
        let m = mesh.display().to_string();
        let out = dir.path().join("out.glb").display().to_string();
        for (args, expect) in [
            (vec!["--error", "0"], "positive"),
            (vec!["--error", "-0.1"], "positive"),
            (vec!["--error", "1e-5"], "more than 64 layers"),
            (vec!["--view", "0,0,0"], "zero length"),
            (vec!["--resolution", "1"], "resolution"),
        ] {
            let mut all = vec!["layers", m.as_str(), "-o", out.as_str()];
            all.extend_from_slice(&args);
            let e = voxlod(&all).unwrap_err().to_string();
            assert!(e.contains(expect), "{args:?}: {e}");
            assert!(!e.contains('\n'), "{e}");
        }
        let png = dir.path().join("x.png").display().to_string();
        let e = voxlod(&["render", &m, "-o", &png, "--view", "0,0,0"])
            .unwrap_err()
            .to_string();
        assert!(e.contains("zero length"), "{e}");
        // Only the input is in the folder: no partial or temporary file.
        let names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names.len(), 1, "{names:?}");
    }
}
