//! Hollows the input's material nearly encloses, filled and lined (our addition to He et al.
//! 1995): two more solids for the voxel candidates, beside the input as given and with its
//! closed cavities filled (module `chain`).
//!
//! Why: a small budget affords a coarse resolution, and a shell thinner than the filter's
//! radius does not survive filtering at it (§2): the dome of a CT scan's skull perforates and
//! the level loses the head's outline. A hollow whose openings are narrower than
//! [`CLOSING_FRACTION`] of the longest side (the cranial cavity, open at the skull's base and
//! orbits) is **filled** by a morphological closing ([`voxlod_sampling::closing`]): the shell
//! is then seen from outside as the solid it bounds. What lies deeper in the hollow is buried
//! by that (a skull's floor), so the hollow is also only **lined**: the fill within the
//! closing's radius of the material, which thickens the shell inwards so that it survives the
//! filter. The portfolio's measured distances choose among the solids.
//!
//! How: the input's solid is filtered at [`RESOLUTION`] samples across its longest side (a
//! hyper-cone of one voxel, inside where the density is at least 0.5), closed, and the density
//! raised to 1 over the fill or its lining; the solid is where that volume, trilinearly
//! interpolated, is at least 0.5 (`voxlod_sampling::ThresholdSolid`, which each grid samples
//! directly, without a surface in between). Away from the hollows the surface is the input's,
//! to the grid's precision. Nothing is made when the hollows hold less than [`LEAST_FILLED`]
//! times the solid's own volume: the material is then a body with notches and bays, not a
//! shell around a hollow. A first look at [`FIRST_LOOK_RESOLUTION`] spares most inputs the
//! fine grid.
//!
//! Cost: one density at [`FIRST_LOOK_RESOLUTION`] and, past its gate, one at [`RESOLUTION`]
//! (O(N³) samples plus the lattice lines' crossings), the closings O(N³), and two copies of
//! the fine grid (16 MB each at 160³).

use voxlod_core::Volume;
use voxlod_sampling::closing::{closing_fill, Closing};
use voxlod_sampling::{filtered_density, level_grid, DensityOptions, Filter, MeshSolid};

use crate::candidate::Fill;
use crate::input::Input;
use crate::BudgetError;

/// Samples across the object's longest side of the grid the closing runs on.
pub const RESOLUTION: usize = 160;
/// The same for the first look.
pub const FIRST_LOOK_RESOLUTION: usize = 64;
/// The first look's isodensity: walls half as thick as at 0.5 stay inside (module `voxel`),
/// so that the coarser grid sees the walls the finer one will. Measured: a CT head's bone
/// surface fills 0.58 times its material at 64 and 0.5, 2.2 times at 64 and 0.25, 3.0 times
/// at 160 and 0.5; a lattice of 27 cells 0.65, 0.92 and 0.91.
pub const FIRST_LOOK_ISO: f32 = 0.25;
/// The closing's radius as a fraction of the longest side: openings narrower than twice this
/// are closed (a CT head's cranial cavity closes at 1/16, not at 1/27).
pub const CLOSING_FRACTION: f64 = 1.0 / 16.0;
/// The least volume filled, as a multiple of the solid's, for the hollows to count.
pub const LEAST_FILLED: f64 = 1.0;

/// The input with its nearly enclosed hollows filled, and with them lined (module docs): for
/// each, the input's density at [`RESOLUTION`] raised to 1 over the fill or its lining, whose
/// samples at 0.5 or above (trilinearly interpolated, `voxlod_sampling::ThresholdSolid`) are the
/// solid; none where the hollows are too small to count, and the filled one alone where the
/// lining leaves less than a ball of the closing's radius unlined.
pub fn hollow_volumes(
    input: &Input,
    solid: &MeshSolid,
) -> Result<Vec<(Fill, Volume)>, BudgetError> {
    if closed_grid(input, solid, FIRST_LOOK_RESOLUTION, FIRST_LOOK_ISO)?.is_none() {
        return Ok(Vec::new());
    }
    let Some((volume, closing)) = closed_grid(input, solid, RESOLUTION, 0.5)? else {
        return Ok(Vec::new());
    };
    let raised = |samples: &[usize]| {
        let mut raised = volume.clone();
        let values = raised.as_slice_mut();
        for &i in samples {
            values[i] = 1.0;
        }
        raised
    };
    let mut volumes = vec![(Fill::Hollows, raised(&closing.filled))];
    // Where the deep part of the hollows (the fill beyond the lining) holds less than a ball of
    // the closing's radius, the lined solid differs from the filled one by a bubble a few
    // samples across at most, which the grids the lining serves filter away or the collapse
    // drops as a small part: it would double the search for the same distances (many-parts
    // of the corpus: 76 deep samples of 584 438 filled, every lined candidate measured as its
    // filled twin; a CT head's bone surface: 230 872 of 796 019, its lined skull a level).
    let radius = closing_radius(RESOLUTION) as f64;
    let ball = 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3);
    if ((closing.filled.len() - closing.lining.len()) as f64) >= ball {
        volumes.push((Fill::HollowLining, raised(&closing.lining)));
    }
    Ok(volumes)
}

/// The closing's radius in samples of a grid of `resolution` ([`CLOSING_FRACTION`]).
fn closing_radius(resolution: usize) -> usize {
    (CLOSING_FRACTION * resolution as f64).round() as usize
}

/// The input's density at `resolution` and what the closing of its samples at `iso` or above
/// fills, when that is at least [`LEAST_FILLED`] times those samples.
fn closed_grid(
    input: &Input,
    solid: &MeshSolid,
    resolution: usize,
    iso: f32,
) -> Result<Option<(Volume, Closing)>, BudgetError> {
    let voxel = input.voxel(resolution);
    let grid = level_grid(&input.bounds, resolution, voxel)?;
    let options = DensityOptions::new(Filter::Hypercone, voxel);
    let (volume, _) = filtered_density(solid, &grid, &options)?;
    let inside: Vec<bool> = volume.as_slice().iter().map(|&d| d >= iso).collect();
    let closing = closing_fill(&inside, volume.grid.dims, closing_radius(resolution))?;
    let material = inside.iter().filter(|&&b| b).count();
    let enough = material > 0 && closing.filled.len() as f64 >= LEAST_FILLED * material as f64;
    Ok(enough.then_some((volume, closing)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;
    use voxlod_contouring::{marching_cubes, ContourOptions};
    use voxlod_core::glam::DVec3;
    use voxlod_core::Axis;
    use voxlod_core::TriangleMesh;
    use voxlod_sampling::{CsgSolid, Shape};

    /// A spherical shell of radius 1 and wall 0.06 with a round hole of `hole` radius through
    /// its top, as a mesh (filtered at 96 samples and contoured).
    fn shell_with_hole(hole: f64) -> TriangleMesh {
        let shape = Shape::sphere(DVec3::ZERO, 1.0)
            .minus(Shape::sphere(DVec3::ZERO, 0.94))
            .minus(Shape::cylinder(DVec3::Z, Axis::Z, hole, 0.5));
        let solid = CsgSolid::new(shape).unwrap();
        let bounds = solid_bounds();
        let voxel = 2.0 / 96.0;
        let grid = level_grid(&bounds, 96, voxel).unwrap();
        let options = DensityOptions::new(Filter::Hypercone, voxel);
        let (density, _) = filtered_density(&solid, &grid, &options).unwrap();
        marching_cubes(&density, &ContourOptions::geometry_only(0.5)).unwrap()
    }

    /// A flat closed box 2 × 2 × 0.2 with walls 0.03 thick and a round hole of radius 0.05
    /// through its top, as a mesh (filtered at 128 samples and contoured): a hollow 0.14 deep.
    fn flat_box_with_hole() -> TriangleMesh {
        let shape = Shape::cuboid(DVec3::new(-1.0, -1.0, -0.1), DVec3::new(1.0, 1.0, 0.1))
            .minus(Shape::cuboid(
                DVec3::new(-0.97, -0.97, -0.07),
                DVec3::new(0.97, 0.97, 0.07),
            ))
            .minus(Shape::cylinder(
                DVec3::new(0.0, 0.0, 0.085),
                Axis::Z,
                0.05,
                0.05,
            ));
        let solid = CsgSolid::new(shape).unwrap();
        let voxel = 2.0 / 128.0;
        let grid = level_grid(&solid_bounds(), 128, voxel).unwrap();
        let options = DensityOptions::new(Filter::Hypercone, voxel);
        let (density, _) = filtered_density(&solid, &grid, &options).unwrap();
        marching_cubes(&density, &ContourOptions::geometry_only(0.5)).unwrap()
    }

    /// A bar 2 × 0.3 × 0.3 with walls 0.015 thick around a sealed hollow 1.97 × 0.27 × 0.27:
    /// the part of the hollow farther than the closing's radius (1/16 of 2) from a wall is a
    /// line 0.02 across.
    fn hollow_bar() -> TriangleMesh {
        use voxlod_core::glam::Vec3;
        let cuboid = |half: Vec3, inward: bool| {
            let mut m = voxlod_testkit::shapes::unit_cube();
            m.positions
                .iter_mut()
                .for_each(|p| *p = (*p * 2.0 - 1.0) * half);
            if inward {
                m.triangles.iter_mut().for_each(|t| t.swap(1, 2));
            }
            m
        };
        let mut bar = cuboid(Vec3::new(1.0, 0.15, 0.15), false);
        voxlod_testkit::shapes::append(&mut bar, &cuboid(Vec3::new(0.985, 0.135, 0.135), true));
        bar
    }

    fn solid_bounds() -> voxlod_core::Bounds {
        use voxlod_core::glam::Vec3;
        voxlod_core::Bounds::from_points([Vec3::splat(-1.0), Vec3::splat(1.0)].iter())
    }

    fn hollows(mesh: &TriangleMesh) -> Vec<(Fill, f64)> {
        let input = Input::prepare(mesh).unwrap();
        let solid = MeshSolid::new(&input.mesh).unwrap();
        let volumes = hollow_volumes(&input, &solid).unwrap();
        let contoured = |v: &Volume| {
            let mesh = marching_cubes(v, &ContourOptions::geometry_only(0.5)).unwrap();
            mesh.signed_volume()
        };
        volumes.iter().map(|(f, v)| (*f, contoured(v))).collect()
    }

    #[test]
    fn a_shell_with_a_narrow_hole_is_filled_to_its_ball_and_lined_inwards() {
        let found = hollows(&shell_with_hole(0.1));
        let ball = 4.0 / 3.0 * PI;
        let wall = ball * (1.0 - 0.94f64.powi(3));
        assert_eq!(found.len(), 2, "{found:?}");
        assert_eq!(found[0].0, Fill::Hollows);
        assert!((found[0].1 - ball).abs() < 0.05 * ball, "{found:?}");
        // The lining: the wall thickened inwards by the closing's radius (1/16 of the longest
        // side, 0.125): a shell from about 0.815 to 1.
        assert_eq!(found[1].0, Fill::HollowLining);
        let lined = ball * (1.0 - (0.94f64 - 0.125).powi(3));
        assert!(found[1].1 > 2.0 * wall, "{found:?}");
        assert!((found[1].1 - lined).abs() < 0.15 * lined, "{found:?}");
    }

    #[test]
    fn a_hollow_within_the_closings_reach_is_filled_only() {
        // The closing's radius is 2/16 = 0.125 of the box's longest side: every sample of a
        // hollow 0.14 deep is within it of a wall, so the lining is the fill.
        let found = hollows(&flat_box_with_hole());
        assert_eq!(found.len(), 1, "{found:?}");
        assert_eq!(found[0].0, Fill::Hollows);
        let slab = 2.0 * 2.0 * 0.2;
        assert!((found[0].1 - slab).abs() < 0.1 * slab, "{found:?}");
    }

    #[test]
    fn a_hollow_whose_deep_part_is_under_a_ball_of_the_closings_radius_is_filled_only() {
        let found = hollows(&hollow_bar());
        assert_eq!(found.len(), 1, "{found:?}");
        assert_eq!(found[0].0, Fill::Hollows);
        let bar = 2.0 * 0.3 * 0.3;
        assert!((found[0].1 - bar).abs() < 0.1 * bar, "{found:?}");
    }

    #[test]
    fn a_shell_with_a_wide_opening_or_a_solid_ball_has_no_hollows() {
        assert!(hollows(&shell_with_hole(0.5)).is_empty());
        let ball = voxlod_testkit::shapes::icosphere(4);
        assert!(hollows(&ball).is_empty());
    }
}
