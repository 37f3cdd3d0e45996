//! Inputs of closed and open parts (a tree's trunk and its leaf cards, a machine with sheet
//! metal guards, a building with open awnings): one more solid for the voxel candidates, the
//! closed parts sampled as a solid and the open parts as shells around them.
//!
//! Why: sampled as one solid, an open part bounds no volume (a leaf card closed by a fan is a
//! solid of zero thickness) and the filter erases it (He et al. 1995 §2–3), so every voxel
//! level keeps only the closed parts; a shell around the whole input (module `shell`) keeps the
//! open parts but doubles every closed part's surface. Here each kind is sampled as what it is:
//! the closed parts' filtered density, and around the open parts the shell's ramp density of
//! their unsigned distance (module `shell_density`), combined by their maximum (the union of the two
//! solids) before contouring. The open parts become thin closed slabs that follow them; the
//! closed parts are as in the input's own voxel level. Our addition to the paper.
//!
//! A part is a connected set of triangles (sharing vertices after the input's weld); it is open
//! where one of its edges is used by one triangle or by more than two.
//!
//! Cost: one edge sort (O(F log F), [`on_open_edges`]), a solid of the closed parts and a closest-point structure
//! of the open parts (O(F log F) each); per grid, the shell's density (module `shell_density`).

use voxlod_core::manifold::on_open_edges;
use voxlod_core::{TriangleMesh, Volume};
use voxlod_metrics::MeshDistance;

use crate::input::Input;
use crate::shell_density::{shell_density, HALF_THICKNESS, RAMP};
use crate::BudgetError;

/// An input's parts split by kind: both non-empty.
pub struct SplitParts {
    /// The closed parts, as one mesh.
    pub closed: TriangleMesh,
    /// The open parts, as one mesh.
    pub open: TriangleMesh,
}

/// The input's closed and open parts (module docs), or `None` where all its parts are of one
/// kind.
pub fn split_open_parts(input: &Input) -> Option<SplitParts> {
    let open_triangle = on_open_edges(&input.mesh.triangles);
    let mut closed = Vec::new();
    let mut open = Vec::new();
    for part in &input.parts {
        let is_open = part.iter().any(|&t| open_triangle[t as usize]);
        let into = if is_open { &mut open } else { &mut closed };
        into.extend(part.iter().map(|&t| input.mesh.triangles[t as usize]));
    }
    if closed.is_empty() || open.is_empty() {
        return None;
    }
    let of = |triangles: Vec<[u32; 3]>| {
        let mut mesh = TriangleMesh::new(input.mesh.positions.clone(), triangles);
        mesh.remove_unreferenced_vertices();
        mesh
    };
    Some(SplitParts {
        closed: of(closed),
        open: of(open),
    })
}

/// `density` (a filtered density of the closed parts on a grid of spacing `voxel`) raised to
/// the shell density of the open parts `open` wherever that is larger: the union of the two
/// solids at isodensity 1/2.
pub fn add_open_shells(
    density: &mut Volume,
    open: &MeshDistance,
    voxel: f64,
) -> Result<(), BudgetError> {
    let (t, w) = (HALF_THICKNESS * voxel, RAMP * voxel);
    let shells = shell_density(&density.grid, open, t, w)?;
    for (d, s) in density.values.iter_mut().zip(&shells.values) {
        *d = d.max(*s);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use voxlod_testkit::shapes::{append, unit_cube};

    /// The unit square at height `z`, as two triangles (the cube's bottom corners).
    fn quad(z: f32) -> TriangleMesh {
        let mut positions = unit_cube().positions[..4].to_vec();
        positions.iter_mut().for_each(|p| p.z = z);
        TriangleMesh::new(positions, vec![[0, 1, 3], [0, 3, 2]])
    }

    #[test]
    fn a_closed_box_and_two_cards_split_into_twelve_and_four_triangles() {
        let mut mesh = unit_cube();
        append(&mut mesh, &quad(3.0));
        append(&mut mesh, &quad(5.0));
        let input = Input::prepare(&mesh).unwrap();
        let split = split_open_parts(&input).expect("both kinds");
        assert_eq!(split.closed.triangle_count(), 12);
        assert_eq!(split.open.triangle_count(), 4);
        assert_eq!(split.open.positions.len(), 8);
    }

    #[test]
    fn inputs_of_one_kind_are_not_split() {
        let cube = unit_cube();
        assert!(split_open_parts(&Input::prepare(&cube).unwrap()).is_none());
        let mut cards = quad(0.0);
        append(&mut cards, &quad(2.0));
        assert!(split_open_parts(&Input::prepare(&cards).unwrap()).is_none());
    }

    #[test]
    fn an_edge_of_three_triangles_makes_its_part_open() {
        let open = on_open_edges(&[[0, 1, 2], [1, 0, 3], [0, 1, 4]]);
        assert_eq!(open, vec![true, true, true]);
        let tetrahedron = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
        assert_eq!(on_open_edges(&tetrahedron), vec![false; 4]);
    }
}
