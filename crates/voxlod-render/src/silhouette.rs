//! The silhouette difference between a mesh and a simplified copy: what a viewer sees of
//! shape (holes closing or opening, ears shrinking, dangling edges drawn one pixel wide) and
//! nothing of shading.
//!
//! The reference and a copy are rendered from the same orthographic cameras
//! ([`view_directions`]: the eight octant diagonals first, then the six axes), each framing the
//! reference's box, one sample per pixel. A pixel is covered when at least half of it is drawn.
//! The difference is the share of pixels covered in exactly one of the two images among those
//! covered in either, pooled over all views: 0 for identical silhouettes, 1 for disjoint ones.
//! The reference's coverage is rendered once ([`SilhouetteReference`]) and reused for every copy.
//! `voxlod evaluate` reports it beside distances; the budget portfolio weighs a level's outline
//! against the input's collapse's with it.
//!
//! A mesh alone is drawn by coverage only (the render's snapping and edge rule, no depth or
//! shading: the same pixels); a copy with dangling edges or points is rendered.
//! Cost: per view and copy O(V + T + pixels of the triangles' boxes): at 256² and 14 views,
//! 1–3 ms for a copy of a thousand triangles, 0.3 s for a reference of 1.4 M.

use glam::DVec3;
use rayon::prelude::*;
use serde::Serialize;
use voxlod_core::{PolyMesh, TriangleMesh};

use crate::raster::{raster_coverage, ScreenVertex};
use crate::{render, Camera, LineItem, MeshItem, PointItem, RenderError, RenderOptions, Scene};

/// The silhouette difference of one copy (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SilhouetteDifference {
    /// Pixels covered in exactly one image over pixels covered in either, over all views.
    pub fraction: f64,
    /// Pixels covered in exactly one of the two images, over all views.
    pub differing_pixels: u64,
    /// Pixels covered in either image, over all views.
    pub covered_pixels: u64,
    /// Views rendered.
    pub views: usize,
}

/// The first `count` (at most 14) view directions: octant diagonals, then the axes.
pub fn view_directions(count: usize) -> Vec<DVec3> {
    let mut all = Vec::with_capacity(14);
    for z in [-1.0, 1.0] {
        for y in [-1.0, 1.0] {
            for x in [-1.0, 1.0] {
                all.push(DVec3::new(x, y, z));
            }
        }
    }
    for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
        all.push(axis);
        all.push(-axis);
    }
    all.truncate(count);
    all
}

/// Flat light grey for surfaces, and the colour of dangling edges and points.
const SURFACE: [f32; 3] = [0.8, 0.8, 0.78];
const WIRE: [f32; 3] = [0.95, 0.55, 0.2];

/// The scene of `mesh` with `level`'s dangling edges and isolated points, when it has some.
fn scene<'a>(mesh: &'a TriangleMesh, level: Option<&'a PolyMesh>) -> Scene<'a> {
    let positions = &mesh.positions;
    let lines = level.filter(|l| !l.lines.is_empty()).map(|l| LineItem {
        positions,
        lines: &l.lines,
        color: WIRE,
        width: 1.0,
    });
    let points = level.filter(|l| !l.points.is_empty()).map(|l| PointItem {
        positions,
        points: &l.points,
        color: WIRE,
        size: 1.5,
    });
    Scene {
        meshes: vec![MeshItem::opaque(mesh, SURFACE)],
        lines: lines.into_iter().collect(),
        points: points.into_iter().collect(),
        ..Default::default()
    }
}

/// `level` drawn as the silhouettes and previews draw it: its triangles flat light grey, its
/// dangling edges one pixel wide and its isolated points, orange.
pub fn level_scene(level: &PolyMesh) -> Scene<'_> {
    scene(&level.mesh, Some(level))
}

/// The pixels at least half covered in one render.
fn covered(scene: &Scene, camera: &Camera) -> Result<Vec<bool>, RenderError> {
    let image = render(scene, camera, &RenderOptions::default())?;
    Ok(image.coverage.iter().map(|&c| c >= 0.5).collect())
}

/// The pixels an opaque `mesh` covers seen by `camera`, as [`covered`] finds them for a scene
/// of `mesh` alone (one sample per pixel, the same snapping and edge rule), without depth or
/// shading. Cost: O(V + T + pixels of the triangles' boxes), on one thread.
fn covered_by(mesh: &TriangleMesh, camera: &Camera) -> Vec<bool> {
    let (width, height) = (camera.width as usize, camera.height as usize);
    let screen: Vec<ScreenVertex> = (mesh.positions.iter())
        .map(|p| match camera.project(p.as_dvec3()) {
            Some(s) => ScreenVertex {
                x: s.x as f32,
                y: s.y as f32,
                ..ScreenVertex::default()
            },
            None => ScreenVertex::CULLED,
        })
        .collect();
    let mut out = vec![false; width * height];
    for t in &mesh.triangles {
        raster_coverage(&mut out, width, height, t.map(|i| screen[i as usize]));
    }
    out
}

/// A mesh's silhouettes, rendered once, against which copies are compared.
pub struct SilhouetteReference {
    cameras: Vec<Camera>,
    coverage: Vec<Vec<bool>>,
}

impl SilhouetteReference {
    /// Renders `reference` from `views` (at most 14) views of `size` × `size` pixels framing its
    /// box.
    pub fn new(
        reference: &TriangleMesh,
        views: usize,
        size: u32,
    ) -> Result<SilhouetteReference, RenderError> {
        let bounds = reference.bounds();
        let cameras = view_directions(views)
            .into_iter()
            .map(|d| Camera::fit(d, &bounds, size, size, None))
            .collect::<Result<Vec<_>, _>>()?;
        valid(reference)?;
        let coverage = (cameras.par_iter())
            .map(|c| covered_by(reference, c))
            .collect();
        Ok(SilhouetteReference { cameras, coverage })
    }

    /// The silhouette difference between the reference and `copy`, its dangling edges and
    /// isolated points drawn too.
    pub fn difference(&self, copy: &PolyMesh) -> Result<SilhouetteDifference, RenderError> {
        if copy.lines.is_empty() && copy.points.is_empty() {
            return self.mesh_difference(&copy.mesh);
        }
        let scene = level_scene(copy);
        let images = (self.cameras.par_iter())
            .map(|camera| covered(&scene, camera))
            .collect::<Result<Vec<_>, RenderError>>()?;
        Ok(self.compared(&images))
    }

    /// The silhouette difference between the reference and the triangles of `copy`.
    pub fn mesh_difference(
        &self,
        copy: &TriangleMesh,
    ) -> Result<SilhouetteDifference, RenderError> {
        valid(copy)?;
        let images: Vec<Vec<bool>> = (self.cameras.par_iter())
            .map(|camera| covered_by(copy, camera))
            .collect();
        Ok(self.compared(&images))
    }

    /// The difference between the reference's coverage and `images`, one per view.
    fn compared(&self, images: &[Vec<bool>]) -> SilhouetteDifference {
        let counts = (self.coverage.iter().zip(images)).map(|(reference, image)| {
            (reference.iter().zip(image)).fold((0u64, 0u64), |(d, u), (&a, &b)| {
                (d + (a != b) as u64, u + (a || b) as u64)
            })
        });
        let (differing, union) = counts.fold((0, 0), |(d, u), c| (d + c.0, u + c.1));
        SilhouetteDifference {
            fraction: if union > 0 {
                differing as f64 / union as f64
            } else {
                0.0
            },
            differing_pixels: differing,
            covered_pixels: union,
            views: self.cameras.len(),
        }
    }
}

/// `mesh`'s indices and positions checked as a render checks them.
fn valid(mesh: &TriangleMesh) -> Result<(), RenderError> {
    mesh.validate()
        .map_err(|e| RenderError::Invalid(format!("mesh 0: {e}")))
}

#[cfg(test)]
mod tests {
    use super::*;
    use voxlod_core::glam::Vec3;
    use voxlod_testkit::shapes::{icosphere, torus};

    /// A soup of `n` triangles of random corners in the unit cube, some tiny, some long.
    fn soup(n: usize) -> TriangleMesh {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let mut mesh = TriangleMesh::default();
        for t in 0..n as u32 {
            let scale = if t % 3 == 0 { 0.01 } else { 1.0 };
            let a = Vec3::new(next(), next(), next());
            for _ in 0..2 {
                let d = Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5);
                mesh.positions.push(a + scale * d);
            }
            mesh.positions.push(a);
            mesh.triangles.push([3 * t, 3 * t + 1, 3 * t + 2]);
        }
        mesh
    }

    #[test]
    fn coverage_alone_is_the_renders_coverage_pixel_for_pixel() {
        for mesh in [icosphere(3), torus(24, 12, 1.0, 0.3), soup(400)] {
            let bounds = mesh.bounds();
            for d in view_directions(14) {
                for size in [37, 256] {
                    let camera = Camera::fit(d, &bounds, size, size, None).unwrap();
                    let drawn = covered(&scene(&mesh, None), &camera).unwrap();
                    let alone = covered_by(&mesh, &camera);
                    assert!(drawn.iter().any(|&c| c));
                    assert_eq!(drawn, alone, "view {d:?}, {size}²");
                }
            }
        }
    }
}
