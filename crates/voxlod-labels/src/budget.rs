//! The budget stage per label: each label's mesh reduced to at most about a number of
//! triangles by meshoptimizer's quadric edge collapse, its topology kept.
//!
//! - Marching cubes ([`budget_meshes`]): each label's closed mesh reduced on its own, the labels
//!   in parallel.
//! - The shared surface ([`budget_shared`]): simplified patch by patch before the labels' meshes
//!   are taken out. A patch is every triangle between the same two labels; each is simplified
//!   as a mesh of its own with the junction curves where it meets other patches locked (and
//!   the ring of vertices next to them), towards the smaller of its two labels' shares for it:
//!   each label's budget shared among its patches in proportion to their triangles, none below
//!   what its locked vertices hold (the background does not limit a patch). So the two labels
//!   of a patch still use the same vertices and triangles, with opposite orientation, and
//!   neighbours stay joined without gap or overlap (`budget/patches.rs`, `budget/share.rs`);
//!   the labels' meshes are then taken out of the patches (`budget/extract.rs`). A patch is
//!   moved by at most [`MEAN_SHIFT`] voxels on average, so that a patch is never flattened
//!   onto its locked junctions.
//!
//! The reductions keep each piece's topology (`budget/reduce.rs`): what meshoptimizer would
//! break (pinch, fold, flatten or drop) is locked, reduced less or kept as it was. A label
//! stays above the budget when its locked junctions, singular corners or such pieces hold more
//! triangles; [`BudgetReport::above`] lists those labels.

mod extract;
mod patches;
mod reduce;
mod share;

use rayon::prelude::*;
use voxlod_core::TriangleMesh;

use crate::surface_nets::SharedSurface;
use crate::LabelsError;

/// The smallest budget: a closed surface needs four triangles.
pub const MIN_TRIANGLES: usize = 4;

/// The most a patch of the shared surface may move, on average, by the budget, in voxels (the
/// smallest spacing): the volume between the patch before and after over its area. A reduction
/// that would move it more (meshoptimizer flattens a patch onto its locked junctions when
/// asked for fewer triangles than they allow) is asked for more triangles, and its labels may
/// stay above the budget. Each label's volume then changes by at most this times its area.
pub const MEAN_SHIFT: f64 = 0.1;

/// What the budget stage did.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BudgetReport {
    /// The budget, triangles per label.
    pub triangles: usize,
    /// The labels left above the budget with their triangle counts, most triangles first.
    pub above: Vec<(u32, usize)>,
    /// Pieces (connected components of a label's mesh or of a patch) kept as they were because
    /// every reduction meshoptimizer made of them broke their topology or moved them too far.
    pub kept_parts: usize,
}

impl BudgetReport {
    /// The report of a budget of `triangles` that gave `meshes` for `labels` (in that order),
    /// `kept_parts` pieces kept as they were.
    pub fn of(
        triangles: usize,
        labels: &[u32],
        meshes: &[TriangleMesh],
        kept_parts: usize,
    ) -> BudgetReport {
        let mut above: Vec<(u32, usize)> = labels
            .iter()
            .zip(meshes)
            .map(|(&l, m)| (l, m.triangles.len()))
            .filter(|&(_, n)| n > triangles)
            .collect();
        above.sort_by_key(|&(l, n)| (std::cmp::Reverse(n), l));
        BudgetReport {
            triangles,
            above,
            kept_parts,
        }
    }
}

/// Refuses a budget below [`MIN_TRIANGLES`] ([`LabelsError::InvalidOption`], option
/// `triangles`).
pub fn check_budget(triangles: usize) -> Result<(), LabelsError> {
    if triangles < MIN_TRIANGLES {
        return Err(LabelsError::InvalidOption {
            option: "triangles",
            value: triangles.to_string(),
            problem: format!(
                "must be at least {MIN_TRIANGLES} (a closed surface needs four triangles)"
            ),
        });
    }
    Ok(())
}

/// Each of `meshes` (closed label meshes, as marching cubes makes them) reduced towards
/// `triangles`, in parallel, its unused vertices dropped and its normals too (module docs);
/// returns the pieces kept as they were. A mesh at or under the budget is left alone. The
/// result of each mesh has the input's components, Euler characteristic and boundary, and no
/// more non-manifold edges or vertices, inconsistent edges or duplicate triangles; nothing is
/// locked, so no volume limit applies: the budget is met unless that topology forbids it.
///
/// Cost: per mesh one meshoptimizer pass and one topology measure, O(F log F) (more where a
/// pass fails, `budget/reduce.rs`); the meshes in parallel.
pub fn budget_meshes(meshes: &mut [TriangleMesh], triangles: usize) -> Result<usize, LabelsError> {
    check_budget(triangles)?;
    Ok(meshes
        .par_iter_mut()
        .filter(|m| m.triangles.len() > triangles)
        .map(|mesh| {
            let aim = reduce::Aim {
                target: triangles,
                volume: f64::INFINITY,
                lock_border: false,
            };
            let reduced = reduce::reduce(mesh, &[], aim);
            mesh.triangles = reduced.triangles;
            mesh.normals.clear();
            mesh.remove_unreferenced_vertices();
            reduced.kept_parts
        })
        .sum())
}

/// The meshes of `labels` (in that order) out of `surface` simplified patch by patch towards
/// `triangles` per label (module docs), and the pieces kept as they were. Promises: every
/// triangle between two of the labels is used by both, over the same vertices (positions bit
/// for bit), with opposite orientation; each mesh is closed and consistently oriented when the
/// surface's label meshes are, its junction curves and singular corners (with the triangles
/// around them) as they were. Fails only when the memory limit refuses the patches.
///
/// Cost: a parallel sort of the triangles, O(F log F); the patches' reductions in parallel,
/// each O(F log F) in its triangles; then each label taken out in parallel, O(its triangles).
pub fn budget_shared(
    surface: &SharedSurface,
    labels: &[u32],
    triangles: usize,
) -> Result<(Vec<TriangleMesh>, usize), LabelsError> {
    check_budget(triangles)?;
    let simplified = patches::simplify_patches(surface, labels, triangles)?;
    let meshes = extract::label_meshes(surface, &simplified.patches, labels);
    Ok((meshes, simplified.kept_parts))
}
