//! Asset levels written compressed (`EXT_meshopt_compression` over `KHR_mesh_quantization`):
//! read back by our reader, every corner of every triangle is a corner of the input within the
//! quantization's stated error (`scene::columns`): positions within half a grid step per
//! component, normals and tangents within twice the `i8` rounding's length, texture
//! coordinates in 0..=1 and colours within half a `u16` step, texture coordinates outside
//! 0..=1 exact (kept float); counts exact; the Khronos validator reports nothing; the file is
//! smaller than the plain one. On Spot (`../shared/data/assets/spot`, when present) the sizes
//! are printed.

use std::collections::HashMap;
use std::path::Path;

use voxlod_asset::{collapse, Asset, Material, TextureRef};
use voxlod_core::glam::{Vec2, Vec3, Vec4};
use voxlod_gltf::streams::Quantization;
use voxlod_gltf::{asset_glb, parse_scene, AssetGlbOptions, Compression, Layout};
use voxlod_testkit::assets::textured_sphere;

/// A textured sphere with every attribute the writer stores: normals, tangents, two texture
/// coordinate sets (set 1 tiling, outside 0..=1), colours, and two materials (the second
/// normal-mapped through set 1).
fn rich_asset() -> Asset {
    let mut a = textured_sphere(3);
    let m = &mut a.mesh;
    m.tangents = m
        .normals
        .iter()
        .map(|n| {
            let t = n.cross(Vec3::Y).normalize_or(Vec3::X);
            t.extend(if n.z < 0.0 { -1.0 } else { 1.0 })
        })
        .collect();
    m.uv[1] = m.uv[0].iter().map(|t| *t * 3.0 - Vec2::ONE).collect();
    m.colors = m
        .positions
        .iter()
        .map(|p| Vec4::new(0.5 + 0.5 * p.x, 0.5 + 0.5 * p.y, 0.5 + 0.5 * p.z, 1.0))
        .collect();
    m.material = m
        .triangles
        .iter()
        .map(|t| u32::from(m.positions[t[0] as usize].y > 0.0))
        .collect();
    let mut second = Material {
        name: "normal mapped".into(),
        metallic: 0.0,
        ..Material::default()
    };
    second.normal_texture = Some(TextureRef {
        tex_coord: 1,
        ..a.materials[0].base_color_texture.clone().unwrap()
    });
    a.materials.push(second);
    a
}

/// What a corner of a triangle carries (its material by name: the writer numbers materials
/// in order of use).
#[derive(Clone, Debug)]
struct Corner {
    position: Vec3,
    normal: Vec3,
    tangent: Vec4,
    uv: [Vec2; 2],
    color: Vec4,
    material: String,
}

fn corners(a: &Asset) -> Vec<Corner> {
    let m = &a.mesh;
    m.triangles
        .iter()
        .enumerate()
        .flat_map(|(t, tri)| {
            tri.map(|v| {
                let v = v as usize;
                let uv = |set: usize| m.uv[set].get(v).copied().unwrap_or(Vec2::ZERO);
                Corner {
                    position: m.positions[v],
                    normal: m.normals.get(v).copied().unwrap_or(Vec3::Z),
                    tangent: m.tangents.get(v).copied().unwrap_or(Vec4::X),
                    uv: [uv(0), uv(1)],
                    color: m.colors.get(v).copied().unwrap_or(Vec4::ONE),
                    material: a.materials[m.material[t] as usize].name.clone(),
                }
            })
        })
        .collect()
}

/// The stated error bounds (see the module documentation).
struct Bounds {
    /// Whether the input has normals (else the reader computes them: not compared).
    normals: bool,
    position: f32,
    direction: f32,
    unorm16: f32,
}

impl Bounds {
    fn of(grid: &Quantization, input: &Asset) -> Bounds {
        let extent = extent(input);
        // Half a step, plus the f32 rounding of the reader's scale-and-translate (a few ulps of
        // the coordinates' magnitude).
        let ulps = 4.0 * f32::EPSILON * (extent + grid.offset.abs().max_element());
        Bounds {
            normals: !input.mesh.normals.is_empty(),
            position: 0.5 * grid.scale + ulps,
            direction: 2.0 * 3f32.sqrt() * 0.5 / 127.0,
            unorm16: 0.5 / 65535.0 + 2.0 * f32::EPSILON,
        }
    }

    /// Whether `b` is `a` within the bounds (uv set 1, outside 0..=1, exactly).
    fn holds(&self, a: &Corner, b: &Corner) -> bool {
        let close = |x: &[f32], y: &[f32], e: f32| x.iter().zip(y).all(|(p, q)| (p - q).abs() <= e);
        a.material == b.material
            && close(
                &a.position.to_array(),
                &b.position.to_array(),
                self.position,
            )
            && (!self.normals || (a.normal - b.normal).length() <= self.direction)
            && (a.tangent.truncate() - b.tangent.truncate()).length() <= self.direction
            && a.tangent.w == b.tangent.w
            && close(&a.uv[0].to_array(), &b.uv[0].to_array(), self.unorm16)
            && a.uv[1] == b.uv[1]
            && close(&a.color.to_array(), &b.color.to_array(), self.unorm16)
    }
}

/// Every corner of `back` is a corner of `input` within `bounds`: candidates are the input's
/// corners on the same grid point (the positions' bound is half a step).
fn assert_corners_within(input: &Asset, back: &Asset, grid: &Quantization, bounds: &Bounds) {
    let key = |p: Vec3| grid.quantize(p);
    let mut by_point: HashMap<[u16; 3], Vec<Corner>> = HashMap::new();
    for c in corners(input) {
        by_point.entry(key(c.position)).or_default().push(c);
    }
    let back_corners = corners(back);
    assert_eq!(back_corners.len(), input.mesh.triangles.len() * 3);
    for (k, c) in back_corners.iter().enumerate() {
        // A point read back near a grid point's edge may round to the neighbour: look there too.
        let near: Vec<&Corner> = (0..27)
            .flat_map(|d| {
                let step = |i: usize| (d / 3usize.pow(i as u32)) % 3;
                let q = key(c.position);
                let at = [0, 1, 2].map(|i| (q[i] as i32 + step(i) as i32 - 1).max(0) as u16);
                by_point.get(&at).into_iter().flatten()
            })
            .collect();
        assert!(
            near.iter().any(|a| bounds.holds(a, c)),
            "corner {k} read back ({c:?}) is no input corner within the bounds; nearest: {:?}",
            near.first()
        );
    }
}

/// The vertices the writer stores: each material's primitive has its own copy of the vertices
/// its triangles use.
fn vertices_per_material(a: &Asset) -> usize {
    let m = &a.mesh;
    let mut used = std::collections::HashSet::new();
    for (t, tri) in m.triangles.iter().enumerate() {
        for &v in tri {
            used.insert((m.material[t], v));
        }
    }
    used.len()
}

fn extent(a: &Asset) -> f32 {
    a.mesh
        .positions
        .iter()
        .map(|p| p.abs().max_element())
        .fold(0.0, f32::max)
}

fn grid_of(levels: &[Asset]) -> Quantization {
    voxlod_gltf::positions_grid(levels)
}

#[test]
fn compressed_levels_read_back_within_the_quantization_error() {
    let input = rich_asset();
    let coarse = collapse(&input, 200).unwrap();
    let levels = [input.clone(), coarse.clone()];
    let grid = grid_of(&levels);
    let bounds = Bounds::of(&grid, &input);
    let dir = tempfile::tempdir().unwrap();
    for layout in [Layout::MsftLod, Layout::LodNodes] {
        let options = AssetGlbOptions {
            layout,
            compression: Compression::Meshopt,
            ..Default::default()
        };
        let bytes = asset_glb(&levels, &options).unwrap();
        let back = parse_scene(&bytes, None).unwrap();
        assert!(back.warnings.is_empty(), "{:?}", back.warnings);
        let b = &back.asset;
        assert_eq!(b.mesh.triangles.len(), input.mesh.triangles.len());
        assert_eq!(b.mesh.positions.len(), vertices_per_material(&input));
        assert_eq!(b.images, input.images);
        assert_eq!(b.materials.len(), 2);
        assert_corners_within(&input, b, &grid, &bounds);

        let plain = asset_glb(
            &levels,
            &AssetGlbOptions {
                layout,
                ..Default::default()
            },
        )
        .unwrap();
        assert!(
            bytes.len() < plain.len(),
            "{layout:?}: compressed {} bytes, plain {}",
            bytes.len(),
            plain.len()
        );
        let path = dir.path().join(format!("{layout:?}.glb"));
        std::fs::write(&path, &bytes).unwrap();
        if let Some(v) = voxlod_testkit::gltf_validator::validate_gltf(&path) {
            assert_eq!((v.errors, v.warnings), (0, 0), "{layout:?}: {}", v.report);
        }
    }
    // The coarse level alone (LOD1 is not read: the reader takes LOD0), written on its own.
    let alone = asset_glb(std::slice::from_ref(&coarse), &AssetGlbOptions::meshopt()).unwrap();
    let back = parse_scene(&alone, None).unwrap().asset;
    assert_eq!(back.mesh.triangles.len(), coarse.mesh.triangles.len());
    let grid = grid_of(std::slice::from_ref(&coarse));
    assert_corners_within(&coarse, &back, &grid, &Bounds::of(&grid, &coarse));
}

#[test]
fn texture_coordinates_in_the_unit_square_are_quantized_and_others_kept_float() {
    let input = rich_asset();
    let bytes = asset_glb(std::slice::from_ref(&input), &AssetGlbOptions::meshopt()).unwrap();
    let json = gltf::binary::Glb::from_slice(&bytes)
        .unwrap()
        .json
        .into_owned();
    let root: serde_json::Value = serde_json::from_slice(&json).unwrap();
    let accessor = |name: &str| {
        let k = root["meshes"][0]["primitives"][0]["attributes"][name]
            .as_u64()
            .unwrap();
        root["accessors"][k as usize].clone()
    };
    assert_eq!(accessor("POSITION")["componentType"], 5123);
    assert_eq!(accessor("NORMAL")["componentType"], 5120);
    assert_eq!(accessor("TANGENT")["componentType"], 5120);
    assert_eq!(accessor("TEXCOORD_0")["componentType"], 5123);
    assert_eq!(accessor("TEXCOORD_0")["normalized"], true);
    assert_eq!(accessor("TEXCOORD_1")["componentType"], 5126);
    assert_eq!(accessor("COLOR_0")["componentType"], 5123);
    assert_eq!(
        root["extensionsRequired"],
        serde_json::json!(["EXT_meshopt_compression", "KHR_mesh_quantization"])
    );
    let views = root["bufferViews"].as_array().unwrap();
    let encoded = views
        .iter()
        .filter(|v| v["extensions"]["EXT_meshopt_compression"].is_object())
        .count();
    assert_eq!(encoded, root["accessors"].as_array().unwrap().len());
}

/// Spot written plain and compressed: the sizes, for the benchmarks (skips without the data).
#[test]
fn spot_compressed_is_smaller() {
    let Some(data) = voxlod_testkit::data::shared_data() else {
        voxlod_testkit::skips::skip("no ../shared/data: Spot's compression is not measured");
        return;
    };
    let obj = data.join("assets/spot/spot.obj");
    if !obj.is_file() {
        voxlod_testkit::skips::skip(format!("{} is missing", obj.display()));
        return;
    }
    let spot = voxlod_io::read_asset(Path::new(&obj)).unwrap().asset;
    let levels = [
        spot.clone(),
        collapse(&spot, spot.mesh.triangles.len() / 4).unwrap(),
    ];
    let plain = asset_glb(&levels, &AssetGlbOptions::default()).unwrap();
    let packed = asset_glb(&levels, &AssetGlbOptions::meshopt()).unwrap();
    let image: usize = spot.images.iter().map(|i| i.bytes.len()).sum();
    eprintln!(
        "Spot, 2 levels ({} + {} triangles): plain {} bytes, meshopt {} bytes ({:.3}); \
         without the {image}-byte texture: {} and {} ({:.3})",
        levels[0].mesh.triangles.len(),
        levels[1].mesh.triangles.len(),
        plain.len(),
        packed.len(),
        packed.len() as f64 / plain.len() as f64,
        plain.len() - image,
        packed.len() - image,
        (packed.len() - image) as f64 / (plain.len() - image) as f64
    );
    assert!(packed.len() < plain.len());
    let back = parse_scene(&packed, None).unwrap().asset;
    let grid = grid_of(&levels);
    assert_corners_within(&spot, &back, &grid, &Bounds::of(&grid, &spot));
}
