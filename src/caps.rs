//! Cutting away the caps that sampling adds over an open input's holes, so that a level of an
//! open scan keeps its openings (the budget pipeline, [`crate::budget`]).
//!
//! To sample an open mesh as a solid, its holes are closed with fans first
//! (`voxlod_sampling::MeshSolid`), and every level then has a surface over each hole that the
//! input does not have: it costs triangles and shows in the distance from the level to the
//! input. The paper's objects are closed, so this is our addition.
//!
//! **Which triangles are caps.** A triangle of the level is a cap triangle when the input point
//! nearest its centroid lies on the input's border (on a boundary edge, within a
//! millionth-scale tolerance) and is farther than `reach` from it. Over a hole, every point's
//! nearest input point is on the hole's rim, and all but a thin band next to the rim is farther
//! than `reach` (the budget pipeline uses half a voxel of the level, the contouring's own
//! accuracy); elsewhere the nearest input point lies inside the input's triangles, or the
//! triangle is within `reach` of the rim (the band that meets it, kept).
//!
//! **What the cut leaves.** Removing a set of triangles from a closed manifold leaves a
//! manifold with border, except where two removed regions touch at a single vertex; such
//! pinched vertices are split by [`voxlod_envelope::repair_for_envelope`] (no point moves).
//! The result stays consistently oriented, since only triangles are dropped.
//!
//! Cost: one closest-point query per level triangle against the input's BVH (built once per run
//! by [`InputBorder::new`]), O(T log F), in parallel.

use std::collections::HashSet;

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
    border: HashSet<(u32, u32)>,
    tolerance: f64,
}

impl InputBorder {
    /// The border of `input` after welding coincident vertices; `None` when it has none (a
    /// closed input).
    pub fn new(input: &TriangleMesh) -> Result<Option<InputBorder>, MetricsError> {
        let mut mesh = input.clone();
        weld_vertices(&mut mesh);
        let border = border_edges(&mesh);
        if border.is_empty() {
            return Ok(None);
        }
        let distance = MeshDistance::new(&mesh)?;
        let tolerance = 1e-6 * mesh.bounds().diagonal().max(f64::MIN_POSITIVE);
        Ok(Some(InputBorder {
            mesh,
            distance,
            border,
            tolerance,
        }))
    }

    /// Whether `p`'s nearest input point lies on the border and is farther than `reach`.
    fn over_a_hole(&self, p: DVec3, reach: f64) -> bool {
        let nearest = self.distance.closest(p);
        if nearest.distance <= reach {
            return false;
        }
        let [a, b, c] = self.mesh.triangles[nearest.triangle];
        let corner = |v: u32| self.mesh.positions[v as usize].as_dvec3();
        [(a, b), (b, c), (c, a)].into_iter().any(|(u, w)| {
            self.border.contains(&(u.min(w), u.max(w)))
                && segment_distance(nearest.point, corner(u), corner(w)) <= self.tolerance
        })
    }
}

/// Edges used by one triangle, as (smaller, larger) vertex pairs.
fn border_edges(mesh: &TriangleMesh) -> HashSet<(u32, u32)> {
    let mut count = std::collections::HashMap::new();
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

/// `level` without its cap triangles (see the module documentation), pinched vertices split;
/// and how many triangles were cut.
pub fn cut_caps(level: &TriangleMesh, border: &InputBorder, reach: f64) -> (TriangleMesh, usize) {
    let keep: Vec<bool> = (0..level.triangles.len())
        .into_par_iter()
        .map(|t| {
            let [a, b, c] = level.corners(t);
            !border.over_a_hole((a + b + c) / 3.0, reach)
        })
        .collect();
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
