//! What of the input can be seen from outside (our addition to He et al. 1995, as scene
//! remeshers do it): the input drawn from a sphere of views (crate `voxlod-render`,
//! [`visible_triangles`]); its parts that no view sees (furniture in a closed building, a
//! part buried in others) are dropped before any candidate is made, and the triangles seen
//! are the surface every candidate is measured against and fitted to ([`Input::seen`]), so
//! that a level is not pulled towards faces buried in the union of the parts.
//!
//! A part is kept whole where any of its triangles is seen: a closed part cut down to its seen
//! faces would no longer bound a solid. A triangle smaller than a pixel of the views may be
//! reported hidden ([`voxlod_render::visibility`]); it still counts where its part is seen.
//!
//! Cost: [`VIEWS`] renders of [`RESOLUTION`]² samples (O(views · (T + samples)), on all
//! threads), and where parts go, a second preparation of the input.

use voxlod_core::components::submesh;
use voxlod_render::{visible_triangles, VisibilityOptions};

use crate::input::{Input, Seen};
use crate::BudgetError;

/// Directions the input is drawn from.
pub const VIEWS: usize = 64;
/// Samples a side of each view.
pub const RESOLUTION: u32 = 512;

/// `input` without its parts that no view sees, with [`Input::seen`] set; unchanged where no
/// triangle is seen at all (nothing to go by). Fails on the memory limit of the views.
pub fn without_hidden(input: Input) -> Result<Input, BudgetError> {
    let options = VisibilityOptions {
        views: VIEWS,
        resolution: RESOLUTION,
        ..VisibilityOptions::default()
    };
    let seen = visible_triangles(&input.mesh, &options)?;
    if !seen.iter().any(|&s| s) {
        return Ok(input);
    }
    let part_seen = |p: &Vec<u32>| p.iter().any(|&t| seen[t as usize]);
    let hidden_parts = input.parts.iter().filter(|p| !part_seen(p)).count();
    let mut kept: Vec<u32> = input
        .parts
        .iter()
        .filter(|p| part_seen(p))
        .flatten()
        .copied()
        .collect();
    kept.sort_unstable();
    let mut input = match hidden_parts {
        0 => input,
        _ => {
            let mut smaller = Input::prepare(&submesh(&input.mesh, &kept))?;
            smaller.preparation = input.preparation;
            smaller
        }
    };
    // Preparing a prepared mesh keeps its triangles in order (nothing to weld or drop); were
    // that not so, the views are drawn again.
    let mut mask: Vec<bool> = kept.iter().map(|&t| seen[t as usize]).collect();
    if mask.len() != input.mesh.triangle_count() {
        mask = visible_triangles(&input.mesh, &options)?;
    }
    let seen_triangles: Vec<u32> = (0..mask.len() as u32)
        .filter(|&t| mask[t as usize])
        .collect();
    input.seen = Some(Seen {
        mesh: submesh(&input.mesh, &seen_triangles),
        mask,
        hidden_parts,
    });
    Ok(input)
}
