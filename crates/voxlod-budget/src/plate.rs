//! A closed plate far thinner than its size (sheet metal, a card or cloth modelled with a
//! thickness) simplified as the sheet it is ([`Method::Plate`]): one of its two large sides
//! taken as an open sheet, moved to the plate's mid-surface, collapsed by
//! meshoptimizer as a sheet (its border free, the vertices it keeps moved where their quadric
//! error is least: `simplifyWithUpdate`), then thickened again — a copy half the thickness
//! out along the vertex normals, a reversed copy half the thickness in, and a strip of two
//! triangles per border edge stitching their borders — into a closed, oriented manifold.
//!
//! This goes beyond the paper (He et al. 1995): a voxel grid sees no inside in a plate thinner
//! than a voxel, so the paper's filter erases it, and every quadric collapse of the closed
//! plate passes its two sides, a thickness apart, through each other (their vertices collapse
//! independently, each side's error measured against its own planes only). Collapsing one
//! sheet and deriving both sides from it keeps them apart by construction, wherever the
//! thickness is below the simplified sheet's curvature radius.
//!
//! **Detection** ([`Plate::detect`]): every connected part must be thin by its volume over its
//! area (twice the volume over the area, the thickness of a flat plate, under [`THIN`] of its
//! diagonal: O(F), which rules out ordinary solids before anything else is built); then a ray
//! from each triangle's centre along its inward normal through an obvhs BVH must find, within
//! [`THIN`] of the part's diagonal, a triangle facing the other way ([`FACING`]). The
//! triangles that found one, joined along shared edges, must form two sides per part, each
//! pairing with the other for at least [`PAIRED`] of its area, leaving at most [`RIM`] of the
//! part's area to the rim between them. Anything else: `None`.
//!
//! **Levels** ([`Plate::level`]): the sheet collapsed to the count whose thickened level hits
//! the budget, aimed again in proportion where it missed, its border either collapsing freely
//! or with vertices locked at about the collapsed sheet's edge length ([`Border`]: each wins
//! at some budgets, so the portfolio gets both).
//!
//! Cost: the test by volume O(F); where it passes, the BVH O(F log F) and one ray per
//! triangle; each level one meshoptimizer collapse of the sheet per aim (at most [`AIMS`]).

use std::collections::{HashMap, HashSet};
use std::time::Duration;

use meshopt::SimplifyOptions;
use obvhs::bvh2::builder::build_bvh2;
use obvhs::ray::{Ray, RayHit};
use obvhs::triangle::Triangle;
use obvhs::BvhBuildParams;
use voxlod_core::components::triangle_components;
use voxlod_core::glam::{DVec3, Vec3, Vec3A};
use voxlod_core::{mesh_topology, Bounds, TriangleMesh};

use crate::candidate::{Candidate, Method};
use crate::input::Input;
use crate::promises::within_budget;

/// A part is a plate where its thickness is under this fraction of its diagonal.
pub const THIN: f64 = 0.01;

/// Two triangles face each other across a plate where their unit normals' dot product is at
/// most this (within about 25° of opposite).
pub const FACING: f32 = -0.9;

/// Each side must find the other across the plate for at least this fraction of its area.
pub const PAIRED: f64 = 0.9;

/// The rim (what is on neither side) may be at most this fraction of a part's area.
pub const RIM: f64 = 0.1;

/// Collapses of the sheet tried at most per level, aiming again in proportion to the miss.
pub const AIMS: usize = 6;

/// [`Border::Spaced`] locks a border vertex about every this many times the edge length of
/// the collapsed sheet's triangles, were they equilateral and of equal area.
pub const BORDER_SPACING: f64 = 1.5;

/// How the sheet's border collapses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Border {
    /// As meshoptimizer collapses a border: along itself, wherever its quadrics allow. A
    /// straight border keeps few vertices, and the long triangles fanning from its long edges
    /// into a curved sheet are the level's farthest (the thin shell at 430 triangles: 0.32 %
    /// of the diagonal beside the left border, where it keeps 3 of its 21 vertices).
    Free,
    /// With a border vertex locked about every [`BORDER_SPACING`] edges of the collapsed
    /// sheet along each loop, the rest free: the thin shell at 430 triangles at 0.19 %. At
    /// the smallest budgets the locks take too much of the budget (at 26, 4.2 % against
    /// [`Border::Free`]'s 1.5 %); both are candidates.
    Spaced,
}

/// A plate's mid-surface: one side of every part moved half the local thickness inwards.
#[derive(Clone, Debug)]
pub struct Plate {
    /// The sheet, oriented as the side it came from (facing out of the plate).
    pub sheet: TriangleMesh,
    /// The plate's thickness at each of the sheet's vertices.
    pub thickness: Vec<f32>,
}

/// What a ray across the plate found from one triangle: the triangle facing it and how far.
#[derive(Clone, Copy, Debug)]
struct Across {
    partner: u32,
    distance: f32,
}

impl Plate {
    /// The mid-surface of `mesh` where every connected part of it is a thin plate (module
    /// docs); `None` otherwise, after O(F) for most inputs. `mesh` must be closed, consistently
    /// oriented and facing outwards (as the portfolio's input is prepared); one that is not
    /// gives `None`.
    pub fn detect(mesh: &TriangleMesh) -> Option<Plate> {
        Plate::detect_parts(mesh, &triangle_components(mesh))
    }

    /// [`Plate::detect`] with the parts (triangles of each connected part) already found.
    pub fn detect_parts(mesh: &TriangleMesh, parts: &[Vec<u32>]) -> Option<Plate> {
        if parts.is_empty() || !parts.iter().all(|p| thin_by_volume(mesh, p)) {
            return None;
        }
        let topology = mesh_topology(mesh);
        if !topology.is_closed_manifold() || !topology.is_consistently_oriented() {
            return None;
        }
        let across = rays_across(mesh, parts);
        let mut side = Vec::new();
        for part in parts {
            side.extend(one_side(mesh, part, &across)?);
        }
        Some(mid_surface(mesh, &side, &across))
    }

    /// The closed level of about `budget` triangles: the sheet collapsed (its border as
    /// `border` says) and thickened again, aiming again where the count missed the budget's
    /// tolerance, at most [`AIMS`] collapses. The first within the tolerance, else the closest to the budget;
    /// `None` where meshoptimizer leaves nothing. The level has 2 × the sheet's triangles and
    /// 2 per border edge; it is closed and consistently oriented by construction, and a
    /// manifold wherever the collapsed sheet is one.
    pub fn level(&self, budget: usize, border: Border) -> Option<TriangleMesh> {
        let most = self.sheet.triangle_count();
        let mut target = ((0.4 * budget as f64).round() as usize).clamp(1, most);
        let mut best: Option<(TriangleMesh, Vec<f32>, usize)> = None;
        for _ in 0..AIMS {
            let (sheet, offsets) = collapsed(&self.sheet, &self.thickness, target, border);
            if sheet.triangles.is_empty() {
                break;
            }
            let made = 2 * sheet.triangle_count() + 2 * border_edges(&sheet).len();
            let miss = |m: usize| m.abs_diff(budget);
            if best.as_ref().is_none_or(|b| miss(made) < miss(b.2)) {
                best = Some((sheet, offsets, made));
            }
            if within_budget(made, budget) {
                break;
            }
            // Each sheet triangle gives two of the level's, each border edge two more: the
            // border shrinks with the sheet, so aim in proportion.
            let aim = target as f64 * budget as f64 / made as f64;
            let next = aim.round().clamp(1.0, most as f64) as usize;
            if next == target {
                break;
            }
            target = next;
        }
        let (sheet, offsets, _) = best?;
        Some(thickened(&sheet, &offsets))
    }
}

/// The plate candidates of `input` for `budget` ([`Plate::level`], with the border free and
/// spaced), where the budget is below the input's triangles (else the input itself is the
/// level).
pub(crate) fn candidates(plate: &Plate, input: &Input, budget: usize) -> Vec<Candidate> {
    if budget >= input.mesh.triangle_count() {
        return Vec::new();
    }
    [Border::Free, Border::Spaced]
        .into_iter()
        .filter_map(|border| plate.level(budget, border))
        .map(|mesh| Candidate::new(Method::Plate, mesh))
        .collect()
}

/// `sheet` collapsed towards `target` triangles by meshoptimizer (no error limit, the border
/// as `border` says), its vertices placed where their quadrics are least
/// (`simplifyWithUpdate`): the collapsed sheet over its own vertices, and half of `thickness`
/// at each. The whole sheet where `target` is not below its triangles.
fn collapsed(
    sheet: &TriangleMesh,
    thickness: &[f32],
    target: usize,
    border: Border,
) -> (TriangleMesh, Vec<f32>) {
    let mut positions: Vec<[f32; 3]> = sheet.positions.iter().map(|p| p.to_array()).collect();
    let mut indices = sheet.triangles.as_flattened().to_vec();
    if target < sheet.triangle_count() {
        let locks = match border {
            Border::Free => None,
            Border::Spaced => Some(border_locks(sheet, BORDER_SPACING * edge_at(sheet, target))),
        };
        let kept = meshopt::simplify_with_update(
            &mut indices,
            &mut positions,
            &mut [],
            &[],
            0,
            locks.as_deref(),
            3 * target,
            f32::MAX,
            SimplifyOptions::ErrorAbsolute,
            None,
        );
        indices.truncate(kept);
    }
    let mut index = vec![u32::MAX; positions.len()];
    let (mut used, mut half) = (Vec::new(), Vec::new());
    for v in indices.iter_mut() {
        if index[*v as usize] == u32::MAX {
            index[*v as usize] = used.len() as u32;
            used.push(Vec3::from_array(positions[*v as usize]));
            half.push(0.5 * thickness[*v as usize]);
        }
        *v = index[*v as usize];
    }
    let triangles = indices
        .chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]])
        .collect();
    (TriangleMesh::new(used, triangles), half)
}

/// Whether the part's thickness by volume (twice its volume over its area) is positive and
/// under [`THIN`] of its diagonal. O(part).
fn thin_by_volume(mesh: &TriangleMesh, part: &[u32]) -> bool {
    let (mut volume, mut area) = (0.0, 0.0);
    let mut bounds = Bounds::EMPTY;
    for &t in part {
        let [a, b, c] = mesh.corners(t as usize);
        volume += a.dot(b.cross(c)) / 6.0;
        area += 0.5 * (b - a).cross(c - a).length();
        for p in [a, b, c] {
            bounds.grow(p);
        }
    }
    let thickness = 2.0 * volume / area;
    thickness > 0.0 && thickness < THIN * bounds.diagonal()
}

/// For each triangle of `mesh`, what a ray from its centre along its inward normal finds
/// within [`THIN`] of its part's diagonal: the nearest triangle facing it ([`FACING`]), if
/// any. O(F log F) for the BVH, then one ray per triangle on all cores.
fn rays_across(mesh: &TriangleMesh, parts: &[Vec<u32>]) -> Vec<Option<Across>> {
    use rayon::prelude::*;
    let triangles: Vec<Triangle> = (mesh.triangles.iter())
        .map(|t| {
            let [v0, v1, v2] = t.map(|v| Vec3A::from(mesh.positions[v as usize]));
            Triangle { v0, v1, v2 }
        })
        .collect();
    let normals: Vec<Vec3A> = triangles.iter().map(|t| t.compute_normal()).collect();
    let mut reach = vec![0.0f32; mesh.triangle_count()];
    for part in parts {
        let diagonal = part_bounds(mesh, part).diagonal();
        part.iter()
            .for_each(|&t| reach[t as usize] = (THIN * diagonal) as f32);
    }
    let mut build_time = Duration::ZERO;
    let bvh = build_bvh2(&triangles, BvhBuildParams::fast_build(), &mut build_time);
    let slot_triangle = &bvh.primitive_indices;
    (0..triangles.len())
        .into_par_iter()
        .map(|t| {
            let tri = &triangles[t];
            let (centre, inward) = ((tri.v0 + tri.v1 + tri.v2) / 3.0, -normals[t]);
            let ray = Ray::new(centre, inward, 0.0, reach[t]);
            let mut hit = RayHit::none();
            let found = bvh.ray_traverse(ray, &mut hit, |ray, slot| {
                let other = slot_triangle[slot] as usize;
                if other == t || normals[other].dot(normals[t]) > FACING {
                    return f32::INFINITY;
                }
                triangles[other].intersect(ray)
            });
            found.then(|| Across {
                partner: slot_triangle[hit.primitive_id as usize],
                distance: hit.t,
            })
        })
        .collect()
}

/// The box of a part's vertices.
fn part_bounds(mesh: &TriangleMesh, part: &[u32]) -> Bounds {
    let mut bounds = Bounds::EMPTY;
    for &t in part {
        for p in mesh.corners(t as usize) {
            bounds.grow(p);
        }
    }
    bounds
}

/// One side of a part (module docs): the triangles that found a partner across the plate,
/// joined along shared edges into groups; the largest group and the group most of its area
/// found must pair with each other for [`PAIRED`] of their areas and leave at most [`RIM`] of
/// the part's area. The largest group's triangles, or `None`.
fn one_side(mesh: &TriangleMesh, part: &[u32], across: &[Option<Across>]) -> Option<Vec<u32>> {
    let group = groups_of(mesh, part, across);
    let area = |t: u32| {
        let [a, b, c] = mesh.corners(t as usize);
        0.5 * (b - a).cross(c - a).length()
    };
    let mut sizes: HashMap<u32, f64> = HashMap::new();
    let mut pairs: HashMap<(u32, u32), f64> = HashMap::new();
    let mut whole = 0.0;
    for &t in part {
        whole += area(t);
        let (Some(&g), Some(a)) = (group.get(&t), across[t as usize]) else {
            continue;
        };
        *sizes.entry(g).or_default() += area(t);
        if let Some(&h) = group.get(&a.partner) {
            *pairs.entry((g, h)).or_default() += area(t);
        }
    }
    let largest = |of: &HashMap<u32, f64>| {
        of.iter()
            .max_by(|a, b| a.1.total_cmp(b.1))
            .map(|(&k, &v)| (k, v))
    };
    let (first, first_area) = largest(&sizes)?;
    let partners: HashMap<u32, f64> = (pairs.iter())
        .filter(|((g, _), _)| *g == first)
        .map(|(&(_, h), &a)| (h, a))
        .collect();
    let (second, first_paired) = largest(&partners)?;
    let second_area = sizes.get(&second).copied().unwrap_or(0.0);
    let second_paired = pairs.get(&(second, first)).copied().unwrap_or(0.0);
    let paired = second != first
        && first_paired >= PAIRED * first_area
        && second_paired >= PAIRED * second_area
        && first_area + second_area >= (1.0 - RIM) * whole;
    paired.then(|| {
        (part.iter().copied())
            .filter(|t| group.get(t) == Some(&first))
            .collect()
    })
}

/// The groups of a part's triangles that found a partner across the plate, joined along
/// their shared edges: each such triangle's group (a representative triangle).
fn groups_of(mesh: &TriangleMesh, part: &[u32], across: &[Option<Across>]) -> HashMap<u32, u32> {
    let mut parent: HashMap<u32, u32> = (part.iter())
        .filter(|&&t| across[t as usize].is_some())
        .map(|&t| (t, t))
        .collect();
    fn root(parent: &mut HashMap<u32, u32>, mut t: u32) -> u32 {
        while parent[&t] != t {
            let up = parent[&parent[&t]];
            parent.insert(t, up);
            t = up;
        }
        t
    }
    let mut first_at: HashMap<(u32, u32), u32> = HashMap::new();
    let sides: Vec<u32> = (part.iter().copied())
        .filter(|t| parent.contains_key(t))
        .collect();
    for t in sides {
        let [a, b, c] = mesh.triangles[t as usize];
        for (u, v) in [(a, b), (b, c), (c, a)] {
            let edge = (u.min(v), u.max(v));
            match first_at.get(&edge) {
                Some(&s) => {
                    let (rs, rt) = (root(&mut parent, s), root(&mut parent, t));
                    parent.insert(rs, rt);
                }
                None => {
                    first_at.insert(edge, t);
                }
            }
        }
    }
    let keys: Vec<u32> = parent.keys().copied().collect();
    keys.into_iter()
        .map(|t| (t, root(&mut parent, t)))
        .collect()
}

/// The `side` triangles of `mesh` as a sheet of their own vertices, each vertex moved inwards
/// (against its area-weighted normal) by half the plate's thickness there: the area-weighted
/// mean of its triangles' distances across.
fn mid_surface(mesh: &TriangleMesh, side: &[u32], across: &[Option<Across>]) -> Plate {
    let mut index: HashMap<u32, u32> = HashMap::new();
    let mut positions = Vec::new();
    let triangles: Vec<[u32; 3]> = (side.iter())
        .map(|&t| {
            mesh.triangles[t as usize].map(|v| {
                *index.entry(v).or_insert_with(|| {
                    positions.push(mesh.positions[v as usize]);
                    positions.len() as u32 - 1
                })
            })
        })
        .collect();
    let mut sheet = TriangleMesh::new(positions, triangles);
    let (mut normal, mut weighted, mut weight) = {
        let n = sheet.positions.len();
        (vec![DVec3::ZERO; n], vec![0.0f64; n], vec![0.0f64; n])
    };
    for (k, &t) in side.iter().enumerate() {
        let [a, b, c] = sheet.corners(k);
        let doubled = (b - a).cross(c - a);
        let distance = across[t as usize].map_or(0.0, |a| a.distance as f64);
        for &v in &sheet.triangles[k] {
            normal[v as usize] += doubled;
            weighted[v as usize] += doubled.length() * distance;
            weight[v as usize] += doubled.length();
        }
    }
    let thickness: Vec<f32> = (weighted.iter().zip(&weight))
        .map(|(&s, &w)| if w > 0.0 { (s / w) as f32 } else { 0.0 })
        .collect();
    for (v, p) in sheet.positions.iter_mut().enumerate() {
        let inward = -normal[v].normalize_or_zero();
        *p = (p.as_dvec3() + inward * 0.5 * thickness[v] as f64).as_vec3();
    }
    Plate { sheet, thickness }
}

/// `sheet` thickened into a closed surface: each vertex `offsets` out along its area-weighted
/// normal (the copy keeping the sheet's orientation) and as far in (the copy reversed), and two
/// triangles per border edge between the copies, oriented with them.
fn thickened(sheet: &TriangleMesh, offsets: &[f32]) -> TriangleMesh {
    let mut with_normals = sheet.clone();
    with_normals.compute_vertex_normals();
    let n = sheet.positions.len() as u32;
    let moved = |sign: f32| {
        (sheet.positions.iter().zip(&with_normals.normals))
            .zip(offsets)
            .map(move |((&p, &normal), &o)| p + sign * o * normal)
    };
    let positions: Vec<Vec3> = moved(1.0).chain(moved(-1.0)).collect();
    let mut triangles = sheet.triangles.clone();
    triangles.extend(
        sheet
            .triangles
            .iter()
            .map(|&[a, b, c]| [a + n, c + n, b + n]),
    );
    for (a, b) in border_edges(sheet) {
        // The top copy runs a→b here; the strip runs b→a along it and a'→b' below.
        triangles.extend([[b, a, a + n], [b, a + n, b + n]]);
    }
    TriangleMesh::new(positions, triangles)
}

/// The length of an edge of `sheet` collapsed to `target` triangles, were they equilateral
/// and of equal area.
fn edge_at(sheet: &TriangleMesh, target: usize) -> f64 {
    let area: f64 = (0..sheet.triangle_count())
        .map(|t| {
            let [a, b, c] = sheet.corners(t);
            0.5 * (b - a).cross(c - a).length()
        })
        .sum();
    (4.0 * area / (target.max(1) as f64 * 3f64.sqrt())).sqrt()
}

/// meshoptimizer's locks for `sheet`: along each border loop, a vertex at least `spacing`
/// (summed along the border) after the last one locked, starting anywhere on the loop.
fn border_locks(sheet: &TriangleMesh, spacing: f64) -> Vec<meshopt::SimplifyVertex> {
    let mut locks = vec![meshopt::SimplifyVertex::None; sheet.positions.len()];
    let next: HashMap<u32, u32> = border_edges(sheet).into_iter().collect();
    let mut seen = HashSet::new();
    let mut starts: Vec<u32> = next.keys().copied().collect();
    starts.sort_unstable();
    for start in starts {
        if !seen.insert(start) {
            continue;
        }
        locks[start as usize] = meshopt::SimplifyVertex::Lock;
        let (mut v, mut run) = (start, 0.0);
        while let Some(&w) = next.get(&v) {
            run += sheet.positions[v as usize].distance(sheet.positions[w as usize]) as f64;
            if run >= spacing {
                locks[w as usize] = meshopt::SimplifyVertex::Lock;
                run = 0.0;
            }
            if !seen.insert(w) {
                break;
            }
            v = w;
        }
    }
    locks
}

/// The sheet's border edges, directed as its triangles run along them (an edge whose reverse
/// no triangle has), in a fixed order.
fn border_edges(sheet: &TriangleMesh) -> Vec<(u32, u32)> {
    let directed: HashSet<(u32, u32)> = (sheet.triangles.iter())
        .flat_map(|&[a, b, c]| [(a, b), (b, c), (c, a)])
        .collect();
    let mut border: Vec<(u32, u32)> = (directed.iter().copied())
        .filter(|&(a, b)| !directed.contains(&(b, a)))
        .collect();
    border.sort_unstable();
    border
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit cube flattened to `thickness`: a square plate whose sides are two triangles.
    fn slab(thickness: f32) -> TriangleMesh {
        let mut mesh = voxlod_testkit::shapes::unit_cube();
        let low = mesh
            .positions
            .iter()
            .map(|p| p.z)
            .fold(f32::INFINITY, f32::min);
        for p in &mut mesh.positions {
            p.z = (p.z - low) * thickness;
        }
        mesh
    }

    #[test]
    fn a_thin_slab_is_a_plate_and_a_thick_one_is_not() {
        let plate = Plate::detect(&slab(1e-3)).expect("a plate");
        assert_eq!(plate.sheet.triangle_count(), 2);
        assert!(plate
            .sheet
            .positions
            .iter()
            .all(|p| (p.z - 5e-4).abs() < 1e-6));
        assert!(plate.thickness.iter().all(|&t| (t - 1e-3).abs() < 1e-6));
        assert!(Plate::detect(&slab(0.3)).is_none());
    }
}
