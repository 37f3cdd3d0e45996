//! The scene proxy as one more method of the evaluation ([`PROXY`]): at every budget, the level
//! of [`voxlod::proxy`] (the whole scene sampled as one solid and remeshed by the voxel method,
//! then given a UV atlas and textures baked from the scene: one mesh, one material), measured
//! like the simplifiers' levels (distances, silhouettes, topology) and drawn for its appearance
//! with its own baked textures, not with looks taken from the input's nearest points. Its atlas
//! splits vertices along chart borders; its geometry is measured welded by position, so that
//! its vertices and topology are those of its surface.
//!
//! The proxy makes every budget's level in one call, each level capped by the one above
//! ([`voxlod::ProxyOptions::monotone`]), so it is not searched budget by budget: its parameter
//! is the budget itself. A budget the portfolio finds no level for
//! ([`voxlod::portfolio::BudgetError::NoLevel`]) is a miss, and the proxy is made again without
//! it; a level further from its budget than [`EvaluateOptions::max_miss_factor`] is a miss too,
//! as for the simplifiers. It needs an asset with looks: [`super::evaluate`] passes over it.
//!
//! Cost: that of [`voxlod::proxy`] (the portfolio's voxel search per budget, then one atlas and
//! one bake of [`EvaluateOptions::proxy_texture`]² texels per level), once more per missed
//! budget; then one measurement per level.

use std::time::Instant;

use voxlod::core::weld::weld_vertices;
use voxlod::core::PolyMesh;
use voxlod::portfolio::BudgetError;
use voxlod::pyramid::PyramidError;
use voxlod::{Proxy, ProxyOptions};
use voxlod_asset::Asset;

use super::error::EvaluateError;
use super::results::{Curve, CurvePoint};
use super::search::{out_of_reach, unmeasurable, CurveJob};
use super::trial::Trial;
use crate::methods::{
    BudgetPipeline, Method, MethodInput, RunFailure, SearchLimits, SearchSpace, Simplifier,
};

/// The scene proxy, as options, reports and `--methods` name it (`proxy`).
pub const PROXY: Method = Method::new(&SceneProxy);

/// The handle's simplifier: its name, description and parameter for reports. Its levels come
/// from the whole asset with its looks, which [`MethodInput`] does not hold, so
/// [`Simplifier::run`] refuses; the evaluation makes them with [`voxlod::proxy`].
struct SceneProxy;

impl Simplifier for SceneProxy {
    fn name(&self) -> &'static str {
        "proxy"
    }

    fn description(&self) -> &'static str {
        "scene proxy: the whole scene remeshed by the voxel method, its looks baked into one \
         texture set (voxlod::proxy)"
    }

    fn parameter_name(&self) -> &'static str {
        "target-triangles"
    }

    fn search_space(&self, limits: &SearchLimits) -> SearchSpace {
        BudgetPipeline.search_space(limits)
    }

    fn run(&self, _input: &MethodInput, _budget: f64) -> Result<PolyMesh, RunFailure> {
        Err(RunFailure::NotPrepared(
            "with its looks: the proxy is made from the asset by evaluate_asset",
        ))
    }
}

/// A method by its name: one of [`Method::ALL`], or `proxy` ([`PROXY`]).
///
/// # Errors
///
/// An unknown name, with the names there are.
pub fn method_named(name: &str) -> Result<Method, String> {
    if name == PROXY.name() {
        return Ok(PROXY);
    }
    name.parse().map_err(|_| {
        let names: Vec<&str> = Method::ALL.iter().map(|m| m.name()).collect();
        format!(
            "unknown method '{name}' (expected one of {}, {})",
            names.join(", "),
            PROXY.name()
        )
    })
}

/// The proxy of `scene` at each of the job's budgets, measured: its curve, with the misses of
/// the budgets it cannot reach. `on_point` hears of each measured level. Fails when the proxy
/// fails otherwise ([`EvaluateError::Proxy`]) or a level cannot be measured.
pub(super) fn proxy_curve(
    scene: &Asset,
    job: &CurveJob,
    on_point: &mut impl FnMut(Method, &CurvePoint),
) -> Result<Curve, EvaluateError> {
    let start = Instant::now();
    let options = job.options;
    let (made, unreached, runs) = made_at_reachable(scene, job.budgets, options.proxy_texture)?;
    let mut points = Vec::new();
    let mut misses = Vec::new();
    for &budget in job.budgets {
        if let Some((_, miss)) = unreached.iter().find(|(b, _)| *b == budget) {
            misses.push(miss.clone());
            continue;
        }
        let levels = made.as_ref().map_or(&[][..], |m| &m.levels[..]);
        let Some(level) = levels.iter().find(|l| l.report.budget == budget) else {
            continue;
        };
        let mut surface = level.asset.mesh.geometry();
        weld_vertices(&mut surface);
        let trial = Trial {
            step: budget as i64,
            parameter: budget as f64,
            level: PolyMesh::from(surface),
            seconds: level.report.seconds + level.bake.seconds,
        };
        if let Some(miss) = out_of_reach(PROXY, &trial, budget, options) {
            misses.push(miss);
            continue;
        }
        match job
            .measurer
            .measure_asset(PROXY, &trial, budget, &level.asset)
        {
            Ok(point) => {
                on_point(PROXY, &point);
                points.push(point);
            }
            Err(e) => misses.push(unmeasurable(e, PROXY, &trial, budget)?),
        }
    }
    let texels = options.proxy_texture;
    let mut notes = vec![format!(
        "Textures of {texels} × {texels} texels baked from the input; the appearance is the \
         levels' own."
    )];
    notes.extend(made.into_iter().flat_map(|m| m.warnings));
    Ok(Curve {
        method: PROXY,
        parameter: PROXY.parameter_name(),
        points,
        misses,
        trials: runs,
        seconds: start.elapsed().as_secs_f64(),
        notes,
    })
}

/// Budgets the proxy found no level for, each with its miss.
type Unreached = Vec<(usize, String)>;

/// The proxy of `scene` at every budget it can reach, with `texels`² textures: a budget the
/// portfolio finds no level for is dropped and the proxy made again without it. Returns the
/// proxy (`None` when no budget is left), the budgets dropped, and the calls made.
fn made_at_reachable(
    scene: &Asset,
    budgets: &[usize],
    texels: u32,
) -> Result<(Option<Proxy>, Unreached, usize), EvaluateError> {
    let mut left = budgets.to_vec();
    let mut unreached = Vec::new();
    let mut runs = 0;
    while !left.is_empty() {
        runs += 1;
        match voxlod::proxy(scene, &ProxyOptions::for_triangles(&left, texels)) {
            Ok(made) => return Ok((Some(made), unreached, runs)),
            Err(PyramidError::Budget(BudgetError::NoLevel { budget, why }))
                if left.contains(&budget) =>
            {
                left.retain(|&b| b != budget);
                unreached.push((budget, format!("budget {budget}: no proxy level: {why}")));
            }
            Err(e) => return Err(EvaluateError::Proxy(e)),
        }
    }
    Ok((None, unreached, runs))
}
