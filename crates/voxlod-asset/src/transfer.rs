//! Looks for a surface that shares no vertex with the input (a voxel level of He et al. 1995,
//! a clustering level of Rossignac–Borrel or Low–Tan): each of its vertices takes the look of
//! the nearest point of the input, found through the BVH of `voxlod-metrics`, interpolated
//! barycentrically on the triangle that holds it. The vertex colour is what the input shows
//! there: its vertex colour × its material's base colour factor × its base colour texture (at
//! the interpolated texture coordinates), so that a level of a textured asset is never grey;
//! the normal is the input's interpolated shading normal where it faces the level's own side
//! (the level's otherwise). Each triangle takes the material of the input triangle nearest its
//! centre, without textures (the level has no texture coordinates of the input's; baking new
//! textures is another stage), its factors otherwise kept.
//!
//! Beyond the papers: the voxel paper's levels carry positions only.
//!
//! Cost: O((V + T) log N) closest-point queries on all cores for V vertices and T triangles of
//! the level and N input triangles, plus decoding each base colour texture once.

use rayon::prelude::*;
use voxlod_core::glam::{DVec3, Vec2, Vec3, Vec4};
use voxlod_core::TriangleMesh;
use voxlod_metrics::MeshDistance;

use crate::texture::{decode_base_colours, Texels};
use crate::{Asset, AssetError, AssetMesh, Material};

/// A level with the looks it took from the input, and what could not be taken.
#[derive(Clone, Debug, PartialEq)]
pub struct Transferred {
    /// The level as an asset: its positions and triangles, colours and normals per vertex, and
    /// a material per triangle (the input's, untextured) where the input has materials.
    pub asset: Asset,
    /// Images that could not be decoded (their material's factor stood in).
    pub warnings: Vec<String>,
}

/// The level with colours, normals and materials taken from the nearest points of `input`.
/// Refuses an invalid input or an empty level.
pub fn transfer(input: &Asset, level: &TriangleMesh) -> Result<Transferred, AssetError> {
    input.validate()?;
    if level.triangles.is_empty() {
        return Err(AssetError::Invalid(
            "the level has no triangles to take looks onto".into(),
        ));
    }
    let search = MeshDistance::new(&input.mesh.geometry())
        .map_err(|e| AssetError::Invalid(format!("the input cannot be searched: {e}")))?;
    let (textures, warnings) = decode_base_colours(input)?;
    let own_normals = level_normals(level);
    let looks: Vec<(Vec4, Vec3)> = level
        .positions
        .par_iter()
        .zip(&own_normals)
        .map(|(&p, &own)| {
            let near = search.closest(p.as_dvec3());
            let at = Barycentric::on(&input.mesh, near.triangle, near.point);
            (
                colour_at(input, &textures, &at),
                normal_at(&input.mesh, &at, own),
            )
        })
        .collect();
    let material = nearest_materials(input, level, &search);
    let (materials, material) = untextured_materials(&input.materials, material);
    let asset = Asset {
        mesh: AssetMesh {
            positions: level.positions.clone(),
            triangles: level.triangles.clone(),
            normals: looks.iter().map(|l| l.1).collect(),
            colors: looks.iter().map(|l| l.0).collect(),
            material,
            ..AssetMesh::default()
        },
        materials,
        images: Vec::new(),
        parts: Vec::new(),
    };
    Ok(Transferred { asset, warnings })
}

/// A point on an input triangle by its barycentric weights.
pub(crate) struct Barycentric {
    pub(crate) triangle: usize,
    pub(crate) weights: [f32; 3],
}

impl Barycentric {
    /// The weights of `point` (on or near triangle `t`), clamped to the triangle; a degenerate
    /// triangle gives its first corner.
    pub(crate) fn on(mesh: &AssetMesh, t: usize, point: DVec3) -> Barycentric {
        let [a, b, c] = mesh.triangles[t].map(|v| mesh.positions[v as usize].as_dvec3());
        let (e0, e1, ep) = (b - a, c - a, point - a);
        let (d00, d01, d11) = (e0.dot(e0), e0.dot(e1), e1.dot(e1));
        let (d20, d21) = (ep.dot(e0), ep.dot(e1));
        let det = d00 * d11 - d01 * d01;
        let weights = if det.abs() <= f64::EPSILON * d00 * d11 || !det.is_finite() {
            [1.0, 0.0, 0.0]
        } else {
            let v = ((d11 * d20 - d01 * d21) / det).clamp(0.0, 1.0);
            let w = ((d00 * d21 - d01 * d20) / det).clamp(0.0, 1.0 - v);
            [(1.0 - v - w) as f32, v as f32, w as f32]
        };
        Barycentric {
            triangle: t,
            weights,
        }
    }

    /// An attribute interpolated at the point.
    fn mix<T>(&self, mesh: &AssetMesh, values: &[T]) -> T
    where
        T: Copy + std::ops::Mul<f32, Output = T> + std::ops::Add<Output = T>,
    {
        let [i, j, k] = mesh.triangles[self.triangle].map(|v| values[v as usize]);
        i * self.weights[0] + j * self.weights[1] + k * self.weights[2]
    }
}

/// What the input shows at a point: vertex colour × base colour factor × base colour texture.
pub(crate) fn colour_at(input: &Asset, textures: &[Option<Texels>], at: &Barycentric) -> Vec4 {
    let mesh = &input.mesh;
    let mut colour = if mesh.colors.is_empty() {
        Vec4::ONE
    } else {
        at.mix(mesh, &mesh.colors)
    };
    if let Some(&m) = mesh.material.get(at.triangle) {
        let material = &input.materials[m as usize];
        colour *= Vec4::from(material.base_color);
        if let (Some(slot), Some(texels)) = (&material.base_color_texture, &textures[m as usize]) {
            let set = slot
                .transform
                .and_then(|t| t.tex_coord)
                .unwrap_or(slot.tex_coord);
            let uv: Vec2 = at.mix(mesh, &mesh.uv[set as usize]);
            colour *= texels.sample(slot, uv);
        }
    }
    colour
}

/// The input's shading normal at a point where it faces the level's side, else the level's.
fn normal_at(mesh: &AssetMesh, at: &Barycentric, own: Vec3) -> Vec3 {
    if mesh.normals.is_empty() {
        return own;
    }
    let n = at.mix(mesh, &mesh.normals).normalize_or_zero();
    if n.dot(own) > 0.0 || own == Vec3::ZERO {
        n
    } else {
        own
    }
}

/// The level's own vertex normals: as stored, or area-weighted from its triangles.
fn level_normals(level: &TriangleMesh) -> Vec<Vec3> {
    if level.normals.len() == level.positions.len() {
        return level.normals.clone();
    }
    let mut normals = vec![Vec3::ZERO; level.positions.len()];
    for t in &level.triangles {
        let [a, b, c] = t.map(|v| level.positions[v as usize]);
        let n = (b - a).cross(c - a);
        for &v in t {
            normals[v as usize] += n;
        }
    }
    normals.iter().map(|n| n.normalize_or_zero()).collect()
}

/// The input material of the input triangle nearest each level triangle's centre (none when
/// the input has no materials).
fn nearest_materials(input: &Asset, level: &TriangleMesh, search: &MeshDistance) -> Vec<u32> {
    if input.mesh.material.is_empty() {
        return Vec::new();
    }
    level
        .triangles
        .par_iter()
        .map(|t| {
            let centre = t.iter().map(|&v| level.positions[v as usize]).sum::<Vec3>() / 3.0;
            input.mesh.material[search.closest(centre.as_dvec3()).triangle]
        })
        .collect()
}

/// The materials the level uses, untextured, and its triangles' indices into them.
fn untextured_materials(input: &[Material], material: Vec<u32>) -> (Vec<Material>, Vec<u32>) {
    let mut new_index = vec![u32::MAX; input.len()];
    let mut used = Vec::new();
    let material = material
        .into_iter()
        .map(|m| {
            if new_index[m as usize] == u32::MAX {
                new_index[m as usize] = used.len() as u32;
                used.push(input[m as usize].untextured());
            }
            new_index[m as usize]
        })
        .collect();
    (used, material)
}
