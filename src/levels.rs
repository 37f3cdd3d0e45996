//! The main job in one call: levels of detail of a mesh, a scanned volume or a solid (He, Hong,
//! Kaufman, Varshney, Wang 1995, §2 and §4).
//!
//! [`lod`] prepares the [`Source`] (welding and hole closing for a mesh, the threshold solid
//! for a scan), checks the iso value, plans every level (refusing what would not fit in memory
//! before any work), then samples each level from the original source with its own filter
//! radius, contours it by marching cubes, and, when asked, simplifies it by simplification
//! envelopes ([`LodOptions::then_envelope`]). Every level is a closed, consistently oriented
//! mesh, or empty where the filter removed the whole object (a warning says so). [`lod_with`]
//! reports progress after each step and stops when asked. The levels one at a time are
//! [`crate::lod::plan`] and [`crate::lod::build_level`]. Cost: per level, the sampling (O(N³)
//! samples) and marching cubes (O(N³)); the finest level dominates.
//!
//! **Beyond the paper, by default** (each can be turned off in [`LodOptions`]):
//!
//! - *The genus never rises* from a level to the next ([`LodOptions::monotone`]). The paper
//!   promises that holes fade as the filter widens, but a wall thinner than the filter fades
//!   unevenly and perforates first (the pinion gear's coarsest level went from genus 1 to 3,
//!   thingi10k-42722 from 3 to 14). Each level's filtered density passes through
//!   [`voxlod_sampling::MonotoneChain`] before marching cubes: the cavities of the finer level
//!   stay solid (their filtered density is added, as if the object had been filled before
//!   filtering), and if that is not enough a threshold guarded by local topological numbers
//!   refuses every sample flip that would open a tunnel. We chose constraining each level by
//!   the one above over smoothing the density until handles go because it leaves the paper's
//!   filter untouched wherever the topology does not change, and a thin hollow part then
//!   closes up from outside, which is what a viewer sees of it. Each level reports the handles
//!   removed and the components gained or lost ([`LodLevel::monotone`]). The rules need the
//!   dense volume: a level sampled in the narrow band (resolutions around 1000 and above) is
//!   not constrained, and the chain starts again below it.
//! - *Clean levels* ([`LodOptions::clean`], [`voxlod_contouring::clean_mesh()`]): no sliver,
//!   needle or zero-area triangle and no self-intersection, closed and manifold kept.
//! - *A start at or below the input* ([`LodOptions::finest`], [`crate::finest`]): for a mesh,
//!   the pyramid is scaled down so that the finest level's estimated triangle count is at most
//!   the input's (at most the pyramid's own resolution, at least 16 samples).

use std::time::Instant;

use voxlod_core::mesh_topology;
use voxlod_core::validate::{find_defect, Requirements};
use voxlod_sampling::{LevelPlan, MonotoneChain};

use crate::budget::lod_by_budget;
use crate::error::Error;
use crate::finest::{choose_finest, scaled, surface_resolution, Finest, FinestChoice};
use crate::lod::{plan, sample_level, LevelOptions, LodLevel, LodSource};
use crate::lod_options::{Lod, LodOptions};
use crate::progress::{run_to_end, Event, ProgressFn, Tracker};
use crate::source::Source;
use crate::then_envelope::simplify_level;

/// Levels of detail of `source`, with the defaults of `options`.
///
/// ```
/// # fn main() -> Result<(), voxlod::Error> {
/// use voxlod::sampling::{CsgSolid, Shape};
/// use voxlod::core::glam::DVec3;
/// // A sphere of radius 1 as an implicit solid, three levels from 24 samples.
/// let ball = CsgSolid::new(Shape::sphere(DVec3::ZERO, 1.0))?;
/// let options = voxlod::LodOptions::halving(24, 3, voxlod::sampling::Filter::Hypercone);
/// let lod = voxlod::lod(&voxlod::Source::Solid(&ball), &options)?;
/// assert_eq!(lod.levels.len(), 3);
/// for level in &lod.levels {
///     assert!(level.topology.is_closed_manifold() && level.topology.genus == Some(0));
/// }
/// assert!(lod.levels[2].mesh.triangle_count() < lod.levels[0].mesh.triangle_count());
/// # Ok(())
/// # }
/// ```
pub fn lod(source: &Source, options: &LodOptions) -> Result<Lod, Error> {
    lod_with(source, options, &run_to_end)
}

/// [`lod`], reporting progress to `progress` after each step (a level's sampling, contouring
/// and envelope step) and stopping with [`Error::Cancelled`] when it answers
/// [`crate::Control::Stop`]; a level's failure names the level.
///
/// ```
/// # fn main() -> Result<(), voxlod::Error> {
/// use std::sync::atomic::{AtomicUsize, Ordering};
/// use voxlod::sampling::{CsgSolid, Shape};
/// use voxlod::core::glam::DVec3;
/// let ball = CsgSolid::new(Shape::sphere(DVec3::ZERO, 1.0))?;
/// let options = voxlod::LodOptions::halving(16, 4, voxlod::sampling::Filter::Hypercone);
/// // Stop once the first level is complete.
/// let levels = AtomicUsize::new(0);
/// let stop_after_one = |p: voxlod::Progress| match p.event {
///     voxlod::Event::LodLevel(_) if levels.fetch_add(1, Ordering::Relaxed) == 0 => {
///         voxlod::Control::Stop
///     }
///     _ => voxlod::Control::Continue,
/// };
/// let e = voxlod::lod_with(&voxlod::Source::Solid(&ball), &options, &stop_after_one);
/// assert!(matches!(e, Err(voxlod::Error::Cancelled)));
/// assert_eq!(levels.load(Ordering::Relaxed), 1);
/// # Ok(())
/// # }
/// ```
pub fn lod_with(
    source: &Source,
    options: &LodOptions,
    progress: &ProgressFn,
) -> Result<Lod, Error> {
    let start = Instant::now();
    options.check()?;
    if options.triangles.is_some() || options.error.is_some() {
        return lod_by_budget(source, options, progress);
    }
    let prepared = source.prepare()?;
    let iso = prepared.iso(options.iso)?;
    let (pyramid, mut finest) = match (options.finest, source) {
        (Finest::InputTriangles, Source::Mesh(mesh)) => choose_finest(mesh, &options.pyramid),
        _ => (options.pyramid.clone(), None),
    };
    let mut level_options = LevelOptions {
        pyramid,
        iso,
        normals: options.normals,
        clean: options.clean,
    };
    let lod_source = prepared.lod_source();
    let mut plans = plan(&lod_source, &level_options)?;
    let steps = if options.then_envelope.is_some() {
        3
    } else {
        2
    };
    let mut tracker = Tracker::start(progress, plans.len() * steps)?;
    let mut warnings = prepared.warnings().to_vec();
    let mut chain = monotone_chain(options, &lod_source);
    let mut levels = Vec::with_capacity(plans.len());
    let mut k = 0;
    while k < plans.len() {
        let p = plans[k];
        let level = one_level(
            &lod_source,
            &p,
            &level_options,
            options,
            &mut chain,
            &mut tracker,
        )
        .map_err(|e| e.context(format!("level {}", p.level)))?;
        if k == 0 && level.mesh.is_empty() {
            if let Some(choice) = finest.as_mut() {
                if let Some(finer) = finer_start(&lod_source, &level_options, choice, iso)? {
                    warnings.push(finer);
                    level_options.pyramid = scaled(&options.pyramid, choice.resolution);
                    plans = plan(&lod_source, &level_options)?;
                    chain = monotone_chain(options, &lod_source);
                    continue;
                }
            }
        }
        if level.mesh.is_empty() {
            warnings.push(empty_level_warning(&p, iso));
        }
        // A band level too large to be made dense skips the rule (`keep_monotone` gives None).
        if chain.is_some() && level.monotone.is_none() && plans.len() > 1 {
            warnings.push(band_level_warning(&p));
        }
        if level.clean_skipped {
            warnings.push(format!(
                "level {} (resolution {}): {} triangles from the narrow band, more than the {} \
                 that are cleaned; kept as marching cubes made them (closed and oriented, \
                 slivers and needles not removed) to stay within memory",
                p.level,
                p.resolution,
                level.mesh.triangles.len(),
                crate::lod::CLEAN_BAND_AT_MOST_TRIANGLES
            ));
        }
        tracker.ask(Event::LodLevel(&level))?;
        levels.push(level);
        k += 1;
    }
    if levels.iter().all(|l| l.mesh.is_empty()) {
        return Err(Error::NoSurface {
            iso,
            voxel_size: plans[0].voxel_size,
            radius: plans[0].radius,
        });
    }
    Ok(Lod {
        levels,
        route: prepared.route(),
        preparation: prepared.preparation().copied(),
        iso,
        warnings,
        budgets: Vec::new(),
        finest,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// The chain that keeps the genus from rising, when asked: a scan filtered directly fills
/// cavities with its largest value (its material), a solid with density 1.
fn monotone_chain(options: &LodOptions, source: &LodSource) -> Option<MonotoneChain> {
    let mut monotone = options.monotone?;
    if let LodSource::Direct(volume) = source {
        monotone.fill_density = volume.range().map_or(1.0, |(_, high)| high);
    }
    Some(MonotoneChain::new(monotone))
}

/// When the finest level chosen from the input's triangles vanished (parts thinner than the
/// filter), the coarsest finer resolution up to the pyramid's own at which it has a surface:
/// `choice` updated and the warning that says so; `None` when there is none.
fn finer_start(
    source: &LodSource,
    level_options: &LevelOptions,
    choice: &mut FinestChoice,
    iso: f32,
) -> Result<Option<String>, Error> {
    let LodSource::Solid(solid) = source else {
        return Ok(None);
    };
    let (from, up_to) = (choice.resolution, choice.given_resolution);
    if from >= up_to {
        return Ok(None);
    }
    let Some(found) = surface_resolution(*solid, &level_options.pyramid, from, up_to, iso)? else {
        return Ok(None);
    };
    choice.resolution = found;
    Ok(Some(format!(
        "level 0: at resolution {from} (chosen from the input's {} triangles) the filter \
         removed the whole object (parts thinner than a voxel); the chain starts at resolution \
         {found} instead, the coarsest at which it has a surface",
        choice.input_triangles
    )))
}

/// Samples, keeps the genus from rising (when asked), contours and (when asked) simplifies one
/// level, checking that its vertices stayed
/// within 32-bit coordinates.
fn one_level(
    source: &LodSource,
    plan: &LevelPlan,
    level_options: &LevelOptions,
    options: &LodOptions,
    chain: &mut Option<MonotoneChain>,
    tracker: &mut Tracker,
) -> Result<LodLevel, Error> {
    let mut sampled = sample_level(source, plan, level_options)?;
    let monotone_start = Instant::now();
    let monotone = match chain {
        Some(chain) => sampled.keep_monotone(chain, level_options)?,
        None => None,
    };
    let monotone_seconds = monotone_start.elapsed().as_secs_f64();
    tracker.step(plan.level, "sampled")?;
    let mut level = sampled.contour(level_options)?;
    level.monotone = monotone;
    level.monotone_seconds = monotone_seconds;
    if let Some(defect) = find_defect(&level.mesh, &Requirements::computed()) {
        return Err(Error::ComputedBeyondRange {
            defect,
            cause: "the object's extent or position is too large for 32-bit coordinates",
        });
    }
    tracker.step(plan.level, "contoured")?;
    if let Some(step) = &options.then_envelope {
        let (mesh, report) = simplify_level(&level.mesh, step, plan.voxel_size)
            .map_err(|e| Error::from(e).context("`then_envelope`"))?;
        level.mesh = mesh;
        level.envelope = report;
        level.topology = mesh_topology(&level.mesh);
        tracker.step(plan.level, "simplified")?;
    }
    Ok(level)
}

/// The warning for a level sampled in the narrow band while the genus is kept from rising: the
/// rule needs the dense volume, so the chain is not kept across that level.
fn band_level_warning(plan: &LevelPlan) -> String {
    format!(
        "level {} (resolution {}) was sampled in the narrow band: the genus is not kept from \
         rising across it (the rule needs a dense volume, which the band avoids), and the \
         levels below start a new chain",
        plan.level, plan.resolution
    )
}

/// The warning for a level the filter removed.
fn empty_level_warning(plan: &LevelPlan, iso: f32) -> String {
    format!(
        "level {}: the filter of radius {:.4} removed the whole object (no density reaches \
         {iso}); the level is empty. Use fewer levels, or a lower `iso` for parts thinner than a \
         voxel",
        plan.level, plan.radius
    )
}
