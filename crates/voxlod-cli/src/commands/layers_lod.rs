//! `voxlod layers … --lod`: the layered shells at several resolutions as one `MSFT_lod` chain
//! (crate `voxlod-layers`, module `glb_chain`), switched where each level's filter radius spans
//! at most 0.45 px on screen.

use clap::Args;
use serde::Serialize;

use super::common::CliError;
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
    /// without --lod, and levels that would fall below 2 samples (the library refuses the
    /// rest: [`voxlod::check_layers_levels`]).
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
    /// With looks: the charts of the level's layers' atlases, all together.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub charts: Option<usize>,
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

impl ChainReport {
    /// What the report says about `chain`, made at `resolutions`.
    pub fn of(chain: &voxlod::LayersChain, resolutions: &[usize]) -> ChainReport {
        let levels = chain.levels.iter().zip(resolutions).zip(&chain.radii);
        let charts = |k: usize| {
            let looks = chain.baked.get(k)?.as_ref()?.looks.iter().flatten();
            Some(looks.map(|l| l.report.charts).sum())
        };
        ChainReport {
            levels: levels
                .enumerate()
                .map(|(level, ((l, &resolution), &radius))| ChainLevelReport {
                    level,
                    resolution,
                    grid: l.layered.mesh.grid.dims,
                    radius,
                    layers: l.layered.mesh.layers.len(),
                    triangles: l.layered.mesh.triangle_count(),
                    charts: charts(level),
                    seconds: l.seconds,
                })
                .collect(),
            screen_coverage: chain.screen_coverage.clone(),
            radius_limit_pixels: voxlod::layers::RADIUS_LIMIT_PIXELS,
            bytes: chain.bytes.len(),
        }
    }
}
