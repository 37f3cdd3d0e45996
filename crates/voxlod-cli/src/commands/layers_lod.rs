//! `voxlod layers … --lod`: the layered shells at several resolutions as one `MSFT_lod` chain
//! (crate `voxlod-layers`, module `glb_chain`), switched where each level's filter radius spans
//! at most 0.45 px on screen.

use clap::Args;
use serde::Serialize;
use voxlod::layers::{layered_chain_document, GlbOptions, LayeredLevel};
use voxlod::{LayersOptions, Source};

use super::common::{in_file, CliError};
use super::values::number;

/// The flags of the chain.
#[derive(Args, Debug, Clone)]
pub struct LodArgs {
    /// With a .glb output: layered shells at several resolutions in one MSFT_lod chain, each
    /// filtered with --radius voxels of its own grid; a viewer draws the coarsest level whose
    /// filter radius spans at most 0.45 px on screen (where layers beat the single surface)
    #[arg(long)]
    pub lod: bool,
    /// With --lod: levels, each half the resolution of the one before (from --resolution)
    #[arg(long, value_name = "L", default_value_t = 4, conflicts_with = "resolutions",
        value_parser = number::<usize>, allow_hyphen_values = true)]
    pub levels: usize,
    /// With --lod: explicit resolutions, finest first, e.g. 256,128,64
    #[arg(long, value_name = "A,B,...", value_delimiter = ',',
        value_parser = number::<usize>, allow_hyphen_values = true)]
    pub resolutions: Option<Vec<usize>>,
}

impl LodArgs {
    /// The levels' resolutions, finest first; `None` without --lod. Refuses the chain's flags
    /// without --lod, and levels that would fall below 2 samples.
    pub fn resolutions(&self, finest: usize) -> Result<Option<Vec<usize>>, CliError> {
        if !self.lod {
            if self.resolutions.is_some() {
                return Err(CliError::usage("--resolutions needs --lod"));
            }
            return Ok(None);
        }
        let list = match &self.resolutions {
            Some(list) => list.clone(),
            None => {
                if self.levels == 0 {
                    return Err(CliError::usage("--levels must be at least 1"));
                }
                (0..self.levels.min(usize::BITS as usize))
                    .map(|k| finest >> k)
                    .collect()
            }
        };
        if let Some(&r) = list.iter().find(|&&r| r < 2) {
            return Err(CliError::usage(format!(
                "--lod: a level of resolution {r}: every level needs at least 2 samples \
                 (fewer --levels, or a larger --resolution)"
            )));
        }
        if list.windows(2).any(|w| w[1] >= w[0]) {
            return Err(CliError::usage(format!(
                "--resolutions {list:?}: they must decrease strictly from the finest"
            )));
        }
        Ok(Some(list))
    }
}

/// One level in the report.
#[derive(Clone, Debug, Serialize)]
pub struct ChainLevelReport {
    pub level: usize,
    pub resolution: usize,
    pub grid: [usize; 3],
    /// The filter's support radius in the input's units.
    pub radius: f64,
    pub layers: usize,
    pub triangles: usize,
    pub seconds: f64,
}

/// What the report says about the chain.
#[derive(Clone, Debug, Serialize)]
pub struct ChainReport {
    pub levels: Vec<ChainLevelReport>,
    pub screen_coverage: Vec<f64>,
    pub radius_limit_pixels: f64,
    pub bytes: usize,
}

/// The layered levels of `source` and the bytes of their chain; the first level is the finest.
pub fn layered_chain(
    input: &std::path::Path,
    source: &Source,
    options: &LayersOptions,
    resolutions: &[usize],
) -> Result<(Vec<voxlod::Layers>, Vec<u8>, ChainReport), CliError> {
    let levels =
        voxlod::layers_levels(source, options, resolutions).map_err(|e| in_file(input, e))?;
    let radii: Vec<f64> = levels
        .iter()
        .map(|l| voxlod::layers_radius(&l.layered, options.radius_voxels))
        .collect();
    let chain: Vec<LayeredLevel> = levels
        .iter()
        .zip(&radii)
        .map(|(l, &radius)| LayeredLevel {
            mesh: &l.layered.mesh,
            orders: &l.layered.orders,
            radius,
        })
        .collect();
    let fail = |e| in_file(input, voxlod::Error::from(e));
    let (doc, bin) = layered_chain_document(&chain, &GlbOptions::default()).map_err(fail)?;
    let bytes = voxlod_gltf::to_glb(&doc, bin)
        .map_err(|e| CliError::msg(format!("{}: {e}", input.display())))?;
    let report = ChainReport {
        levels: levels
            .iter()
            .zip(resolutions)
            .zip(&radii)
            .enumerate()
            .map(|(level, ((l, &resolution), &radius))| ChainLevelReport {
                level,
                resolution,
                grid: l.layered.mesh.grid.dims,
                radius,
                layers: l.layered.mesh.layers.len(),
                triangles: l.layered.mesh.triangle_count(),
                seconds: l.seconds,
            })
            .collect(),
        screen_coverage: serde_json::from_value(
            doc["nodes"][0]["extras"]["MSFT_screencoverage"].clone(),
        )
        .unwrap_or_default(),
        radius_limit_pixels: voxlod::layers::RADIUS_LIMIT_PIXELS,
        bytes: bytes.len(),
    };
    Ok((levels, bytes, report))
}
