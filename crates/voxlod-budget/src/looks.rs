//! Budget levels of an asset with their looks: the portfolio chooses each level on the asset's
//! geometry ([`crate::levels`]), then the level gets the asset's looks by the way it was made.
//!
//! - A level that is the input's own collapse ([`Method::Collapse`],
//!   [`Method::CollapseAsGiven`]) is made again with the attributes weighed in
//!   (`voxlod_asset::collapse`, meshoptimizer's `simplifyWithAttributes`): its vertices are the
//!   input's, with their texture coordinates, colours, normals and materials, UV seams and
//!   material borders kept. A level collapsed from the level above ([`Method::Above`]) is made
//!   so from that level's looks, where it kept them. It is kept when it meets the budget within the tolerance and is
//!   measured no farther from the input than the allowance below (larger for a textured
//!   asset, whose texture a transfer would reduce to vertex colours); otherwise the chosen
//!   level takes the looks as the next case does.
//! - Every other level (voxel, shell, clustering-like, checked collapses, the level above)
//!   is replaced by the input's collapse with attributes where that meets the budget and is
//!   measured no farther from the input, or, for a textured asset, where it is within
//!   [`TEXTURED_ALLOWANCE`] and its colours are closer to the input's
//!   (`voxlod_asset::colour_error`: what the input shows at points over its surface against
//!   what the level shows at the nearest points) than the level's with transferred looks;
//!   otherwise it
//!   takes colours, normals and untextured materials from the nearest input point
//!   (`voxlod_asset::transfer`), the base colour texture sampled into vertex colours, so that
//!   no level of a textured asset comes out grey.
//!
//! Beyond the paper: He et al. (1995) carry positions only; Varshney et al.'s envelopes keep
//! the input's vertices for the same reason the collapse does here.
//!
//! Cost: the portfolio's, plus one attribute collapse and one distance measure per level, and
//! one nearest-point pass per level that does not keep the input's vertices (O(V log N)); a
//! level of a textured asset compared by colour adds two colour measures (O(T log L) each).

use serde::Serialize;
use voxlod_asset::{Asset, AssetError};
use voxlod_core::TriangleMesh;
use voxlod_metrics::{mesh_distance, DistanceOptions};

use crate::candidate::Method;
use crate::options::BUDGET_TOLERANCE;
use crate::{levels, BudgetError, BudgetLevel, InputReport, PortfolioOptions};

/// A collapsed level with attributes may be this much farther (Hausdorff) from the input than
/// the geometric collapse the portfolio measured, as a multiple, before the geometric level
/// is kept instead with looks taken from the nearest input points.
pub const ATTRIBUTE_ALLOWANCE: f64 = 1.25;

/// [`ATTRIBUTE_ALLOWANCE`] for an asset whose triangles use a base colour texture: a level
/// that takes its looks from the nearest input points has the texture sampled into vertex
/// colours, one per vertex, which loses the texture's detail; the collapse keeps the texture.
/// On Spot and generated textured scenes (`scripts/looks-bench.sh`) the collapse with its
/// texture rendered closer to the input (PSNR over 14 views) than the geometric collapse with
/// transferred colours up to 4.5 times the latter's Hausdorff distance.
pub const TEXTURED_ALLOWANCE: f64 = 5.0;

/// How a level got its looks.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Looks {
    /// Its vertices are the input's with all their attributes (the collapse with attributes).
    Kept,
    /// Colours, normals and materials taken from the nearest input points.
    Transferred,
    /// New texture coordinates and textures cast from the input (crate `voxlod-bake`): a
    /// level of a textured input that shares no vertex with it.
    Baked,
}

/// One budget's level of an asset.
#[derive(Clone, Debug)]
pub struct AssetLevel {
    /// The level with its looks.
    pub asset: Asset,
    /// How it got them.
    pub looks: Looks,
    /// The portfolio's report of the level (for a kept collapse, its triangles and distance
    /// are the collapse with attributes').
    pub report: BudgetLevel,
}

/// A run of budgets on an asset.
#[derive(Clone, Debug)]
pub struct AssetBudgeted {
    /// One level per budget, in the order the budgets were given.
    pub levels: Vec<AssetLevel>,
    /// The input's geometry as the run saw it.
    pub input: InputReport,
    /// The portfolio's warnings and the looks' (images that could not be decoded).
    pub warnings: Vec<String>,
    /// Wall seconds of the whole run.
    pub seconds: f64,
}

/// One level per budget of `options.triangles` from `asset`, each with the asset's looks
/// (module docs). Fails as [`crate::levels`] does, and on an invalid asset.
pub fn asset_levels(
    asset: &Asset,
    options: &PortfolioOptions,
) -> Result<AssetBudgeted, BudgetError> {
    let start = std::time::Instant::now();
    asset.validate().map_err(looks_error)?;
    let geometry = asset.mesh.geometry();
    // A collapse is made again with the attributes, from the input's own vertices: a fit of
    // the collapse made without them would be thrown away.
    let geometric = PortfolioOptions {
        fit_collapses: false,
        ..options.clone()
    };
    let run = levels(&geometry, &geometric)?;
    let mut warnings = run.warnings;
    // From the largest budget down, so that a level collapsed from the level above can be
    // collapsed from that level's looks.
    let mut order: Vec<usize> = (0..run.levels.len()).collect();
    order.sort_by_key(|&k| std::cmp::Reverse(run.levels[k].report.budget));
    let mut made: Vec<Option<AssetLevel>> = vec![None; run.levels.len()];
    let mut levels_in: Vec<Option<crate::Level>> = run.levels.into_iter().map(Some).collect();
    for k in order {
        let Some(level) = levels_in[k].take() else {
            continue;
        };
        let collapsed = match (level.report.method, level.report.simplified_from) {
            (Method::Collapse | Method::CollapseAsGiven, _) => Some(asset),
            (Method::Above, Some(b)) => made
                .iter()
                .flatten()
                .find(|l| l.report.budget == b && l.looks == Looks::Kept)
                .map(|l| &l.asset),
            _ => None,
        };
        // A level made otherwise is compared with the input's collapse with attributes, which
        // replaces it where it is no farther from the input.
        let source = match collapsed {
            Some(source) => Source {
                asset: source,
                allowance: allowance(asset),
                by_colour: false,
            },
            None => Source {
                asset,
                allowance: 1.0,
                by_colour: textured(asset),
            },
        };
        let (asset_level, more) =
            with_looks(asset, source, &geometry, level.mesh, level.report, options)?;
        warnings.extend(more);
        made[k] = Some(asset_level);
    }
    let out: Vec<AssetLevel> = made.into_iter().flatten().collect();
    warnings.sort();
    warnings.dedup();
    Ok(AssetBudgeted {
        levels: out,
        input: run.input,
        warnings,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// What a level is collapsed from with its looks, and how it is judged.
#[derive(Clone, Copy)]
struct Source<'a> {
    /// The input, or the level above with its looks.
    asset: &'a Asset,
    /// How much farther than the chosen level the collapse may be.
    allowance: f64,
    /// Whether a collapse beyond the allowance is compared by colour (a level made otherwise of
    /// a textured asset).
    by_colour: bool,
}

/// The level with looks: `source` collapsed with attributes where that meets the budget and is
/// measured no farther from the input than its allowance times the chosen level, or, where
/// it is compared by colour, no farther than [`TEXTURED_ALLOWANCE`] times and closer in colour
/// ([`voxlod_asset::colour_error`]) than the chosen mesh with transferred looks; else the
/// chosen mesh with looks from the nearest input points.
fn with_looks(
    asset: &Asset,
    source: Source<'_>,
    geometry: &TriangleMesh,
    mesh: TriangleMesh,
    mut report: BudgetLevel,
    options: &PortfolioOptions,
) -> Result<(AssetLevel, Vec<String>), BudgetError> {
    let kept = voxlod_asset::collapse(source.asset, report.budget).map_err(looks_error)?;
    let t = kept.mesh.triangles.len();
    let within = (t as f64) <= report.budget as f64 * (1.0 + BUDGET_TOLERANCE) && t > 0;
    let mut taken = None;
    if within {
        let d = mesh_distance(
            geometry,
            &kept.mesh.geometry(),
            &DistanceOptions::for_samples(options.careful_samples),
        )?;
        let mut keep = d.hausdorff <= report.hausdorff * source.allowance;
        if !keep && source.by_colour && d.hausdorff <= report.hausdorff * TEXTURED_ALLOWANCE {
            let transferred = voxlod_asset::transfer(asset, &mesh).map_err(looks_error)?;
            let error = |level: &Asset| voxlod_asset::colour_error(asset, level);
            keep = error(&kept).map_err(looks_error)?
                < error(&transferred.asset).map_err(looks_error)?;
            taken = Some(transferred);
        }
        if keep {
            report.triangles = t;
            report.hausdorff_fraction = d.hausdorff_fraction;
            report.hausdorff = d.hausdorff;
            report.mean_distance = d.mean;
            let level = AssetLevel {
                asset: kept,
                looks: Looks::Kept,
                report,
            };
            return Ok((level, Vec::new()));
        }
    }
    let taken = match taken {
        Some(taken) => taken,
        None => voxlod_asset::transfer(asset, &mesh).map_err(looks_error)?,
    };
    let level = AssetLevel {
        asset: taken.asset,
        looks: Looks::Transferred,
        report,
    };
    Ok((level, taken.warnings))
}

/// How much farther than the geometric collapse a collapse with attributes may be:
/// [`TEXTURED_ALLOWANCE`] for a textured asset ([`textured`]), else [`ATTRIBUTE_ALLOWANCE`].
fn allowance(asset: &Asset) -> f64 {
    if textured(asset) {
        TEXTURED_ALLOWANCE
    } else {
        ATTRIBUTE_ALLOWANCE
    }
}

/// Whether the asset has texture coordinates and a triangle whose material has a base colour
/// texture.
fn textured(asset: &Asset) -> bool {
    let coordinates = !asset.mesh.uv[0].is_empty() || !asset.mesh.uv[1].is_empty();
    coordinates
        && (0..asset.mesh.triangles.len())
            .filter_map(|t| asset.material_of(t))
            .any(|m| m.base_color_texture.is_some())
}

/// An asset stage's failure as the crate's error (a memory refusal keeps its class).
fn looks_error(e: AssetError) -> BudgetError {
    match e {
        AssetError::Core(c) => BudgetError::Core(c),
        other => BudgetError::InvalidOption {
            name: "asset",
            problem: other.to_string(),
        },
    }
}
