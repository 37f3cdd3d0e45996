//! The input's own collapses, the portfolio's first members: meshoptimizer's `simplify` as
//! gltfpack runs it (Garland–Heckbert quadric edge collapse with the border free and no error
//! limit), its checked form that keeps the topology where the plain one broke a promise, and
//! `simplifySloppy`'s grid clustering. Cost: O(F log F) each (sloppy O(F)), on one thread.

use voxlod_quadric::{simplify_sloppy, simplify_to_budget, simplify_unchecked, QuadricOptions};

use voxlod_core::TriangleMesh;

use crate::candidate::{Candidate, Method};
use crate::input::Input;
use crate::promises::within_budget;
use voxlod_contouring::clean_mesh::without_zero_area;

/// meshoptimizer passes the checked collapse may make in each of its ratchets (each pass also
/// checks the topology and the crossings of its result): enough for the locks around a few
/// pinches. Those that reached their budgets took at most 8 passes in all, while one that
/// stalls spends every pass of both ratchets (a 40 k-triangle boot at 4 988: 24 passes at 12,
/// 0.59 s, to stop at 22 172 triangles); 8 rather than 12 changed none of 377 levels of 93
/// inputs and took 5–10 % off their chains.
pub const KEPT_ATTEMPTS: usize = 8;

/// The largest input whose checked collapse is tried where its plain collapse broke its
/// topology: each pass also checks the topology and the crossings of the whole result, and on
/// large inputs whose plain collapse pinched (a CT surface's hundreds of thin walls) every pass
/// is refused, seconds for nothing. Where the plain collapse only crossed, the locks around the
/// few folds let the checked one through at any size, but only for the largest budget that
/// needs one: below a larger budget's collapse, a stall is not worth a collapse of the whole
/// input (the 1.4 M-triangle sphereflake asked for 1 000 and 300: its checked collapse from
/// the input at 300 took 37 s and stalled at 1 360 176 triangles).
pub const KEPT_AT_MOST: usize = 250_000;

/// meshoptimizer passes the checked collapse of a mesh above [`KEPT_AT_MOST`] triangles may
/// make in each of its ratchets (`voxlod_quadric::QuadricOptions::max_attempts`): a pass of the
/// whole input costs about what `simplify` takes for it. A large scan whose folds the locks
/// settle needs up to five (a 268 686-triangle head at 5 000 triangles), while one that stalls
/// spends every pass of both ratchets (the 1.4 M-triangle sphereflake at 300: with 12, 24
/// passes and 37 s, to stop at 1 360 176 triangles).
pub const KEPT_ATTEMPTS_LARGE: usize = 6;

/// The input collapsed towards `budget` by meshoptimizer's `simplify`, border free, within
/// `max_error` (mesh units) of its own estimate. A budget at or above the input's triangles
/// gives the input itself. `None` where meshoptimizer refuses the mesh.
pub fn plain(input: &Input, budget: usize, max_error: Option<f64>) -> Option<Candidate> {
    if budget >= input.mesh.triangle_count() {
        return Some(Candidate::new(Method::Collapse, input.mesh.clone()));
    }
    let make = |target: usize| plain_to(input, target, max_error);
    refilled(make, budget)
}

/// How many more times [`refilled`] makes a candidate, at most.
pub const REFILLS: usize = 3;

/// Where making a candidate left it outside the budget's tolerance, `make` again aiming off in
/// proportion (at most [`REFILLS`] times): above the budget where flattened pockets were
/// dropped, below it where flattened parts were inflated into tetrahedra (`Candidate::new`).
/// The first make within the tolerance, else the first. Cost: up to [`REFILLS`] more
/// collapses, only where the first misses the tolerance.
fn refilled(make: impl Fn(usize) -> Option<Candidate>, budget: usize) -> Option<Candidate> {
    let first = make(budget)?;
    let (mut target, mut made) = (budget, first.triangles());
    for _ in 0..REFILLS {
        if within_budget(made, budget) || made == 0 {
            break;
        }
        let aim = (target as f64 * budget as f64 / made as f64).round() as usize;
        if aim == target || aim == 0 {
            break;
        }
        target = aim;
        let Some(again) = make(target) else { break };
        made = again.triangles();
        if within_budget(made, budget) {
            return Some(again);
        }
    }
    Some(first)
}

/// [`plain`] aiming at `target` triangles.
fn plain_to(input: &Input, target: usize, max_error: Option<f64>) -> Option<Candidate> {
    let budget = target.min(input.mesh.triangle_count());
    let mesh = collapsed_plainly(&input.mesh, budget, max_error)?;
    Some(Candidate::new(
        Method::Collapse,
        without_zero_area(mesh, input.cell()),
    ))
}

/// `mesh` collapsed towards `budget` by meshoptimizer's `simplify`, border free, within
/// `max_error` of its own estimate: one unchecked pass (the checked form is [`kept`]).
fn collapsed_plainly(
    mesh: &TriangleMesh,
    budget: usize,
    max_error: Option<f64>,
) -> Option<TriangleMesh> {
    match max_error {
        None => Some(simplify_unchecked(mesh, budget, false).ok()?.0),
        Some(e) => {
            let options = QuadricOptions {
                max_attempts: 1,
                ..QuadricOptions::budget(e)
            };
            Some(simplify_to_budget(mesh, budget, &options).ok()?.mesh)
        }
    }
}

/// Crossing pairs beyond the input's that edge flips are tried on at most ([`uncrossed`]):
/// flips take apart the few folds of a collapse (a cow's plain collapse at 1 000 triangles
/// crosses itself in 4 pairs, at 676 in 18); a collapse that crosses itself in many places is
/// a tangle they would only spend time on.
pub const UNCROSS_AT_MOST: usize = 32;

/// The input's plain collapse `plain` with its crossing triangles taken apart by edge flips
/// (`voxlod_core::uncross`: the vertices kept, the surface changed only inside the flipped
/// quads), where that leaves no more crossing pairs than the input has; `None` where the flips
/// do not. Cost: a crossing count per pass and a scan of the mesh per flip tried.
pub fn uncrossed(input: &Input, plain: &Candidate) -> Option<Candidate> {
    if plain.crossings? > input.crossings() + UNCROSS_AT_MOST {
        return None;
    }
    let (mesh, left) = voxlod_core::uncross::uncrossed(&plain.mesh);
    if left > input.crossings() || mesh.triangles == plain.mesh.triangles {
        return None;
    }
    Some(Candidate::new(Method::CollapseUncrossed, mesh))
}

/// The input's plain collapse made in two steps: to twice `budget`, then on to `budget`
/// (both [`plain`]), where the first step keeps `keeps` (the caller's promises, crossings
/// included). meshoptimizer collapses the cheapest edges first over the whole mesh; stopping
/// halfway and starting again re-ranks them on the coarser mesh, so the second step takes
/// another path, and where the one-step collapse folded a thin part through itself it often
/// does not (an owl scan at 3 050 triangles: one step crossed, two steps kept every promise at
/// 0.18 % of the diagonal, closer than the checked collapse). `None` where
/// twice the budget is not below the input's triangles or the first step breaks a promise.
/// Cost: two collapses and the caller's check.
pub fn in_two_steps(
    input: &Input,
    budget: usize,
    max_error: Option<f64>,
    keeps: impl FnOnce(&mut Candidate) -> bool,
) -> Option<Candidate> {
    let halfway = budget.checked_mul(2)?;
    if halfway >= input.mesh.triangle_count() {
        return None;
    }
    let mut first = plain(input, halfway, max_error)?;
    if !keeps(&mut first) {
        return None;
    }
    let mesh = collapsed_plainly(&first.mesh, budget, max_error)?;
    let second = Candidate::new(
        Method::CollapseInTwoSteps,
        without_zero_area(mesh, input.cell()),
    );
    Some(second)
}

/// The input exactly as given (`given`, before its vertices were merged) collapsed towards
/// `budget` as [`plain`] collapses the prepared input, turned right side out with it.
pub fn as_given(given: &TriangleMesh, budget: usize, input: &Input) -> Option<Candidate> {
    if budget >= given.triangle_count() {
        return None;
    }
    let make = |target: usize| {
        let mut mesh = simplify_unchecked(given, target, false).ok()?.0;
        if input.preparation.turned_right_side_out {
            mesh.flip_orientation();
        }
        let mesh = without_zero_area(mesh, input.cell());
        Some(Candidate::new(Method::CollapseAsGiven, mesh))
    };
    refilled(make, budget)
}

/// `mesh` (the input, cut into a manifold where it is not, or a collapse of it) collapsed
/// towards `budget` with its topology kept, but for an open input's holes, which may close (its
/// levels promise no boundary), and no crossing triangles added (voxlod-quadric: each
/// meshoptimizer pass checked, rejected passes retried with locks). `None` where `mesh` has no
/// more triangles than the budget or is not a manifold.
pub fn kept(
    mesh: &TriangleMesh,
    budget: usize,
    input: &Input,
    max_error: Option<f64>,
) -> Option<Candidate> {
    if budget >= mesh.triangle_count() {
        return None;
    }
    let options = QuadricOptions {
        max_attempts: match mesh.triangle_count() > KEPT_AT_MOST {
            true => KEPT_ATTEMPTS_LARGE,
            false => KEPT_ATTEMPTS,
        },
        holes_may_close: input.topology.boundary_loops > 0,
        ..QuadricOptions::budget(max_error.unwrap_or(f64::INFINITY))
    };
    let done = simplify_to_budget(mesh, budget, &options).ok()?;
    let mesh = without_zero_area(done.mesh, input.cell());
    Some(Candidate::new(Method::CollapseKept, mesh))
}

/// The input clustered to about `budget` triangles by meshoptimizer's `simplifySloppy`.
pub fn sloppy(input: &Input, budget: usize) -> Option<Candidate> {
    if budget >= input.mesh.triangle_count() {
        return None;
    }
    let mesh = simplify_sloppy(&input.mesh, budget).ok()?;
    (!mesh.triangles.is_empty()).then(|| Candidate::new(Method::Sloppy, mesh))
}

#[cfg(test)]
mod tests {
    use super::*;
    use voxlod_core::glam::Vec3;
    use voxlod_testkit::shapes::{append, icosphere, icosphere_at};

    #[test]
    fn a_collapse_whose_flattened_parts_are_inflated_is_aimed_lower() {
        // A ball and 40 specks: collapsed to 200 triangles, meshoptimizer flattens 22 specks,
        // whose tetrahedra (`Candidate::new`) bring the count to 244, outside the tolerance.
        let mut mesh = icosphere(3);
        for i in 0..40 {
            let a = i as f32 * 0.7;
            let at = Vec3::new(1.5 * a.cos(), 1.5 * a.sin(), 0.1 * i as f32 - 2.0);
            append(&mut mesh, &icosphere_at(1, 0.05, at));
        }
        let input = Input::prepare(&mesh).unwrap();
        let first = plain_to(&input, 200, None).unwrap();
        assert!(
            !within_budget(first.triangles(), 200),
            "{}",
            first.triangles()
        );
        let aimed = plain(&input, 200, None).unwrap();
        assert!(
            within_budget(aimed.triangles(), 200),
            "{}",
            aimed.triangles()
        );
        assert!(aimed.topology.is_closed_manifold());
    }

    #[test]
    fn uncrossed_takes_the_plain_collapses_few_folds_apart_with_its_vertices() {
        // The generated linked rings at an eighth of their triangles: meshoptimizer's collapse
        // folds one ring through its neighbour in a few places.
        let input = Input::prepare(&voxlod_testkit::corpus::rings()).unwrap();
        let budget = input.mesh.triangle_count() / 8;
        let mut plain = plain(&input, budget, None).unwrap();
        let pairs = voxlod_core::crossing_pairs(&plain.mesh).len();
        assert!(pairs > 0 && pairs <= UNCROSS_AT_MOST, "{pairs}");
        plain.crossings = Some(pairs);
        let flipped = uncrossed(&input, &plain).unwrap();
        assert_eq!(flipped.method, Method::CollapseUncrossed);
        assert!(voxlod_core::crossing_pairs(&flipped.mesh).is_empty());
        assert_eq!(flipped.triangles(), plain.triangles());
        assert_eq!(flipped.topology.genus, plain.topology.genus);
        assert!(flipped.topology.is_closed_manifold());
        let bits = |m: &TriangleMesh| -> std::collections::HashSet<[u32; 3]> {
            m.positions
                .iter()
                .map(|p| p.to_array().map(f32::to_bits))
                .collect()
        };
        assert_eq!(bits(&flipped.mesh), bits(&plain.mesh));
        // A collapse that does not cross has nothing to flip.
        let mut clean = Candidate::new(Method::Collapse, flipped.mesh.clone());
        clean.crossings = Some(0);
        assert!(uncrossed(&input, &clean).is_none());
    }

    #[test]
    fn in_two_steps_reaches_the_budget_where_its_first_step_keeps_the_promises() {
        let input = Input::prepare(&icosphere(4)).unwrap();
        let two = in_two_steps(&input, 500, None, |_| true).unwrap();
        assert_eq!(two.method, Method::CollapseInTwoSteps);
        assert!(within_budget(two.triangles(), 500), "{}", two.triangles());
        assert!(two.topology.is_closed_manifold() && two.topology.genus == Some(0));
        // Its first step ruled out, or twice the budget not below the input: none.
        assert!(in_two_steps(&input, 500, None, |_| false).is_none());
        let most = input.mesh.triangle_count() / 2;
        assert!(in_two_steps(&input, most, None, |_| true).is_none());
        // The first step is what the caller judges: 1 000 triangles.
        let mut seen = 0;
        in_two_steps(&input, 500, None, |c| {
            seen = c.triangles();
            true
        });
        assert!(within_budget(seen, 1_000), "{seen}");
    }
}
