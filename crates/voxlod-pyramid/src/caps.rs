//! Cutting away the caps that sampling adds over an open input's holes, so that a level of an
//! open scan keeps its openings (the budget pipeline, [`crate::budget`]).
//!
//! To sample an open mesh as a solid, its holes are closed with fans first
//! (`voxlod_sampling::MeshSolid`), and every level then has a surface over each hole that the
//! input does not have: it costs triangles and shows in the distance from the level to the
//! input. The paper's objects are closed, so this is our addition.
//!
//! **Which triangles are caps.** A triangle of the level is a cap candidate of hole `L` when
//! the input point nearest its centroid lies on the input's border loop `L` (on a boundary edge,
//! within a millionth-scale tolerance) and is farther than `reach` from it. Over a hole, every
//! point's nearest input point is on the hole's rim, and all but a thin band next to the rim is
//! farther than `reach` (the budget pipeline uses half a voxel of the level, the contouring's own
//! accuracy); elsewhere the nearest input point lies inside the input's triangles, or the
//! triangle is within `reach` of the rim (the band that meets it, kept).
//!
//! **One opening per hole.** Cutting every candidate would open more loops than the input has
//! (stray candidates beside a rim where the level bulges past it, and islands of kept triangles
//! inside a cap, each become a loop of their own). So per hole only the largest connected set of
//! its candidates is the cap, and the kept pieces that this cap encloses (pieces bounded by the
//! cap alone and smaller than it) are cut with it: the cut region is then connected with a
//! connected outside, a disk on a level of genus 0 around the hole, whose removal opens exactly
//! one loop. A level keeps as many openings as the input has holes, less the holes that the
//! level's resolution has closed over (caps within `reach` of their rim everywhere) and less
//! merges of caps that touch at a coarse resolution.
//!
//! **What the cut leaves.** Removing a set of triangles from a closed manifold leaves a
//! manifold with border, except where two removed regions touch at a single vertex; such
//! pinched vertices are split by [`voxlod_envelope::repair_for_envelope`] (no point moves).
//! The result stays consistently oriented, since only triangles are dropped.
//!
//! Cost: one closest-point query per level triangle against the input's BVH (built once per run
//! by [`InputBorder::new`]), O(T log F), in parallel; then O(T) for the triangle adjacency and
//! the cap regions, and per hole a search of the kept pieces around its cap bounded by the
//! cap's size.

use std::collections::{HashMap, VecDeque};

use rayon::prelude::*;
use voxlod_core::glam::DVec3;
use voxlod_core::weld::weld_vertices;
use voxlod_core::TriangleMesh;
use voxlod_envelope::repair_for_envelope;
use voxlod_metrics::{MeshDistance, MetricsError};

/// An open input's border, with a closest-point structure over its triangles.
pub struct InputBorder {
    mesh: TriangleMesh,
    distance: MeshDistance,
    /// Border edges (smaller, larger vertex) and the border loop each belongs to.
    border: HashMap<(u32, u32), u32>,
    /// Border loops of the input.
    loops: usize,
    tolerance: f64,
}

impl InputBorder {
    /// The border of `input` after welding coincident vertices; `None` when it has none (a
    /// closed input).
    pub fn new(input: &TriangleMesh) -> Result<Option<InputBorder>, MetricsError> {
        let mut mesh = input.clone();
        weld_vertices(&mut mesh);
        let edges = border_edges(&mesh);
        if edges.is_empty() {
            return Ok(None);
        }
        let (border, loops) = label_loops(edges);
        let distance = MeshDistance::new(&mesh)?;
        let tolerance = 1e-6 * mesh.bounds().diagonal().max(f64::MIN_POSITIVE);
        Ok(Some(InputBorder {
            mesh,
            distance,
            border,
            loops,
            tolerance,
        }))
    }

    /// The border loop whose hole `p` is over: `p`'s nearest input point lies on that loop and
    /// is farther than `reach`.
    fn hole_under(&self, p: DVec3, reach: f64) -> Option<u32> {
        let nearest = self.distance.closest(p);
        if nearest.distance <= reach {
            return None;
        }
        let [a, b, c] = self.mesh.triangles[nearest.triangle];
        let corner = |v: u32| self.mesh.positions[v as usize].as_dvec3();
        [(a, b), (b, c), (c, a)].into_iter().find_map(|(u, w)| {
            let hole = *self.border.get(&(u.min(w), u.max(w)))?;
            (segment_distance(nearest.point, corner(u), corner(w)) <= self.tolerance)
                .then_some(hole)
        })
    }
}

/// Each border edge's loop: border edges sharing a vertex are on one loop (a vertex where two
/// loops touch joins them). The number of loops.
fn label_loops(edges: Vec<(u32, u32)>) -> (HashMap<(u32, u32), u32>, usize) {
    let mut next: HashMap<u32, Vec<u32>> = HashMap::new();
    for &(u, w) in &edges {
        next.entry(u).or_default().push(w);
        next.entry(w).or_default().push(u);
    }
    let mut loop_of: HashMap<u32, u32> = HashMap::new();
    let mut loops = 0u32;
    let mut starts: Vec<u32> = next.keys().copied().collect();
    starts.sort_unstable();
    for start in starts {
        if loop_of.contains_key(&start) {
            continue;
        }
        let mut stack = vec![start];
        loop_of.insert(start, loops);
        while let Some(v) = stack.pop() {
            for &w in &next[&v] {
                if loop_of.insert(w, loops).is_none() {
                    stack.push(w);
                }
            }
        }
        loops += 1;
    }
    let labelled = edges.into_iter().map(|e| (e, loop_of[&e.0])).collect();
    (labelled, loops as usize)
}

/// Edges used by one triangle, as (smaller, larger) vertex pairs.
fn border_edges(mesh: &TriangleMesh) -> Vec<(u32, u32)> {
    let mut count = HashMap::new();
    for &[a, b, c] in &mesh.triangles {
        for (u, w) in [(a, b), (b, c), (c, a)] {
            *count.entry((u.min(w), u.max(w))).or_insert(0u32) += 1;
        }
    }
    count
        .into_iter()
        .filter(|&(_, n)| n == 1)
        .map(|(e, _)| e)
        .collect()
}

/// Distance from `p` to the segment `ab`.
fn segment_distance(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let t = if ab.length_squared() > 0.0 {
        ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    p.distance(a + t * ab)
}

/// `level` without its caps (see the module documentation), pinched vertices split; and how
/// many triangles were cut.
pub fn cut_caps(level: &TriangleMesh, border: &InputBorder, reach: f64) -> (TriangleMesh, usize) {
    let holes: Vec<Option<u32>> = (0..level.triangles.len())
        .into_par_iter()
        .map(|t| {
            let [a, b, c] = level.corners(t);
            border.hole_under((a + b + c) / 3.0, reach)
        })
        .collect();
    if holes.iter().all(Option::is_none) {
        return (level.clone(), 0);
    }
    let neighbours = triangle_neighbours(level);
    let mut keep = vec![true; level.triangles.len()];
    for cap in largest_caps(&holes, &neighbours, border.loops) {
        for &t in &cap {
            keep[t as usize] = false;
        }
        for island in enclosed_pieces(&cap, &keep, &neighbours) {
            for t in island {
                keep[t as usize] = false;
            }
        }
    }
    let cut = keep.iter().filter(|&&k| !k).count();
    if cut == 0 {
        return (level.clone(), 0);
    }
    let mut out = level.clone();
    let mut flags = keep.iter();
    out.triangles.retain(|_| *flags.next().unwrap_or(&true));
    out.remove_unreferenced_vertices();
    let (repaired, _) = repair_for_envelope(&out);
    (repaired, cut)
}

/// The triangles sharing an edge with each triangle of `mesh`.
fn triangle_neighbours(mesh: &TriangleMesh) -> Vec<Vec<u32>> {
    let mut edges: Vec<((u32, u32), u32)> = Vec::with_capacity(3 * mesh.triangles.len());
    for (t, &[a, b, c]) in mesh.triangles.iter().enumerate() {
        for (u, w) in [(a, b), (b, c), (c, a)] {
            edges.push(((u.min(w), u.max(w)), t as u32));
        }
    }
    edges.sort_unstable();
    let mut neighbours = vec![Vec::with_capacity(3); mesh.triangles.len()];
    for group in edges.chunk_by(|x, y| x.0 == y.0) {
        for &(_, t) in group {
            for &(_, other) in group {
                if other != t {
                    neighbours[t as usize].push(other);
                }
            }
        }
    }
    neighbours
}

/// The triangles reachable from `seed` through neighbours that `inside` accepts, stopping once
/// more than `limit` are found (then `None`).
fn flood(
    seed: u32,
    neighbours: &[Vec<u32>],
    seen: &mut [bool],
    limit: usize,
    inside: impl Fn(u32) -> bool,
) -> Option<Vec<u32>> {
    let mut found = vec![seed];
    let mut queue = VecDeque::from([seed]);
    seen[seed as usize] = true;
    while let Some(t) = queue.pop_front() {
        for &n in &neighbours[t as usize] {
            if !seen[n as usize] && inside(n) {
                seen[n as usize] = true;
                found.push(n);
                if found.len() > limit {
                    return None;
                }
                queue.push_back(n);
            }
        }
    }
    Some(found)
}

/// Per hole, the largest connected set of triangles over it.
fn largest_caps(holes: &[Option<u32>], neighbours: &[Vec<u32>], loops: usize) -> Vec<Vec<u32>> {
    let mut best: Vec<Vec<u32>> = vec![Vec::new(); loops];
    let mut seen = vec![false; holes.len()];
    for t in 0..holes.len() {
        let Some(hole) = holes[t] else { continue };
        if seen[t] {
            continue;
        }
        let region = flood(t as u32, neighbours, &mut seen, usize::MAX, |n| {
            holes[n as usize] == Some(hole)
        })
        .unwrap_or_default();
        if region.len() > best[hole as usize].len() {
            best[hole as usize] = region;
        }
    }
    best.retain(|cap| !cap.is_empty());
    best
}

/// The kept pieces that `cap` encloses: connected sets of kept triangles next to the cap, cut
/// off from the rest by the cap alone, and smaller than it.
fn enclosed_pieces(cap: &[u32], keep: &[bool], neighbours: &[Vec<u32>]) -> Vec<Vec<u32>> {
    let mut in_cap = vec![false; keep.len()];
    for &t in cap {
        in_cap[t as usize] = true;
    }
    let mut seen = in_cap.clone();
    let mut pieces = Vec::new();
    for &t in cap {
        for &n in &neighbours[t as usize] {
            if seen[n as usize] || !keep[n as usize] {
                continue;
            }
            if let Some(piece) = flood(n, neighbours, &mut seen, cap.len(), |m| !in_cap[m as usize])
            {
                pieces.push(piece);
            }
        }
    }
    pieces
}
