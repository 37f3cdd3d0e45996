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
//! **Levels side by side** (same levels, less waiting): the levels are sampled and their genus
//! settled in turn, but while a dense level is settled the next is already sampled on another
//! task, and once settled the level is contoured, cleaned and checked on a task of its own
//! while the coarser levels go on ([`crate::lod::sample_ahead`] says when: dense levels, the
//! next at most 256 MiB, both within the memory limit). The finest level's cleaning, partly
//! sequential, then overlaps the rest of the chain. Its progress (contoured, simplified, the
//! finished level) is reported in level order once the levels are made.
//!
//! **Beyond the paper, by default** (each can be turned off in [`LodOptions`]):
//!
//! - *The genus never rises* from a level to the next ([`LodOptions::monotone`]). The paper
//!   promises that holes fade as the filter widens, but a wall thinner than the filter fades
//!   unevenly and perforates first (without this, the pinion gear's coarsest level has genus 3
//!   where its finer levels have 1, thingi10k-42722 14 where they have 3). Each level's filtered density passes through
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
//!   needle or zero-area triangle and no self-intersection, closed and manifold kept. Such
//!   levels are contoured with vertices kept 0.072 cell from the samples
//!   ([`voxlod_contouring::CleanOptions::contour_clamp`]; plain marching cubes' triangles,
//!   vertices moved along their edges), which leaves no edge or triangle for cleaning to fix:
//!   it then costs one scan of the triangles.
//! - *A start at or below the input* ([`LodOptions::finest`], [`crate::finest`]): for a mesh,
//!   the pyramid is scaled down so that the finest level's estimated triangle count is at most
//!   the input's (at most the pyramid's own resolution, at least 16 samples).

use std::time::Instant;

use voxlod_core::mesh_topology;
use voxlod_core::validate::{find_defect, Requirements};
use voxlod_sampling::{LevelPlan, MonotoneChain, TopologyRecord};

use crate::error::PyramidError;
use crate::finest::{choose_finest, scaled, surface_resolution, Finest, FinestChoice};
use crate::lod::{
    plan, sample_ahead, sample_level, LevelOptions, LodError, LodLevel, LodSource, SampledLevel,
};
use crate::lod_options::{Lod, LodOptions};
use crate::progress::{run_to_end, Event, ProgressFn, Tracker};
use crate::source::Source;
use crate::then_envelope::simplify_level;

/// Levels of detail of `source`, with the defaults of `options`.
///
/// ```
/// # fn main() -> Result<(), voxlod_pyramid::PyramidError> {
/// use voxlod_sampling::{CsgSolid, Shape};
/// use voxlod_core::glam::DVec3;
/// // A sphere of radius 1 as an implicit solid, three levels from 24 samples.
/// let ball = CsgSolid::new(Shape::sphere(DVec3::ZERO, 1.0))?;
/// let options = voxlod_pyramid::LodOptions::halving(24, 3, voxlod_sampling::Filter::Hypercone);
/// let lod = voxlod_pyramid::lod(&voxlod_pyramid::Source::Solid(&ball), &options)?;
/// assert_eq!(lod.levels.len(), 3);
/// for level in &lod.levels {
///     assert!(level.topology.is_closed_manifold() && level.topology.genus == Some(0));
/// }
/// assert!(lod.levels[2].mesh.triangle_count() < lod.levels[0].mesh.triangle_count());
/// # Ok(())
/// # }
/// ```
pub fn lod(source: &Source, options: &LodOptions) -> Result<Lod, PyramidError> {
    lod_with(source, options, &run_to_end)
}

/// [`lod`], reporting progress to `progress` after each step (a level's sampling, contouring
/// and envelope step; levels made side by side report their contouring once made) and stopping with [`PyramidError::Cancelled`] when it answers
/// [`crate::Control::Stop`]; a level's failure names the level. The levels are moved into
/// [`LodOptions::frame`] once made (those given to `progress` are in the source's own frame).
///
/// ```
/// # fn main() -> Result<(), voxlod_pyramid::PyramidError> {
/// use std::sync::atomic::{AtomicUsize, Ordering};
/// use voxlod_sampling::{CsgSolid, Shape};
/// use voxlod_core::glam::DVec3;
/// let ball = CsgSolid::new(Shape::sphere(DVec3::ZERO, 1.0))?;
/// let options = voxlod_pyramid::LodOptions::halving(16, 4, voxlod_sampling::Filter::Hypercone);
/// // Stop once the first level is complete.
/// let levels = AtomicUsize::new(0);
/// let stop_after_one = |p: voxlod_pyramid::Progress| match p.event {
///     voxlod_pyramid::Event::LodLevel(_) if levels.fetch_add(1, Ordering::Relaxed) == 0 => {
///         voxlod_pyramid::Control::Stop
///     }
///     _ => voxlod_pyramid::Control::Continue,
/// };
/// let e = voxlod_pyramid::lod_with(&voxlod_pyramid::Source::Solid(&ball), &options, &stop_after_one);
/// assert!(matches!(e, Err(voxlod_pyramid::PyramidError::Cancelled)));
/// assert_eq!(levels.load(Ordering::Relaxed), 1);
/// # Ok(())
/// # }
/// ```
pub fn lod_with(
    source: &Source,
    options: &LodOptions,
    progress: &ProgressFn,
) -> Result<Lod, PyramidError> {
    let to_frame = source.to_frame(options.frame)?;
    let mut lod = lod_levels(source, options, progress, true)?;
    for level in &mut lod.levels {
        to_frame.apply(&mut level.mesh);
    }
    Ok(lod)
}

/// [`lod_with`]. With `overlap`, the next level is sampled on another task while this one is
/// finished, when [`sample_ahead`] allows it; without, one level at a time. The levels are the
/// same either way (the tests compare them bit for bit).
fn lod_levels(
    source: &Source,
    options: &LodOptions,
    progress: &ProgressFn,
    overlap: bool,
) -> Result<Lod, PyramidError> {
    let start = Instant::now();
    options.check()?;
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
        snap: true,
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
    let chained = options.monotone.is_some();
    let source = &lod_source;
    let mut levels = Vec::with_capacity(plans.len());
    // Made again from a finer start when level 0 came out empty (`finer_start`).
    'chain: loop {
        let made = chain_levels(
            source,
            &plans,
            &level_options,
            options,
            &mut tracker,
            overlap,
        );
        // The callback said stop: nothing more is reported.
        if let Some(Err(PyramidError::Cancelled)) = made.last() {
            return Err(PyramidError::Cancelled);
        }
        for (level, p) in made.into_iter().zip(&plans) {
            let level = level.map_err(|e| e.context(format!("level {}", p.level)))?;
            tracker.step(p.level, "contoured")?;
            if options.then_envelope.is_some() {
                tracker.step(p.level, "simplified")?;
            }
            if levels.is_empty() && level.mesh.is_empty() {
                if let Some(choice) = finest.as_mut() {
                    if let Some(finer) = finer_start(source, &level_options, choice, iso)? {
                        warnings.push(finer);
                        level_options.pyramid = scaled(&options.pyramid, choice.resolution);
                        plans = plan(source, &level_options)?;
                        continue 'chain;
                    }
                }
            }
            warnings.extend(level_warnings(&level, iso, chained && plans.len() > 1));
            tracker.ask(Event::LodLevel(&level))?;
            levels.push(level);
        }
        break;
    }
    if levels.iter().all(|l| l.mesh.is_empty()) {
        return Err(PyramidError::NoSurface {
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
) -> Result<Option<String>, PyramidError> {
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

/// The next level, sampled on another task while the level above it was settled, or why its
/// sampling failed (reported in its turn, as if it had been sampled then).
type Ahead = Option<Result<SampledLevel, LodError>>;

/// A level whose density is settled (kept from gaining handles, when asked): what is left is
/// independent of the other levels.
struct Settled {
    sampled: SampledLevel,
    monotone: Option<TopologyRecord>,
    monotone_seconds: f64,
}

/// Every level of `plans`, in order, each `Ok` or why it failed; the list ends at the first
/// level whose sampling or genus step failed (its error last). The levels are sampled and
/// settled in turn on this thread, the genus step being a chain from each level to the next.
/// With `overlap`, where [`sample_ahead`] allows it for a level and the next, the next level
/// is sampled on another task while this one is settled, and this one is contoured, cleaned
/// and checked on a task of its own while the coarser levels go on, so that the finest
/// level's cleaning (most of the chain's time, and partly sequential) overlaps the rest.
/// Every level is the one made one at a time.
fn chain_levels(
    source: &LodSource,
    plans: &[LevelPlan],
    level_options: &LevelOptions,
    options: &LodOptions,
    tracker: &mut Tracker,
    overlap: bool,
) -> Vec<Result<LodLevel, PyramidError>> {
    let mut chain = monotone_chain(options, source);
    let mut slots: Vec<Option<Result<LodLevel, PyramidError>>> =
        plans.iter().map(|_| None).collect();
    let mut failed = None;
    rayon::in_place_scope(|scope| {
        let mut ahead: Ahead = None;
        for (k, slot) in slots.iter_mut().enumerate() {
            let p = &plans[k];
            let next = (plans.get(k + 1))
                .filter(|next| overlap && sample_ahead(source, p, next, &level_options.pyramid));
            let sampled = match ahead.take() {
                Some(sampled) => sampled,
                None => sample_level(source, p, level_options),
            };
            let settled = sampled.map_err(PyramidError::from).and_then(|sampled| {
                rayon::in_place_scope(|inner| {
                    if let Some(next) = next {
                        inner.spawn(|_| ahead = Some(sample_level(source, next, level_options)));
                    }
                    settle_level(sampled, level_options, &mut chain, tracker)
                })
            });
            match settled {
                Ok(settled) if next.is_some() => scope
                    .spawn(move |_| *slot = Some(finish_level(settled, level_options, options))),
                Ok(settled) => *slot = Some(finish_level(settled, level_options, options)),
                Err(e) => {
                    failed = Some(e);
                    break;
                }
            }
        }
    });
    let mut made: Vec<_> = slots.into_iter().map_while(|s| s).collect();
    made.extend(failed.map(Err));
    made
}

/// Keeps the genus of a sampled level from rising (when asked) and reports it sampled.
fn settle_level(
    sampled: SampledLevel,
    level_options: &LevelOptions,
    chain: &mut Option<MonotoneChain>,
    tracker: &mut Tracker,
) -> Result<Settled, PyramidError> {
    let level = sampled.plan.level;
    let monotone_start = Instant::now();
    let (sampled, monotone) = match chain {
        Some(chain) => sampled.keep_monotone(chain, level_options)?,
        None => (sampled, None),
    };
    let monotone_seconds = monotone_start.elapsed().as_secs_f64();
    tracker.step(level, "sampled")?;
    Ok(Settled {
        sampled,
        monotone,
        monotone_seconds,
    })
}

/// Contours, cleans and (when asked) simplifies one settled level, checking that its vertices
/// stayed within 32-bit coordinates.
fn finish_level(
    settled: Settled,
    level_options: &LevelOptions,
    options: &LodOptions,
) -> Result<LodLevel, PyramidError> {
    let plan = settled.sampled.plan;
    let mut level = settled.sampled.contour(level_options)?;
    level.monotone = settled.monotone;
    level.monotone_seconds = settled.monotone_seconds;
    if let Some(defect) = find_defect(&level.mesh, &Requirements::computed()) {
        return Err(PyramidError::ComputedBeyondRange {
            defect,
            cause: "the object's extent or position is too large for 32-bit coordinates",
        });
    }
    if let Some(step) = &options.then_envelope {
        let (mesh, report) = simplify_level(&level.mesh, step, plan.voxel_size)
            .map_err(|e| PyramidError::from(e).context("`then_envelope`"))?;
        level.mesh = mesh;
        level.envelope = report;
        level.topology = mesh_topology(&level.mesh);
    }
    Ok(level)
}

/// The warnings of one finished level: empty, sampled in the band while the genus is kept from
/// rising along a `chained` pyramid, or left uncleaned.
fn level_warnings(level: &LodLevel, iso: f32, chained: bool) -> Vec<String> {
    let p = &level.plan;
    let mut warnings = Vec::new();
    if level.mesh.is_empty() {
        warnings.push(empty_level_warning(p, iso));
    }
    // A band level too large to be made dense skips the rule (`keep_monotone` gives None).
    if chained && level.monotone.is_none() {
        warnings.push(band_level_warning(p));
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
    warnings
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

#[cfg(test)]
mod tests {
    use super::*;
    use voxlod_core::glam::DVec3;
    use voxlod_core::TriangleMesh;
    use voxlod_sampling::{CsgSolid, Filter, Shape};

    /// Every bit of a mesh: positions and normals, then triangles.
    fn bits(mesh: &TriangleMesh) -> Vec<[u32; 3]> {
        let vectors = mesh.positions.iter().chain(&mesh.normals);
        let vectors = vectors.map(|p| p.to_array().map(f32::to_bits));
        vectors.chain(mesh.triangles.iter().copied()).collect()
    }

    /// A thin hollow sphere (the genus step fills its cavity and guards its perforations) by
    /// the default chain, with the next level sampled on another task and one level at a time:
    /// the same meshes bit for bit, the same topology records and warnings, and levels were in
    /// fact sampled ahead.
    #[test]
    fn overlapping_levels_give_the_chain_made_one_at_a_time() {
        let shell = Shape::sphere(DVec3::ZERO, 1.0).minus(Shape::sphere(DVec3::ZERO, 0.93));
        let solid = CsgSolid::new(shell).unwrap();
        let source = Source::Solid(&solid);
        let options = LodOptions::halving(96, 5, Filter::Hypercone);
        let lod_source = LodSource::Solid(&solid);
        let level_options = LevelOptions {
            pyramid: options.pyramid.clone(),
            ..Default::default()
        };
        let plans = plan(&lod_source, &level_options).unwrap();
        let ahead = (plans.windows(2))
            .filter(|w| sample_ahead(&lod_source, &w[0], &w[1], &options.pyramid))
            .count();
        assert_eq!(ahead, plans.len() - 1);
        let together = lod_levels(&source, &options, &run_to_end, true).unwrap();
        let apart = lod_levels(&source, &options, &run_to_end, false).unwrap();
        assert_eq!(together.levels.len(), 5);
        assert_eq!(together.warnings, apart.warnings);
        let mut acted = 0;
        for (a, b) in together.levels.iter().zip(&apart.levels) {
            assert!(bits(&a.mesh) == bits(&b.mesh), "level {}", a.plan.level);
            assert!(!a.mesh.is_empty(), "level {}", a.plan.level);
            assert_eq!(a.plan, b.plan);
            assert_eq!(a.monotone, b.monotone);
            assert_eq!(a.topology, b.topology);
            let record = a.monotone.expect("a record per level");
            acted += record.samples_filled + record.samples_kept_inside;
        }
        assert!(acted > 0, "the genus step changed nothing");
    }

    /// With a frame asked for, the levels of a scan in LPS are those in its own frame turned
    /// half about z (x and y negated), the same triangles facing the same way.
    #[test]
    fn levels_are_moved_into_the_frame_asked_for() {
        use voxlod_core::{Frame, Grid, Orientation, Volume};
        let grid = Grid::new([12, 12, 12], [1.0; 3], [2.0, 3.0, 4.0]).unwrap();
        let ball = |i: usize| (i as f32 - 5.5).powi(2);
        let values = (0..grid.len())
            .map(|n| 16.0 - ball(n % 12) - ball(n / 12 % 12) - ball(n / 144))
            .collect();
        let lps = Orientation {
            frame: Frame::Lps,
            ..Default::default()
        };
        let volume = Volume::from_vec(grid, values).unwrap().oriented(lps);
        let source = Source::Threshold {
            volume: &volume,
            threshold: 0.0,
        };
        let own = LodOptions::halving(12, 1, Filter::Hypercone);
        let ras = LodOptions {
            frame: Some(Frame::Ras),
            ..own.clone()
        };
        let (a, b) = (lod(&source, &own).unwrap(), lod(&source, &ras).unwrap());
        let (a, b) = (&a.levels[0].mesh, &b.levels[0].mesh);
        assert!(!a.is_empty());
        assert_eq!(a.triangles, b.triangles);
        for (p, q) in a.positions.iter().zip(&b.positions) {
            assert_eq!((q.x, q.y, q.z), (-p.x, -p.y, p.z));
        }
    }
}
