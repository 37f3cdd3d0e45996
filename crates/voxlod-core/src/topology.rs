//! Combinatorial topology of a triangle mesh: edges, boundary loops, manifoldness, orientation,
//! components, Euler characteristic and genus.
//!
//! The genus is how the voxel paper's claim is checked (§1, §4): filtering simplifies the genus
//! of an object in a controlled way, level after level, while every level stays a closed,
//! consistently oriented manifold.
//!
//! Everything here is decided from the vertex indices alone (weld coincident vertices first,
//! see [`crate::weld`], to judge a triangle soup). Cost: O(F) to list each vertex's triangles,
//! then one pass over the vertices in parallel, each sorting the few edges, triangles and link
//! ends of its own star (edges, duplicates and fans are counted at their smallest vertex), plus
//! near-linear union-find passes.

use rayon::prelude::*;
use serde::Serialize;

use crate::rows::Rows;
use crate::TriangleMesh;

/// What a mesh is, combinatorially. See [`mesh_topology`].
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Topology {
    /// Vertices used by at least one triangle.
    pub vertices: usize,
    /// Vertices in the file that no triangle uses.
    pub unreferenced_vertices: usize,
    /// Triangles, degenerate ones included.
    pub triangles: usize,
    /// Distinct undirected edges of the non-degenerate triangles.
    pub edges: usize,
    /// Edges used by exactly one triangle.
    pub boundary_edges: usize,
    /// Closed loops of the surface's boundary (holes); see [`count_boundary_loops`].
    pub boundary_loops: usize,
    /// Edges used by three or more triangles.
    pub non_manifold_edges: usize,
    /// Vertices whose triangles do not form a single fan (a pinch, or two cones touching).
    pub non_manifold_vertices: usize,
    /// Edges used twice in the same direction: the neighbours disagree about orientation.
    pub inconsistent_edges: usize,
    /// Triangles with a repeated vertex index.
    pub degenerate_triangles: usize,
    /// Triangles with the same three vertices as an earlier one (in any order).
    pub duplicate_triangles: usize,
    /// Connected components (triangles sharing a vertex are connected).
    pub components: usize,
    /// V - E + F over the used vertices.
    pub euler_characteristic: i64,
    /// (2C - χ - B) / 2, defined when the mesh is an oriented 2-manifold (with or without boundary).
    pub genus: Option<i64>,
}

impl Topology {
    /// A closed 2-manifold: no boundary, every edge shared by exactly two triangles, every vertex a single fan.
    pub fn is_closed_manifold(&self) -> bool {
        self.boundary_edges == 0 && self.is_manifold()
    }

    /// Every edge shared by at most two triangles and every vertex a single fan.
    pub fn is_manifold(&self) -> bool {
        self.non_manifold_edges == 0
            && self.non_manifold_vertices == 0
            && self.degenerate_triangles == 0
    }

    /// Neighbouring triangles agree on orientation across every interior edge.
    pub fn is_consistently_oriented(&self) -> bool {
        self.inconsistent_edges == 0
    }
}

/// Disjoint sets of vertex indices, with path halving.
pub(crate) struct UnionFind {
    parent: Vec<u32>,
}

impl UnionFind {
    pub(crate) fn new(n: usize) -> Self {
        UnionFind {
            parent: (0..n as u32).collect(),
        }
    }
    pub(crate) fn find(&mut self, mut x: u32) -> u32 {
        while self.parent[x as usize] != x {
            let p = self.parent[x as usize];
            self.parent[x as usize] = self.parent[p as usize];
            x = p;
        }
        x
    }
    pub(crate) fn union(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            self.parent[ra.max(rb) as usize] = ra.min(rb);
        }
    }
}

/// Computes the [`Topology`] of `mesh` from its indices.
///
/// ```
/// use voxlod_core::{glam::Vec3, mesh_topology, TriangleMesh};
///
/// // A square of two triangles: one boundary loop, a disc (genus 0).
/// let square = TriangleMesh::new(
///     vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
///     vec![[0, 1, 2], [0, 2, 3]],
/// );
/// let topology = mesh_topology(&square);
/// assert_eq!((topology.edges, topology.boundary_edges, topology.boundary_loops), (5, 4, 1));
/// assert_eq!(topology.euler_characteristic, 1);
/// assert_eq!(topology.genus, Some(0));
/// assert!(topology.is_manifold() && !topology.is_closed_manifold());
///
/// // Flip one triangle: the shared diagonal is then used twice in the same direction.
/// let mut folded = square.clone();
/// folded.triangles[1].swap(1, 2);
/// let topology = mesh_topology(&folded);
/// assert_eq!(topology.inconsistent_edges, 1);
/// assert_eq!(topology.genus, None);
/// ```
pub fn mesh_topology(mesh: &TriangleMesh) -> Topology {
    let nv = mesh.positions.len();
    let tris = &mesh.triangles;
    let incidence = Incidence::new(tris, nv);
    let used: Vec<bool> = (0..nv).map(|v| !incidence.around(v).is_empty()).collect();
    let vertices = used.iter().filter(|&&u| u).count();
    let degenerate_triangles = tris.iter().filter(|t| is_degenerate(t)).count();
    let stars = star_counts(tris, &incidence);
    let (duplicate_triangles, non_manifold_vertices) =
        (stars.duplicate_triangles, stars.non_manifold_vertices);
    let edges = stars.edges;
    let boundary_loops = count_boundary_loops(&edges.odd_edges, nv);
    let components = count_components(tris, &used);

    let euler_characteristic = vertices as i64 - edges.edges as i64 + tris.len() as i64;
    let oriented_manifold = edges.non_manifold_edges == 0
        && non_manifold_vertices == 0
        && edges.inconsistent_edges == 0
        && degenerate_triangles == 0;
    let genus = oriented_manifold
        .then(|| {
            let twice = 2 * components as i64 - euler_characteristic - boundary_loops as i64;
            (twice >= 0 && twice % 2 == 0).then_some(twice / 2)
        })
        .flatten();

    Topology {
        vertices,
        unreferenced_vertices: nv - vertices,
        triangles: tris.len(),
        edges: edges.edges,
        boundary_edges: edges.boundary_edges,
        boundary_loops,
        non_manifold_edges: edges.non_manifold_edges,
        non_manifold_vertices,
        inconsistent_edges: edges.inconsistent_edges,
        degenerate_triangles,
        duplicate_triangles,
        components,
        euler_characteristic,
        genus,
    }
}

/// A repeated vertex index.
#[inline]
fn is_degenerate(&[a, b, c]: &[u32; 3]) -> bool {
    a == b || b == c || a == c
}

/// The undirected edges of the non-degenerate triangles, by how many triangles use each.
struct EdgeCounts {
    edges: usize,
    boundary_edges: usize,
    non_manifold_edges: usize,
    inconsistent_edges: usize,
    /// Edges used an odd number of times, `(a, b, used_once)`: the boundary, and the
    /// non-manifold edges it runs on (the input of [`count_boundary_loops`]).
    odd_edges: Vec<(u32, u32, bool)>,
}

/// Connected components over shared vertices, counting only used vertices.
fn count_components(tris: &[[u32; 3]], used: &[bool]) -> usize {
    let mut uf = UnionFind::new(used.len());
    for &[a, b, c] in tris {
        uf.union(a, b);
        uf.union(b, c);
    }
    // Only used vertices are ever joined, so a used vertex's set holds used vertices alone and
    // its root is one of them: a component is a used vertex that is its own root.
    (0..used.len() as u32)
        .filter(|&v| used[v as usize] && uf.find(v) == v)
        .count()
}

/// The holes of a surface: the independent cycles of its boundary, counted as the cycle rank
/// E − V + C of the graph of edges used an odd number of times (the boundary of the triangles
/// as a chain modulo 2, which always closes into cycles), over its components that hold at least
/// one edge used once. `odd_edges` are `(a, b, used_once)`; `vertex_count` bounds the indices.
///
/// On a manifold these are the boundary edges alone, and a vertex where two holes touch gives
/// two cycles. Where a hole's rim runs along a non-manifold edge (a fin's base, a sheet glued
/// along an edge: used three times), the loop continues through that edge, so a rim of boundary
/// edges broken by non-manifold ones still counts as the loop it is. Components of odd
/// non-manifold edges only (no edge used once) are not holes and count nothing. Cost: a
/// union-find pass over the edges.
pub fn count_boundary_loops(odd_edges: &[(u32, u32, bool)], vertex_count: usize) -> usize {
    let mut graph = UnionFind::new(vertex_count);
    for &(a, b, _) in odd_edges {
        graph.union(a, b);
    }
    // Per component: edges, vertices, and whether an edge is used once.
    let mut components = rustc_hash::FxHashMap::<u32, (usize, usize, bool)>::default();
    let mut seen = rustc_hash::FxHashSet::default();
    for &(a, b, once) in odd_edges {
        let c = components.entry(graph.find(a)).or_default();
        c.0 += 1;
        c.2 |= once;
        for v in [a, b] {
            if seen.insert(v) {
                components.entry(graph.find(v)).or_default().1 += 1;
            }
        }
    }
    components
        .values()
        .filter(|c| c.2)
        .map(|&(e, v, _)| (e + 1).saturating_sub(v))
        .sum()
}

/// Each vertex's triangles ([`Rows`]): a triangle once per corner, degenerate ones included,
/// in triangle order, so a triangle that repeats a vertex lies twice in a row in its list.
pub struct Incidence(Rows<u32>);

impl Incidence {
    /// The lists of `tris` over `nv` vertices.
    pub fn new(tris: &[[u32; 3]], nv: usize) -> Incidence {
        let corners = || {
            (tris.iter().enumerate()).flat_map(|(t, tri)| tri.iter().map(move |&v| (v, t as u32)))
        };
        Incidence(Rows::new(nv, corners))
    }

    /// The triangles at vertex `v`.
    #[inline]
    pub fn around(&self, v: usize) -> &[u32] {
        self.0.row(v)
    }

    /// Where each vertex's list starts (one more entry than vertices), and the lists one after
    /// another.
    pub fn into_parts(self) -> (Vec<u32>, Vec<u32>) {
        self.0.into_parts()
    }
}

/// What the vertices' stars hold, summed over the vertices.
struct StarCounts {
    edges: EdgeCounts,
    duplicate_triangles: usize,
    non_manifold_vertices: usize,
}

/// One thread's scratch lists, reused from vertex to vertex.
#[derive(Default)]
struct StarScratch {
    /// The edges of the star to larger vertices: (other end, used from this vertex out).
    ends: Vec<(u32, bool)>,
    /// The sorted vertex triples of the star's triangles whose smallest vertex this is.
    triples: Vec<[u32; 3]>,
    /// The link: each non-degenerate triangle's edge opposite the vertex.
    link: Vec<(u32, u32)>,
    ids: Vec<u32>,
    parent: Vec<u32>,
}

/// Edges, duplicate triangles and non-manifold vertices from each vertex's star, in parallel
/// over the vertices: an undirected edge is counted at its smaller vertex (its uses there are
/// the half-edges of its key), a triangle among the duplicates at its smallest vertex, and a
/// vertex is a single fan when its link is connected. The counts of one global sort of the
/// half-edges and of the triangles (tests compare the two).
fn star_counts(tris: &[[u32; 3]], incidence: &Incidence) -> StarCounts {
    let nv = incidence.0.rows();
    (0..nv)
        .into_par_iter()
        .fold(
            || (StarScratch::default(), StarCounts::new()),
            |(mut scratch, mut counts), v| {
                counts.add_star(v as u32, tris, incidence.around(v), &mut scratch);
                (scratch, counts)
            },
        )
        .map(|(_, counts)| counts)
        .reduce(StarCounts::new, StarCounts::merge)
}

impl StarCounts {
    fn new() -> StarCounts {
        StarCounts {
            edges: EdgeCounts {
                edges: 0,
                boundary_edges: 0,
                non_manifold_edges: 0,
                inconsistent_edges: 0,
                odd_edges: Vec::new(),
            },
            duplicate_triangles: 0,
            non_manifold_vertices: 0,
        }
    }

    fn merge(mut self, other: StarCounts) -> StarCounts {
        let (e, o) = (&mut self.edges, other.edges);
        e.edges += o.edges;
        e.boundary_edges += o.boundary_edges;
        e.non_manifold_edges += o.non_manifold_edges;
        e.inconsistent_edges += o.inconsistent_edges;
        e.odd_edges.extend(o.odd_edges);
        self.duplicate_triangles += other.duplicate_triangles;
        self.non_manifold_vertices += other.non_manifold_vertices;
        self
    }

    /// Adds the star of vertex `v`, whose triangles are `around`.
    fn add_star(&mut self, v: u32, tris: &[[u32; 3]], around: &[u32], s: &mut StarScratch) {
        s.ends.clear();
        s.triples.clear();
        s.link.clear();
        for (k, &t) in around.iter().enumerate() {
            let tri = tris[t as usize];
            let mut sorted = tri;
            sorted.sort_unstable();
            if sorted[0] == v && (k == 0 || around[k - 1] != t) {
                s.triples.push(sorted);
            }
            if is_degenerate(&tri) {
                continue;
            }
            let at = tri.iter().position(|&w| w == v).unwrap_or(0);
            let (next, prev) = (tri[(at + 1) % 3], tri[(at + 2) % 3]);
            s.link.push((next, prev));
            if next > v {
                s.ends.push((next, true));
            }
            if prev > v {
                s.ends.push((prev, false));
            }
        }
        if s.triples.len() > 1 {
            s.triples.sort_unstable();
            self.duplicate_triangles += s.triples.windows(2).filter(|w| w[0] == w[1]).count();
        }
        s.ends.sort_unstable_by_key(|e| e.0);
        for uses in s.ends.chunk_by(|p, q| p.0 == q.0) {
            self.edges.add_edge(v, uses);
        }
        if s.link.len() > 1 && !link_is_connected(s) {
            self.non_manifold_vertices += 1;
        }
    }
}

impl EdgeCounts {
    /// One undirected edge (v, w), w > v, with its uses `(w, used from v out)`.
    fn add_edge(&mut self, v: u32, uses: &[(u32, bool)]) {
        let w = uses[0].0;
        self.edges += 1;
        match uses.len() {
            1 => {
                self.boundary_edges += 1;
                self.odd_edges.push((v, w, true));
            }
            2 => {
                if uses[0].1 == uses[1].1 {
                    self.inconsistent_edges += 1;
                }
            }
            n => {
                self.non_manifold_edges += 1;
                if n % 2 == 1 {
                    self.odd_edges.push((v, w, false));
                }
            }
        }
    }
}

/// A vertex is manifold when the triangles around it are connected through the edges that
/// contain it (one fan): when its link's edges (`s.link`, at least two) form one connected
/// graph. A degenerate triangle (a repeated index) spans no fan and is not in the link, so a
/// vertex that only degenerate triangles use has an empty link and is no pinch. A union-find
/// over the link's ends, numbered by their sorted order.
fn link_is_connected(s: &mut StarScratch) -> bool {
    s.ids.clear();
    s.ids.extend(s.link.iter().flat_map(|&(a, b)| [a, b]));
    s.ids.sort_unstable();
    s.ids.dedup();
    s.parent.clear();
    s.parent.extend(0..s.ids.len() as u32);
    fn find(parent: &mut [u32], mut x: u32) -> u32 {
        while parent[x as usize] != x {
            let p = parent[x as usize];
            parent[x as usize] = parent[p as usize];
            x = p;
        }
        x
    }
    for &(a, b) in &s.link {
        let local = |x: u32| s.ids.binary_search(&x).unwrap() as u32;
        let (ra, rb) = (find(&mut s.parent, local(a)), find(&mut s.parent, local(b)));
        if ra != rb {
            s.parent[ra.max(rb) as usize] = ra.min(rb);
        }
    }
    let root = find(&mut s.parent, 0);
    (1..s.ids.len() as u32).all(|i| find(&mut s.parent, i) == root)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_shapes::unit_cube;
    use glam::Vec3;

    // The sort-based counts that `star_counts` replaced: the reference it is checked against.

    fn edge_key(a: u32, b: u32) -> u64 {
        ((a.min(b) as u64) << 32) | a.max(b) as u64
    }

    /// For each vertex, whether a triangle uses it.
    fn used_vertices(mesh: &TriangleMesh) -> Vec<bool> {
        let mut used = vec![false; mesh.positions.len()];
        for t in &mesh.triangles {
            for &v in t {
                used[v as usize] = true;
            }
        }
        used
    }

    /// Triangles with the same three vertices as an earlier one, in any order: one parallel sort of
    /// the sorted vertex triples.
    fn count_duplicate_triangles(tris: &[[u32; 3]]) -> usize {
        let mut sorted_tris: Vec<[u32; 3]> = tris
            .par_iter()
            .map(|t| {
                let mut s = *t;
                s.sort_unstable();
                s
            })
            .collect();
        sorted_tris.par_sort_unstable();
        sorted_tris.windows(2).filter(|w| w[0] == w[1]).count()
    }

    /// Counts the edges from one sort of the 3F half-edges.
    fn count_edges(tris: &[[u32; 3]]) -> EdgeCounts {
        // Half-edges: (undirected key, forward?) for each side of each non-degenerate triangle.
        let mut half: Vec<(u64, bool)> = tris
            .par_iter()
            .filter(|t| !is_degenerate(t))
            .flat_map_iter(|&[a, b, c]| {
                [(a, b), (b, c), (c, a)]
                    .into_iter()
                    .map(|(u, v)| (edge_key(u, v), u < v))
            })
            .collect();
        half.par_sort_unstable_by_key(|h| h.0);

        let mut counts = EdgeCounts {
            edges: 0,
            boundary_edges: 0,
            non_manifold_edges: 0,
            inconsistent_edges: 0,
            odd_edges: Vec::new(),
        };
        for uses in half.chunk_by(|p, q| p.0 == q.0) {
            let key = uses[0].0;
            counts.edges += 1;
            match uses.len() {
                1 => {
                    counts.boundary_edges += 1;
                    counts
                        .odd_edges
                        .push(((key >> 32) as u32, key as u32, true));
                }
                2 => {
                    if uses[0].1 == uses[1].1 {
                        counts.inconsistent_edges += 1;
                    }
                }
                n => {
                    counts.non_manifold_edges += 1;
                    if n % 2 == 1 {
                        counts
                            .odd_edges
                            .push(((key >> 32) as u32, key as u32, false));
                    }
                }
            }
        }
        counts
    }

    /// A vertex is manifold when the triangles around it are connected through the edges that
    /// contain it (one fan). Counted with a union-find over each vertex's incident triangles.
    fn count_non_manifold_vertices(mesh: &TriangleMesh, used: &[bool]) -> usize {
        let nv = mesh.positions.len();
        let incidence = Incidence::new(&mesh.triangles, nv);
        (0..nv)
            .into_par_iter()
            .filter(|&v| used[v])
            .filter(|&v| {
                let around = incidence.around(v);
                // Each incident triangle contributes the two other vertices (its "link" edge);
                // the fan is connected when the link edges form one connected graph. A degenerate
                // triangle (a repeated index) spans no fan: it is counted as degenerate instead, and
                // a vertex that only degenerate triangles use (a triangle collapsed to a point or to
                // an edge) has an empty link and is no pinch.
                let link: Vec<(u32, u32)> = around
                    .iter()
                    .map(|&t| mesh.triangles[t as usize])
                    .filter(|&[a, b, c]| a != b && b != c && a != c)
                    .map(|tri| {
                        let at = tri.iter().position(|&w| w == v as u32).unwrap_or(0);
                        (tri[(at + 1) % 3], tri[(at + 2) % 3])
                    })
                    .collect();
                if link.len() <= 1 {
                    return false;
                }
                let mut ids: Vec<u32> = link.iter().flat_map(|&(a, b)| [a, b]).collect();
                ids.sort_unstable();
                ids.dedup();
                let local = |x: u32| ids.binary_search(&x).unwrap() as u32;
                let mut uf = UnionFind::new(ids.len());
                for &(a, b) in &link {
                    uf.union(local(a), local(b));
                }
                let root = uf.find(0);
                (1..ids.len() as u32).any(|i| uf.find(i) != root)
            })
            .count()
    }

    /// Random meshes (closed cubes welded together, random extra triangles: degenerate ones,
    /// duplicates in any order, pages on shared edges, flipped ones, pinches, unused vertices)
    /// counted from the stars and from the global sorts: every count equal.
    #[test]
    fn star_counts_are_those_of_the_global_sorts() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(14);
        // Rounds that had each kind of defect: the meshes must exercise every count.
        let mut seen = [0usize; 5];
        for round in 0..60 {
            let nv = rng.random_range(1..40u32);
            let mut tris: Vec<[u32; 3]> = Vec::new();
            let cube = unit_cube();
            if nv >= 8 {
                let shift = rng.random_range(0..=nv - 8);
                tris.extend(cube.triangles.iter().map(|t| t.map(|v| v + shift)));
            }
            for _ in 0..rng.random_range(0..3 * nv as usize + 2) {
                let t = if !tris.is_empty() && rng.random_range(0..4) == 0 {
                    // A copy of an earlier triangle, rotated or flipped.
                    let mut t = tris[rng.random_range(0..tris.len())];
                    t.rotate_left(rng.random_range(0..3));
                    if rng.random_range(0..2) == 0 {
                        t.swap(0, 1);
                    }
                    t
                } else {
                    // Few distinct vertices at times: degenerate triangles and shared edges.
                    let span = if rng.random_range(0..3) == 0 {
                        3.min(nv)
                    } else {
                        nv
                    };
                    [0; 3].map(|_| rng.random_range(0..span))
                };
                tris.push(t);
            }
            let positions = vec![Vec3::ZERO; nv as usize + rng.random_range(0..3)];
            let mesh = TriangleMesh::new(positions, tris.clone());
            let incidence = Incidence::new(&tris, mesh.positions.len());
            let stars = star_counts(&tris, &incidence);
            let reference = count_edges(&tris);
            let e = &stars.edges;
            assert_eq!(
                (
                    e.edges,
                    e.boundary_edges,
                    e.non_manifold_edges,
                    e.inconsistent_edges
                ),
                (
                    reference.edges,
                    reference.boundary_edges,
                    reference.non_manifold_edges,
                    reference.inconsistent_edges
                ),
                "round {round}"
            );
            let sorted = |mut odd: Vec<(u32, u32, bool)>| {
                odd.sort_unstable();
                odd
            };
            assert_eq!(sorted(e.odd_edges.clone()), sorted(reference.odd_edges));
            assert_eq!(stars.duplicate_triangles, count_duplicate_triangles(&tris));
            let used = used_vertices(&mesh);
            let pinches = count_non_manifold_vertices(&mesh, &used);
            assert_eq!(stars.non_manifold_vertices, pinches, "round {round}");
            let kinds = [
                e.boundary_edges,
                e.non_manifold_edges,
                e.inconsistent_edges,
                stars.duplicate_triangles,
                pinches,
            ];
            for (s, k) in seen.iter_mut().zip(kinds) {
                *s += (k > 0) as usize;
            }
        }
        assert!(seen.iter().all(|&s| s >= 5), "{seen:?}");
    }

    #[test]
    fn cube_is_a_closed_sphere() {
        let t = mesh_topology(&unit_cube());
        assert_eq!(t.vertices, 8);
        assert_eq!(t.edges, 18);
        assert_eq!(t.euler_characteristic, 2);
        assert_eq!(t.genus, Some(0));
        assert_eq!(t.components, 1);
        assert!(t.is_closed_manifold());
        assert!(t.is_consistently_oriented());
    }

    #[test]
    fn open_cube_has_one_loop() {
        let mut cube = unit_cube();
        cube.triangles.truncate(10); // drop the two triangles of the x = 0 side
        let t = mesh_topology(&cube);
        assert_eq!(t.boundary_edges, 4);
        assert_eq!(t.boundary_loops, 1);
        assert_eq!(t.genus, Some(0));
        assert!(!t.is_closed_manifold());
    }

    #[test]
    fn a_rim_through_non_manifold_edges_is_one_loop() {
        // A closed cube plus a fin: a triangle on cube edge 0–1 (then used three times) to a new
        // vertex 8. The fin's two free edges are the only boundary edges; with the fin's base
        // they close one loop. Counting boundary edges alone finds a path and no loop.
        let mut m = unit_cube();
        let (a, b) = (m.triangles[0][0], m.triangles[0][1]);
        m.positions.push(Vec3::new(0.5, -1.0, -1.0));
        m.triangles.push([a, b, 8]);
        let t = mesh_topology(&m);
        assert_eq!((t.boundary_edges, t.non_manifold_edges), (2, 1));
        assert_eq!(t.boundary_loops, 1);
        // A second fin on another edge: a second loop.
        let (c, d) = (m.triangles[2][1], m.triangles[2][2]);
        m.positions.push(Vec3::new(2.0, 2.0, 2.0));
        m.triangles.push([c, d, 9]);
        let t = mesh_topology(&m);
        assert_eq!((t.boundary_edges, t.non_manifold_edges), (4, 2));
        assert_eq!(t.boundary_loops, 2);
    }

    #[test]
    fn loops_of_touching_holes_and_of_sheets_on_one_edge() {
        // Two triangles touching at vertex 0: two rims sharing a vertex, two loops.
        let m = TriangleMesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::Y, -Vec3::X, -Vec3::Y],
            vec![[0, 1, 2], [0, 3, 4]],
        );
        assert_eq!(mesh_topology(&m).boundary_loops, 2);
        // Three triangles on edge 0–1 (a book of three pages): each page's two free edges
        // close through the spine, three loops.
        let m = TriangleMesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z, -Vec3::Y],
            vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]],
        );
        let t = mesh_topology(&m);
        assert_eq!((t.boundary_edges, t.boundary_loops), (6, 3));
        // Four triangles on one edge (used an even number of times): the spine is not on the
        // boundary; the four pages' free edges are four paths from 0 to 1, three loops.
        let m = TriangleMesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z, -Vec3::Y, -Vec3::Z],
            vec![[0, 1, 2], [1, 0, 3], [0, 1, 4], [1, 0, 5]],
        );
        let t = mesh_topology(&m);
        assert_eq!((t.boundary_edges, t.boundary_loops), (8, 3));
    }

    #[test]
    fn flags_inconsistent_and_non_manifold() {
        let mut cube = unit_cube();
        cube.triangles[0].swap(1, 2);
        let t = mesh_topology(&cube);
        assert_eq!(t.inconsistent_edges, 3);
        assert_eq!(t.genus, None);

        // Three triangles on one edge.
        let m = TriangleMesh::new(
            vec![
                Vec3::ZERO,
                Vec3::X,
                Vec3::Y,
                Vec3::Z,
                Vec3::new(-1.0, 0.0, 0.0),
            ],
            vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]],
        );
        let t = mesh_topology(&m);
        assert_eq!(t.non_manifold_edges, 1);
        assert_eq!(t.components, 1);
    }

    #[test]
    fn counts_pinched_vertices_and_duplicates() {
        // Two triangles touching at one vertex only.
        let m = TriangleMesh::new(
            vec![
                Vec3::ZERO,
                Vec3::X,
                Vec3::Y,
                Vec3::new(-1.0, 0.0, 0.0),
                Vec3::new(0.0, -1.0, 0.0),
            ],
            vec![[0, 1, 2], [0, 3, 4], [2, 1, 0], [0, 0, 1]],
        );
        let t = mesh_topology(&m);
        assert_eq!(t.non_manifold_vertices, 1);
        assert_eq!(t.duplicate_triangles, 1);
        assert_eq!(t.degenerate_triangles, 1);
    }

    #[test]
    fn triangles_collapsed_to_a_point_or_an_edge_alone() {
        // `v 0 0 0` / `f 1 1 1`: one vertex, one triangle, no edge.
        let point = TriangleMesh::new(vec![Vec3::ZERO], vec![[0, 0, 0]]);
        let t = mesh_topology(&point);
        assert_eq!((t.vertices, t.triangles, t.edges), (1, 1, 0));
        assert_eq!(t.degenerate_triangles, 1);
        assert_eq!(t.non_manifold_vertices, 0);
        assert_eq!(t.components, 1);
        assert_eq!(t.genus, None);

        // A triangle collapsed to an edge that nothing else uses.
        let sliver = TriangleMesh::new(vec![Vec3::ZERO, Vec3::X], vec![[0, 0, 1]]);
        let t = mesh_topology(&sliver);
        assert_eq!((t.vertices, t.edges, t.degenerate_triangles), (2, 0, 1));
        assert_eq!(t.non_manifold_vertices, 0);
    }

    #[test]
    fn closed_cube_plus_a_lone_point_facet() {
        let mut m = unit_cube();
        m.positions.push(Vec3::splat(5.0));
        m.triangles.push([8, 8, 8]);
        let t = mesh_topology(&m);
        assert_eq!((t.vertices, t.edges, t.triangles), (9, 18, 13));
        assert_eq!(t.degenerate_triangles, 1);
        assert_eq!((t.boundary_edges, t.non_manifold_edges), (0, 0));
        assert_eq!(t.non_manifold_vertices, 0);
        assert_eq!(t.components, 2);
        assert_eq!(t.euler_characteristic, 9 - 18 + 13);
        assert_eq!(t.genus, None);
        assert!(!t.is_manifold());

        // The same point collapsed onto a cube corner leaves that corner's fan whole.
        let mut m = unit_cube();
        m.triangles.push([0, 0, 0]);
        m.triangles.push([0, 0, 6]);
        let t = mesh_topology(&m);
        assert_eq!(t.non_manifold_vertices, 0);
        assert_eq!(t.degenerate_triangles, 2);
        assert_eq!(t.components, 1);
    }

    #[test]
    fn torus_has_genus_one() {
        // A 4x3 quad torus triangulated: V=12, E=36, F=24, χ=0.
        let (n, m) = (4u32, 3u32);
        let mut positions = Vec::new();
        for i in 0..n {
            for j in 0..m {
                let a = i as f32 / n as f32 * std::f32::consts::TAU;
                let b = j as f32 / m as f32 * std::f32::consts::TAU;
                positions.push(Vec3::new(
                    (2.0 + b.cos()) * a.cos(),
                    (2.0 + b.cos()) * a.sin(),
                    b.sin(),
                ));
            }
        }
        let id = |i: u32, j: u32| (i % n) * m + (j % m);
        let mut triangles = Vec::new();
        for i in 0..n {
            for j in 0..m {
                triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        let t = mesh_topology(&TriangleMesh::new(positions, triangles));
        assert_eq!(t.euler_characteristic, 0);
        assert_eq!(t.genus, Some(1));
        assert!(t.is_closed_manifold());
    }
}
