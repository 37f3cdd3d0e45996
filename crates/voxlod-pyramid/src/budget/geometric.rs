//! The geometric stage (step 3 of [`crate::budget`], He et al. 1995 §5): meshoptimizer's
//! quadric collapse with the topology kept, dropping the smallest parts where it stalls above
//! the budget (our addition), with twins that restore the input's detached parts (step 6), or
//! simplification envelopes with ε searched for the count. Cost: per level, up to four quadric
//! runs, or up to four envelope runs, and one distance measurement per candidate.

use voxlod_contouring::clean_mesh::without_zero_area;
use voxlod_core::TriangleMesh;
use voxlod_envelope::{simplify_envelope, EnvelopeOptions, Epsilon};
use voxlod_quadric::{simplify_dropping_parts, PartsOptions, PartsSimplified, QuadricOptions};

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
        if let Some(done) = collapse(level, budget, error) {
            let mesh = done.simplified.mesh;
            let quadric = Candidate {
                distance: ctx.measure(&mesh),
                mesh,
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

/// The quadric stage on `level`'s mesh for `target` triangles within `error`: meshoptimizer's
/// collapse with the topology kept, the smallest parts dropped where it stalls above the
/// target, and no zero-area triangle left ([`without_degenerate`]). `None` where it fails.
pub(super) fn collapse(
    level: &LodLevel,
    target: usize,
    error: Option<f64>,
) -> Option<PartsSimplified> {
    let options = PartsOptions {
        quadric: QuadricOptions::budget(error.unwrap_or(f64::INFINITY)),
        ..PartsOptions::default()
    };
    let mut done = simplify_dropping_parts(&level.mesh, target, &options).ok()?;
    let simplified = std::mem::take(&mut done.simplified.mesh);
    done.simplified.mesh = without_degenerate(simplified, level.plan.voxel_size);
    Some(done)
}

/// `mesh` with its zero-area triangles fixed, judged against a voxel of `voxel`
/// ([`voxlod_contouring::clean_mesh::without_zero_area`]).
pub(super) fn without_degenerate(mesh: TriangleMesh, voxel: f64) -> TriangleMesh {
    without_zero_area(mesh, voxel)
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

#[cfg(test)]
mod tests {
    use super::without_degenerate;
    use voxlod_core::glam::Vec3;
    use voxlod_core::{mesh_topology, TriangleMesh};
    use voxlod_metrics::health::count_zero_area_triangles;

    /// An octahedron whose top vertex is moved onto the middle of the edge from +x to +y: the
    /// top's four triangles lie flat in the equator's plane, one of them with zero area, and the
    /// bottom triangle under that edge touches the moved vertex without sharing it.
    fn octahedron_with_a_cap() -> TriangleMesh {
        let positions = vec![
            Vec3::X,
            Vec3::Y,
            -Vec3::X,
            -Vec3::Y,
            Vec3::new(0.5, 0.5, 0.0),
            -Vec3::Z,
        ];
        let triangles = vec![
            [0, 1, 4],
            [1, 2, 4],
            [2, 3, 4],
            [3, 0, 4],
            [1, 0, 5],
            [2, 1, 5],
            [3, 2, 5],
            [0, 3, 5],
        ];
        TriangleMesh::new(positions, triangles)
    }

    #[test]
    fn a_zero_area_triangle_is_flipped_away_and_nothing_else_changes() {
        let mesh = octahedron_with_a_cap();
        let before = mesh_topology(&mesh);
        assert!(before.is_closed_manifold() && before.is_consistently_oriented());
        assert_eq!(count_zero_area_triangles(&mesh), 1);
        let volume = mesh.signed_volume();
        // The lower pyramid alone: base area 2, height 1.
        assert!((volume - 2.0 / 3.0).abs() < 1e-6, "{volume}");
        let fixed = without_degenerate(mesh.clone(), 1.0);
        assert_eq!(count_zero_area_triangles(&fixed), 0);
        let after = mesh_topology(&fixed);
        assert!(after.is_closed_manifold() && after.is_consistently_oriented());
        // A flip: the cap and the bottom triangle under its long edge become two triangles
        // that tile that bottom triangle, so the count and the volume stay.
        assert_eq!(fixed.triangle_count(), 8);
        assert!((fixed.signed_volume() - volume).abs() < 1e-6);
        // A mesh without a cap comes back as it was, vertex order included.
        assert_eq!(without_degenerate(fixed.clone(), 1.0), fixed);
    }
}
