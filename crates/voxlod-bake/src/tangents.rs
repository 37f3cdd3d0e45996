//! MikkTSpace tangents (Mikkelsen 2008) for a mesh with texture coordinates, through the
//! `bevy_mikktspace` crate (the reference C code's results, in safe Rust), in glTF's
//! convention: the tangent points along +u, and the bitangent `w · (normal × tangent)` points
//! up the image (−v, since glTF's v points down), so that a normal map's green channel means
//! "up". The coordinates are given to MikkTSpace as (u, 1 − v) for that.
//!
//! Cost: MikkTSpace's, O(n log n) for n corners.

use bevy_mikktspace::{generate_tangents, Geometry, TangentSpace};
use voxlod_core::glam::{Vec2, Vec3, Vec4};

/// Per-vertex tangents (xyz unit, w ±1) of the indexed mesh; a vertex with corners that
/// disagree takes its last corner's, one that no triangle names or MikkTSpace left out gets
/// a unit vector perpendicular to its normal.
pub fn mikktspace(
    positions: &[Vec3],
    normals: &[Vec3],
    uv: &[Vec2],
    triangles: &[[u32; 3]],
) -> Vec<Vec4> {
    let mut mesh = Mikk {
        positions,
        normals,
        uv,
        triangles,
        tangents: normals.iter().map(|&n| fallback(n)).collect(),
    };
    // The error type has no values: the generation cannot fail.
    let _ = generate_tangents(&mut mesh);
    mesh.tangents
}

/// A unit tangent perpendicular to `n`, for a vertex MikkTSpace gave none.
fn fallback(n: Vec3) -> Vec4 {
    let t = n
        .try_normalize()
        .map_or(Vec3::X, |n| n.any_orthonormal_vector());
    t.extend(1.0)
}

struct Mikk<'a> {
    positions: &'a [Vec3],
    normals: &'a [Vec3],
    uv: &'a [Vec2],
    triangles: &'a [[u32; 3]],
    tangents: Vec<Vec4>,
}

impl Mikk<'_> {
    fn vertex(&self, face: usize, vert: usize) -> usize {
        self.triangles[face][vert] as usize
    }
}

impl Geometry for Mikk<'_> {
    fn num_faces(&self) -> usize {
        self.triangles.len()
    }

    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }

    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.positions[self.vertex(face, vert)].to_array()
    }

    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        self.normals[self.vertex(face, vert)].to_array()
    }

    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        let uv = self.uv[self.vertex(face, vert)];
        [uv.x, 1.0 - uv.y]
    }

    fn set_tangent(&mut self, tangent: Option<TangentSpace>, face: usize, vert: usize) {
        if let Some(t) = tangent {
            let v = self.vertex(face, vert);
            self.tangents[v] = Vec4::from(t.tangent_encoded());
        }
    }
}
