//! Assets side by side as one scene ([`join`]): a folder of props, each file an asset, becomes
//! the one asset a scene proxy samples and bakes from.
//!
//! Each asset keeps its triangles, materials, images and parts; only the indices move. An
//! attribute that some assets have and others lack is given to all, with a value that changes
//! nothing where it is filled in: shading normals from the geometry (area-weighted), texture
//! coordinates (0, 0) (the filled assets' materials read no texture through them), white vertex
//! colours (they multiply), and tangents along +x (no normal map of the filled assets reads
//! them). An asset without materials gets glTF's default material for its triangles, so that
//! every triangle of the join has one. Cost: O(V + F) over all assets, one copy.

use voxlod_core::glam::{Vec2, Vec3, Vec4};

use crate::asset::{Asset, AssetMesh, Material, Part};
use crate::error::AssetError;

/// The `assets`, each with its name (a file's stem), as one asset in the order given: positions
/// as they are (a common frame is the caller's), each part named `NAME/part`, or `NAME` for an
/// asset of one part. Refuses an empty list and joins that would pass 2³² vertices or triangles.
pub fn join(assets: Vec<(String, Asset)>) -> Result<Asset, AssetError> {
    if assets.is_empty() {
        return Err(AssetError::Invalid("no assets to join".into()));
    }
    let vertices: usize = assets.iter().map(|(_, a)| a.mesh.positions.len()).sum();
    let triangles: usize = assets.iter().map(|(_, a)| a.mesh.triangles.len()).sum();
    if vertices > u32::MAX as usize || triangles > u32::MAX as usize {
        return Err(AssetError::Invalid(format!(
            "{vertices} vertices and {triangles} triangles in all: more than 32-bit indices hold"
        )));
    }
    let has = Present::of(&assets);
    let mut out = Asset {
        mesh: AssetMesh::default(),
        materials: Vec::new(),
        images: Vec::new(),
        parts: Vec::new(),
    };
    for (name, asset) in assets {
        append(&mut out, &name, asset, &has);
    }
    Ok(out)
}

/// Which attributes any of the assets has (each is then given to all).
struct Present {
    normals: bool,
    tangents: bool,
    uv: [bool; 2],
    colors: bool,
}

impl Present {
    fn of(assets: &[(String, Asset)]) -> Present {
        let any = |f: &dyn Fn(&AssetMesh) -> bool| assets.iter().any(|(_, a)| f(&a.mesh));
        Present {
            normals: any(&|m| !m.normals.is_empty()),
            tangents: any(&|m| !m.tangents.is_empty()),
            uv: [any(&|m| !m.uv[0].is_empty()), any(&|m| !m.uv[1].is_empty())],
            colors: any(&|m| !m.colors.is_empty()),
        }
    }
}

/// `asset` appended to `out`, its indices moved past `out`'s and its missing attributes filled
/// where another asset has them (module docs).
fn append(out: &mut Asset, name: &str, asset: Asset, has: &Present) {
    let Asset {
        mesh,
        mut materials,
        images,
        parts,
    } = asset;
    let (first_vertex, first_triangle) = (
        out.mesh.positions.len() as u32,
        out.mesh.triangles.len() as u32,
    );
    let (first_material, first_image) = (out.materials.len() as u32, out.images.len());
    let n = mesh.positions.len();
    let normals = match (has.normals, mesh.normals.is_empty()) {
        (true, true) => {
            let mut geometry = mesh.geometry();
            geometry.compute_vertex_normals();
            geometry.normals
        }
        _ => mesh.normals,
    };
    fill(&mut out.mesh.normals, normals, n, has.normals, Vec3::Z);
    fill(
        &mut out.mesh.tangents,
        mesh.tangents,
        n,
        has.tangents,
        Vec4::new(1.0, 0.0, 0.0, 1.0),
    );
    let [uv0, uv1] = mesh.uv;
    fill(&mut out.mesh.uv[0], uv0, n, has.uv[0], Vec2::ZERO);
    fill(&mut out.mesh.uv[1], uv1, n, has.uv[1], Vec2::ZERO);
    fill(&mut out.mesh.colors, mesh.colors, n, has.colors, Vec4::ONE);
    out.mesh.positions.extend(mesh.positions);
    (out.mesh.triangles).extend(mesh.triangles.iter().map(|t| t.map(|v| v + first_vertex)));
    if materials.is_empty() {
        materials.push(Material::default());
    }
    match mesh.material.is_empty() {
        true => {
            (out.mesh.material).extend(std::iter::repeat_n(first_material, mesh.triangles.len()))
        }
        false => (out.mesh.material).extend(mesh.material.iter().map(|m| m + first_material)),
    }
    for m in &mut materials {
        let slots = [
            &mut m.base_color_texture,
            &mut m.metallic_roughness_texture,
            &mut m.normal_texture,
            &mut m.occlusion_texture,
            &mut m.emissive_texture,
        ];
        for slot in slots.into_iter().flatten() {
            slot.image += first_image;
        }
    }
    out.materials.extend(materials);
    out.images.extend(images);
    let single = parts.len() <= 1;
    out.parts.extend(parts.into_iter().map(|p| Part {
        name: match single {
            true => name.to_string(),
            false => format!("{name}/{}", p.name),
        },
        first_triangle: p.first_triangle + first_triangle,
        triangle_count: p.triangle_count,
    }));
}

/// Appends `values` (one per vertex, or none) to `to` where any asset has the attribute, with
/// `filler` for each of the `n` vertices where this one has none.
fn fill<T: Copy>(to: &mut Vec<T>, values: Vec<T>, n: usize, any: bool, filler: T) {
    match (any, values.is_empty()) {
        (false, _) => {}
        (true, true) => to.extend(std::iter::repeat_n(filler, n)),
        (true, false) => to.extend(values),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::asset::{Image, Sampler, TextureRef};
    use std::sync::Arc;

    /// A unit right triangle at `x`, of one part named `part`.
    fn triangle(x: f32, part: &str) -> Asset {
        let mesh = AssetMesh {
            positions: vec![
                Vec3::new(x, 0.0, 0.0),
                Vec3::new(x + 1.0, 0.0, 0.0),
                Vec3::new(x, 1.0, 0.0),
            ],
            triangles: vec![[0, 1, 2]],
            ..AssetMesh::default()
        };
        Asset {
            mesh,
            materials: Vec::new(),
            images: Vec::new(),
            parts: vec![Part {
                name: part.into(),
                first_triangle: 0,
                triangle_count: 1,
            }],
        }
    }

    #[test]
    fn assets_joined_keep_their_triangles_materials_images_and_parts() {
        let plain = triangle(0.0, "a");
        let mut textured = triangle(5.0, "b");
        textured.mesh.uv[0] = vec![Vec2::new(0.5, 0.5); 3];
        textured.mesh.normals = vec![Vec3::Z; 3];
        let image = |name: &str| Image {
            name: name.into(),
            mime: "image/png".into(),
            bytes: Arc::new(Vec::new()),
        };
        textured.images = vec![image("unused"), image("used")];
        textured.materials = vec![Material {
            base_color_texture: Some(TextureRef {
                image: 1,
                tex_coord: 0,
                transform: None,
                sampler: Sampler::default(),
            }),
            ..Material::default()
        }];
        textured.mesh.material = vec![0];
        textured.parts.push(Part {
            name: "empty".into(),
            first_triangle: 1,
            triangle_count: 0,
        });

        let joined = join(vec![("plain".into(), plain), ("textured".into(), textured)]).unwrap();
        joined.validate().unwrap();
        let m = &joined.mesh;
        assert_eq!(m.triangles, vec![[0, 1, 2], [3, 4, 5]]);
        assert_eq!(m.positions[3], Vec3::new(5.0, 0.0, 0.0));
        // The plain triangle gets the default material, the textured one its own, which reads
        // its second image, now the join's second.
        assert_eq!(m.material, vec![0, 1]);
        assert_eq!(joined.materials[0], Material::default());
        let texture = joined.materials[1].base_color_texture.as_ref().unwrap();
        assert_eq!(joined.images[texture.image].name, "used");
        // Attributes filled where the other asset had them: normals from the geometry.
        assert_eq!(m.uv[0][..3], [Vec2::ZERO; 3]);
        assert_eq!(m.uv[0][3], Vec2::new(0.5, 0.5));
        assert!(m.normals[..3]
            .iter()
            .all(|n| (*n - Vec3::Z).length() < 1e-6));
        assert!(m.colors.is_empty() && m.tangents.is_empty() && m.uv[1].is_empty());
        let names: Vec<&str> = joined.parts.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(names, ["plain", "textured/b", "textured/empty"]);
        assert_eq!(joined.parts[1].first_triangle, 1);
    }

    #[test]
    fn nothing_to_join_is_refused() {
        assert!(matches!(join(Vec::new()), Err(AssetError::Invalid(_))));
    }
}
