//! One proxy for a whole scene, its looks baked ([`proxy`]): every part and instance of the
//! scene (a glTF scene flattened into world space by its reader, or a folder of meshes made
//! into one asset) sampled as one solid, levels by triangle budget made by the paper's method
//! (the voxel filter merges parts, closes gaps narrower than a voxel, drops what is hidden
//! inside and lowers the genus, He et al. 1995 §2–5; then the quadric stage spends the
//! budget), each level then given texture coordinates and textures cast from the scene
//! (crate `voxlod-bake`): one mesh, one material and one texture set per level, drawn in one
//! call.
//!
//! The levels come from the portfolio of crate `voxlod-budget` restricted to new surfaces
//! ([`voxlod_budget::PortfolioOptions::remesh`]): voxel levels, shells around open parts and
//! the level above collapsed further, never the scene's own collapse (which keeps every part,
//! every hidden face and a draw call per material). Parts that pass through each other are
//! sampled as their union. Every level is closed, an oriented manifold, its genus never above
//! the level before it.
//!
//! Beyond the paper: He et al. carry positions only; the bake is what scene remeshers
//! (Simplygon, InstaLOD) add to such a proxy.
//!
//! Cost: the portfolio's voxel search per budget (a few samplings of the scene's solid,
//! O(N³) at the resolution a budget affords), then per level one atlas and one bake
//! (O(texels · log F) for F scene triangles).

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::Instant;

use serde::Serialize;
use voxlod_asset::Asset;
use voxlod_bake::{bake_levels, BakeOptions, BakeReport, TextureSize};
use voxlod_budget::{levels_with, BudgetLevel, InputReport, PortfolioOptions};
use voxlod_fit::FitOptions;
use voxlod_sampling::Filter;

use crate::error::{InvalidOption, PyramidError};
use crate::progress::{run_to_end, Control, Event, Progress, ProgressFn};

/// Options of [`proxy`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ProxyOptions {
    /// The triangle budgets, one level each, in the order given.
    pub triangles: Vec<usize>,
    /// The low-pass filter of the voxel levels (He et al. 1995 §3).
    pub filter: Filter,
    /// No level has more handles than the level of the next larger budget.
    pub monotone: bool,
    /// The voxel levels' vertices fitted to the scene's surface where that measures closer.
    pub fit: Option<FitOptions>,
    /// Gaps between parts narrower than this (scene units) closed in every level; `None`:
    /// only what the filter closes, gaps under about a voxel
    /// ([`voxlod_budget::PortfolioOptions::close_gaps`]).
    pub close_gaps: Option<f64>,
    /// Parts seen from none of a sphere of views around the scene are dropped, and the levels
    /// are measured against and fitted to what is seen
    /// ([`voxlod_budget::PortfolioOptions::drop_hidden`]).
    pub drop_hidden: bool,
    /// The atlas and the bake: texture size (or texel density), padding, creases, the cage.
    pub bake: BakeOptions,
    /// Where not empty, one per budget: the pixels across which the level is drawn (the
    /// diameter of the scene's bounding sphere, around its box, on screen). Each level's
    /// textures then have about one texel per pixel there: a density of this many texels
    /// over the diameter per scene unit, the texture as large as the charts need at it,
    /// instead of `bake.atlas.texture`. The way game engines choose a
    /// level by its screen size (Simplygon's and Unreal's), applied to its textures.
    pub screen_sizes: Vec<u32>,
}

/// Texels per scene unit for a level drawn `pixels` across a scene whose bounding sphere has
/// diameter `diameter`: one texel per pixel where the surface faces the viewer.
fn screen_density(pixels: u32, diameter: f64) -> f32 {
    (pixels as f64 / diameter) as f32
}

impl Default for ProxyOptions {
    /// No budget yet ([`ProxyOptions::for_triangles`]), the hyper-cone, monotone, the quick
    /// fit, gaps closed by the filter alone, hidden parts dropped, 1024² textures.
    fn default() -> Self {
        ProxyOptions {
            triangles: Vec::new(),
            filter: Filter::Hypercone,
            monotone: true,
            fit: Some(FitOptions::quick()),
            close_gaps: None,
            drop_hidden: true,
            bake: BakeOptions::for_texture(1024),
            screen_sizes: Vec::new(),
        }
    }
}

impl ProxyOptions {
    /// One level per count in `budgets`, textures of `texels` a side.
    pub fn for_triangles(budgets: &[usize], texels: u32) -> Self {
        ProxyOptions {
            triangles: budgets.to_vec(),
            bake: BakeOptions::for_texture(texels),
            ..Default::default()
        }
    }
}

/// One level of a proxy.
#[derive(Clone, Debug)]
pub struct ProxyLevel {
    /// The level with its texture coordinates, its one material and its textures.
    pub asset: Asset,
    /// How the portfolio made it and how far it is from the scene's surface.
    pub report: BudgetLevel,
    /// What the bake did: texture size, charts, texel utilisation, texels that hit the scene.
    pub bake: BakeReport,
}

/// A scene's proxy levels, in the order of the budgets.
#[derive(Clone, Debug)]
pub struct Proxy {
    /// One per budget.
    pub levels: Vec<ProxyLevel>,
    /// The scene's geometry as the portfolio prepared it.
    pub input: InputReport,
    /// The portfolio's and the bakes' warnings.
    pub warnings: Vec<String>,
    /// Wall time of the whole call.
    pub seconds: f64,
}

/// The proxy levels of `scene` for `options` (module docs). Fails on options out of range, an
/// invalid scene, the memory limit (asked before each texture), or a level the atlas cannot
/// parameterize.
pub fn proxy(scene: &Asset, options: &ProxyOptions) -> Result<Proxy, PyramidError> {
    proxy_with(scene, options, &run_to_end)
}

/// [`proxy`], reporting progress (the portfolio's steps, then one per bake) and stopping with
/// [`PyramidError::Cancelled`] when `progress` answers [`Control::Stop`].
pub fn proxy_with(
    scene: &Asset,
    options: &ProxyOptions,
    progress: &ProgressFn,
) -> Result<Proxy, PyramidError> {
    let start = Instant::now();
    if options.triangles.is_empty() {
        let problem = "give at least one budget";
        return Err(InvalidOption::new("triangles", "[]", problem).into());
    }
    check_screen_sizes(options)?;
    scene.validate().map_err(voxlod_bake::BakeError::from)?;
    let geometry = scene.mesh.geometry();
    let portfolio = PortfolioOptions {
        filter: options.filter,
        monotone: options.monotone,
        fit: options.fit.clone(),
        close_gaps: options.close_gaps,
        drop_hidden: options.drop_hidden,
        ..PortfolioOptions::remesh(&options.triangles)
    };
    let ask = |done: usize, total: usize| {
        let what = "proxy levels";
        let event = Event::Step { level: 0, what };
        progress(Progress { done, total, event }) == Control::Continue
    };
    let run = levels_with(&geometry, &portfolio, &ask)?;
    let mut warnings = run.warnings;
    let longest = geometry.bounds().longest_extent();
    let bake_options: Vec<BakeOptions> = (run.levels.iter().enumerate())
        .map(|(i, level)| {
            let mut bake_options = BakeOptions {
                voxel_size: (level.report.resolution).map(|r| (longest / r.max(1) as f64) as f32),
                ..options.bake.clone()
            };
            if let Some(&pixels) = options.screen_sizes.get(i) {
                let density = screen_density(pixels, geometry.bounds().diagonal());
                bake_options.atlas.texture = TextureSize::Density(density);
            }
            bake_options
        })
        .collect();
    let total = options.triangles.len();
    let event = Event::Step {
        level: 0,
        what: "atlases",
    };
    if progress(Progress {
        done: 0,
        total,
        event,
    }) == Control::Stop
    {
        return Err(PyramidError::Cancelled);
    }
    let each: Vec<_> = (run.levels.iter().zip(&bake_options))
        .map(|(level, o)| Some((&level.mesh, o)))
        .collect();
    // Bakes end in any order (the smaller levels' first): each reports its level and how many
    // have ended; a stop asked after any of them cancels the proxy.
    let (done, stopped) = (AtomicUsize::new(0), AtomicBool::new(false));
    let after = |k: usize| {
        let done = 1 + done.fetch_add(1, Ordering::Relaxed);
        let event = Event::Step {
            level: k,
            what: "bake",
        };
        let go_on = progress(Progress { done, total, event }) == Control::Continue;
        stopped.fetch_or(!go_on, Ordering::Relaxed);
        go_on
    };
    let baked = bake_levels(scene, &each, &after)?;
    if stopped.load(Ordering::Relaxed) {
        return Err(PyramidError::Cancelled);
    }
    let mut levels = Vec::with_capacity(run.levels.len());
    for (level, baked) in run.levels.into_iter().zip(baked) {
        let Some(baked) = baked else {
            return Err(PyramidError::Cancelled);
        };
        let budget = level.report.budget;
        let noted = baked.report.warnings.iter();
        warnings.extend(noted.map(|w| format!("{budget} triangles: {w}")));
        levels.push(ProxyLevel {
            asset: baked.asset,
            report: level.report,
            bake: baked.report,
        });
    }
    Ok(Proxy {
        levels,
        input: run.input,
        warnings,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// Screen sizes, where given, are one per budget and at least one pixel.
fn check_screen_sizes(options: &ProxyOptions) -> Result<(), PyramidError> {
    let sizes = &options.screen_sizes;
    let given = format!("{sizes:?}");
    if !sizes.is_empty() && sizes.len() != options.triangles.len() {
        let problem = format!(
            "give one screen size per budget ({} budgets, {} screen sizes)",
            options.triangles.len(),
            sizes.len()
        );
        return Err(InvalidOption::new("screen_sizes", given, problem).into());
    }
    if sizes.contains(&0) {
        let problem = "a level is drawn at least one pixel across";
        return Err(InvalidOption::new("screen_sizes", given, problem).into());
    }
    Ok(())
}
