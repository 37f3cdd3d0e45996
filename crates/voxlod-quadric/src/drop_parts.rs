//! Dropping the smallest parts when a budget cannot afford them all: the quadric stage keeps
//! every component (module docs of the crate), so a level with more components than its budget
//! can carry stalls above it. The voxel method "gradually reduce[s] the genus and small features"
//! (He et al. 1995, §4), which a topology-preserving simplifier cannot; this drops small parts
//! after the voxel stage too, on a finer level that still holds the large parts' shape.
//!
//! [`simplify_dropping_parts`] runs [`simplify_to_budget`]; while its result stops more than
//! [`PartsOptions::slack`] above the budget, the components are ranked by the diagonal of their
//! bounding box, and the smallest are removed from the *unsimplified* mesh until the triangles
//! they held in the stalled result cover the excess; the collapse then runs again on what is
//! left (at most [`PartsOptions::max_rounds`] rounds; the largest component is never dropped).
//! A dropped part moves the two-sided distance by about its own diagonal (the distance from it to
//! the kept surface it hung on), which is why the smallest go first. Each kept component keeps
//! its topology; the result has fewer components, and fewer handles if a dropped part had some.
//! Our addition: neither the paper nor meshoptimizer drops parts by size.
//!
//! Cost: per round one [`simplify_to_budget`] and a union-find over the triangles, O(F log F).

use rustc_hash::FxHashMap as HashMap;

use voxlod_core::TriangleMesh;

use crate::{root, simplify_to_budget, QuadricError, QuadricOptions, Simplified};

/// How [`simplify_dropping_parts`] runs.
#[derive(Clone, Debug, PartialEq)]
pub struct PartsOptions {
    /// The quadric stage's options.
    pub quadric: QuadricOptions,
    /// Parts are dropped only while the result is more than this fraction above the budget.
    pub slack: f64,
    /// Rounds of dropping at most.
    pub max_rounds: usize,
}

impl Default for PartsOptions {
    /// [`QuadricOptions::budget`] without a distance limit, 10 % slack, three rounds.
    fn default() -> Self {
        PartsOptions {
            quadric: QuadricOptions::budget(f64::INFINITY),
            slack: 0.10,
            max_rounds: 3,
        }
    }
}

/// What [`simplify_dropping_parts`] made: the simplified mesh and the parts it left out.
#[derive(Clone, Debug)]
pub struct PartsSimplified {
    /// The last collapse (of the kept parts).
    pub simplified: Simplified,
    /// Components of the input dropped.
    pub dropped_parts: usize,
    /// The input's triangles in them.
    pub dropped_triangles: usize,
    /// The largest bounding-box diagonal among them (0 when none was dropped).
    pub largest_dropped: f64,
}

/// One component of the input: its bounding-box diagonal and whether it is still kept.
struct Part {
    diagonal: f64,
    triangles: usize,
    kept: bool,
}

/// [`simplify_to_budget`], dropping the smallest components where it stalls above `budget`
/// (module docs).
pub fn simplify_dropping_parts(
    mesh: &TriangleMesh,
    budget: usize,
    options: &PartsOptions,
) -> Result<PartsSimplified, QuadricError> {
    let (labels, mut parts) = label_parts(mesh);
    let part_of: HashMap<[u32; 3], u32> = mesh
        .positions
        .iter()
        .zip(&labels)
        .filter(|pair| *pair.1 != u32::MAX)
        .map(|(p, &l)| (p.to_array().map(f32::to_bits), l))
        .collect();
    let mut kept_mesh = mesh.clone();
    let mut rounds = 0;
    loop {
        let done = simplify_to_budget(&kept_mesh, budget, &options.quadric)?;
        let over = done.mesh.triangle_count() as f64 > budget as f64 * (1.0 + options.slack);
        if !over || rounds >= options.max_rounds {
            return Ok(summary(done, &parts));
        }
        rounds += 1;
        let mut held = vec![0usize; parts.len()];
        for t in &done.mesh.triangles {
            let p = done.mesh.positions[t[0] as usize]
                .to_array()
                .map(f32::to_bits);
            if let Some(&l) = part_of.get(&p) {
                held[l as usize] += 1;
            }
        }
        let excess = done.mesh.triangle_count() - budget;
        if !drop_smallest(&mut parts, &held, excess) {
            return Ok(summary(done, &parts));
        }
        kept_mesh = TriangleMesh::new(
            mesh.positions.clone(),
            mesh.triangles
                .iter()
                .filter(|t| parts[labels[t[0] as usize] as usize].kept)
                .copied()
                .collect(),
        );
        kept_mesh.normals = mesh.normals.clone();
        kept_mesh.remove_unreferenced_vertices();
    }
}

/// Marks the smallest kept parts dropped until the triangles they `held` cover `excess`,
/// keeping at least the largest; whether any was dropped.
fn drop_smallest(parts: &mut [Part], held: &[usize], excess: usize) -> bool {
    let mut order: Vec<usize> = (0..parts.len()).filter(|&i| parts[i].kept).collect();
    order.sort_by(|&a, &b| parts[a].diagonal.total_cmp(&parts[b].diagonal));
    order.pop();
    let mut freed = 0;
    let mut any = false;
    for i in order {
        if freed >= excess {
            break;
        }
        parts[i].kept = false;
        freed += held[i];
        any = true;
    }
    any
}

/// The component of every vertex (by the union-find root's rank among the roots) and each
/// component's diagonal and triangles.
fn label_parts(mesh: &TriangleMesh) -> (Vec<u32>, Vec<Part>) {
    let mut parent: Vec<u32> = (0..mesh.positions.len() as u32).collect();
    for &[a, b, c] in &mesh.triangles {
        for (u, w) in [(a, b), (b, c)] {
            let (ru, rw) = (root(&mut parent, u), root(&mut parent, w));
            parent[ru as usize] = rw;
        }
    }
    let mut index: HashMap<u32, u32> = HashMap::default();
    let mut labels = vec![u32::MAX; mesh.positions.len()];
    let mut boxes: Vec<([f32; 3], [f32; 3], usize)> = Vec::new();
    for &[a, b, c] in &mesh.triangles {
        let r = root(&mut parent, a);
        let next = index.len() as u32;
        let l = *index.entry(r).or_insert(next);
        if l as usize == boxes.len() {
            boxes.push(([f32::INFINITY; 3], [f32::NEG_INFINITY; 3], 0));
        }
        let entry = &mut boxes[l as usize];
        entry.2 += 1;
        for v in [a, b, c] {
            labels[v as usize] = l;
            let p = mesh.positions[v as usize].to_array();
            for (k, &x) in p.iter().enumerate() {
                entry.0[k] = entry.0[k].min(x);
                entry.1[k] = entry.1[k].max(x);
            }
        }
    }
    let parts = boxes
        .into_iter()
        .map(|(low, high, triangles)| Part {
            diagonal: (0..3)
                .map(|k| f64::from(high[k] - low[k]).powi(2))
                .sum::<f64>()
                .sqrt(),
            triangles,
            kept: true,
        })
        .collect();
    (labels, parts)
}

/// The result and the figures of the dropped parts.
fn summary(simplified: Simplified, parts: &[Part]) -> PartsSimplified {
    let dropped = parts.iter().filter(|p| !p.kept);
    PartsSimplified {
        simplified,
        dropped_parts: dropped.clone().count(),
        dropped_triangles: dropped.clone().map(|p| p.triangles).sum(),
        largest_dropped: dropped.map(|p| p.diagonal).fold(0.0, f64::max),
    }
}
