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

use super::manifold::check_manifold;
use super::EnvelopeError;

/// The prepared input (see the module documentation).
pub(crate) struct Base {
    pub pos: Vec<DVec3>,
    /// Unit angle-weighted vertex normals; zero for vertices no proper triangle uses.
    pub normals: Vec<DVec3>,
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

        let mut star_offsets = vec![0u32; n + 1];
        for tri in &tris {
            for &v in tri {
                star_offsets[v as usize + 1] += 1;
            }
        }
        for i in 0..n {
            star_offsets[i + 1] += star_offsets[i];
        }
        let mut fill = star_offsets.clone();
        let mut star_list = vec![0u32; star_offsets[n] as usize];
        for (t, tri) in tris.iter().enumerate() {
            for &v in tri {
                star_list[fill[v as usize] as usize] = t as u32;
                fill[v as usize] += 1;
            }
        }

        let mut acc = vec![DVec3::ZERO; n];
        for &[a, b, c] in &tris {
            let p = [pos[a as usize], pos[b as usize], pos[c as usize]];
            let face = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
            for (i, &v) in [a, b, c].iter().enumerate() {
                let e1 = (p[(i + 1) % 3] - p[i]).normalize_or_zero();
                let e2 = (p[(i + 2) % 3] - p[i]).normalize_or_zero();
                let angle = e1.dot(e2).clamp(-1.0, 1.0).acos();
                acc[v as usize] += face * angle;
            }
        }
        let mut normals: Vec<DVec3> = acc.into_iter().map(|v| v.normalize_or_zero()).collect();
        for _ in 0..smoothing {
            // Each edge is seen from both of its triangles (once from the border's): the weights
            // do not matter much, the direction does.
            let mut sum = normals.clone();
            for &[a, b, c] in &tris {
                for (u, w) in [(a, b), (b, c), (c, a)] {
                    sum[u as usize] += normals[w as usize];
                    sum[w as usize] += normals[u as usize];
                }
            }
            normals = sum.into_iter().map(|v| v.normalize_or_zero()).collect();
        }

        // In a manifold, an inner vertex has as many neighbours as triangles; a border vertex
        // one more.
        let border = (0..n)
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
            .collect();

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

    pub fn vertex_count(&self) -> usize {
        self.pos.len()
    }

    /// The triangles around `v` in the input.
    #[inline]
    pub fn star(&self, v: usize) -> &[u32] {
        &self.star_list[self.star_offsets[v] as usize..self.star_offsets[v + 1] as usize]
    }

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
