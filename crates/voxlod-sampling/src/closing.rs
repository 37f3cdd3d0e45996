//! A morphological closing of a voxel solid (our addition to He et al. 1995, used where a
//! hollow that its material nearly encloses, such as the cranial cavity of a CT bone surface,
//! should turn solid before filtering): [`closing_fill`] returns the samples outside the solid
//! that a closing by `radius` steps encloses, and the lining among them (those within the
//! radius of the material).
//!
//! How, on the grid padded by the radius:
//! 1. the inside is dilated by `radius` steps (a ball of 6-neighbour and 26-neighbour steps
//!    in turn, rounder than either alone);
//! 2. what the grid's outer corner cannot reach through the dilated solid (6-adjacent steps,
//!    components labelled by [`crate::digital_topology::label_components`]) is enclosed;
//! 3. the enclosed set is eroded by `radius` again (the outside dilated), and the part of it
//!    outside the solid is the fill.
//!
//! Cost: O(N³) for N³ samples whatever the radius; memory four masks of a byte a sample and a
//! 16-bit distance a sample.

use rayon::prelude::*;

use crate::digital_topology::label_components;
use crate::run_components::RunComponents;
use crate::SamplingError;

/// What a closing fills, as sample indices.
pub struct Closing {
    /// The samples outside the solid that the closing encloses.
    pub filled: Vec<usize>,
    /// Those of them within the closing's radius of the solid: the hollow's lining, which
    /// thickens a shell inwards without burying what lies deeper (a skull's floor).
    pub lining: Vec<usize>,
}

/// The samples outside `inside` (a grid of `dims` samples, x fastest) that its closing by
/// `radius` steps encloses (steps 1 to 3 of the module docs, on a grid padded by `radius`), and
/// the lining among them.
pub fn closing_fill(
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

/// `mask` grown by `steps` steps, alternating 6- and 26-neighbour steps, the first a
/// 6-neighbour one (a rounder ball than either alone). The mask's samples on the grid's outer
/// frame must have all their neighbours in the mask, and no step may reach the frame (the grid
/// is padded for that).
///
/// How: growing by a set of steps is adding it (Minkowski), and the sum does not depend on the
/// order, so the ⌈steps/2⌉ 6-neighbour steps are the samples within that city-block distance
/// of the mask and the ⌊steps/2⌋ 26-neighbour steps a cube around them; both distances are
/// separable, one forward and one backward sweep a row per axis ([`sweep`]), each sweep's rows
/// on all cores. Cost: O(N³) whatever the radius; a 16-bit distance a sample.
fn dilate(mask: Vec<bool>, dims: [usize; 3], steps: usize) -> Vec<bool> {
    let (faces, cubes) = (steps.div_ceil(2), steps / 2);
    let far = u16::try_from(steps + 1).unwrap_or(u16::MAX);
    let mut distance: Vec<u16> = mask.iter().map(|&b| if b { 0 } else { far }).collect();
    for axis in 0..3 {
        sweep(&mut distance, dims, axis);
    }
    let mut grown: Vec<bool> = distance.iter().map(|&d| (d as usize) <= faces).collect();
    for axis in 0..3 {
        distance
            .par_iter_mut()
            .zip(&grown)
            .for_each(|(d, &b)| *d = if b { 0 } else { far });
        sweep(&mut distance, dims, axis);
        grown
            .par_iter_mut()
            .zip(&distance)
            .for_each(|(b, &d)| *b = (d as usize) <= cubes);
    }
    grown
}

/// Each sample's `distance` lowered to one more than its neighbour's along `axis`, forward then
/// backward: with the other axes' sweeps before it, the city-block distance to the samples at
/// 0; alone, the distance along `axis` (saturating at `u16::MAX`).
fn sweep(distance: &mut [u16], dims: [usize; 3], axis: usize) {
    let [nx, ny, _] = dims;
    match axis {
        // Rows along x, each on its own.
        0 => distance.par_chunks_mut(nx).for_each(|row| {
            for i in 1..row.len() {
                row[i] = row[i].min(row[i - 1].saturating_add(1));
            }
            for i in (0..row.len() - 1).rev() {
                row[i] = row[i].min(row[i + 1].saturating_add(1));
            }
        }),
        // Slabs of constant z, each on its own, row after row along y.
        1 => distance.par_chunks_mut(nx * ny).for_each(|slab| {
            sweep_lines(slab, nx, &lower);
        }),
        // Slab after slab along z, each slab's rows on all cores.
        _ => sweep_lines_parallel(distance, nx * ny, nx),
    }
}

/// `data`'s consecutive lines of `len` lowered by `step` from the line before, then after.
fn sweep_lines(data: &mut [u16], len: usize, step: &impl Fn(&mut [u16], &[u16])) {
    let lines = data.len() / len;
    for k in 1..lines {
        let (before, rest) = data.split_at_mut(k * len);
        step(&mut rest[..len], &before[(k - 1) * len..]);
    }
    for k in (0..lines.saturating_sub(1)).rev() {
        let (this, after) = data.split_at_mut((k + 1) * len);
        step(&mut this[k * len..], &after[..len]);
    }
}

/// [`sweep_lines`] for long lines (whole slabs), each line's `chunk`s on all cores.
fn sweep_lines_parallel(data: &mut [u16], len: usize, chunk: usize) {
    let step = |to: &mut [u16], from: &[u16]| {
        (to.par_chunks_mut(chunk).zip(from.par_chunks(chunk))).for_each(|(t, f)| lower(t, f))
    };
    sweep_lines(data, len, &step);
}

/// Each of `to` lowered to one more than the same place of `from`.
fn lower(to: &mut [u16], from: &[u16]) {
    for (t, &f) in to.iter_mut().zip(from) {
        *t = (*t).min(f.saturating_add(1));
    }
}

/// The 6-connected regions among `samples` (indices into a grid of `dims`).
pub fn regions(samples: &[usize], dims: [usize; 3]) -> Result<u64, SamplingError> {
    let mut mask = vec![false; dims.iter().product()];
    samples.iter().for_each(|&i| mask[i] = true);
    Ok(RunComponents::new(dims, &mask, true)?.count())
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

    /// The dilation as its definition says, step by step over the whole grid: the oracle for
    /// [`dilate`].
    fn step_by_step(mut mask: Vec<bool>, dims: [usize; 3], steps: usize) -> Vec<bool> {
        use voxlod_core::grid::FACE_OFFSETS;
        let inner = |i: usize| {
            let [x, y, z] = coords(dims, i);
            [x, y, z].iter().zip(dims).all(|(&c, n)| c > 0 && c + 1 < n)
        };
        for step in 0..steps {
            let offsets = match step % 2 {
                0 => deltas(dims, &FACE_OFFSETS),
                _ => deltas(dims, &all_neighbours()),
            };
            let before = mask.clone();
            for i in (0..mask.len()).filter(|&i| before[i] && inner(i)) {
                for &d in &offsets {
                    mask[i.wrapping_add_signed(d)] = true;
                }
            }
        }
        mask
    }

    #[test]
    fn dilation_is_the_steps_one_after_another() {
        // Scattered points and a slab, away from the frame by more than the steps.
        let mask = grid(|x, y, z| {
            let inner = [x, y, z].iter().all(|&c| (6..N - 6).contains(&c));
            inner && ((x * 7 + y * 13 + z * 5) % 29 == 0 || (z == 11 && x < 12))
        });
        for steps in 0..=5 {
            let fast = dilate(mask.clone(), [N; 3], steps);
            assert!(
                fast == step_by_step(mask.clone(), [N; 3], steps),
                "{steps} steps"
            );
        }
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
