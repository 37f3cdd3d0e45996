//! The geometric stage (step 3 of [`crate::budget`], He et al. 1995 §5): meshoptimizer's
//! quadric collapse with the topology kept, dropping the smallest parts where it stalls above
//! the budget (our addition), with twins that restore the input's detached parts (step 6), or
//! simplification envelopes with ε searched for the count. Cost: per level, up to four quadric
//! runs, or up to four envelope runs, and one distance measurement per candidate.

use voxlod_core::TriangleMesh;
use voxlod_envelope::{simplify_envelope, EnvelopeOptions, Epsilon};
use voxlod_quadric::{simplify_dropping_parts, PartsOptions, QuadricOptions};

use super::candidate::Candidate;
use super::context::BudgetContext;
use super::detached::with_detached_parts;
use super::{Stage, Then, BUDGET_TOLERANCE};
use crate::lod::LodLevel;

/// The geometric stages asked for, applied to `level` for `budget`; a stage that fails is
/// left out (the voxel level itself is the candidate of [`Then::None`]; [`Then::Auto`]'s
/// envelopes run after the search, where the quadric stage stalled).
pub(super) fn stages(
    ctx: &BudgetContext,
    level: &LodLevel,
    iso: f32,
    budget: usize,
    error: Option<f64>,
) -> Vec<Candidate> {
    let mut out = Vec::new();
    let want_quadric = matches!(ctx.then, Then::Auto | Then::Quadric);
    if ctx.then == Then::None {
        out.push(Candidate {
            mesh: level.mesh.clone(),
            stage: Stage::Voxel,
            error_bound: 0.5 * level.plan.voxel_size,
            distance: ctx.measure(&level.mesh),
            parts_dropped: 0,
            parts_restored: 0,
            iso,
            facts: Default::default(),
        });
    }
    if want_quadric {
        let options = PartsOptions {
            quadric: QuadricOptions::budget(error.unwrap_or(f64::INFINITY)),
            ..PartsOptions::default()
        };
        if let Ok(done) = simplify_dropping_parts(&level.mesh, budget, &options) {
            let quadric = Candidate {
                distance: ctx.measure(&done.simplified.mesh),
                mesh: done.simplified.mesh,
                stage: Stage::Quadric,
                error_bound: done.simplified.error_bound,
                parts_dropped: done.dropped_parts,
                parts_restored: 0,
                iso,
                facts: Default::default(),
            };
            let twins = with_detached_parts(ctx, level, &quadric, budget, error);
            out.push(quadric);
            out.extend(twins);
        }
    }
    if ctx.then == Then::Envelope {
        out.extend(envelope_candidate(ctx, level, iso, budget, error));
    }
    out
}

/// The envelope stage on `level` for `budget`, measured.
pub(super) fn envelope_candidate(
    ctx: &BudgetContext,
    level: &LodLevel,
    iso: f32,
    budget: usize,
    error: Option<f64>,
) -> Option<Candidate> {
    let (mesh, epsilon) = envelope_to_count(&level.mesh, budget, error, level)?;
    Some(Candidate {
        distance: ctx.measure(&mesh),
        mesh,
        stage: Stage::Envelope,
        error_bound: epsilon,
        parts_dropped: 0,
        parts_restored: 0,
        iso,
        facts: Default::default(),
    })
}

/// Simplification envelopes (tight preset) with ε searched so that the count comes near
/// `budget`: ε starts at one voxel and is scaled by the count's ratio to the budget (counts fall
/// about as 1/ε), at most four runs, ε never above `error`. The run nearest the budget and its ε.
fn envelope_to_count(
    mesh: &TriangleMesh,
    budget: usize,
    error: Option<f64>,
    level: &LodLevel,
) -> Option<(TriangleMesh, f64)> {
    let options = EnvelopeOptions::tight().with_measure_samples(0);
    let cap = error.unwrap_or(f64::INFINITY);
    let mut epsilon = level.plan.voxel_size.min(cap);
    let mut best: Option<(TriangleMesh, f64)> = None;
    for _ in 0..4 {
        let done = simplify_envelope(mesh, Epsilon::Absolute(epsilon), &options).ok()?;
        let got = done.mesh.triangle_count().max(1);
        let miss = |n: usize| (n as f64 / budget as f64).ln().abs();
        if best
            .as_ref()
            .is_none_or(|b| miss(got) < miss(b.0.triangle_count()))
        {
            best = Some((done.mesh, epsilon));
        }
        if miss(got) <= (1.0 + BUDGET_TOLERANCE).ln() {
            break;
        }
        let next = (epsilon * got as f64 / budget as f64).min(cap);
        if next == epsilon {
            break;
        }
        epsilon = next;
    }
    best
}
