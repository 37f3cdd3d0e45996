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
//! A seen triangle may show only a sliver: the measure's points on it are kept only where a
//! view sees them past the input's solid parts ([`seen_only`]), so that a face buried in the
//! union of the parts but for a strip (a block of a CAD assembly under another) is measured
//! where it shows.
//!
//! Cost: [`VIEWS`] renders of [`RESOLUTION`]² samples (O(views · (T + samples)), on all
//! threads), and where parts go, a second preparation of the input.

use voxlod_core::components::submesh;
use voxlod_core::glam::DVec3;
use voxlod_core::manifold::on_odd_edges;
use voxlod_render::{seen_points, visible_triangles, VisibilityOptions};

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

/// A measured point counts as seen within this many pixels of the views (in depth) behind a
/// face that shows ([`voxlod_render::seen_points`]): a point on a face tilted from a view lies
/// up to about a pixel behind the samples around it.
pub const POINT_REACH: f64 = 2.0;

/// Each of `sets`, points on the input's seen triangles, without those that no view sees
/// past the input's solid parts: a triangle counts as seen where any sample of it shows, and a
/// large face buried in other parts but for a sliver (two blocks of a CAD assembly sharing a
/// wall) would otherwise pull every candidate towards its buried rest. Only parts that bound a
/// volume ([`solid_parts`]) hide a point: a leaf card's texture may be clear where a branch
/// behind it shows. A set that would lose every point is left whole. Nothing changes where the
/// input has no [`Input::seen`] or no solid part. Cost: [`VIEWS`] drawings of the solid parts,
/// O(1) per point and view.
pub fn seen_only<const N: usize>(
    input: &Input,
    sets: [&mut Vec<DVec3>; N],
) -> Result<(), BudgetError> {
    if input.seen.is_none() {
        return Ok(());
    }
    let Some(solids) = solid_parts(input) else {
        return Ok(());
    };
    let options = VisibilityOptions {
        views: VIEWS,
        resolution: RESOLUTION,
        ..VisibilityOptions::default()
    };
    let all: Vec<DVec3> = sets.iter().flat_map(|s| s.iter().copied()).collect();
    let seen = seen_points(&solids, &all, &options, POINT_REACH)?;
    let mut flags = seen.into_iter();
    for set in sets {
        let keep: Vec<bool> = flags.by_ref().take(set.len()).collect();
        if keep.iter().any(|&k| k) {
            let mut k = keep.into_iter();
            set.retain(|_| k.next().unwrap_or(true));
        }
    }
    Ok(())
}

/// The input's parts that bound a volume, as one mesh: those none of whose edges is used by
/// an odd number of triangles (`voxlod_core::manifold::on_odd_edges`: a closed part, or closed
/// parts touching along edges); `None` where there is none. Cost: O(F log F), one edge sort.
fn solid_parts(input: &Input) -> Option<voxlod_core::TriangleMesh> {
    let on_odd_edge = on_odd_edges(&input.mesh.triangles);
    let solid: Vec<u32> = (input.parts.iter())
        .filter(|p| !p.iter().any(|&t| on_odd_edge[t as usize]))
        .flatten()
        .copied()
        .collect();
    (!solid.is_empty()).then(|| submesh(&input.mesh, &solid))
}

#[cfg(test)]
mod tests {
    use super::*;
    use voxlod_core::glam::Vec3;
    use voxlod_core::TriangleMesh;
    use voxlod_testkit::shapes::{append, unit_cube};

    /// Two unit cubes sharing the edge x = 1, y = 1 (its two vertices welded: an edge of four
    /// triangles), and a square card of two triangles beside them.
    fn cubes_and_card() -> TriangleMesh {
        let mut mesh = unit_cube();
        let mut other = unit_cube();
        other
            .positions
            .iter_mut()
            .for_each(|p| *p += Vec3::new(1.0, 1.0, 0.0));
        append(&mut mesh, &other);
        let card = TriangleMesh::new(
            vec![
                Vec3::new(3.0, 0.0, 0.0),
                Vec3::new(4.0, 0.0, 0.0),
                Vec3::new(4.0, 0.0, 1.0),
                Vec3::new(3.0, 0.0, 1.0),
            ],
            vec![[0, 1, 2], [0, 2, 3]],
        );
        append(&mut mesh, &card);
        mesh
    }

    #[test]
    fn solid_parts_are_closed_parts_touching_along_edges_not_cards() {
        let input = Input::prepare(&cubes_and_card()).unwrap();
        assert_eq!(
            input.parts.len(),
            2,
            "the cubes are one part, the card another"
        );
        let solid = solid_parts(&input).unwrap();
        assert_eq!(solid.triangle_count(), 24);
        let bounds = solid.bounds();
        assert_eq!(
            (bounds.min, bounds.max),
            (DVec3::ZERO, DVec3::new(2.0, 2.0, 1.0))
        );
    }

    #[test]
    fn seen_only_drops_points_of_a_face_buried_under_a_block_and_keeps_those_behind_a_card() {
        // A slab (z 0 to 0.5) under a block that leaves a strip x > 0.9 of its top open, and a
        // card standing before the slab's face y = 0. Points of the slab's top: one under the
        // block (buried), one on the strip (seen); one on the face y = 0 behind the card (seen:
        // a card hides nothing, its texture may be clear there).
        let mut mesh = unit_cube();
        mesh.positions.iter_mut().for_each(|p| p.z *= 0.5);
        let mut block = unit_cube();
        block.positions.iter_mut().for_each(|p| {
            p.x *= 0.9;
            p.z += 0.5;
        });
        append(&mut mesh, &block);
        let card = TriangleMesh::new(
            vec![
                Vec3::new(0.2, -0.1, 0.1),
                Vec3::new(0.8, -0.1, 0.1),
                Vec3::new(0.8, -0.1, 0.4),
                Vec3::new(0.2, -0.1, 0.4),
            ],
            vec![[0, 1, 2], [0, 2, 3]],
        );
        append(&mut mesh, &card);
        let input = without_hidden(Input::prepare(&mesh).unwrap()).unwrap();
        assert!(input.seen.is_some());
        let (buried, strip, behind) = (
            DVec3::new(0.45, 0.5, 0.5),
            DVec3::new(0.95, 0.5, 0.5),
            DVec3::new(0.5, 0.0, 0.25),
        );
        let mut points = vec![buried, strip, behind];
        seen_only(&input, [&mut points]).unwrap();
        assert_eq!(points, [strip, behind]);
    }
}
