//! Nearly enclosed cavities filled (our addition): a morphological closing
//! of the input's solid that fills the hollows its material almost encloses, such as the
//! cranial cavity of a CT bone surface, which the skull encloses but for the openings at its
//! base and the orbits. Each budget's search runs twice more, on the input so filled and on
//! the input with the hollow only lined (below), beside the searches of module `filled`, and
//! the closest level is kept.
//!
//! Why: a small budget affords a coarse resolution, and a shell thinner than the filter's
//! radius does not survive filtering at it (He et al. 1995, §2): the skull's dome perforates
//! and the level loses the head's outline (silhouette). Module `filled` turns a hollow part
//! solid only when its cavity is closed. Here the cavity needs only be closed up to openings
//! narrower than [`CLOSING_FRACTION`] of the object's longest side. Filled, the shell is seen
//! from outside as the solid it bounds, and the distance to the input pays only the shell's
//! thickness behind its outer side, which the search weighs against the other levels' losses.
//! But what lies deeper in the hollow is buried (the skull's floor, up to 11 % of the diagonal
//! from the filled level's surface), so the hollow is also **lined**: only the fill within `r`
//! of the material, which thickens the shell inwards to survive the filter. On the CT bone
//! surface at 300 triangles the lined input's level is the closest (Hausdorff 11.07 % filled,
//! 8.51 % lined; BENCHMARKS.md).
//!
//! How, on a grid of [`RESOLUTION`] samples across the longest side (the density of
//! [`crate::voxelize`], inside where it is at least 0.5):
//! 1. the inside is dilated by `r` = [`CLOSING_FRACTION`] of the longest side (a ball of
//!    the grid's 6-neighbour steps and 26-neighbour steps in turn);
//! 2. what the outside of the grid cannot reach through the dilated solid (6-adjacent steps,
//!    components labelled by runs: [`voxlod_sampling::digital_topology::label_components`])
//!    is enclosed;
//! 3. the enclosed set is eroded by `r` again (the closing), and the part of it outside the
//!    solid is the filled cavity;
//! 4. the density is raised to 1 over the filled cavity (or its lining: the samples of step
//!    1's dilation) and contoured at 0.5 (marching cubes): the surface away from the cavities
//!    is the input's, to the grid's precision.
//!
//! Nothing is filled (and no search added) when the hollows hold less than [`LEAST_FILLED`]
//! times the solid's own volume: the material is then not a shell around a hollow but a body
//! with notches and bays, which the dilated levels already close (module docs of
//! [`crate::budget`], step 1). Measured at this grid on the shared data: the CT bone surface
//! fills 3.1 times its material; the eleven shared meshes 0 to 0.98 times (a hollow printed
//! part, Thingi10K 42722), the sphereflake 0.48 times, and the search on their fills found
//! no closer level (BENCHMARKS.md).
//!
//! Cost: one voxelization of the input at [`FIRST_LOOK_RESOLUTION`] and, past its gate, one at
//! [`RESOLUTION`], O(F + N³) with N³ samples; the closings, O(N³); two marching cubes,
//! O(N³); and two more searches per budget. Memory: the density (4 bytes a sample) and
//! four masks (1 byte a sample each) and a 16-bit distance a sample.

use voxlod_contouring::{marching_cubes, ContourOptions};
use voxlod_core::cavities::FilledCavities;
use voxlod_core::{TriangleMesh, Volume};
use voxlod_sampling::closing::{closing_fill, regions, Closing};

use crate::error::PyramidError;
use crate::source::Source;
use crate::voxelize::{voxelize, VoxelizeOptions};

/// Samples across the object's longest side of the grid the closing runs on.
pub(super) const RESOLUTION: usize = 160;
/// The same for a first, cheap look: most inputs hold far less than [`LEAST_FILLED`], and
/// this coarser grid tells so at a tenth of the cost (at 48, the CT bone surface's skull
/// is too thin to enclose anything: 0.42 times its material filled, 3.16 at 64).
pub(super) const FIRST_LOOK_RESOLUTION: usize = 64;
/// The closing's radius as a fraction of the longest side: openings narrower than twice this
/// are closed (measured on the CT bone surface: 1/16 closes the cranial cavity, 1/27 does not).
pub(super) const CLOSING_FRACTION: f64 = 1.0 / 16.0;
/// The least volume filled, as a multiple of the solid's, for the hollows to count (at the
/// first look, half of it).
pub(super) const LEAST_FILLED: f64 = 1.0;

/// The input mesh (welded) with its nearly enclosed cavities filled, when it has any: filled
/// whole, and lined (only the fill within the closing's radius of the material).
pub(super) fn enclosed_filled(input: &TriangleMesh) -> Result<Vec<FilledCavities>, PyramidError> {
    if closed_grid(input, FIRST_LOOK_RESOLUTION, 0.5 * LEAST_FILLED)?.is_none() {
        return Ok(Vec::new());
    }
    let Some((volume, closing)) = closed_grid(input, RESOLUTION, LEAST_FILLED)? else {
        return Ok(Vec::new());
    };
    let cavities = regions(&closing.filled, volume.grid.dims)? as usize;
    let mut fills = Vec::new();
    for samples in [&closing.filled, &closing.lining] {
        let mut raised = volume.clone();
        let values = raised.as_slice_mut();
        for &i in samples {
            values[i] = 1.0;
        }
        let mesh = marching_cubes(&raised, &ContourOptions::geometry_only(0.5))?;
        if !mesh.is_empty() {
            fills.push(FilledCavities {
                mesh,
                cavities,
                components_removed: 0,
            });
        }
    }
    Ok(fills)
}

/// The input's density at `resolution` and what its closing fills (steps 1 to 3 of the
/// module docs), when that is at least `least` times the solid's samples.
fn closed_grid(
    input: &TriangleMesh,
    resolution: usize,
    least: f64,
) -> Result<Option<(Volume, Closing)>, PyramidError> {
    let volume = voxelize(&Source::Mesh(input), &VoxelizeOptions::at(resolution))?.volume;
    let inside: Vec<bool> = volume.as_slice().iter().map(|&d| d >= 0.5).collect();
    let radius = (CLOSING_FRACTION * resolution as f64).round() as usize;
    let closing = closing_fill(&inside, volume.grid.dims, radius)?;
    let solid = inside.iter().filter(|&&b| b).count();
    let enough = solid > 0 && closing.filled.len() as f64 >= least * solid as f64;
    Ok(enough.then_some((volume, closing)))
}
