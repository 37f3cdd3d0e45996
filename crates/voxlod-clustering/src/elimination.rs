//! Elimination, Rossignac–Borrel §3.5 (also Low–Tan step 8): from triangles whose vertices have
//! been replaced by their clusters, the simplified triangles `ST`, dangling edges `SE` and
//! isolated points `SP`.
//!
//! A triangle whose three clusters differ stays a triangle; with exactly two equal it
//! degenerates into an edge, with all three equal into a point. Then, as the paper lists:
//! every duplicate triangle, edge and point is removed, every edge that bounds a triangle, and
//! every point that bounds an edge or a triangle.
//!
//! Where we choose:
//! - Duplicates are judged on the vertex set, whatever the winding (the paper locates each
//!   triangle by its lowest, middle and highest vertex, which forgets the winding). Of a group
//!   of duplicates, the kept triangle has the winding of the one that came first in the input
//!   (the lowest source triangle index), so the output is deterministic.
//! - Points only come from triangles that collapse to one cluster (the paper's "when all three
//!   representative vertices are equal"). Vertices no triangle uses are not part of the model
//!   and produce nothing (the paper's data structure would list their clusters as isolated
//!   points if they formed clusters of their own; the bunny scan has 1 113 such vertices).
//! - Instead of the paper's linked lists (cluster → edges → triangles) we sort packed integer
//!   keys: triangles by (lowest, middle, highest) cluster and edges by (lowest, highest), which is
//!   the same ordering, flat and cache-friendly. The output lists come in that order.
//!
//! Series of levels (§4): eliminating the previous level's `ST`, `SE` and `SP` mapped through
//! the merge of clusters gives exactly what eliminating the original triangles mapped to the
//! merged clusters would. What a level removed is a face of something it kept, and stays a face
//! (or a duplicate) of that thing's image; collapse only ever makes more things equal.
//!
//! Cost: one parallel pass over the input, then radix sorts of the non-point results, O(T + S·b)
//! for S surviving triangles and edges and b key bits; memory O(S + clusters).

use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;

use crate::sort::{bits_for, radix_sort_by_key};

/// The simplified model, in cluster ids. `triangle_sources[i]` is the index of the first input
/// triangle (of the original mesh) that produced `triangles[i]`.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Simplices {
    /// Distinct triangles, winding of their first source, ordered by sorted vertex ids.
    pub triangles: Vec<[u32; 3]>,
    /// For each of `triangles`, the first input triangle that produced it.
    pub triangle_sources: Vec<u32>,
    /// Dangling edges `[a, b]` with `a < b`, in increasing order; none bounds a triangle.
    pub edges: Vec<[u32; 2]>,
    /// Isolated points in increasing order; none bounds an edge or a triangle.
    pub points: Vec<u32>,
}

const ODD: u32 = 1 << 31;
const CHUNK: usize = 1 << 14;

#[derive(Clone, Copy, Default, Debug)]
struct TriEntry {
    key: [u32; 3],
    /// Source triangle, with [`ODD`] set when the winding is the odd permutation of `key`.
    src: u32,
}

/// An edge `[a, b]`, `a < b`, as `a << 32 | b`: integer order is lexicographic order.
type EdgeKey = u64;

#[inline]
fn edge_key(p: u32, q: u32) -> EdgeKey {
    ((p.min(q) as u64) << 32) | p.max(q) as u64
}

/// Eliminates `triangles` (vertex ids) after mapping each vertex `v` to `cluster_of[v]`, a
/// cluster id below `clusters`. Input triangle `t` is source `t`. Cluster ids that no triangle
/// reaches produce nothing.
pub fn eliminate(triangles: &[[u32; 3]], cluster_of: &[u32], clusters: usize) -> Simplices {
    let flags = point_flags(clusters);
    let parts = map_triangles(triangles, cluster_of, Some(&flags));
    finish(parts, Some(flags), clusters)
}

/// [`eliminate`] when every cluster id below `clusters` is the cluster of a vertex of some
/// triangle, as it is for clusters made from the used vertices: then the isolated points are
/// exactly the clusters that no triangle or edge uses, and no per-triangle bookkeeping is needed
/// for them.
pub(crate) fn eliminate_covering(
    triangles: &[[u32; 3]],
    cluster_of: &[u32],
    clusters: usize,
) -> Simplices {
    let parts = map_triangles(triangles, cluster_of, None);
    finish(parts, None, clusters)
}

fn map_triangles(
    triangles: &[[u32; 3]],
    cluster_of: &[u32],
    flags: Option<&[AtomicBool]>,
) -> Vec<(Vec<TriEntry>, Vec<EdgeKey>)> {
    triangles
        .par_chunks(CHUNK)
        .enumerate()
        .map(|(ci, chunk)| {
            let mut tris = Vec::new();
            let mut edges = Vec::new();
            for (i, t) in chunk.iter().enumerate() {
                let src = (ci * CHUNK + i) as u32;
                let m = t.map(|v| cluster_of[v as usize]);
                classify(m, src, &mut tris, &mut edges, flags);
            }
            (tris, edges)
        })
        .collect()
}

/// Eliminates a previous level's simplices after mapping each of its clusters `c` to
/// `merge[c]`, a cluster id below `clusters` (§4: the merged clusters of an octree level).
/// Every id below `clusters` must be the image of a cluster that the previous level's simplices
/// use (true of an octree merge, whose clusters are made of the finer ones).
pub fn eliminate_merged(previous: &Simplices, merge: &[u32], clusters: usize) -> Simplices {
    let mut parts: Vec<(Vec<TriEntry>, Vec<EdgeKey>)> = previous
        .triangles
        .par_chunks(CHUNK)
        .zip(previous.triangle_sources.par_chunks(CHUNK))
        .map(|(chunk, sources)| {
            let mut tris = Vec::new();
            let mut edges = Vec::new();
            for (t, &src) in chunk.iter().zip(sources) {
                classify(
                    t.map(|v| merge[v as usize]),
                    src,
                    &mut tris,
                    &mut edges,
                    None,
                );
            }
            (tris, edges)
        })
        .collect();
    let mut edges = Vec::with_capacity(previous.edges.len());
    for e in &previous.edges {
        let (a, b) = (merge[e[0] as usize], merge[e[1] as usize]);
        if a != b {
            edges.push(edge_key(a, b));
        }
    }
    parts.push((Vec::new(), edges));
    // Collapsed edges and the previous points become points unless something uses them: with
    // every merged cluster covered, those are exactly the unused clusters.
    finish(parts, None, clusters)
}

fn point_flags(clusters: usize) -> Vec<AtomicBool> {
    (0..clusters).map(|_| AtomicBool::new(false)).collect()
}

#[inline]
fn set_flag(flags: &[AtomicBool], c: u32) {
    let f = &flags[c as usize];
    // Reading first keeps the cache line shared between threads when the flag is already set.
    if !f.load(Ordering::Relaxed) {
        f.store(true, Ordering::Relaxed);
    }
}

#[inline(always)]
fn classify(
    [a, b, c]: [u32; 3],
    src: u32,
    tris: &mut Vec<TriEntry>,
    edges: &mut Vec<EdgeKey>,
    flags: Option<&[AtomicBool]>,
) {
    // Most triangles of a fine mesh fall inside one cell: test that case first.
    if a == b && b == c {
        if let Some(flags) = flags {
            set_flag(flags, a);
        }
    } else if a != b && b != c && a != c {
        // Rotate the lowest id first (a rotation keeps the winding), then order the other two.
        let (x, y, z) = if a < b && a < c {
            (a, b, c)
        } else if b < c {
            (b, c, a)
        } else {
            (c, a, b)
        };
        let (key, odd) = if y < z {
            ([x, y, z], 0)
        } else {
            ([x, z, y], ODD)
        };
        tris.push(TriEntry {
            key,
            src: src | odd,
        });
    } else {
        let (p, q) = if a == b { (a, c) } else { (a, b) };
        let key = edge_key(p, q);
        // Neighbouring triangles often collapse onto the same edge: skip the repeat at once.
        if edges.last() != Some(&key) {
            edges.push(key);
        }
    }
}

fn finish(
    parts: Vec<(Vec<TriEntry>, Vec<EdgeKey>)>,
    flags: Option<Vec<AtomicBool>>,
    clusters: usize,
) -> Simplices {
    let bits = bits_for(clusters);
    let (tri_count, edge_count) = parts
        .iter()
        .fold((0, 0), |(t, e), p| (t + p.0.len(), e + p.1.len()));
    let mut tris = Vec::with_capacity(tri_count);
    let mut cand = Vec::with_capacity(edge_count);
    for (t, e) in parts {
        tris.extend_from_slice(&t);
        cand.extend_from_slice(&e);
    }

    let (mut tris, mut cand) = rayon::join(
        move || {
            sort_triangles(&mut tris, bits);
            tris
        },
        move || {
            sort_edges(&mut cand, bits);
            cand
        },
    );

    // Distinct triangles, each with its first source and that source's winding.
    let mut out = Simplices::default();
    let mut i = 0;
    while i < tris.len() {
        let key = tris[i].key;
        let mut best = tris[i].src;
        let mut j = i + 1;
        while j < tris.len() && tris[j].key == key {
            if tris[j].src & !ODD < best & !ODD {
                best = tris[j].src;
            }
            j += 1;
        }
        let [x, y, z] = key;
        out.triangles.push(if best & ODD == 0 {
            [x, y, z]
        } else {
            [x, z, y]
        });
        out.triangle_sources.push(best & !ODD);
        i = j;
    }
    tris.clear();

    // The edges of the kept triangles, sorted the same way as the candidates.
    let mut bounding: Vec<EdgeKey> = Vec::with_capacity(3 * out.triangles.len());
    let mut used = vec![false; clusters];
    for t in &out.triangles {
        bounding.extend([
            edge_key(t[0], t[1]),
            edge_key(t[1], t[2]),
            edge_key(t[0], t[2]),
        ]);
        for &v in t {
            used[v as usize] = true;
        }
    }
    sort_edges(&mut bounding, bits);

    // Distinct candidate edges that bound no kept triangle.
    cand.dedup();
    let mut b = 0;
    for &key in &cand {
        let (p, q) = ((key >> 32) as u32, key as u32);
        used[p as usize] = true;
        used[q as usize] = true;
        while b < bounding.len() && bounding[b] < key {
            b += 1;
        }
        if b >= bounding.len() || bounding[b] != key {
            out.edges.push([p, q]);
        }
    }
    drop(cand);

    out.points = (0..clusters)
        .filter(|&c| !used[c] && flags.as_ref().is_none_or(|f| f[c].load(Ordering::Relaxed)))
        .map(|c| c as u32)
        .collect();
    out
}

fn sort_triangles(tris: &mut Vec<TriEntry>, bits: u32) {
    if 3 * bits <= 64 {
        radix_sort_by_key(tris, 3 * bits, |e| {
            ((e.key[0] as u64) << (2 * bits)) | ((e.key[1] as u64) << bits) | e.key[2] as u64
        });
    } else {
        tris.sort_unstable_by_key(|e| e.key);
    }
}

fn sort_edges(edges: &mut Vec<EdgeKey>, bits: u32) {
    // Squeeze out the unused high bits of each half so that the sort makes fewer passes.
    radix_sort_by_key(edges, 2 * bits, |&k| {
        ((k >> 32) << bits) | (k & 0xFFFF_FFFF)
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Identity clusters: elimination of the triangles as they are.
    fn ident(n: usize) -> Vec<u32> {
        (0..n as u32).collect()
    }

    #[test]
    fn collapsed_triangles_become_edges_and_points() {
        // Triangle 0 stays; 1 collapses to edge (3, 4); 2 to point 5.
        let tris = [[0, 1, 2], [3, 4, 3], [5, 5, 5]];
        let s = eliminate(&tris, &ident(6), 6);
        assert_eq!(s.triangles, vec![[0, 1, 2]]);
        assert_eq!(s.edges, vec![[3, 4]]);
        assert_eq!(s.points, vec![5]);
    }

    #[test]
    fn duplicates_keep_the_first_winding() {
        let tris = [
            [2, 1, 0],
            [0, 1, 2],
            [1, 0, 2],
            [3, 4, 3],
            [4, 3, 4],
            [5, 5, 5],
            [5, 5, 5],
        ];
        let s = eliminate(&tris, &ident(6), 6);
        assert_eq!(s.triangles, vec![[0, 2, 1]]); // rotation of [2, 1, 0]
        assert_eq!(s.triangle_sources, vec![0]);
        assert_eq!(s.edges, vec![[3, 4]]);
        assert_eq!(s.points, vec![5]);
    }

    #[test]
    fn faces_of_kept_simplices_are_removed() {
        // Edge (0, 1) bounds triangle (0, 1, 2); point 2 bounds it; point 4 bounds edge (3, 4).
        let tris = [
            [0, 1, 2],
            [0, 1, 1],
            [1, 0, 0],
            [2, 2, 2],
            [3, 4, 4],
            [4, 4, 4],
            [6, 6, 6],
        ];
        let s = eliminate(&tris, &ident(7), 7);
        assert_eq!(s.triangles, vec![[0, 1, 2]]);
        assert_eq!(s.edges, vec![[3, 4]]);
        assert_eq!(s.points, vec![6]);
    }

    #[test]
    fn merging_levels_equals_eliminating_from_scratch() {
        // A strip of 20 triangles over 22 vertices, clustered in pairs then in fours.
        let n = 22u32;
        let tris: Vec<[u32; 3]> = (0..n - 2)
            .map(|i| {
                if i % 2 == 0 {
                    [i, i + 1, i + 2]
                } else {
                    [i + 1, i, i + 2]
                }
            })
            .collect();
        for (f, c) in [(2, 4), (3, 6), (2, 6), (5, 10)] {
            let fine: Vec<u32> = (0..n).map(|v| v / f).collect();
            let coarse: Vec<u32> = (0..n).map(|v| v / c).collect();
            let fc = (n / f + 1) as usize;
            let cc = (n / c + 1) as usize;
            let merge: Vec<u32> = (0..fc as u32).map(|k| k * f / c).collect();
            let level1 = eliminate(&tris, &fine, fc);
            let direct = eliminate(&tris, &coarse, cc);
            assert_eq!(eliminate_merged(&level1, &merge, cc), direct, "{f} {c}");
        }
    }

    #[test]
    fn wide_keys_fall_back_to_a_comparison_sort() {
        // 2^22 clusters need 66 key bits for a triangle.
        let clusters = 1 << 22;
        let big = (clusters - 1) as u32;
        let tris = [[big, 0, 1], [1, big, 0], [big - 1, big - 1, 7]];
        let s = eliminate(&tris, &ident(clusters), clusters);
        assert_eq!(s.triangles, vec![[0, 1, big]]);
        assert_eq!(s.edges, vec![[7, big - 1]]);
    }
}
