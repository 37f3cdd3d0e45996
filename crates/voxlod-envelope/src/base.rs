//! The input mesh, checked and prepared once for every level of a series: `f64` positions,
//! unit vertex normals, each vertex's triangles (its star), which vertices lie on the border,
//! and a closest-point structure (voxlod-metrics) for the offsets' Voronoi test.
//!
//! Vertex normals are angle-weighted averages of the face normals: unlike area weights they do
//! not depend on how a flat fan happens to be cut into triangles (marching-cubes slivers).
//! Optionally they are then smoothed: each round replaces a normal by the normalised sum of
//! itself and its neighbours' (over the edges). The paper assumes normals that "faithfully
//! represent" the object; on a scan the raw normals carry the scanner's noise, and offsets far
//! out along noisy normals cross each other everywhere. Any unit direction keeps the distance
//! bound (an offset vertex is within its ε of its vertex); the crossing check keeps the
//! offsets apart whatever the normals.
//! Cost: O(V + F) per smoothing round plus the closest-point BVH build, O(F log F).

use glam::DVec3;
use voxlod_core::TriangleMesh;
use voxlod_metrics::MeshDistance;

use super::manifold::{check_manifold, stars};
use super::EnvelopeError;

/// The prepared input (see the module documentation).
pub(crate) struct Base {
    /// The input's positions, in `f64`.
    pub pos: Vec<DVec3>,
    /// Unit angle-weighted vertex normals; zero for vertices no proper triangle uses.
    pub normals: Vec<DVec3>,
    /// The input's triangles.
    pub tris: Vec<[u32; 3]>,
    /// `star_offsets[v]..star_offsets[v + 1]` indexes `star_list` for vertex `v`.
    star_offsets: Vec<u32>,
    star_list: Vec<u32>,
    /// Vertices on an edge that only one triangle uses.
    pub border: Vec<bool>,
    /// Diagonal of the box of the used vertices.
    pub diagonal: f64,
    /// Contact tolerance of the intersection tests, in mesh units (10⁻⁹ of the diagonal).
    pub tol: f64,
    /// Closest points on the input (for the Voronoi limit).
    pub distance: MeshDistance,
}

impl Base {
    /// Checks `mesh` (triangles present, indices in range, finite coordinates, manifold and
    /// consistently oriented) and prepares it, with `smoothing` rounds of normal smoothing.
    pub fn new(mesh: &TriangleMesh, smoothing: usize) -> Result<Base, EnvelopeError> {
        voxlod_core::validate::validate_mesh(mesh, &Default::default())?;
        let n = mesh.positions.len();
        if n >= (u32::MAX / 2) as usize || mesh.triangles.len() >= (u32::MAX / 2) as usize {
            return Err(EnvelopeError::TooLarge(format!(
                "{n} vertices and {} triangles (at most {} of each)",
                mesh.triangles.len(),
                u32::MAX / 2 - 1
            )));
        }
        check_manifold(mesh)?;
        let pos: Vec<DVec3> = mesh.positions.iter().map(|p| p.as_dvec3()).collect();
        let tris = mesh.triangles.clone();
        let (star_offsets, star_list) = stars(&tris, n, |_| true);
        let normals = vertex_normals(&pos, &tris, smoothing);
        let border = border_vertices(&tris, &star_offsets, &star_list);
        let bounds = mesh.bounds();
        let diagonal = bounds.diagonal();
        let distance = MeshDistance::new(mesh)?;
        Ok(Base {
            pos,
            normals,
            tris,
            star_offsets,
            star_list,
            border,
            diagonal,
            tol: 1e-9 * diagonal.max(f64::MIN_POSITIVE),
            distance,
        })
    }

    /// How many vertices the input has (used or not).
    pub fn vertex_count(&self) -> usize {
        self.pos.len()
    }

    /// The triangles around `v` in the input.
    #[inline]
    pub fn star(&self, v: usize) -> &[u32] {
        &self.star_list[self.star_offsets[v] as usize..self.star_offsets[v + 1] as usize]
    }

    /// The corners of input triangle `t`.
    #[inline]
    pub fn corners(&self, t: usize) -> [DVec3; 3] {
        self.tris[t].map(|v| self.pos[v as usize])
    }

    /// Whether some triangle uses `v`.
    #[inline]
    pub fn is_used(&self, v: usize) -> bool {
        self.star_offsets[v + 1] > self.star_offsets[v]
    }
}

/// Unit angle-weighted vertex normals, then `smoothing` rounds of smoothing (see the module
/// documentation) that never tilt a normal out of the cone of its own faces' normals; zero for
/// vertices no proper triangle uses.
fn vertex_normals(pos: &[DVec3], tris: &[[u32; 3]], smoothing: usize) -> Vec<DVec3> {
    let faces: Vec<DVec3> = tris
        .iter()
        .map(|&[a, b, c]| {
            let p = [pos[a as usize], pos[b as usize], pos[c as usize]];
            (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero()
        })
        .collect();
    let mut acc = vec![DVec3::ZERO; pos.len()];
    for (&[a, b, c], &face) in tris.iter().zip(&faces) {
        let p = [pos[a as usize], pos[b as usize], pos[c as usize]];
        for (i, &v) in [a, b, c].iter().enumerate() {
            let e1 = (p[(i + 1) % 3] - p[i]).normalize_or_zero();
            let e2 = (p[(i + 2) % 3] - p[i]).normalize_or_zero();
            let angle = e1.dot(e2).clamp(-1.0, 1.0).acos();
            acc[v as usize] += face * angle;
        }
    }
    let mut normals: Vec<DVec3> = acc.into_iter().map(|v| v.normalize_or_zero()).collect();
    if smoothing == 0 {
        return normals;
    }
    // The least cosine a smoothed normal may make with one of its vertex's faces: that of the
    // raw normal, or cos 60°, whichever is less. Without this limit, 20 rounds on a machined
    // part tilt the normals at every sharp edge towards the larger side, the offsets along them
    // run nearly parallel to the smaller side's faces and cross the rest of the envelope, and
    // the crossing check shrinks them to nothing (the pinion gear of ../shared/data at 2 %: 558
    // of 650 vertices with a zero side, 1 182 triangles left of 1 300 where the paper's preset
    // leaves 308).
    let least = least_face_cosines(&normals, tris, &faces);
    let floor: Vec<f64> = least.iter().map(|&c| c.min(0.5)).collect();
    for _ in 0..smoothing {
        // Each edge is seen from both of its triangles (once from the border's): the weights
        // do not matter much, the direction does.
        let mut sum = normals.clone();
        for &[a, b, c] in tris {
            for (u, w) in [(a, b), (b, c), (c, a)] {
                sum[u as usize] += normals[w as usize];
                sum[w as usize] += normals[u as usize];
            }
        }
        let smoothed: Vec<DVec3> = sum.into_iter().map(|v| v.normalize_or_zero()).collect();
        let cosines = least_face_cosines(&smoothed, tris, &faces);
        for (v, n) in normals.iter_mut().enumerate() {
            if cosines[v] >= floor[v] {
                *n = smoothed[v];
            }
        }
    }
    normals
}

/// Per vertex, the least cosine between its normal in `normals` and the normals of its faces
/// (1 for a vertex without faces).
fn least_face_cosines(normals: &[DVec3], tris: &[[u32; 3]], faces: &[DVec3]) -> Vec<f64> {
    let mut least = vec![1.0f64; normals.len()];
    for (tri, face) in tris.iter().zip(faces) {
        for &v in tri {
            least[v as usize] = least[v as usize].min(normals[v as usize].dot(*face));
        }
    }
    least
}

/// The vertices on the border. In a manifold, an inner vertex has as many neighbours as
/// triangles; a border vertex one more.
fn border_vertices(tris: &[[u32; 3]], star_offsets: &[u32], star_list: &[u32]) -> Vec<bool> {
    (0..star_offsets.len() - 1)
        .map(|v| {
            let ts = &star_list[star_offsets[v] as usize..star_offsets[v + 1] as usize];
            if ts.is_empty() {
                return false;
            }
            let mut around: Vec<u32> = ts
                .iter()
                .flat_map(|&t| tris[t as usize])
                .filter(|&w| w as usize != v)
                .collect();
            around.sort_unstable();
            around.dedup();
            around.len() != ts.len()
        })
        .collect()
}
