//! `voxlod view`: one self-contained HTML page showing `.glb` files in a browser (crate
//! `voxlod-view`).

use std::path::PathBuf;

use clap::Args;
use serde::Serialize;
use voxlod::io::OutputSet;
use voxlod_view::{page_html, read_model, ViewError, ViewOptions};

use super::common::say;
use super::common::{print_json, CliError};

/// Write one HTML page that shows .glb files with WebGL2, with nothing to fetch at view time.
///
/// An MSFT_lod chain (voxlod lod --format glb), or one node per level named LOD0, LOD1, …
/// (--layout lod-nodes), switches levels by screen coverage as the camera moves (an overlay
/// names the level and its triangles); levels with looks are drawn with their base colour
/// textures (texture transforms, samplers), vertex colours, normal maps, emissive, and alpha
/// masks or blending, as voxlod lod writes an asset's levels and voxlod proxy its proxies
/// (meshopt-compressed files are decoded before the page is written); layered shells (voxlod
/// layers) are blended back to front in the stored order of the camera's octant while the
/// filter radius on screen is at most 0.45 px, else the single surface is drawn; other .glb
/// files are drawn with their lines and points. Drag to orbit, wheel to zoom, keys 1-9 pick a
/// file. The camera can be set in the address: page.html#camera=DISTANCE,DX,DY,DZ&model=I.
///
/// Examples:
///   voxlod lod bunny.obj -o bunny-lods --format glb && voxlod view bunny-lods/lod.glb -o bunny.html
///   voxlod view bunny-layers.glb bunny-lods/lod.glb -o both.html
///   voxlod proxy scene.glb -o proxy.glb --triangles 2000,500 && voxlod view proxy.glb -o proxy.html
#[derive(Args, Debug)]
#[command(verbatim_doc_comment)]
pub struct ViewArgs {
    /// The .glb files to show
    #[arg(required = true, value_name = "GLB")]
    pub inputs: Vec<PathBuf>,
    /// The HTML page to write
    #[arg(short, long, value_name = "HTML")]
    pub output: PathBuf,
    /// Print a JSON report on standard output
    #[arg(long)]
    pub json: bool,
}

#[derive(Serialize)]
struct ViewReport {
    output: String,
    bytes: usize,
    models: Vec<ModelReport>,
}

#[derive(Serialize)]
struct ModelReport {
    input: String,
    kind: &'static str,
    levels: usize,
    triangles: usize,
}

pub fn run(args: ViewArgs) -> Result<(), CliError> {
    let mut out = OutputSet::protecting(&args.inputs);
    out.check(&args.output)?;
    let models = args
        .inputs
        .iter()
        .map(|p| read_model(p))
        .collect::<Result<Vec<_>, _>>()
        .map_err(view_error)?;
    let html = page_html(&models, &ViewOptions::default()).map_err(view_error)?;
    out.text(&args.output, &html)?;
    out.commit()?;
    let report = ViewReport {
        output: args.output.display().to_string(),
        bytes: html.len(),
        models: models
            .iter()
            .zip(&args.inputs)
            .map(|(m, p)| ModelReport {
                input: p.display().to_string(),
                kind: match (m.glb.layered, m.glb.levels) {
                    (true, 1) => "layered",
                    (true, _) => "layered lod chain",
                    (false, 1) => "mesh",
                    _ => "lod chain",
                },
                levels: m.glb.levels,
                triangles: m.glb.triangles,
            })
            .collect(),
    };
    if args.json {
        print_json(&report)?;
    } else {
        say(format_args!(
            "{} ({} bytes, {} models)",
            report.output,
            report.bytes,
            report.models.len()
        ));
    }
    Ok(())
}

/// A page's failure with its class: a file's (unreadable: I/O; not a usable `.glb`: bad input),
/// a glTF failure's and the memory budget's as the library's, no input as a usage error.
fn view_error(e: ViewError) -> CliError {
    match e {
        ViewError::Io(e) => e.into(),
        ViewError::Core(e) => e.into(),
        ViewError::Gltf(e) => voxlod::Error::from(e).into(),
        ViewError::NoInput => CliError::usage(e.to_string()),
    }
}
