//! The shared surface simplified patch by patch: a patch is every triangle between the same two
//! labels, simplified as a mesh of its own with the vertices that other patches use locked, so
//! the junction curves where patches meet keep every vertex and edge, and the two labels of a
//! patch keep sharing the same triangles.
//!
//! Locked, beside the patch's border: every vertex whose corner touches three or more labels
//! (the junctions: such a corner always has faces of two patches) or is singular (a label's
//! surface has several sheets there), and every vertex of a triangle at such a corner. The
//! ring around a junction keeps each patch from drawing a new edge between two junction
//! vertices (an edge collapse makes new edges only at the vertex it keeps, between it and the
//! neighbours of the one it removes, and no vertex next to a junction is removed): two
//! patches of one label cutting the same zigzag of a junction curve would otherwise each draw
//! it, and give the label an edge of four triangles. The ring around a singular corner keeps
//! its triangles the voxels' faces the label meshes split it by ([`super::extract`]).
//!
//! Cost: a stable parallel sort of the triangles by their pair of labels, O(F log F); a pass
//! over each patch for its floor and area; the patches in parallel, largest first, each one
//! reduction (`reduce.rs`) of its triangles with a vertex free to move.

use std::ops::Range;

use rayon::prelude::*;
use rustc_hash::{FxHashMap, FxHashSet};
use voxlod_core::memory;

use super::reduce::{compact_triangles, reduce, Aim, Reduced};
use super::share::shares;
use super::MEAN_SHIFT;
use crate::surface_nets::SharedSurface;
use crate::LabelsError;

/// The triangles between one pair of labels.
pub(crate) struct Patch {
    /// `[inside, outside]`, as [`SharedSurface::sides`].
    pub sides: [u32; 2],
    /// The patch's triangles after simplification, over the surface's vertices, wound as the
    /// surface winds them.
    pub triangles: Vec<[u32; 3]>,
}

/// The patches of `surface` and how many components were kept as they were because every
/// reduction of them broke their topology or moved them too far.
pub(crate) struct Patches {
    pub patches: Vec<Patch>,
    pub kept_parts: usize,
}

/// Every patch of `surface` simplified towards its target, the smaller of its two labels'
/// shares for it (`share.rs`: each label's budget `triangles` shared among its patches by their
/// triangles, none under its floor, the triangles its locked vertices hold; labels not in
/// `labels`, the background among them, do not limit a patch), and no further than moves the
/// patch by [`MEAN_SHIFT`] voxels on average (the volume between the patch before and after
/// over its area). Fails only when the memory limit refuses the sort.
pub(crate) fn simplify_patches(
    surface: &SharedSurface,
    labels: &[u32],
    triangles: usize,
) -> Result<Patches, LabelsError> {
    let n = surface.triangles.len();
    memory::check_allocation(
        "the budget's patches",
        memory::bytes_of::<u32>(n)
            + memory::bytes_of::<[u32; 3]>(n)
            + memory::bytes_of::<bool>(surface.positions.len()),
    )?;
    let mut order: Vec<u32> = (0..n as u32).collect();
    order.par_sort_by_key(|&t| surface.sides[t as usize]);
    let ranges = patch_ranges(surface, &order);
    let original = |r: &Range<usize>| -> Vec<[u32; 3]> {
        order[r.clone()]
            .iter()
            .map(|&t| surface.triangles[t as usize])
            .collect()
    };
    let locked = locked_vertices(surface);
    let voxel = surface.world.spacing.min_element();
    let measures: Vec<(usize, f64)> = ranges
        .par_iter()
        .map(|(_, r)| {
            let of = &order[r.clone()];
            (
                floor(surface, &locked, of),
                MEAN_SHIFT * voxel * area(surface, of),
            )
        })
        .collect();
    let aims = aims(&ranges, &measures, labels, triangles);
    let mut by_size: Vec<usize> = (0..ranges.len()).collect();
    by_size.sort_by_key(|&p| std::cmp::Reverse(ranges[p].1.len()));
    let mut done: Vec<(usize, Reduced)> = by_size
        .into_par_iter()
        .map(|p| {
            (
                p,
                simplify_patch(surface, original(&ranges[p].1), aims[p], &locked),
            )
        })
        .collect();
    done.sort_by_key(|d| d.0);
    let kept_parts = done.iter().map(|d| d.1.kept_parts).sum();
    let patches = ranges
        .into_iter()
        .zip(done)
        .map(|((sides, _), (_, reduced))| Patch {
            sides,
            triangles: reduced.triangles,
        })
        .collect();
    Ok(Patches {
        patches,
        kept_parts,
    })
}

/// The runs of equal labels in the sorted `order`: per patch its labels and range of `order`.
fn patch_ranges(surface: &SharedSurface, order: &[u32]) -> Vec<([u32; 2], Range<usize>)> {
    let mut ranges = Vec::new();
    let mut start = 0;
    for run in order.chunk_by(|&a, &b| surface.sides[a as usize] == surface.sides[b as usize]) {
        ranges.push((surface.sides[run[0] as usize], start..start + run.len()));
        start += run.len();
    }
    ranges
}

/// The area of the surface's triangles `of`, in world units squared.
fn area(surface: &SharedSurface, of: &[u32]) -> f64 {
    of.iter()
        .map(|&t| {
            let [a, b, c] =
                surface.triangles[t as usize].map(|v| surface.positions[v as usize].as_dvec3());
            0.5 * (b - a).cross(c - a).length()
        })
        .sum()
}

/// The fewest triangles patch `of` (triangles of the surface) can be brought to without
/// flattening it onto its locked vertices: its triangles whose every vertex is locked, plus
/// one per locked vertex of the others (as [`reduce`] asks at least).
fn floor(surface: &SharedSurface, locked: &[bool], of: &[u32]) -> usize {
    let mut fixed = 0;
    let mut rim: Vec<u32> = Vec::new();
    for &t in of {
        let tri = surface.triangles[t as usize];
        if tri.iter().all(|&v| locked[v as usize]) {
            fixed += 1;
        } else {
            rim.extend(tri.iter().filter(|&&v| locked[v as usize]));
        }
    }
    rim.sort_unstable();
    rim.dedup();
    (fixed + rim.len()).min(of.len())
}

/// Each patch's aim (the doc of [`simplify_patches`]), from the patches' labels and
/// triangles, and per patch its floor and the largest change of volume it may take.
fn aims(
    ranges: &[([u32; 2], Range<usize>)],
    measures: &[(usize, f64)],
    labels: &[u32],
    budget: usize,
) -> Vec<Aim> {
    let asked: FxHashSet<u32> = labels.iter().copied().filter(|&l| l != 0).collect();
    let mut of_label: FxHashMap<u32, Vec<usize>> = FxHashMap::default();
    for (p, (sides, _)) in ranges.iter().enumerate() {
        for l in sides.iter().filter(|l| asked.contains(l)) {
            of_label.entry(*l).or_default().push(p);
        }
    }
    let mut aims: Vec<Aim> = ranges
        .iter()
        .zip(measures)
        .map(|((_, range), &(_, volume))| Aim {
            target: range.len(),
            volume,
            lock_border: true,
        })
        .collect();
    for own in of_label.values() {
        let sizes: Vec<(usize, usize)> = own
            .iter()
            .map(|&p| (ranges[p].1.len(), measures[p].0))
            .collect();
        for (&p, target) in own.iter().zip(shares(&sizes, budget)) {
            aims[p].target = aims[p].target.min(target);
        }
    }
    aims
}

/// Per vertex whether no patch may move it (module docs).
fn locked_vertices(surface: &SharedSurface) -> Vec<bool> {
    let held = |v: &u32| {
        let flags = surface.flags[*v as usize];
        !flags.has_two_labels() || flags.is_singular()
    };
    let mut locked: Vec<bool> = (0..surface.positions.len() as u32)
        .into_par_iter()
        .map(|v| held(&v))
        .collect();
    let around: Vec<[u32; 3]> = surface
        .triangles
        .par_iter()
        .filter(|t| t.iter().any(held))
        .copied()
        .collect();
    for v in around.into_iter().flatten() {
        locked[v as usize] = true;
    }
    locked
}

/// `triangles` (one patch) reduced towards `aim` with `locked` kept. Only the triangles with a
/// vertex free to go are handed to meshoptimizer (a collapse changes only triangles of the
/// vertex it removes), so a patch locked nearly everywhere costs little; should they draw an
/// edge that the triangles left out already have (which their reduction cannot see), the whole
/// patch is reduced instead.
fn simplify_patch(
    surface: &SharedSurface,
    triangles: Vec<[u32; 3]>,
    aim: Aim,
    locked: &[bool],
) -> Reduced {
    let (moving, fixed): (Vec<[u32; 3]>, Vec<[u32; 3]>) = triangles
        .iter()
        .partition(|t| t.iter().any(|&v| !locked[v as usize]));
    if aim.target >= triangles.len() || moving.is_empty() {
        return Reduced {
            triangles,
            kept_parts: 0,
        };
    }
    let ask = Aim {
        target: aim.target.saturating_sub(fixed.len()),
        ..aim
    };
    let mut out = reduce_triangles(surface, &moving, ask, locked);
    let drawn = new_locked_edges(&moving, &out.triangles, locked);
    if !drawn.is_empty() && edges(&fixed).any(|e| drawn.contains(&e)) {
        return reduce_triangles(surface, &triangles, aim, locked);
    }
    out.triangles.extend(fixed);
    out
}

/// `triangles` (over the surface's vertices) reduced towards `aim` with `locked` kept, over
/// the surface's vertices.
fn reduce_triangles(
    surface: &SharedSurface,
    triangles: &[[u32; 3]],
    aim: Aim,
    locked: &[bool],
) -> Reduced {
    let (mesh, sources) = compact_triangles(&surface.positions, triangles.iter().copied());
    let local_locks: Vec<bool> = sources.iter().map(|&v| locked[v as usize]).collect();
    let mut reduced = reduce(&mesh, &local_locks, aim);
    for t in &mut reduced.triangles {
        *t = t.map(|v| sources[v as usize]);
    }
    reduced
}

/// The edges of `after` between two locked vertices that `before` lacks.
fn new_locked_edges(
    before: &[[u32; 3]],
    after: &[[u32; 3]],
    locked: &[bool],
) -> FxHashSet<(u32, u32)> {
    let both = |&(a, b): &(u32, u32)| locked[a as usize] && locked[b as usize];
    let old: FxHashSet<(u32, u32)> = edges(before).filter(both).collect();
    edges(after)
        .filter(both)
        .filter(|e| !old.contains(e))
        .collect()
}

/// The edges of `triangles`, as sorted pairs (each once per triangle using it).
fn edges(triangles: &[[u32; 3]]) -> impl Iterator<Item = (u32, u32)> + '_ {
    triangles
        .iter()
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .map(|(a, b)| (a.min(b), a.max(b)))
}
