//! Nearly enclosed cavities filled (our addition; issue 12, item 3): a morphological closing
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
//! [`RESOLUTION`], O(F + N³) with N³ samples; the closings, O(r N³); two marching cubes,
//! O(N³); and two more searches per budget. Memory: the density (4 bytes a sample) and
//! four masks (1 byte a sample each).

use voxlod_contouring::{marching_cubes, ContourOptions};
use voxlod_core::cavities::FilledCavities;
use voxlod_core::grid::FACE_OFFSETS as FACES;
use voxlod_core::{TriangleMesh, Volume};
use voxlod_sampling::digital_topology::label_components;
use voxlod_sampling::run_components::RunComponents;
use voxlod_sampling::SamplingError;

use crate::error::Error;
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
pub(super) fn enclosed_filled(input: &TriangleMesh) -> Result<Vec<FilledCavities>, Error> {
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
) -> Result<Option<(Volume, Closing)>, Error> {
    let volume = voxelize(&Source::Mesh(input), &VoxelizeOptions::at(resolution))?.volume;
    let inside: Vec<bool> = volume.as_slice().iter().map(|&d| d >= 0.5).collect();
    let radius = (CLOSING_FRACTION * resolution as f64).round() as usize;
    let closing = closing_fill(&inside, volume.grid.dims, radius)?;
    let solid = inside.iter().filter(|&&b| b).count();
    let enough = solid > 0 && closing.filled.len() as f64 >= least * solid as f64;
    Ok(enough.then_some((volume, closing)))
}

/// What a closing fills, as sample indices.
pub(super) struct Closing {
    /// The samples outside the solid that the closing encloses.
    pub(super) filled: Vec<usize>,
    /// Those of them within the closing's radius of the solid: the hollow's lining, which
    /// thickens a shell inwards without burying what lies deeper (a skull's floor).
    pub(super) lining: Vec<usize>,
}

/// The samples outside `inside` (a grid of `dims` samples, x fastest) that its closing by
/// `radius` steps encloses (steps 1 to 3 of the module docs, on a grid padded by `radius`), and
/// the lining among them.
pub(super) fn closing_fill(
    inside: &[bool],
    dims: [usize; 3],
    radius: usize,
) -> Result<Closing, SamplingError> {
    let pad = radius + 1;
    let padded = dims.map(|n| n + 2 * pad);
    let at = |i: usize| index(padded, shift(coords(dims, i), pad));
    let mut mask = vec![false; padded.iter().product()];
    for (i, &b) in inside.iter().enumerate() {
        if b {
            mask[at(i)] = true;
        }
    }
    let dilated = dilate(mask, padded, radius);
    // The outside: the component of the padded grid's corner among the samples the dilated
    // solid leaves open, 6-connected.
    let open: Vec<bool> = dilated.iter().map(|&solid| !solid).collect();
    let (labels, _) = label_components(padded, &open, true)?;
    let outside = labels.iter().map(|&l| l == labels[0]).collect();
    let closed = dilate(outside, padded, radius);
    let filled: Vec<usize> = (0..inside.len())
        .filter(|&i| !inside[i] && !closed[at(i)])
        .collect();
    let lining = filled.iter().copied().filter(|&i| dilated[at(i)]).collect();
    Ok(Closing { filled, lining })
}

/// `mask` grown by `steps` steps, alternating 6- and 26-neighbour steps (a rounder ball than
/// either alone). Each step grows from the samples added by the two steps before (the mask's
/// own boundary for the first two): a sample older than that has all its 26 neighbours in
/// already. The mask's samples on the grid's outer frame must have all their neighbours in the
/// mask, and no step may reach the frame (the grid is padded for that), so no step looks
/// beyond the grid.
fn dilate(mut mask: Vec<bool>, dims: [usize; 3], steps: usize) -> Vec<bool> {
    let face = deltas(dims, &FACES);
    let full = deltas(dims, &all_neighbours());
    let boundary = |i: usize| {
        let [x, y, z] = coords(dims, i);
        let frame = [x, y, z]
            .iter()
            .zip(dims)
            .any(|(&c, n)| c == 0 || c + 1 == n);
        !frame && full.iter().any(|&d| !mask[i.wrapping_add_signed(d)])
    };
    let first: Vec<usize> = (0..mask.len())
        .filter(|&i| mask[i] && boundary(i))
        .collect();
    let (mut older, mut last) = (Vec::new(), first);
    for step in 0..steps {
        let offsets = if step % 2 == 1 { &full } else { &face };
        let mut added = Vec::new();
        for &i in older.iter().chain(&last) {
            for &d in offsets {
                let j = i.wrapping_add_signed(d);
                if !mask[j] {
                    mask[j] = true;
                    added.push(j);
                }
            }
        }
        older = std::mem::replace(&mut last, added);
    }
    mask
}

/// The 6-connected regions among `samples` (indices into a grid of `dims`).
fn regions(samples: &[usize], dims: [usize; 3]) -> Result<u64, SamplingError> {
    let mut mask = vec![false; dims.iter().product()];
    samples.iter().for_each(|&i| mask[i] = true);
    Ok(RunComponents::new(dims, &mask, true)?.count())
}

/// The 26 offsets of the full neighbourhood.
fn all_neighbours() -> Vec<[i64; 3]> {
    let range = || -1..=1i64;
    (range().flat_map(|z| range().flat_map(move |y| range().map(move |x| [x, y, z]))))
        .filter(|&o| o != [0, 0, 0])
        .collect()
}

/// `offsets` as steps of the linear index on a grid of `dims`.
fn deltas(dims: [usize; 3], offsets: &[[i64; 3]]) -> Vec<isize> {
    let (nx, ny) = (dims[0] as i64, dims[1] as i64);
    (offsets.iter())
        .map(|[x, y, z]| (x + nx * (y + ny * z)) as isize)
        .collect()
}

fn coords(dims: [usize; 3], i: usize) -> [usize; 3] {
    [
        i % dims[0],
        (i / dims[0]) % dims[1],
        i / (dims[0] * dims[1]),
    ]
}

fn shift([x, y, z]: [usize; 3], by: usize) -> [usize; 3] {
    [x + by, y + by, z + by]
}

fn index(dims: [usize; 3], [x, y, z]: [usize; 3]) -> usize {
    x + dims[0] * (y + dims[1] * z)
}

#[cfg(test)]
mod tests {
    use super::*;

    const N: usize = 24;

    /// A grid of N³ samples, inside where `f` says so.
    fn grid(f: impl Fn(usize, usize, usize) -> bool) -> Vec<bool> {
        (0..N * N * N)
            .map(|i| {
                let [x, y, z] = coords([N; 3], i);
                f(x, y, z)
            })
            .collect()
    }

    /// A box's wall one sample thick, from 5 to 18 on every axis, with a square hole of
    /// `hole` samples a side in its face at x = 18.
    fn boxed_shell(hole: usize) -> Vec<bool> {
        let lo = 12 - hole / 2;
        grid(|x, y, z| {
            let in_box = [x, y, z].iter().all(|&c| (5..=18).contains(&c));
            let on_wall = [x, y, z].iter().any(|&c| c == 5 || c == 18);
            let in_hole = x == 18 && (lo..lo + hole).contains(&y) && (lo..lo + hole).contains(&z);
            in_box && on_wall && !in_hole
        })
    }

    fn is_interior(i: usize) -> bool {
        coords([N; 3], i).iter().all(|&c| (6..=17).contains(&c))
    }

    #[test]
    fn a_box_wall_with_a_narrow_hole_is_filled_inside_and_nowhere_else() {
        let filled = closing_fill(&boxed_shell(2), [N; 3], 2).unwrap().filled;
        // The 12³ samples inside, and the hole's 4: nothing outside the box.
        assert_eq!(
            filled.iter().filter(|&&i| is_interior(i)).count(),
            12 * 12 * 12
        );
        assert_eq!(filled.len(), 12 * 12 * 12 + 4);
        assert_eq!(regions(&filled, [N; 3]).unwrap(), 1);
    }

    #[test]
    fn the_lining_is_the_fill_within_the_radius_of_the_wall() {
        let closing = closing_fill(&boxed_shell(2), [N; 3], 2).unwrap();
        // Every filled sample within 2 steps of a wall plane (coordinates 6, 7, 16, 17), and
        // the hole's: all but the core of 8³ samples from 8 to 15.
        let core = |i: usize| coords([N; 3], i).iter().all(|&c| (8..=15).contains(&c));
        assert!(closing.lining.iter().all(|&i| !core(i)));
        assert_eq!(closing.lining.len(), 12 * 12 * 12 + 4 - 8 * 8 * 8);
    }

    #[test]
    fn a_hole_wider_than_the_closing_leaves_the_inside_open() {
        // The outside flows in through a hole of 8: only the inner corners and edges that the
        // closing rounds are filled, far fewer than the inside's samples.
        let filled = closing_fill(&boxed_shell(8), [N; 3], 2).unwrap().filled;
        assert!(filled.len() < 12 * 12 * 12 / 10, "{}", filled.len());
        // A closing of 4 spans it: the inside is filled but for a dent behind the hole, where
        // the closing's erosion reaches in from outside.
        let closed = closing_fill(&boxed_shell(8), [N; 3], 4).unwrap().filled;
        let inside = closed.iter().filter(|&&i| is_interior(i)).count();
        assert!(inside > 12 * 12 * 12 * 9 / 10, "{inside}");
    }

    #[test]
    fn a_convex_solid_has_nothing_to_fill() {
        let solid = grid(|x, y, z| [x, y, z].iter().all(|&c| (4..=19).contains(&c)));
        assert!(closing_fill(&solid, [N; 3], 3).unwrap().filled.is_empty());
        let ball = grid(|x, y, z| {
            let d = |c: usize| (c as f64 - 11.5).powi(2);
            d(x) + d(y) + d(z) < 64.0
        });
        assert!(closing_fill(&ball, [N; 3], 3).unwrap().filled.is_empty());
    }

    #[test]
    fn dilation_grows_a_point_into_the_alternating_ball() {
        let mut mask = vec![false; N * N * N];
        let centre = index([N; 3], [12, 12, 12]);
        mask[centre] = true;
        // A face step then any step: every offset within 1 on each axis but one, which may
        // reach 2: 27 + 3 axes × 2 signs × 9 = 81 samples.
        let grown = dilate(mask.clone(), [N; 3], 2);
        let expected = |i: usize| {
            let a = coords([N; 3], i).map(|c| (c as i64 - 12).abs());
            a.iter().all(|&c| c <= 2) && a.iter().filter(|&&c| c == 2).count() <= 1
        };
        assert!((0..N * N * N).all(|i| grown[i] == expected(i)));
        assert_eq!(grown.iter().filter(|&&b| b).count(), 81);
        assert_eq!(dilate(mask, [N; 3], 1).iter().filter(|&&b| b).count(), 7);
    }
}
