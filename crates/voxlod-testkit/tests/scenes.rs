//! The generated scenes are what their documentation says: valid assets, the parts and
//! materials claimed (counted by name), textures that decode, every closed piece welding into
//! a closed, outward-oriented surface, leaf cards open and alpha-masked, instances that are
//! copies of one mesh under similarities, and a building whose windows open onto a hollow
//! interior.

use glam::Vec3;
use voxlod_asset::{decode, AlphaMode, Asset};
use voxlod_core::components::submesh;
use voxlod_core::weld::weld_vertices;
use voxlod_core::{mesh_topology, TriangleMesh};
use voxlod_testkit::scenes;

/// What a scene promises: parts, materials, and its triangles within a range.
struct Claim {
    name: &'static str,
    parts: usize,
    materials: usize,
    triangles: std::ops::Range<usize>,
}

fn claims() -> Vec<(Claim, Asset)> {
    let claim = |name, parts, materials, triangles| Claim {
        name,
        parts,
        materials,
        triangles,
    };
    vec![
        (claim("room", 73, 8, 10_000..100_000), scenes::room()),
        (claim("machine", 213, 6, 10_000..100_000), scenes::machine()),
        (claim("tree", 487, 2, 5_000..100_000), scenes::tree()),
        (
            claim("building", 113, 5, 5_000..100_000),
            scenes::building(),
        ),
        (claim("props", 76, 4, 10_000..100_000), scenes::props()),
    ]
}

/// The part's triangles welded by position: its own surface.
fn part_surface(asset: &Asset, part: usize) -> TriangleMesh {
    let p = &asset.parts[part];
    let range = p.first_triangle..p.first_triangle + p.triangle_count;
    let mut mesh = submesh(&asset.mesh.geometry(), &range.collect::<Vec<_>>());
    weld_vertices(&mut mesh);
    mesh
}

#[test]
fn every_scene_is_valid_with_its_parts_materials_and_textures() {
    for (claim, asset) in claims() {
        let name = claim.name;
        asset.validate().unwrap_or_else(|e| panic!("{name}: {e}"));
        let t = asset.mesh.triangles.len();
        assert!(claim.triangles.contains(&t), "{name}: {t} triangles");
        assert_eq!(asset.parts.len(), claim.parts, "{name}: parts");
        assert_eq!(asset.materials.len(), claim.materials, "{name}: materials");
        // The parts tile the triangles in order, each of one material.
        let mut next = 0;
        for part in &asset.parts {
            assert_eq!(part.first_triangle, next, "{name}: {}", part.name);
            next += part.triangle_count;
            let range = part.first_triangle as usize..next as usize;
            let first = asset.mesh.material[range.start];
            assert!(
                asset.mesh.material[range].iter().all(|&m| m == first),
                "{name}: {} has two materials",
                part.name
            );
        }
        assert_eq!(next as usize, t, "{name}: the parts cover the mesh");
        for k in 0..asset.materials.len() as u32 {
            assert!(
                asset.mesh.material.contains(&k),
                "{name}: material {k} unused"
            );
        }
        assert!(!asset.images.is_empty());
        for image in &asset.images {
            let texels = decode(image).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!((texels.width, texels.height), (256, 256), "{}", image.name);
            // A pattern, not a flat colour: a misplaced texel must be able to show.
            let first = texels.rgba[0];
            assert!(
                texels
                    .rgba
                    .iter()
                    .any(|&c| (c - first).abs().max_element() > 0.05),
                "{name}: {} is flat",
                image.name
            );
        }
        assert_eq!(asset.mesh.normals.len(), asset.mesh.positions.len());
        assert!(asset
            .mesh
            .normals
            .iter()
            .all(|n| (n.length() - 1.0).abs() < 1e-4));
    }
}

#[test]
fn closed_pieces_weld_closed_and_outward_and_leaf_cards_are_open() {
    for (claim, asset) in claims() {
        for (k, part) in asset.parts.iter().enumerate() {
            let surface = part_surface(&asset, k);
            let topology = mesh_topology(&surface);
            let what = format!("{}: {}", claim.name, part.name);
            if part.name.starts_with("leaf card") {
                assert_eq!(topology.boundary_loops, 1, "{what}");
                assert_eq!(topology.genus, Some(0), "{what}");
                continue;
            }
            assert!(topology.is_closed_manifold(), "{what}: {topology:?}");
            assert!(topology.is_consistently_oriented(), "{what}");
            assert_eq!(topology.components, 1, "{what}");
            assert_eq!(topology.genus, Some(0), "{what}");
            assert!(surface.signed_volume() > 0.0, "{what}: inside out");
        }
    }
}

#[test]
fn a_box_piece_encloses_its_volume() {
    let piece = scenes::pieces::block(Vec3::new(0.5, 1.0, 1.5), 3.0, 1.0);
    let mut mesh = TriangleMesh::new(piece.positions, piece.triangles);
    weld_vertices(&mut mesh);
    // 3 × 6 × 9 cells on the axes: faces 2·(18 + 54 + 27) quads, two triangles each.
    assert_eq!(mesh.triangles.len(), 2 * 2 * (18 + 54 + 27));
    assert!((mesh.signed_volume() - 6.0).abs() < 1e-5);
    let frustum = scenes::pieces::frustum([1.0, 0.5, 2.0], 256, 1.0);
    let mut mesh = TriangleMesh::new(frustum.positions, frustum.triangles);
    weld_vertices(&mut mesh);
    // π h (R² + R r + r²) / 3, within the 256-gon's shortfall.
    let exact = std::f64::consts::PI * 2.0 * (1.0 + 0.5 + 0.25) / 3.0;
    assert!((mesh.signed_volume() / exact - 1.0).abs() < 1e-3);
}

#[test]
fn leaf_cards_are_masked_double_sided_and_cut_out() {
    let tree = scenes::tree();
    let leaf = tree
        .materials
        .iter()
        .find(|m| m.name == "leaves")
        .expect("a leaf material");
    assert_eq!(leaf.alpha_mode, AlphaMode::Mask);
    assert!(leaf.double_sided);
    let image = &tree.images[leaf.base_color_texture.as_ref().unwrap().image];
    let texels = decode(image).unwrap();
    let clear = texels.rgba.iter().filter(|c| c.w == 0.0).count();
    let solid = texels.rgba.iter().filter(|c| c.w == 1.0).count();
    assert_eq!(clear + solid, texels.rgba.len(), "alpha is 0 or 1");
    assert!(clear > texels.rgba.len() / 5 && solid > texels.rgba.len() / 5);
}

#[test]
fn props_are_instances_of_three_meshes() {
    let props = scenes::props();
    for (kind, count) in [("crate ", 33), ("barrel ", 21), ("cone ", 21)] {
        let instances: Vec<usize> = (0..props.parts.len())
            .filter(|&k| props.parts[k].name.starts_with(kind))
            .collect();
        assert_eq!(instances.len(), count, "{kind}");
        let first = part_surface(&props, instances[0]);
        for &k in &instances[1..] {
            let other = part_surface(&props, k);
            assert_eq!(other.triangles, first.triangles, "{kind}: same mesh");
            // A similarity keeps every distance's ratio to the first edge's.
            let d = |m: &TriangleMesh, a: usize, b: usize| m.positions[a].distance(m.positions[b]);
            let scale = d(&other, 0, 1) / d(&first, 0, 1);
            let n = first.positions.len();
            for (a, b) in [(0, n / 2), (1, n - 1), (n / 3, 2 * n / 3)] {
                let ratio = d(&other, a, b) / d(&first, a, b);
                assert!(
                    (ratio / scale - 1.0).abs() < 1e-4,
                    "{kind}: not a similarity"
                );
            }
        }
    }
}

#[test]
fn the_building_is_hollow_behind_its_windows() {
    let building = scenes::building();
    let boxes: Vec<(String, Vec3, Vec3)> = (0..building.parts.len())
        .map(|k| {
            let b = part_surface(&building, k).bounds();
            let (lo, hi) = (b.min.as_vec3(), b.max.as_vec3());
            (building.parts[k].name.clone(), lo, hi)
        })
        .collect();
    let inside = |p: Vec3| {
        boxes
            .iter()
            .find(|(_, lo, hi)| p.cmpge(*lo).all() && p.cmple(*hi).all())
    };
    // The front wall's windows are centred at x = −8.5/2 + 8.5 (k + 0.5) / 3; a line from
    // outside through each, into the room, meets no part until the room's far side.
    for floor in 0..3 {
        for k in 0..3 {
            let x = -4.25 + 8.5 * (k as f32 + 0.5) / 3.0;
            let y = 3.0 * floor as f32 + 1.7;
            for step in 0..=60 {
                let p = Vec3::new(x, y, 4.0 - 0.05 * step as f32);
                assert!(inside(p).is_none(), "{p} is in {:?}", inside(p).unwrap().0);
            }
        }
    }
    // Between the walls and below the roof, the middle of each storey is empty.
    for floor in 0..3 {
        let p = Vec3::new(-1.2, 3.0 * floor as f32 + 1.5, 0.5);
        assert!(inside(p).is_none(), "{p}");
    }
}

#[test]
fn scene_1m_is_a_valid_million_triangle_machine() {
    let big = scenes::scene_1m();
    big.validate().unwrap();
    let t = big.mesh.triangles.len();
    assert!((900_000..1_200_000).contains(&t), "{t} triangles");
    assert_eq!(big.parts.len(), 213);
    assert_eq!(big.materials.len(), 6);
}
