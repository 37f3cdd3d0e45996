//! The input's own collapse keeps its looks: on a textured grid of two materials whose texture
//! coordinates are its x and y, every level vertex is an input vertex with its attributes, the
//! material border and the texture seam stay, and the count comes near the budget.

use std::collections::HashSet;

use voxlod_asset::{collapse, Asset, AssetMesh, Material};
use voxlod_core::glam::{Vec2, Vec3, Vec4};

/// An n × n grid over [0, 1]², z a gentle bump, texture coordinates (x, y), colour (x, y, 0, 1);
/// the left half material 0, the right half material 1, their vertices split along x = 0.5.
fn grid(n: usize) -> Asset {
    let mut mesh = AssetMesh::default();
    let mut index = std::collections::HashMap::new();
    let mut vertex = |mesh: &mut AssetMesh, i: usize, j: usize, side: u32| {
        *index.entry((i, j, side)).or_insert_with(|| {
            let (x, y) = (i as f32 / n as f32, j as f32 / n as f32);
            let z = 0.1 * (x * 3.0).sin() * (y * 2.0).cos();
            mesh.positions.push(Vec3::new(x, y, z));
            mesh.uv[0].push(Vec2::new(x, y));
            mesh.colors.push(Vec4::new(x, y, 0.0, 1.0));
            (mesh.positions.len() - 1) as u32
        })
    };
    for j in 0..n {
        for i in 0..n {
            let side = u32::from(2 * i >= n);
            let c = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)]
                .map(|(a, b)| vertex(&mut mesh, a, b, side));
            mesh.triangles
                .extend([[c[0], c[1], c[2]], [c[0], c[2], c[3]]]);
            mesh.material.extend([side, side]);
        }
    }
    let material = |name: &str| Material {
        name: name.into(),
        ..Material::default()
    };
    Asset {
        mesh,
        materials: vec![material("left"), material("right")],
        images: Vec::new(),
        parts: Vec::new(),
    }
}

fn key(p: Vec3) -> [u32; 3] {
    p.to_array().map(f32::to_bits)
}

#[test]
fn the_level_is_made_of_the_inputs_vertices_with_their_attributes() {
    let input = grid(40);
    let level = collapse(&input, 200).unwrap();
    level.validate().unwrap();
    let t = level.mesh.triangles.len();
    assert!((40..=220).contains(&t), "{t} triangles for a budget of 200");
    let inputs: HashSet<([u32; 3], [u32; 2], [u32; 4])> = (0..input.mesh.positions.len())
        .map(|v| {
            let m = &input.mesh;
            (
                key(m.positions[v]),
                m.uv[0][v].to_array().map(f32::to_bits),
                m.colors[v].to_array().map(f32::to_bits),
            )
        })
        .collect();
    let m = &level.mesh;
    for v in 0..m.positions.len() {
        let attributes = (
            key(m.positions[v]),
            m.uv[0][v].to_array().map(f32::to_bits),
            m.colors[v].to_array().map(f32::to_bits),
        );
        assert!(
            inputs.contains(&attributes),
            "vertex {v} is not an input vertex"
        );
    }
}

#[test]
fn the_material_border_stays_where_it_was() {
    let level = collapse(&grid(40), 200).unwrap();
    let m = &level.mesh;
    assert_eq!(m.material.len(), m.triangles.len());
    for (t, corners) in m.triangles.iter().enumerate() {
        let xs = corners.map(|v| m.positions[v as usize].x);
        let side = m.material[t];
        // Left triangles lie in x ≤ 0.5 and right ones in x ≥ 0.5: no triangle crosses over.
        assert!(
            xs.iter()
                .all(|&x| if side == 0 { x <= 0.5 } else { x >= 0.5 }),
            "triangle {t} of material {side} reaches x = {xs:?}"
        );
    }
    // The border's line x = 0.5 is still covered from both sides: its two ends are kept.
    for side in 0..2u32 {
        let on_border: Vec<f32> = m
            .triangles
            .iter()
            .zip(&m.material)
            .filter(|(_, &k)| k == side)
            .flat_map(|(c, _)| c.iter().map(|&v| m.positions[v as usize]))
            .filter(|p| p.x == 0.5)
            .map(|p| p.y)
            .collect();
        let lo = on_border.iter().cloned().fold(f32::MAX, f32::min);
        let hi = on_border.iter().cloned().fold(f32::MIN, f32::max);
        assert_eq!((lo, hi), (0.0, 1.0), "material {side}'s border");
    }
}

#[test]
fn a_vertex_two_materials_share_becomes_a_seam() {
    // The same grid welded along the border: each border vertex used by both materials.
    let mut input = grid(20);
    let m = &mut input.mesh;
    let mut first: std::collections::HashMap<[u32; 3], u32> = Default::default();
    let remap: Vec<u32> = (0..m.positions.len())
        .map(|v| *first.entry(key(m.positions[v])).or_insert(v as u32))
        .collect();
    for t in &mut m.triangles {
        *t = t.map(|v| remap[v as usize]);
    }
    let level = collapse(&input, 60).unwrap();
    let l = &level.mesh;
    for (t, corners) in l.triangles.iter().enumerate() {
        let side = l.material[t];
        let xs = corners.map(|v| l.positions[v as usize].x);
        assert!(
            xs.iter()
                .all(|&x| if side == 0 { x <= 0.5 } else { x >= 0.5 }),
            "{xs:?}"
        );
    }
}

#[test]
fn an_invalid_asset_is_refused() {
    let mut input = grid(4);
    input.mesh.uv[0].pop();
    let e = collapse(&input, 8).unwrap_err().to_string();
    assert!(e.contains("texture coordinates 0"), "{e}");
}
