//! Building blocks of the corpus: parametric grids (sheets, open tubes, domes, closed spheres),
//! planar subdivision, placement, tubes along curves, and a small deterministic random source.
//! Everything is computed in f64 and stored as f32; the same inputs give the same bits.

use glam::{DQuat, DVec3};

use voxlod_core::TriangleMesh;

/// A small deterministic random source (SplitMix64): the same seed, the same sequence, on every
/// platform.
pub(super) struct Rng(u64);

impl Rng {
    /// A source started from `seed`.
    pub(super) fn new(seed: u64) -> Rng {
        Rng(seed)
    }

    /// The next 64 random bits.
    pub(super) fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        mix(self.0)
    }

    /// A number in [`lo`, `hi`).
    pub(super) fn range(&mut self, lo: f64, hi: f64) -> f64 {
        let unit = (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        lo + (hi - lo) * unit
    }

    /// A direction uniformly distributed on the unit sphere.
    pub(super) fn direction(&mut self) -> DVec3 {
        let z = self.range(-1.0, 1.0);
        let a = self.range(0.0, std::f64::consts::TAU);
        let s = (1.0 - z * z).sqrt();
        DVec3::new(s * a.cos(), s * a.sin(), z)
    }

    /// A rotation by a uniformly random angle about a random axis.
    pub(super) fn rotation(&mut self) -> DQuat {
        let axis = self.direction();
        DQuat::from_axis_angle(axis, self.range(0.0, std::f64::consts::TAU))
    }
}

/// SplitMix64's output function: a well-mixed 64-bit hash of `z`.
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A deterministic value in [-1, 1) for the integer point (`i`, `j`): noise that is the same
/// wherever the same grid point is evaluated.
pub(super) fn hash_noise(i: u32, j: u32) -> f64 {
    let bits = mix(((i as u64) << 32 | j as u64) ^ 0x005E_ED0F_C0DE);
    (bits >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

/// A parametric grid surface: vertex (i, j) at `f(i, j)` for i in 0..=nu (0..nu when `wrap_u`:
/// column nu is column 0) and j in 0..=nv, vertex (i, j) numbered `j * columns + i`; each cell
/// split into two triangles whose normal is ∂f/∂i × ∂f/∂j. 2·nu·nv triangles. Without
/// `wrap_u` it is a disc (one boundary loop); with it, an open tube (two loops).
pub(super) fn grid_surface(
    nu: u32,
    nv: u32,
    wrap_u: bool,
    f: impl Fn(u32, u32) -> DVec3,
) -> TriangleMesh {
    let columns = if wrap_u { nu } else { nu + 1 };
    let positions = (0..=nv)
        .flat_map(|j| (0..columns).map(move |i| (i, j)))
        .map(|(i, j)| f(i, j).as_vec3())
        .collect();
    let id = |i: u32, j: u32| j * columns + i % columns;
    let mut triangles = Vec::with_capacity((2 * nu * nv) as usize);
    for j in 0..nv {
        for i in 0..nu {
            triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    TriangleMesh::new(positions, triangles)
}

/// A surface around a pole: vertex 0 is the pole `f(0, 0)`; ring j (1 ≤ j < nv, and j = nv
/// when `closed` is false) has the `nu` vertices `f(i, j)` numbered `1 + (j - 1) * nu + i`;
/// when `closed`, the last vertex is the second pole `f(0, nv)`. Oriented so that a sphere with
/// i the longitude (counter-clockwise about the pole axis seen from the first pole) and j the
/// colatitude from the first pole has outward normals. Closed: a sphere, 2·nu·(nv - 1)
/// triangles; open: a disc ending in the ring nv, nu·(2nv - 1) triangles.
pub(super) fn polar_surface(
    nu: u32,
    nv: u32,
    closed: bool,
    f: impl Fn(u32, u32) -> DVec3,
) -> TriangleMesh {
    let rings = if closed { nv - 1 } else { nv };
    let mut positions = vec![f(0, 0).as_vec3()];
    for j in 1..=rings {
        positions.extend((0..nu).map(|i| f(i, j).as_vec3()));
    }
    let ring = |i: u32, j: u32| 1 + (j - 1) * nu + i % nu;
    let mut triangles = Vec::new();
    for i in 0..nu {
        triangles.push([0, ring(i, 1), ring(i + 1, 1)]);
    }
    for j in 1..rings {
        for i in 0..nu {
            let (a, b) = (ring(i, j), ring(i + 1, j));
            let (c, d) = (ring(i + 1, j + 1), ring(i, j + 1));
            triangles.push([a, d, c]);
            triangles.push([a, c, b]);
        }
    }
    if closed {
        let pole = positions.len() as u32;
        positions.push(f(0, nv).as_vec3());
        for i in 0..nu {
            triangles.push([ring(i, rings), pole, ring(i + 1, rings)]);
        }
    }
    TriangleMesh::new(positions, triangles)
}

/// The unit direction at longitude i/nu·2π and colatitude j/nv·π.
pub(super) fn sphere_direction(i: u32, j: u32, nu: u32, nv: u32) -> DVec3 {
    let (lon, colat) = (
        std::f64::consts::TAU * (i % nu) as f64 / nu as f64,
        std::f64::consts::PI * j as f64 / nv as f64,
    );
    DVec3::new(
        colat.sin() * lon.cos(),
        colat.sin() * lon.sin(),
        colat.cos(),
    )
}

/// Every triangle split into four at its edges' midpoints, `levels` times (the midpoints stay
/// on the triangles' planes, and an edge's midpoint is shared by its two triangles): 4^levels
/// times the triangles.
pub(super) fn subdivide(mesh: &TriangleMesh, levels: u32) -> TriangleMesh {
    let points = mesh.positions.iter().map(|p| p.as_dvec3()).collect();
    crate::shapes::subdivided(points, mesh.triangles.clone(), levels, |p| p)
}

/// `mesh` scaled per axis by `scale` (all positive, so the winding keeps its sense), then
/// rotated and moved by `offset`.
pub(super) fn placed(
    mesh: &TriangleMesh,
    scale: DVec3,
    rotation: DQuat,
    offset: DVec3,
) -> TriangleMesh {
    let positions = mesh
        .positions
        .iter()
        .map(|p| (rotation * (p.as_dvec3() * scale) + offset).as_vec3())
        .collect();
    TriangleMesh::new(positions, mesh.triangles.clone())
}

/// All `parts` in one mesh, each keeping its own vertices.
pub(super) fn joined(parts: impl IntoIterator<Item = TriangleMesh>) -> TriangleMesh {
    let mut mesh = TriangleMesh::default();
    for part in parts {
        crate::shapes::append(&mut mesh, &part);
    }
    mesh
}

/// A closed tube of `m` sides around the polyline `centre` (at least two points), of radius
/// `radius(k)` at point k, each end closed by a flat fan to the end point: outward,
/// 2·m·(points - 1) + 2m triangles. Ring frames are carried along by parallel transport, so
/// the tube does not twist.
pub(super) fn tube(centre: &[DVec3], m: u32, radius: impl Fn(usize) -> f64) -> TriangleMesh {
    let frames = transported_frames(centre);
    let last = centre.len() as u32 - 1;
    let mut mesh = grid_surface(m, last, true, |i, k| {
        let a = std::f64::consts::TAU * i as f64 / m as f64;
        let (n, b) = frames[k as usize];
        centre[k as usize] + radius(k as usize) * (a.cos() * n + a.sin() * b)
    });
    let start = mesh.positions.len() as u32;
    mesh.positions.push(centre[0].as_vec3());
    mesh.positions.push(centre[last as usize].as_vec3());
    for i in 0..m {
        let next = (i + 1) % m;
        mesh.triangles.push([start, next, i]);
        mesh.triangles
            .push([start + 1, last * m + i, last * m + next]);
    }
    mesh
}

/// For each point of a polyline, two unit vectors (n, b) across its direction t, with
/// (n, b, t) right-handed, carried from point to point by the rotation between successive
/// directions.
fn transported_frames(centre: &[DVec3]) -> Vec<(DVec3, DVec3)> {
    let count = centre.len();
    let direction = |k: usize| {
        let (a, b) = (k.saturating_sub(1), (k + 1).min(count - 1));
        (centre[b] - centre[a]).normalize()
    };
    let mut t = direction(0);
    let mut n = t.any_orthonormal_vector();
    let mut frames = Vec::with_capacity(count);
    for k in 0..count {
        let next = direction(k);
        n = DQuat::from_rotation_arc(t, next) * n;
        n = (n - next * n.dot(next)).normalize();
        t = next;
        frames.push((n, t.cross(n)));
    }
    frames
}

/// The cube [0, 1]³ without its top face (z = 1), every face split into a 2^levels grid: an
/// open box, one boundary loop, 10·4^levels triangles, normals outward.
pub(super) fn open_box(levels: u32) -> TriangleMesh {
    let mut cube = crate::shapes::unit_cube();
    cube.triangles
        .retain(|t| t.iter().any(|&v| cube.positions[v as usize].z < 1.0));
    subdivide(&cube, levels)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_straight_tube_is_a_closed_outward_prism() {
        let centre: Vec<DVec3> = (0..11).map(|k| DVec3::X * k as f64 / 10.0).collect();
        let mesh = tube(&centre, 8, |_| 0.1);
        let t = voxlod_core::mesh_topology(&mesh);
        assert!(t.is_closed_manifold() && t.is_consistently_oriented());
        assert_eq!((t.triangles, t.genus), (2 * 8 * 10 + 16, Some(0)));
        // An octagon of circumradius 0.1 is 4·sin(π/4)·0.01 in area.
        let volume = 4.0 * (std::f64::consts::PI / 4.0).sin() * 0.01;
        assert!((mesh.signed_volume() / volume - 1.0).abs() < 1e-5);
    }

    #[test]
    fn polar_surfaces_close_into_spheres_or_open_into_discs() {
        let sphere = |i, j| sphere_direction(i, j, 12, 6);
        let closed = voxlod_core::mesh_topology(&polar_surface(12, 6, true, sphere));
        assert!(closed.is_closed_manifold() && closed.is_consistently_oriented());
        assert_eq!((closed.triangles, closed.genus), (2 * 12 * 5, Some(0)));
        // Inscribed in the unit ball (4.19), coarse: a little less, and positive.
        let volume = polar_surface(12, 6, true, sphere).signed_volume();
        assert!(volume > 3.5 && volume < 4.19, "{volume}");
        let open = voxlod_core::mesh_topology(&polar_surface(12, 3, false, sphere));
        assert_eq!((open.triangles, open.boundary_loops), (12 * 5, 1));
    }
}
