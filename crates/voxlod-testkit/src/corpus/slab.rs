//! CAD-like plates: a rectangle cut into a grid of cells, some holding a round hole or a slot,
//! triangulated as CAD exporters do (fans and strips of long thin triangles, flat faces, sharp
//! edges) and extruded to a closed solid whose genus is its number of holes.
//!
//! The face is triangulated in plate coordinates (u, v); every cell side carries `k` segments,
//! shared with the neighbouring cell. A plain cell is a fan from its centre; a holed cell is a
//! strip between its sides and the hole's rim, each rim point on the ray from the cell's centre
//! through a side point (the rim is star-shaped about the centre, so the strip never folds).

use glam::{DVec2, DVec3};

use voxlod_core::TriangleMesh;

/// What a cell holds.
#[derive(Clone, Copy, Debug)]
pub(super) enum Cell {
    /// Solid plate.
    Plain,
    /// A round through hole of this radius at the cell's centre.
    Hole(f64),
    /// A slot (a stadium: the points within `radius` of a segment of half-length
    /// `half_length` along u) at the cell's centre.
    Slot { half_length: f64, radius: f64 },
}

/// A plate's layout: cell boundaries along u and v (increasing), the cells row by row (v
/// outer), and the segments per cell side.
pub(super) struct Layout {
    pub(super) u: Vec<f64>,
    pub(super) v: Vec<f64>,
    pub(super) cells: Vec<Cell>,
    pub(super) k: u32,
}

/// The plate's face in (u, v): points and counter-clockwise triangles.
struct Face {
    points: Vec<DVec2>,
    triangles: Vec<[u32; 3]>,
}

/// The closed plate of `layout`, `thickness` thick, each point (u, v, w) (w from 0 on the back
/// to `thickness` on the front) placed at `map(u, v, w)`. `map` must preserve orientation and
/// keep each face (constant u, v or w) flat. Walls run through the thickness in one band.
/// Closed, manifold, outward; genus = the holes and slots.
pub(super) fn plate(layout: &Layout, thickness: f64, map: impl Fn(DVec3) -> DVec3) -> TriangleMesh {
    let face = face(layout);
    let n = face.points.len() as u32;
    let mut positions = Vec::with_capacity(2 * n as usize);
    for w in [0.0, thickness] {
        positions.extend(
            face.points
                .iter()
                .map(|p| map(DVec3::new(p.x, p.y, w)).as_vec3()),
        );
    }
    let mut triangles = Vec::with_capacity(face.triangles.len() * 3);
    for &[a, b, c] in &face.triangles {
        triangles.push([a, c, b]);
        triangles.push([a + n, b + n, c + n]);
    }
    for (a, b) in rim_edges(&face.triangles) {
        triangles.push([a, b, b + n]);
        triangles.push([a, b + n, a + n]);
    }
    TriangleMesh::new(positions, triangles)
}

/// The directed edges of `triangles` whose reverse no triangle has: the face's outline,
/// with the face on the left, in triangle order.
fn rim_edges(triangles: &[[u32; 3]]) -> Vec<(u32, u32)> {
    let directed: std::collections::HashSet<(u32, u32)> = triangles
        .iter()
        .flat_map(|&[a, b, c]| [(a, b), (b, c), (c, a)])
        .collect();
    triangles
        .iter()
        .flat_map(|&[a, b, c]| [(a, b), (b, c), (c, a)])
        .filter(|&(a, b)| !directed.contains(&(b, a)))
        .collect()
}

/// The triangulated face of `layout` (module docs).
fn face(layout: &Layout) -> Face {
    let (nu, nv, k) = (layout.u.len() - 1, layout.v.len() - 1, layout.k as usize);
    let width = nu * k + 1;
    let mut lattice = vec![u32::MAX; width * (nv * k + 1)];
    let mut face = Face {
        points: Vec::new(),
        triangles: Vec::new(),
    };
    for row in 0..nv {
        for column in 0..nu {
            let outline: Vec<u32> = cell_outline(column, row, k)
                .into_iter()
                .map(|(fu, fv)| {
                    let slot = &mut lattice[fv * width + fu];
                    if *slot == u32::MAX {
                        *slot = face.points.len() as u32;
                        face.points.push(lattice_point(layout, fu, fv));
                    }
                    *slot
                })
                .collect();
            let cell = layout.cells[row * nu + column];
            let centre = 0.5
                * DVec2::new(
                    layout.u[column] + layout.u[column + 1],
                    layout.v[row] + layout.v[row + 1],
                );
            fill_cell(&mut face, &outline, centre, cell);
        }
    }
    face
}

/// The lattice indices (fine u, fine v) of cell (`column`, `row`)'s outline, counter-clockwise
/// from its low corner: 4k points, k per side.
fn cell_outline(column: usize, row: usize, k: usize) -> Vec<(usize, usize)> {
    let (u0, v0) = (column * k, row * k);
    let bottom = (0..k).map(|s| (u0 + s, v0));
    let right = (0..k).map(|s| (u0 + k, v0 + s));
    let top = (0..k).map(|s| (u0 + k - s, v0 + k));
    let left = (0..k).map(|s| (u0, v0 + k - s));
    bottom.chain(right).chain(top).chain(left).collect()
}

/// The point of lattice index (`fu`, `fv`): on the cell boundaries, evenly between them.
fn lattice_point(layout: &Layout, fu: usize, fv: usize) -> DVec2 {
    let k = layout.k as usize;
    let along = |bounds: &[f64], f: usize| {
        let (cell, s) = (f / k, f % k);
        if s == 0 {
            bounds[cell]
        } else {
            bounds[cell] + (bounds[cell + 1] - bounds[cell]) * s as f64 / k as f64
        }
    };
    DVec2::new(along(&layout.u, fu), along(&layout.v, fv))
}

/// Triangulates one cell of `outline` (counter-clockwise point indices) around `centre`.
fn fill_cell(face: &mut Face, outline: &[u32], centre: DVec2, cell: Cell) {
    let count = outline.len();
    let reach = |d: DVec2| match cell {
        Cell::Plain => 0.0,
        Cell::Hole(radius) => radius,
        Cell::Slot {
            half_length,
            radius,
        } => stadium_reach(d, half_length, radius),
    };
    let first = face.points.len() as u32;
    if let Cell::Plain = cell {
        face.points.push(centre);
    } else {
        for &p in outline {
            let d = (face.points[p as usize] - centre).normalize();
            face.points.push(centre + d * reach(d));
        }
    }
    for s in 0..count {
        let (a, b) = (outline[s], outline[(s + 1) % count]);
        match cell {
            Cell::Plain => face.triangles.push([first, a, b]),
            _ => {
                let (qa, qb) = (first + s as u32, first + ((s + 1) % count) as u32);
                face.triangles.push([a, b, qb]);
                face.triangles.push([a, qb, qa]);
            }
        }
    }
}

/// How far a ray from the centre of a stadium (the points within `radius` of the segment from
/// (-`half_length`, 0) to (`half_length`, 0)) in the unit direction `d` runs inside it.
fn stadium_reach(d: DVec2, half_length: f64, radius: f64) -> f64 {
    if d.y.abs() > 0.0 {
        let flat = radius / d.y.abs();
        if (flat * d.x).abs() <= half_length {
            return flat;
        }
    }
    let c = DVec2::new(half_length.copysign(d.x), 0.0);
    let along = d.dot(c);
    along + (along * along - c.length_squared() + radius * radius).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stadium_is_reached_on_its_flat_sides_and_round_ends() {
        let reach = |x: f64, y: f64| stadium_reach(DVec2::new(x, y).normalize(), 2.0, 1.0);
        assert_eq!(reach(0.0, 1.0), 1.0);
        assert_eq!(reach(0.0, -1.0), 1.0);
        assert_eq!(reach(1.0, 0.0), 3.0);
        assert_eq!(reach(-1.0, 0.0), 3.0);
        // Along (1, 1): the flat side at x = 1 ≤ 2.
        assert!((reach(1.0, 1.0) - 2f64.sqrt()).abs() < 1e-12);
        // Along (3, 1)/√10: past the flat side, on the end circle around (2, 0).
        let s = reach(3.0, 1.0);
        let p = DVec2::new(3.0, 1.0).normalize() * s;
        assert!(((p - DVec2::new(2.0, 0.0)).length() - 1.0).abs() < 1e-12);
    }

    #[test]
    fn a_plain_plate_is_a_closed_box() {
        let layout = Layout {
            u: vec![0.0, 1.0, 3.0],
            v: vec![0.0, 2.0],
            cells: vec![Cell::Plain, Cell::Plain],
            k: 3,
        };
        let mesh = plate(&layout, 0.5, |p| p);
        let t = voxlod_core::mesh_topology(&mesh);
        assert!(t.is_closed_manifold() && t.is_consistently_oriented());
        assert_eq!(t.genus, Some(0));
        // Two fans of 12 triangles on each face; 2 · (2 + 1) · 3 outline edges, two wall
        // triangles each.
        assert_eq!(t.triangles, 2 * 24 + 2 * 18);
        assert!((mesh.signed_volume() - 3.0).abs() < 1e-6);
    }
}
