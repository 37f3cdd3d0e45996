//! Simplification envelopes in one call (Varshney, Agarwal, Brooks, Wright, Weber 1995): a
//! series of levels with growing ε, each simplifying the one before, every point of a level
//! within ε of the input and back, genus, components and holes kept, vertices a subset of the
//! input's. A non-manifold or inconsistently oriented input can be cut into a manifold first
//! ([`EnvelopeSeriesOptions::repair`]), without moving any point. Cost: O(T log T) per level.

use std::ops::ControlFlow;

use voxlod_core::TriangleMesh;
use voxlod_envelope::{
    envelope_series_until, repair_for_envelope, EnvelopeLevel, EnvelopeOptions, Epsilon,
    ManifoldRepair,
};

use crate::error::Error;
use voxlod_pyramid::progress::{run_to_end, Event, ProgressFn, Tracker};
use voxlod_pyramid::InvalidOption;

/// Options of [`envelope`].
#[derive(Clone, Debug, PartialEq)]
pub struct EnvelopeSeriesOptions {
    /// ε of each level, growing: a distance or a fraction of the bounding-box diagonal.
    pub epsilons: Vec<Epsilon>,
    /// Removal order, offsets, sharp edges, regions, measuring.
    pub options: EnvelopeOptions,
    /// Cut a non-manifold or inconsistently oriented input into a manifold first.
    pub repair: bool,
}

impl Default for EnvelopeSeriesOptions {
    /// One level within 1 % of the diagonal, the paper's method, no repair.
    fn default() -> Self {
        EnvelopeSeriesOptions::paper(vec![Epsilon::percent(1.0)])
    }
}

impl EnvelopeSeriesOptions {
    /// The paper's order and offsets at `epsilons`.
    pub fn paper(epsilons: Vec<Epsilon>) -> Self {
        EnvelopeSeriesOptions {
            epsilons,
            options: EnvelopeOptions::paper(),
            repair: false,
        }
    }

    /// The same guarantees with offsets along smoothed normals and the smallest deviation
    /// first: far fewer triangles at coarse levels, faster.
    pub fn tight(epsilons: Vec<Epsilon>) -> Self {
        EnvelopeSeriesOptions {
            options: EnvelopeOptions::tight(),
            ..EnvelopeSeriesOptions::paper(epsilons)
        }
    }

    /// These options with the input repaired first.
    pub fn with_repair(self) -> Self {
        EnvelopeSeriesOptions {
            repair: true,
            ..self
        }
    }
}

/// The levels of a series.
#[derive(Clone, Debug)]
pub struct EnvelopeSeries {
    /// One per ε, finest first, each with its report.
    pub levels: Vec<EnvelopeLevel>,
    /// What the repair changed, when asked.
    pub repair: Option<ManifoldRepair>,
    /// Vertices and triangles of the input the levels simplify (after repair).
    pub input_vertices: usize,
    /// See `input_vertices`.
    pub input_triangles: usize,
    /// What the repair changed, in words.
    pub warnings: Vec<String>,
}

/// Refuses a sharp-edge angle outside 0 to 180 degrees. Cheap; call it to refuse bad options
/// before reading any input ([`envelope`] calls it too).
pub fn check_envelope_options(options: &EnvelopeSeriesOptions) -> Result<(), Error> {
    if let Some(deg) = options.options.keep_sharp {
        if !(0.0..=180.0).contains(&deg) {
            let problem = "a dihedral angle is between 0 and 180 degrees";
            return Err(InvalidOption::new("keep_sharp", deg, problem).into());
        }
    }
    Ok(())
}

/// A series of envelope levels of `mesh`.
///
/// ```
/// # fn main() -> Result<(), voxlod::Error> {
/// use voxlod::sampling::{CsgSolid, Shape};
/// use voxlod::core::glam::DVec3;
/// // A sphere from marching cubes, simplified within 2 % of its diagonal.
/// let ball = CsgSolid::new(Shape::sphere(DVec3::ZERO, 1.0))?;
/// let lod = voxlod::lod(&voxlod::Source::Solid(&ball), &voxlod::LodOptions::halving(20, 1, voxlod::sampling::Filter::Hypercone))?;
/// let sphere = &lod.levels[0].mesh;
/// let eps = vec![voxlod::envelope::Epsilon::percent(2.0)];
/// let series = voxlod::envelope(sphere, &voxlod::EnvelopeSeriesOptions::tight(eps))?;
/// let level = &series.levels[0];
/// assert!(level.mesh.triangle_count() < sphere.triangle_count());
/// assert_eq!(level.report.topology.genus, Some(0));
/// # Ok(())
/// # }
/// ```
pub fn envelope(
    mesh: &TriangleMesh,
    options: &EnvelopeSeriesOptions,
) -> Result<EnvelopeSeries, Error> {
    envelope_with(mesh, options, &run_to_end)
}

/// [`envelope`], reporting each level to `progress` as soon as it is made and stopping with
/// [`Error::Cancelled`] before the next when asked.
pub fn envelope_with(
    mesh: &TriangleMesh,
    options: &EnvelopeSeriesOptions,
    progress: &ProgressFn,
) -> Result<EnvelopeSeries, Error> {
    check_envelope_options(options)?;
    let mut warnings = Vec::new();
    let repaired;
    let (input, repair) = if options.repair {
        let (m, r) = repair_for_envelope(mesh);
        if r.changed_anything() {
            warnings.push(format!("cut into a manifold for the envelope: {r}"));
        }
        repaired = m;
        (&repaired, Some(r))
    } else {
        (mesh, None)
    };
    let mut tracker = Tracker::start(progress, options.epsilons.len())?;
    let mut levels = Vec::new();
    let mut stopped = None;
    envelope_series_until(input, &options.epsilons, &options.options, |level| {
        let asked = tracker.step(level.report.level, "simplified");
        let asked = asked.and_then(|()| tracker.ask(Event::EnvelopeLevel(&level)));
        levels.push(level);
        match asked {
            Ok(()) => ControlFlow::Continue(()),
            Err(e) => {
                stopped = Some(e);
                ControlFlow::Break(())
            }
        }
    })?;
    if let Some(e) = stopped {
        return Err(e.into());
    }
    Ok(EnvelopeSeries {
        levels,
        repair,
        input_vertices: input.positions.len(),
        input_triangles: input.triangles.len(),
        warnings,
    })
}
