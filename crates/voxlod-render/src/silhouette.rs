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
//! `voxlod evaluate` reports it beside distances; the budget search weighs it between levels
//! of different solids (the input as given and with its hollows filled).
//!
//! Cost: one render per view and copy, O(V + T + covered pixels); at 256² and 14 views, a few
//! tens of milliseconds per copy of tens of thousands of triangles.

use glam::DVec3;
use rayon::prelude::*;
use serde::Serialize;
use voxlod_core::{PolyMesh, TriangleMesh};

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
        let scene = scene(reference, None);
        let coverage = (cameras.par_iter())
            .map(|c| covered(&scene, c))
            .collect::<Result<Vec<_>, RenderError>>()?;
        Ok(SilhouetteReference { cameras, coverage })
    }

    /// The silhouette difference between the reference and `copy`, its dangling edges and
    /// isolated points drawn too.
    pub fn difference(&self, copy: &PolyMesh) -> Result<SilhouetteDifference, RenderError> {
        self.difference_of(&level_scene(copy))
    }

    /// The silhouette difference between the reference and the triangles of `copy`.
    pub fn mesh_difference(
        &self,
        copy: &TriangleMesh,
    ) -> Result<SilhouetteDifference, RenderError> {
        self.difference_of(&scene(copy, None))
    }

    fn difference_of(&self, scene: &Scene) -> Result<SilhouetteDifference, RenderError> {
        let counts = (self.cameras.par_iter().zip(&self.coverage))
            .map(|(camera, reference)| {
                let image = covered(scene, camera)?;
                Ok(reference
                    .iter()
                    .zip(&image)
                    .fold((0u64, 0u64), |(d, u), (&a, &b)| {
                        (d + (a != b) as u64, u + (a || b) as u64)
                    }))
            })
            .collect::<Result<Vec<_>, RenderError>>()?;
        let (differing, union) = (counts.iter()).fold((0, 0), |(d, u), c| (d + c.0, u + c.1));
        Ok(SilhouetteDifference {
            fraction: if union > 0 {
                differing as f64 / union as f64
            } else {
                0.0
            },
            differing_pixels: differing,
            covered_pixels: union,
            views: self.cameras.len(),
        })
    }
}
