//! `read_asset`: OBJ with its MTL materials and textures, PLY and OFF with vertex colours,
//! warnings for what is missing, errors for broken files, and the real Spot asset.

use std::collections::BTreeSet;
use std::path::Path;

use voxlod_asset::AlphaMode;
use voxlod_core::glam::{Vec2, Vec3};
use voxlod_io::{read_asset, IoErrorKind};
use voxlod_testkit::data::shared_data_or_skip;

/// A 4×2 PNG with distinct pixels, as the image crate encodes it.
fn write_png(path: &Path) -> Vec<u8> {
    let image = image::RgbImage::from_fn(4, 2, |x, y| image::Rgb([x as u8 * 60, y as u8 * 200, 7]));
    image.save(path).unwrap();
    std::fs::read(path).unwrap()
}

/// Two quads side by side (textured, sharing the edge 2–3 but with other texture coordinates
/// there: a seam) and a triangle above them (red, half transparent).
const OBJ: &str = "\
# two materials, a seam
mtllib looks.mtl
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 2 0 0
v 2 1 0
v 0 2 0
vt 0 0.1
vt 1 0.1
vt 1 0.8
vt 0 0.8
vt 0.5 0.3
vt 0.5 0.6
vt 0.25 0.9
vn 0 0 1
o sheet
usemtl textured
f 1/1/1 2/2/1 3/3/1 4/4/1
f 2/5/1 5/2/1 6/3/1 3/6/1
usemtl red
f 4/4/1 3/3/1 7/7/1
";

const MTL: &str = "\
newmtl red
Kd 1 0 0
Ns 100
d 0.5

newmtl textured
Kd 1 1 1
map_Kd -clamp on tex.png
";

#[test]
fn obj_with_two_materials_a_texture_and_a_seam() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("looks.obj"), OBJ).unwrap();
    std::fs::write(dir.path().join("looks.mtl"), MTL).unwrap();
    let png = write_png(&dir.path().join("tex.png"));

    let read = read_asset(&dir.path().join("looks.obj")).unwrap();
    assert!(read.warnings.is_empty(), "{:?}", read.warnings);
    let asset = &read.asset;
    let mesh = &asset.mesh;
    // Two quads of two triangles and a triangle; the quads' 8 corners are 8 vertices (the
    // seam splits positions 2 and 3), the triangle's 3 are its own (another part).
    assert_eq!(mesh.triangles.len(), 5);
    assert_eq!(mesh.positions.len(), 11);
    assert_eq!((mesh.uv[0].len(), mesh.normals.len()), (11, 11));
    assert!(mesh.colors.is_empty() && mesh.uv[1].is_empty());
    assert!(mesh.normals.iter().all(|&n| n == Vec3::Z));

    // Every (position, texture coordinate) pair of the file's corners, v flipped.
    let p = [
        [0.0, 0.0],
        [1.0, 0.0],
        [1.0, 1.0],
        [0.0, 1.0],
        [2.0, 0.0],
        [2.0, 1.0],
        [0.0, 2.0],
    ];
    let t = [
        [0.0, 0.1],
        [1.0, 0.1],
        [1.0, 0.8],
        [0.0, 0.8],
        [0.5, 0.3],
        [0.5, 0.6],
        [0.25, 0.9],
    ];
    let key = |pos: Vec3, uv: Vec2| [pos.x, pos.y, pos.z, uv.x, uv.y].map(f32::to_bits);
    let corner = |v: usize, vt: usize| {
        let [u, w]: [f32; 2] = t[vt - 1];
        key(
            Vec3::new(p[v - 1][0], p[v - 1][1], 0.0),
            Vec2::new(u, 1.0 - w),
        )
    };
    let expected: BTreeSet<_> = [
        (1, 1),
        (2, 2),
        (3, 3),
        (4, 4),
        (2, 5),
        (5, 2),
        (6, 3),
        (3, 6),
        (4, 4),
        (3, 3),
        (7, 7),
    ]
    .into_iter()
    .map(|(v, vt)| corner(v, vt))
    .collect();
    let found: BTreeSet<_> = (0..mesh.positions.len())
        .map(|i| key(mesh.positions[i], mesh.uv[0][i]))
        .collect();
    assert_eq!(found, expected);
    // The triangle's own corners: (4, 4), (3, 3), (7, 7), in the file's order.
    let last = mesh.triangles[4].map(|i| key(mesh.positions[i as usize], mesh.uv[0][i as usize]));
    assert_eq!(last, [corner(4, 4), corner(3, 3), corner(7, 7)]);

    // Materials in the MTL's order; the quads are textured, the triangle red.
    let names: Vec<&str> = asset.materials.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["red", "textured"]);
    assert_eq!(mesh.material, [1, 1, 1, 1, 0]);
    let red = &asset.materials[0];
    assert_eq!(red.base_color, [1.0, 0.0, 0.0, 0.5]);
    assert_eq!(red.alpha_mode, AlphaMode::Blend);
    assert_eq!(red.metallic, 0.0);
    assert!((red.roughness - (2.0f32 / 102.0).powf(0.25)).abs() < 1e-6);
    assert!(red.base_color_texture.is_none());
    let textured = &asset.materials[1];
    assert_eq!(textured.base_color, [1.0; 4]);
    assert_eq!(textured.alpha_mode, AlphaMode::Opaque);
    let texture = textured.base_color_texture.as_ref().unwrap();
    assert_eq!((texture.image, texture.tex_coord), (0, 0));
    assert_eq!(texture.sampler.wrap_u, voxlod_asset::Wrap::ClampToEdge);

    // The image is the file's bytes.
    assert_eq!(asset.images.len(), 1);
    assert_eq!(asset.images[0].mime, "image/png");
    assert_eq!(asset.images[0].name, "tex.png");
    assert!(*asset.images[0].bytes == png);

    // Parts: the quads, then the triangle, both of object `sheet`.
    let parts: Vec<(&str, u32, u32)> = asset
        .parts
        .iter()
        .map(|p| (p.name.as_str(), p.first_triangle, p.triangle_count))
        .collect();
    assert_eq!(parts, [("sheet", 0, 4), ("sheet", 4, 1)]);
    // The quads cover their area once: 2 units of area, the triangle half a unit.
    let area = |range: std::ops::Range<usize>| -> f32 {
        mesh.triangles[range]
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
                (b - a).cross(c - a).z * 0.5
            })
            .sum()
    };
    assert!((area(0..4) - 2.0).abs() < 1e-6, "{}", area(0..4));
    assert!((area(4..5) - 0.5).abs() < 1e-6);
}

#[test]
fn a_missing_texture_or_library_is_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("looks.obj"), OBJ).unwrap();
    std::fs::write(dir.path().join("looks.mtl"), MTL).unwrap();
    let read = read_asset(&dir.path().join("looks.obj")).unwrap();
    assert_eq!(read.warnings.len(), 1, "{:?}", read.warnings);
    assert!(read.warnings[0].contains("tex.png"), "{:?}", read.warnings);
    assert!(read.asset.images.is_empty());
    assert!(read.asset.materials[1].base_color_texture.is_none());
    assert_eq!(read.asset.mesh.uv[0].len(), 11);

    std::fs::remove_file(dir.path().join("looks.mtl")).unwrap();
    let read = read_asset(&dir.path().join("looks.obj")).unwrap();
    assert!(
        read.warnings[0].contains("looks.mtl"),
        "{:?}",
        read.warnings
    );
    let names: Vec<&str> = read
        .asset
        .materials
        .iter()
        .map(|m| m.name.as_str())
        .collect();
    assert_eq!(names, ["default"]);
    assert_eq!(read.asset.mesh.material, [0; 5]);
}

/// A PLY header for `n` coloured vertices and one face, colours of `kind` (`uchar`, `float`).
fn ply_header(format: &str, kind: &str, n: usize) -> String {
    format!(
        "ply\nformat {format} 1.0\nelement vertex {n}\nproperty float x\nproperty float y\n\
         property float z\nproperty {kind} red\nproperty {kind} green\nproperty {kind} blue\n\
         property {kind} alpha\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
    )
}

/// sRGB 128/255 in linear light.
const MID: f32 = 0.215_860_5;

#[test]
fn ply_vertex_colours_are_linear_in_ascii_and_binary() {
    let dir = tempfile::tempdir().unwrap();
    let colours: [[u8; 4]; 3] = [[255, 0, 0, 255], [0, 128, 255, 128], [10, 255, 0, 0]];
    let expected = [
        [1.0, 0.0, 0.0, 1.0],
        [0.0, MID, 1.0, 128.0 / 255.0],
        [10.0 / 255.0 / 12.92, 1.0, 0.0, 0.0],
    ];
    let positions = [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

    let mut ascii = ply_header("ascii", "uchar", 3);
    for (p, c) in positions.iter().zip(&colours) {
        ascii += &format!(
            "{} {} {} {} {} {} {}\n",
            p[0], p[1], p[2], c[0], c[1], c[2], c[3]
        );
    }
    ascii += "3 0 1 2\n";
    let mut binary = ply_header("binary_little_endian", "uchar", 3).into_bytes();
    for (p, c) in positions.iter().zip(&colours) {
        p.iter().for_each(|v| binary.extend(v.to_le_bytes()));
        binary.extend(c);
    }
    binary.push(3);
    [0i32, 1, 2]
        .iter()
        .for_each(|v| binary.extend(v.to_le_bytes()));
    let mut floats = ply_header("binary_big_endian", "float", 3).into_bytes();
    for (p, c) in positions.iter().zip(&colours) {
        p.iter().for_each(|v| floats.extend(v.to_be_bytes()));
        c.iter()
            .for_each(|&v| floats.extend((v as f32 / 255.0).to_be_bytes()));
    }
    floats.push(3);
    [0i32, 1, 2]
        .iter()
        .for_each(|v| floats.extend(v.to_be_bytes()));

    for (name, bytes) in [
        ("a.ply", ascii.into_bytes()),
        ("b.ply", binary),
        ("f.ply", floats),
    ] {
        let path = dir.path().join(name);
        std::fs::write(&path, bytes).unwrap();
        let read = read_asset(&path).unwrap();
        assert!(read.warnings.is_empty(), "{name}: {:?}", read.warnings);
        let mesh = &read.asset.mesh;
        assert_eq!(
            (mesh.positions.len(), mesh.triangles.len()),
            (3, 1),
            "{name}"
        );
        assert_eq!(mesh.triangles[0], [0, 1, 2]);
        for (found, want) in mesh.colors.iter().zip(&expected) {
            for k in 0..4 {
                assert!(
                    (found[k] - want[k]).abs() < 1e-6,
                    "{name}: {found} != {want:?}"
                );
            }
        }
        assert_eq!(mesh.colors.len(), 3);
        // Exact at the ends of the scale.
        assert_eq!(mesh.colors[0].to_array(), [1.0, 0.0, 0.0, 1.0], "{name}");
        assert_eq!(read.asset.materials[0].name, "default");
        assert_eq!(read.asset.materials[0].metallic, 0.0);
        assert_eq!(mesh.material, [0]);
    }
}

#[test]
fn coff_colours_and_uncoloured_meshes() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("c.off");
    std::fs::write(
        &path,
        "COFF\n3 1 0\n0 0 0 255 128 0 255\n1 0 0 0 0 0 255\n0 1 0 255 255 255 255\n3 0 1 2\n",
    )
    .unwrap();
    let read = read_asset(&path).unwrap();
    let c = read.asset.mesh.colors[0];
    assert_eq!((c.x, c.z, c.w), (1.0, 0.0, 1.0));
    assert!((c.y - MID).abs() < 1e-6);

    let path = dir.path().join("plain.off");
    std::fs::write(&path, "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n").unwrap();
    let read = read_asset(&path).unwrap();
    assert!(read.asset.mesh.colors.is_empty());
    assert_eq!(read.asset.mesh.triangles.len(), 1);
}

#[test]
fn broken_files_are_errors_naming_them() {
    let dir = tempfile::tempdir().unwrap();
    // A binary PLY cut within its vertices.
    let mut binary = ply_header("binary_little_endian", "uchar", 3).into_bytes();
    binary.extend([0u8; 20]);
    let path = dir.path().join("cut.ply");
    std::fs::write(&path, &binary).unwrap();
    let error = read_asset(&path).unwrap_err();
    assert!(
        error.to_string().starts_with(&path.display().to_string()),
        "{error}"
    );
    assert!(
        matches!(error.kind, IoErrorKind::Truncated | IoErrorKind::Malformed),
        "{error}"
    );

    // An OFF file cut within its vertices.
    let path = dir.path().join("cut.off");
    std::fs::write(&path, "COFF\n3 1 0\n0 0 0 255 0 0\n1 0").unwrap();
    let error = read_asset(&path).unwrap_err();
    assert!(
        error.to_string().starts_with(&path.display().to_string()),
        "{error}"
    );

    // OBJ: a face naming a vertex the file does not have, a bad coordinate, no faces.
    for (name, text, needle) in [
        (
            "far.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n",
            "vertex that does not exist",
        ),
        (
            "nan.obj",
            "v 0 0 x\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
            "not a number",
        ),
        ("lines.obj", "v 0 0 0\nv 1 0 0\nl 1 2\n", "no triangles"),
        (
            "uv.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/2 3/3\n",
            "texture coordinate",
        ),
    ] {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        let error = read_asset(&path).unwrap_err();
        assert!(
            error.to_string().starts_with(&path.display().to_string()),
            "{error}"
        );
        assert!(error.message.contains(needle), "{name}: {error}");
    }
}

#[test]
fn spot_reads_with_its_texture() {
    let test = "spot_reads_with_its_texture";
    let Some(path) = shared_data_or_skip("assets/spot/spot.obj", test) else {
        return;
    };
    let read = read_asset(&path).unwrap();
    assert!(read.warnings.is_empty(), "{:?}", read.warnings);
    let asset = &read.asset;
    let mesh = &asset.mesh;
    // 5856 `f` lines, all triangles; 3225 distinct position/texture-coordinate corners.
    assert_eq!(mesh.triangles.len(), 5856);
    assert_eq!(mesh.positions.len(), 3225);
    assert_eq!(mesh.uv[0].len(), 3225);
    assert!(mesh.normals.is_empty(), "the file has no normals");
    assert_eq!(asset.materials.len(), 1);
    assert_eq!(asset.materials[0].name, "spot");
    assert_eq!(mesh.material, vec![0; 5856]);
    let texture = asset.materials[0].base_color_texture.as_ref().unwrap();
    let png = std::fs::read(path.with_file_name("spot_texture.png")).unwrap();
    assert_eq!(asset.images.len(), 1);
    assert!(*asset.images[texture.image].bytes == png);
    assert_eq!(asset.images[0].mime, "image/png");
    // Every corner has texture coordinates in 0..1, but for 4 of the file's that lie just
    // outside (down to u = -0.052, up to v = 1.00065).
    let outside = mesh.uv[0]
        .iter()
        .filter(|t| !(0.0..=1.0).contains(&t.x) || !(0.0..=1.0).contains(&t.y))
        .count();
    assert_eq!(outside, 4);
    assert!(mesh.uv[0]
        .iter()
        .all(|t| (-0.06..=1.01).contains(&t.x) && (-0.01..=1.01).contains(&t.y)));
    asset.validate().unwrap();
}

#[test]
fn libraries_on_one_line_non_utf8_bytes_and_non_convex_faces() {
    let dir = tempfile::tempdir().unwrap();
    // An L of six corners (area 3), not convex: a fan from its first corner would cover
    // the missing square too.
    let obj =
        b"mtllib a.mtl b.mtl\n# caf\xe9\nv 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\n\
                usemtl blue\nf 3 4 5 6 1 2\n";
    std::fs::write(dir.path().join("l.obj"), obj).unwrap();
    std::fs::write(dir.path().join("a.mtl"), "newmtl red\nKd 1 0 0\n").unwrap();
    std::fs::write(dir.path().join("b.mtl"), "newmtl blue\nKd 0 0 1\nTr 0.25\n").unwrap();
    let read = read_asset(&dir.path().join("l.obj")).unwrap();
    assert_eq!(read.warnings.len(), 1, "{:?}", read.warnings);
    assert!(read.warnings[0].contains("UTF-8"), "{:?}", read.warnings);
    let asset = &read.asset;
    let names: Vec<&str> = asset.materials.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["red", "blue"]);
    assert_eq!(asset.materials[1].base_color, [0.0, 0.0, 1.0, 0.75]);
    let mesh = &asset.mesh;
    assert_eq!((mesh.positions.len(), mesh.triangles.len()), (6, 4));
    assert_eq!(mesh.material, [1; 4]);
    assert!(mesh.uv[0].is_empty() && mesh.normals.is_empty());
    let area: f32 = mesh
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            let z = (b - a).cross(c - a).z * 0.5;
            assert!(z > 0.0, "every triangle keeps the face's winding");
            z
        })
        .sum();
    assert!((area - 3.0).abs() < 1e-6, "{area}");
}

/// Every prefix of the OBJ and MTL, and every byte replaced by a few others: an asset or an
/// error naming the file, never a panic.
#[test]
fn mutated_obj_and_mtl_files_never_panic() {
    let dir = tempfile::tempdir().unwrap();
    write_png(&dir.path().join("tex.png"));
    let obj_path = dir.path().join("looks.obj");
    let mtl_path = dir.path().join("looks.mtl");
    let mut outcomes = [0usize; 2];
    let mut check = |obj: &[u8], mtl: &[u8]| {
        std::fs::write(&obj_path, obj).unwrap();
        std::fs::write(&mtl_path, mtl).unwrap();
        match read_asset(&obj_path) {
            Ok(read) => {
                read.asset.validate().unwrap();
                outcomes[0] += 1;
            }
            Err(error) => {
                assert!(error
                    .to_string()
                    .starts_with(&obj_path.display().to_string()));
                outcomes[1] += 1;
            }
        }
    };
    let (obj, mtl) = (OBJ.as_bytes(), MTL.as_bytes());
    for cut in 0..obj.len() {
        check(&obj[..cut], mtl);
    }
    for cut in 0..mtl.len() {
        check(obj, &mtl[..cut]);
    }
    for k in 0..obj.len() {
        for b in [b'-', b'/', 0xFF] {
            let mut mutated = obj.to_vec();
            mutated[k] = b;
            check(&mutated, mtl);
        }
    }
    for k in 0..mtl.len() {
        for b in [b'-', b'x', b' '] {
            let mut mutated = mtl.to_vec();
            mutated[k] = b;
            check(obj, &mutated);
        }
    }
    assert!(outcomes[0] > 0 && outcomes[1] > 0, "{outcomes:?}");
}

/// The shared OBJ meshes read as assets have the geometry reader's triangles, corner by
/// corner (the asset drops unreferenced vertices and splits by corner attributes, so indices
/// differ; positions do not).
#[test]
fn shared_objs_as_assets_have_the_geometry_readers_triangles() {
    let test = "shared_objs_as_assets_have_the_geometry_readers_triangles";
    for name in ["ogre.obj", "stanford-bunny.obj"] {
        let Some(path) = shared_data_or_skip(&format!("meshes/{name}"), test) else {
            return;
        };
        let start = std::time::Instant::now();
        let geometry = voxlod_io::read_mesh(&path).unwrap().mesh;
        let geometry_time = start.elapsed();
        let start = std::time::Instant::now();
        let read = read_asset(&path).unwrap();
        let asset_time = start.elapsed();
        eprintln!(
            "{name}: read_mesh {geometry_time:?}, read_asset {asset_time:?} ({} triangles, {} vertices as an asset, {} in the file)",
            geometry.triangles.len(),
            read.asset.mesh.positions.len(),
            geometry.positions.len()
        );
        let mesh = &read.asset.mesh;
        assert_eq!(mesh.triangles.len(), geometry.triangles.len(), "{name}");
        for (a, g) in mesh.triangles.iter().zip(&geometry.triangles) {
            let a = a.map(|i| mesh.positions[i as usize]);
            let g = g.map(|i| geometry.positions[i as usize]);
            assert_eq!(a, g, "{name}");
        }
    }
}

#[test]
fn ply_texture_coordinates_and_texture_file() {
    let dir = tempfile::tempdir().unwrap();
    let png = write_png(&dir.path().join("scan.png"));
    let header = "ply\nformat ascii 1.0\ncomment TextureFile scan.png\nelement vertex 3\n\
                  property float x\nproperty float y\nproperty float z\nproperty float s\n\
                  property float t\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    let path = dir.path().join("scan.ply");
    std::fs::write(
        &path,
        format!("{header}0 0 0 0 0.25\n1 0 0 1 0.25\n0 1 0 0 1\n3 0 1 2\n"),
    )
    .unwrap();
    let read = read_asset(&path).unwrap();
    assert!(read.warnings.is_empty(), "{:?}", read.warnings);
    let asset = &read.asset;
    assert_eq!(
        asset.mesh.uv[0],
        [
            Vec2::new(0.0, 0.75),
            Vec2::new(1.0, 0.75),
            Vec2::new(0.0, 0.0)
        ]
    );
    let texture = asset.materials[0].base_color_texture.as_ref().unwrap();
    assert!(*asset.images[texture.image].bytes == png);

    // Without its image: a warning, the coordinates kept, no texture.
    std::fs::remove_file(dir.path().join("scan.png")).unwrap();
    let read = read_asset(&path).unwrap();
    assert!(read.warnings[0].contains("scan.png"), "{:?}", read.warnings);
    assert!(read.asset.materials[0].base_color_texture.is_none());
    assert_eq!(read.asset.mesh.uv[0].len(), 3);

    // Per-corner coordinates of faces are not read: the texture is left out, saying why.
    let header = "ply\nformat ascii 1.0\ncomment TextureFile scan.png\nelement vertex 3\n\
                  property float x\nproperty float y\nproperty float z\nelement face 1\n\
                  property list uchar int vertex_indices\nproperty list uchar float texcoord\nend_header\n";
    std::fs::write(
        &path,
        format!("{header}0 0 0\n1 0 0\n0 1 0\n3 0 1 2 6 0 0 1 0 0 1\n"),
    )
    .unwrap();
    let read = read_asset(&path).unwrap();
    assert!(read.warnings[0].contains("texcoord"), "{:?}", read.warnings);
    assert!(read.asset.mesh.uv[0].is_empty());
}
