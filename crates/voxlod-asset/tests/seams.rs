//! Point seams on generated shapes: a latitude-longitude sphere's poles and a cone's apex (one
//! position held by a vertex per segment, each with its own texture coordinate) are found and
//! nothing else is (a cylinder with capped ends, a box with a cube map's seams, a torus with
//! its two seams); the collapse of a sphere to a small budget lets its pole fans go, keeps
//! every vertex an input vertex with its attributes and each triangle's material, gives each
//! pole corner the texture coordinate between its triangle's others, and reaches counts that
//! the collapse keeping every vertex apart cannot.

use std::collections::{HashMap, HashSet};

use std::f32::consts::TAU;

use voxlod_asset::{
    collapse, collapse_with, point_seams, Asset, AssetMesh, CollapseOptions, Material, SeamOptions,
};
use voxlod_core::glam::{Vec2, Vec3};

/// A latitude-longitude sphere (voxlod-testkit's), u running 0..2 around.
fn uv_sphere(centre: Vec3, rings: u32, segments: u32) -> AssetMesh {
    let mut m = voxlod_testkit::assets::uv_sphere(centre, 1.0, rings, segments);
    for uv in &mut m.uv[0] {
        uv.x *= 2.0;
    }
    m
}

/// Appends `rows` + 1 rings of `segments` + 1 vertices (the seam doubled) at the heights and
/// radii `ring(i)` gives, with texture coordinates (j / segments, i / rows), and their quads.
fn surface_of_revolution(
    m: &mut AssetMesh,
    rows: u32,
    segments: u32,
    ring: impl Fn(u32) -> (f32, f32),
) {
    let base = m.positions.len() as u32;
    for i in 0..=rows {
        let (y, r) = ring(i);
        for j in 0..=segments {
            let phi = j as f32 / segments as f32 * TAU;
            m.positions
                .push(Vec3::new(r * phi.cos(), y, -r * phi.sin()));
            m.normals.push(Vec3::new(phi.cos(), 0.0, -phi.sin()));
            m.uv[0].push(Vec2::new(
                j as f32 / segments as f32,
                i as f32 / rows as f32,
            ));
        }
    }
    let at = |i: u32, j: u32| base + i * (segments + 1) + j;
    for i in 0..rows {
        for j in 0..segments {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            // A row whose ring has radius 0 (an apex) gets the one triangle that is not
            // degenerate.
            if ring(i).1 > 0.0 {
                m.triangles.push([a, b, d]);
            }
            if ring(i + 1).1 > 0.0 {
                m.triangles.push([b, c, d]);
            }
        }
    }
}

/// A flat disc at height `y` facing `up` or down: one centre vertex and a ring of its own
/// (texture coordinates projected from above).
fn cap(m: &mut AssetMesh, y: f32, segments: u32, up: bool) {
    let base = m.positions.len() as u32;
    let normal = if up { Vec3::Y } else { -Vec3::Y };
    m.positions.push(Vec3::new(0.0, y, 0.0));
    m.normals.push(normal);
    m.uv[0].push(Vec2::splat(0.5));
    for j in 0..segments {
        let phi = j as f32 / segments as f32 * TAU;
        m.positions.push(Vec3::new(phi.cos(), y, -phi.sin()));
        m.normals.push(normal);
        m.uv[0].push(Vec2::new(0.5 + 0.5 * phi.cos(), 0.5 - 0.5 * phi.sin()));
    }
    for j in 0..segments {
        let (a, b) = (base + 1 + j, base + 1 + (j + 1) % segments);
        m.triangles
            .push(if up { [base, b, a] } else { [base, a, b] });
    }
}

/// A cone of height 2 over the unit disc: the apex a vertex per segment, the base capped.
fn cone(segments: u32) -> AssetMesh {
    let mut m = AssetMesh::default();
    surface_of_revolution(&mut m, 8, segments, |i| {
        let t = i as f32 / 8.0;
        (2.0 - 2.0 * t, t)
    });
    cap(&mut m, 0.0, segments, false);
    m
}

/// A unit cylinder of height 2, both ends capped.
fn capped_cylinder(segments: u32) -> AssetMesh {
    let mut m = AssetMesh::default();
    surface_of_revolution(&mut m, 6, segments, |i| (1.0 - i as f32 / 3.0, 1.0));
    cap(&mut m, 1.0, segments, true);
    cap(&mut m, -1.0, segments, false);
    m
}

/// A torus (radii 1 and 0.3) with its two seams doubled.
fn torus(nu: u32, nv: u32) -> AssetMesh {
    let mut m = AssetMesh::default();
    for i in 0..=nv {
        for j in 0..=nu {
            let (u, v) = (j as f32 / nu as f32, i as f32 / nv as f32);
            let (a, b) = (u * TAU, v * TAU);
            let n = Vec3::new(b.cos() * a.cos(), b.sin(), -b.cos() * a.sin());
            let centre = Vec3::new(a.cos(), 0.0, -a.sin());
            m.positions.push(centre + 0.3 * n);
            m.normals.push(n);
            m.uv[0].push(Vec2::new(u, v));
        }
    }
    let at = |i: u32, j: u32| i * (nu + 1) + j;
    for i in 0..nv {
        for j in 0..nu {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            m.triangles.extend([[a, b, d], [b, c, d]]);
        }
    }
    m
}

/// A box with a cube map's seams: each face an `n` × `n` grid of its own vertices.
fn cube_mapped_box(n: u32) -> AssetMesh {
    let mut m = AssetMesh::default();
    let axes = [Vec3::X, Vec3::Y, Vec3::Z];
    for (k, normal) in axes.iter().flat_map(|&a| [a, -a]).enumerate() {
        let (mut u_axis, mut v_axis) = (axes[(k / 2 + 1) % 3], axes[(k / 2 + 2) % 3]);
        if normal.dot(u_axis.cross(v_axis)) < 0.0 {
            std::mem::swap(&mut u_axis, &mut v_axis);
        }
        let base = m.positions.len() as u32;
        for i in 0..=n {
            for j in 0..=n {
                let (s, t) = (j as f32 / n as f32, i as f32 / n as f32);
                m.positions
                    .push(normal + u_axis * (2.0 * s - 1.0) + v_axis * (2.0 * t - 1.0));
                m.normals.push(normal);
                m.uv[0].push(Vec2::new(s, t));
            }
        }
        let at = |i: u32, j: u32| base + i * (n + 1) + j;
        for i in 0..n {
            for j in 0..n {
                m.triangles.push([at(i, j), at(i, j + 1), at(i + 1, j + 1)]);
                m.triangles.push([at(i, j), at(i + 1, j + 1), at(i + 1, j)]);
            }
        }
    }
    m
}

fn asset(mesh: AssetMesh) -> Asset {
    let n = mesh.triangles.len();
    Asset {
        mesh: AssetMesh {
            material: vec![0; n],
            ..mesh
        },
        materials: vec![Material::default()],
        images: Vec::new(),
        parts: Vec::new(),
    }
}

fn group_sizes(mesh: &AssetMesh) -> Vec<usize> {
    let seams = point_seams(mesh, &SeamOptions::default()).unwrap();
    let mut sizes: Vec<usize> = seams.members.values().map(Vec::len).collect();
    sizes.sort_unstable();
    sizes
}

#[test]
fn poles_and_apexes_are_point_seams_and_other_seams_are_not() {
    // Each pole: the vertices of segments 1..=96 (segment 0's pole vertex has no triangle).
    assert_eq!(group_sizes(&uv_sphere(Vec3::ZERO, 48, 96)), vec![96, 96]);
    assert_eq!(group_sizes(&cone(40)), vec![40]);
    assert_eq!(group_sizes(&capped_cylinder(40)), Vec::<usize>::new());
    assert_eq!(group_sizes(&torus(48, 24)), Vec::<usize>::new());
    assert_eq!(group_sizes(&cube_mapped_box(8)), Vec::<usize>::new());
}

#[test]
fn a_slit_that_ends_inside_the_surface_is_not_welded() {
    // A grid whose texture is cut along the left half of its middle row: the cut's vertices
    // are doubled, the last one (where the cut ends) is not. The vertex before it is joined
    // to its double by one point seam only, a group of two, below the fan's minimum.
    let n = 6u32;
    let mut m = AssetMesh::default();
    let mut index = HashMap::new();
    let mut vertex = |m: &mut AssetMesh, i: u32, j: u32, below: bool| {
        let cut = j == n / 2 && i < n / 2;
        *index.entry((i, j, below && cut)).or_insert_with(|| {
            m.positions.push(Vec3::new(i as f32, j as f32, 0.0));
            m.normals.push(Vec3::Z);
            let shift = if below && cut { 0.5 } else { 0.0 };
            m.uv[0].push(Vec2::new(i as f32 / n as f32 + shift, j as f32 / n as f32));
            (m.positions.len() - 1) as u32
        })
    };
    for j in 0..n {
        for i in 0..n {
            let below = j < n / 2;
            let c = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)]
                .map(|(a, b)| vertex(&mut m, a, b, below));
            m.triangles.extend([[c[0], c[1], c[2]], [c[0], c[2], c[3]]]);
        }
    }
    let seams = point_seams(&m, &SeamOptions::default()).unwrap();
    assert_eq!(seams.groups(), 0);
    let loose = point_seams(
        &m,
        &SeamOptions {
            min_fan: 2,
            ..SeamOptions::default()
        },
    )
    .unwrap();
    assert_eq!(loose.groups(), 1, "the cut's last doubled vertex");
}

/// How many triangles touch a pole of a unit sphere around the origin.
fn pole_triangles(m: &AssetMesh) -> usize {
    (m.triangles.iter())
        .filter(|t| {
            t.iter()
                .any(|&v| m.positions[v as usize].y.abs() > 1.0 - 1e-5)
        })
        .count()
}

#[test]
fn a_spheres_pole_fans_collapse_with_the_rest() {
    let input = asset(uv_sphere(Vec3::ZERO, 48, 96));
    assert_eq!(input.mesh.triangles.len(), 2 * 48 * 96 - 2 * 96);
    assert_eq!(pole_triangles(&input.mesh), 2 * 96);
    let welded = collapse(&input, 600).unwrap();
    let apart = collapse_with(&input, 600, &CollapseOptions::seams_kept()).unwrap();
    let (w, a) = (welded.mesh.triangles.len(), apart.mesh.triangles.len());
    assert!((540..=660).contains(&w), "{w} triangles for 600");
    assert!((540..=660).contains(&a), "{a} triangles for 600");
    // Kept apart, most of each pole's 96 vertices stay with a triangle each (the 192 of the
    // input's pole rows); welded, a pole is one vertex of a fan like any other vertex's.
    assert!(
        pole_triangles(&apart.mesh) >= 150,
        "{}",
        pole_triangles(&apart.mesh)
    );
    assert!(
        pole_triangles(&welded.mesh) <= 30,
        "{}",
        pole_triangles(&welded.mesh)
    );
}

#[test]
fn each_pole_corner_takes_the_texture_coordinate_between_its_triangles_others() {
    let segments = 96;
    let input = asset(uv_sphere(Vec3::ZERO, 48, segments));
    let level = collapse(&input, 400).unwrap();
    let m = &level.mesh;
    let step = 2.0 / segments as f32;
    let mut checked = 0;
    for t in &m.triangles {
        for k in 0..3 {
            let p = m.positions[t[k] as usize];
            if p.y.abs() < 1.0 - 1e-6 {
                continue;
            }
            let (a, b) = (
                m.uv[0][t[(k + 1) % 3] as usize],
                m.uv[0][t[(k + 2) % 3] as usize],
            );
            let u = m.uv[0][t[k] as usize].x;
            let (lo, hi) = (a.x.min(b.x), a.x.max(b.x));
            assert!(
                u >= lo - step && u <= hi + step,
                "pole corner u {u} beside {a} and {b}"
            );
            // The triangle stays on one side of the meridian seam: no u span beyond half.
            assert!(hi - lo < 1.0, "a triangle spans the seam: {a} {b}");
            checked += 1;
        }
    }
    assert!(checked >= 6, "{checked} pole corners");
}

fn bits(m: &AssetMesh, v: usize) -> ([u32; 3], [u32; 3], [u32; 2]) {
    (
        m.positions[v].to_array().map(f32::to_bits),
        m.normals[v].to_array().map(f32::to_bits),
        m.uv[0][v].to_array().map(f32::to_bits),
    )
}

#[test]
fn welded_levels_are_made_of_input_vertices_and_keep_materials() {
    // Two spheres and a cone of three materials in one mesh.
    let mut mesh = AssetMesh::default();
    let mut materials = Vec::new();
    for (k, part) in [
        uv_sphere(Vec3::ZERO, 24, 48),
        uv_sphere(Vec3::new(3.0, 0.0, 0.0), 16, 32),
        cone(32),
    ]
    .into_iter()
    .enumerate()
    {
        let base = mesh.positions.len() as u32;
        mesh.positions.extend(&part.positions);
        mesh.normals.extend(&part.normals);
        mesh.uv[0].extend(&part.uv[0]);
        mesh.triangles
            .extend(part.triangles.iter().map(|t| t.map(|i| i + base)));
        mesh.material
            .extend(std::iter::repeat_n(k as u32, part.triangles.len()));
        materials.push(Material {
            name: format!("part {k}"),
            ..Material::default()
        });
    }
    let vertex_part: HashMap<_, u32> = (mesh.triangles.iter().zip(&mesh.material))
        .flat_map(|(t, &k)| t.map(|v| (bits(&mesh, v as usize), k)))
        .collect();
    let input = Asset {
        mesh,
        materials,
        images: Vec::new(),
        parts: Vec::new(),
    };
    for budget in [2000, 300, 60] {
        let level = collapse(&input, budget).unwrap();
        level.validate().unwrap();
        let m = &level.mesh;
        // At 60 the cone stops at its cap's seam above the count, and welded poles would let
        // the spheres go whole: the collapse keeps the poles apart there, above the count.
        if budget >= 300 {
            assert!(
                m.triangles.len() <= budget * 11 / 10,
                "{budget}: {}",
                m.triangles.len()
            );
        }
        let mut used = HashSet::new();
        for (t, &k) in m.triangles.iter().zip(&m.material) {
            for &v in t {
                let key = bits(m, v as usize);
                let part = vertex_part.get(&key).copied();
                assert_eq!(
                    part,
                    Some(k),
                    "{budget}: a vertex not of its material's part"
                );
                used.insert(k);
            }
        }
        assert_eq!(used.len(), 3, "{budget}: every part keeps triangles");
    }
}

#[test]
fn counts_below_the_seams_minimum_are_reached_with_texture_coordinates() {
    let input = asset(uv_sphere(Vec3::ZERO, 48, 96));
    let apart = collapse_with(&input, 40, &CollapseOptions::seams_kept()).unwrap();
    let level = collapse(&input, 40).unwrap();
    let (a, t) = (apart.mesh.triangles.len(), level.mesh.triangles.len());
    assert!(
        a > 44,
        "kept apart, the seams stop the collapse above 40: {a}"
    );
    assert!((20..=44).contains(&t), "{t} triangles for 40");
    assert_eq!(level.mesh.uv[0].len(), level.mesh.positions.len());
}
