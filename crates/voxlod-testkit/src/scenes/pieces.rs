//! The scenes' pieces in their own frames, with shading normals and texture coordinates:
//! boxes, frustums (cylinders when both radii agree), latitude-longitude spheres and flat
//! cards. Vertices are not shared across a crease or a texture seam (each face or cap has its
//! own, as glTF stores them), but every vertex of a closed piece is computed from its integer
//! lattice position by one function, so that copies on a crease have identical coordinates
//! and the piece welds into a closed, outward-oriented surface.
//!
//! Cost: linear in the triangles made.

use std::f32::consts::{PI, TAU};

use glam::{Affine3A, Vec2, Vec3};
use voxlod_asset::AssetMesh;

/// A box of half-extents `half` centred at the origin, each face a grid of cells about
/// `1 / density` wide (at least one cell a side); texture coordinates are the face's
/// coordinates times `uv_scale` (repeats per unit). Closed once welded.
pub fn block(half: Vec3, density: f32, uv_scale: f32) -> AssetMesh {
    let cells = half
        .to_array()
        .map(|h| ((2.0 * h * density).round() as u32).max(1));
    let at = |l: [u32; 3]| {
        Vec3::from_array(std::array::from_fn(|a| {
            -half[a] + 2.0 * half[a] * l[a] as f32 / cells[a] as f32
        }))
    };
    let mut m = AssetMesh::default();
    for axis in 0..3 {
        let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
        for side in [0, cells[axis]] {
            let outward = if side == 0 { -1.0 } else { 1.0 };
            let mut normal = Vec3::ZERO;
            normal[axis] = outward;
            let base = m.positions.len() as u32;
            for j in 0..=cells[c] {
                for i in 0..=cells[b] {
                    let mut l = [0; 3];
                    (l[axis], l[b], l[c]) = (side, i, j);
                    let p = at(l);
                    m.positions.push(p);
                    m.normals.push(normal);
                    m.uv[0].push(Vec2::new(p[b] * outward, -p[c]) * uv_scale);
                }
            }
            grid(&mut m.triangles, base, [cells[b], cells[c]], outward < 0.0);
        }
    }
    m
}

/// A frustum along y from −height/2 (radius `bottom`) to +height/2 (radius `top`), both radii
/// positive, `segments` around, capped at both ends: a [`lathe`] of two profile points.
pub fn frustum([bottom, top, height]: [f32; 3], segments: u32, uv_scale: f32) -> AssetMesh {
    lathe(
        &[[bottom, -0.5 * height], [top, 0.5 * height]],
        segments,
        uv_scale,
    )
}

/// The profile of a [`lathe`]: `points` samples of `f(t)` = [radius, y] for t from 0 to 1.
pub fn profile(points: u32, f: impl Fn(f32) -> [f32; 2]) -> Vec<[f32; 2]> {
    let last = points.max(2) - 1;
    (0..=last).map(|k| f(k as f32 / last as f32)).collect()
}

/// A surface of revolution about y: `profile` gives [radius, y] from bottom to top (radii
/// positive), turned through `segments`, capped at both ends; shading normals from the
/// profile's slope (smooth along it), texture coordinates arc length around and along the
/// profile times `uv_scale` on the side, the plan's coordinates on the caps. Closed once
/// welded.
pub fn lathe(profile: &[[f32; 2]], segments: u32, uv_scale: f32) -> AssetMesh {
    let segments = segments.max(3);
    let rings = profile.len() as u32 - 1;
    let point = |j: u32, r: u32| {
        let theta = TAU * (j % segments) as f32 / segments as f32;
        let [radius, y] = profile[r as usize];
        Vec3::new(radius * theta.cos(), y, -radius * theta.sin())
    };
    let mut m = AssetMesh::default();
    let mut along = 0.0;
    for r in 0..=rings {
        let k = r as usize;
        let (before, after) = (
            profile[k.saturating_sub(1)],
            profile[(k + 1).min(rings as usize)],
        );
        // The outward normal in the (radius, y) plane: the profile's tangent turned clockwise.
        let (dr, dy) = (after[0] - before[0], after[1] - before[1]);
        let flat = Vec2::new(dy, -dr).normalize_or(Vec2::X);
        if r > 0 {
            along += Vec2::from(profile[k]).distance(Vec2::from(profile[k - 1]));
        }
        for j in 0..=segments {
            let theta = TAU * j as f32 / segments as f32;
            m.positions.push(point(j, r));
            m.normals.push(Vec3::new(
                flat.x * theta.cos(),
                flat.y,
                -flat.x * theta.sin(),
            ));
            m.uv[0].push(Vec2::new(theta * profile[k][0], -along) * uv_scale);
        }
    }
    grid(&mut m.triangles, 0, [segments, rings], false);
    for (r, up) in [(0, -1.0f32), (rings, 1.0)] {
        let centre = m.positions.len() as u32;
        let y = point(0, r).y;
        m.positions.push(Vec3::new(0.0, y, 0.0));
        for j in 0..segments {
            m.positions.push(point(j, r));
        }
        for k in centre..centre + segments + 1 {
            let p = m.positions[k as usize];
            m.normals.push(Vec3::Y * up);
            m.uv[0].push(Vec2::new(p.x, p.z) * uv_scale);
        }
        for j in 0..segments {
            let (a, b) = (centre + 1 + j, centre + 1 + (j + 1) % segments);
            m.triangles.push(if up > 0.0 {
                [centre, a, b]
            } else {
                [centre, b, a]
            });
        }
    }
    m
}

/// A latitude-longitude sphere of `radius` at the origin, `segments` around and half as many
/// rings, its poles exact (one triangle per segment at each); texture coordinates are
/// longitude (twice around the unit) and latitude. Closed once welded.
pub fn sphere(radius: f32, segments: u32) -> AssetMesh {
    let segments = segments.max(4);
    let rings = segments / 2;
    let point = |i: u32, j: u32| {
        if i == 0 || i == rings {
            return Vec3::Y * if i == 0 { radius } else { -radius };
        }
        let (theta, phi) = (
            PI * i as f32 / rings as f32,
            TAU * (j % segments) as f32 / segments as f32,
        );
        Vec3::new(
            theta.sin() * phi.cos(),
            theta.cos(),
            -theta.sin() * phi.sin(),
        ) * radius
    };
    let mut m = AssetMesh::default();
    for i in 0..=rings {
        for j in 0..=segments {
            let p = point(i, j);
            m.positions.push(p);
            m.normals.push(p / radius);
            m.uv[0].push(Vec2::new(
                2.0 * j as f32 / segments as f32,
                i as f32 / rings as f32,
            ));
        }
    }
    // Rings run down from the north pole, so the grid's winding is reversed; at the poles,
    // one triangle of each cell has two corners on the pole and is dropped.
    grid(&mut m.triangles, 0, [segments, rings], true);
    let positions = &m.positions;
    m.triangles.retain(|t| {
        let [a, b, c] = t.map(|v| positions[v as usize]);
        a != b && b != c && c != a
    });
    m
}

/// An open flat card in the xy plane, `width × height` centred at the origin, facing +z, as
/// `cells × cells` quads; texture coordinates 0..1 across it (v down the image). One boundary
/// loop.
pub fn card(width: f32, height: f32, cells: u32) -> AssetMesh {
    let cells = cells.max(1);
    let mut m = AssetMesh::default();
    for j in 0..=cells {
        for i in 0..=cells {
            let (s, t) = (i as f32 / cells as f32, j as f32 / cells as f32);
            m.positions
                .push(Vec3::new((s - 0.5) * width, (t - 0.5) * height, 0.0));
            m.normals.push(Vec3::Z);
            m.uv[0].push(Vec2::new(s, 1.0 - t));
        }
    }
    grid(&mut m.triangles, 0, [cells, cells], false);
    m
}

/// Two triangles per cell of a grid of `cells[0] × cells[1]` cells whose vertices are numbered
/// row by row from `base`, `cells[0] + 1` a row: counter-clockwise seen from the side that the
/// first axis crossed into the second points to, or clockwise with `flip`.
fn grid(triangles: &mut Vec<[u32; 3]>, base: u32, [columns, rows]: [u32; 2], flip: bool) {
    let row = columns + 1;
    for j in 0..rows {
        for i in 0..columns {
            let a = base + j * row + i;
            let (b, c, d) = (a + 1, a + row + 1, a + row);
            if flip {
                triangles.extend([[a, c, b], [a, d, c]]);
            } else {
                triangles.extend([[a, b, c], [a, c, d]]);
            }
        }
    }
}

/// `piece` moved by `place`: positions transformed, normals by the inverse transpose and
/// renormalised (a mirroring transform also reverses the triangles, so that they stay
/// counter-clockwise seen from outside).
pub fn placed(piece: &AssetMesh, place: Affine3A) -> AssetMesh {
    let normal_matrix = place.matrix3.inverse().transpose();
    let mirrored = place.matrix3.determinant() < 0.0;
    AssetMesh {
        positions: piece
            .positions
            .iter()
            .map(|&p| place.transform_point3(p))
            .collect(),
        normals: piece
            .normals
            .iter()
            .map(|&n| (normal_matrix * n).normalize())
            .collect(),
        triangles: piece
            .triangles
            .iter()
            .map(|&[a, b, c]| if mirrored { [a, c, b] } else { [a, b, c] })
            .collect(),
        uv: piece.uv.clone(),
        ..AssetMesh::default()
    }
}
