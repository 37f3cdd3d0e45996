//! Image-space measurements and previews of simplified levels, drawn with voxlod-render.
//!
//! **Silhouette difference.** The input and a level are rendered from the same orthographic
//! cameras ([`view_directions`]: the eight octant diagonals first, then the six axes), each
//! framing the input's box, one sample per pixel. A pixel is covered when at least half of it
//! is drawn. The difference is the share of pixels covered in exactly one of the two images
//! among those covered in either, pooled over all views: 0 for identical silhouettes, 1 for
//! disjoint ones. It sees what a viewer sees of shape (holes closing, ears shrinking, dangling
//! edges drawn one pixel wide) and nothing of shading. The input's coverage is rendered once
//! ([`SilhouetteReference`]) and reused for every level.
//!
//! **Previews.** [`preview_strip`] draws the input and a method's levels side by side from one
//! three-quarter view, 2 × 2 supersampled, for the report.
//!
//! Cost: one render per view and level, O(V + T + covered pixels); at 256² and 14 views, a few
//! tens of milliseconds per level of tens of thousands of triangles.

use glam::DVec3;
use serde::Serialize;
use voxlod::core::{Bounds, PolyMesh, TriangleMesh};
use voxlod::render::{
    render, Camera, Image, LineItem, MeshItem, PointItem, RenderError, RenderOptions, Scene,
};

/// How the image-space measurements are made.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImageOptions {
    /// Views of the silhouette difference (0 turns it off; at most 14).
    pub views: usize,
    /// Side of each view, in pixels.
    pub size: u32,
}

impl Default for ImageOptions {
    fn default() -> Self {
        ImageOptions::standard()
    }
}

impl ImageOptions {
    /// Fourteen views of 256 × 256 pixels.
    pub fn standard() -> Self {
        ImageOptions {
            views: 14,
            size: 256,
        }
    }

    /// Six views of 128 × 128: for tests and a first look.
    pub fn quick() -> Self {
        ImageOptions {
            views: 6,
            size: 128,
        }
    }

    /// No image-space measurement.
    pub fn off() -> Self {
        ImageOptions { views: 0, size: 0 }
    }
}

/// The silhouette difference of one level (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ImageDifference {
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

fn scene(level: &PolyMesh) -> Scene<'_> {
    let positions = &level.mesh.positions;
    Scene {
        meshes: vec![MeshItem::opaque(&level.mesh, SURFACE)],
        lines: if level.lines.is_empty() {
            Vec::new()
        } else {
            vec![LineItem {
                positions,
                lines: &level.lines,
                color: WIRE,
                width: 1.0,
            }]
        },
        points: if level.points.is_empty() {
            Vec::new()
        } else {
            vec![PointItem {
                positions,
                points: &level.points,
                color: WIRE,
                size: 1.5,
            }]
        },
    }
}

fn covered(image: &Image) -> Vec<bool> {
    image.coverage.iter().map(|&c| c >= 0.5).collect()
}

/// The input's silhouettes, rendered once, against which levels are compared.
pub struct SilhouetteReference {
    cameras: Vec<Camera>,
    coverage: Vec<Vec<bool>>,
}

impl SilhouetteReference {
    /// Renders `input` from `options.views` views framing its box.
    pub fn new(
        input: &TriangleMesh,
        options: &ImageOptions,
    ) -> Result<SilhouetteReference, RenderError> {
        let bounds = input.bounds();
        let cameras = view_directions(options.views)
            .into_iter()
            .map(|d| Camera::fit(d, &bounds, options.size, options.size, None))
            .collect::<Result<Vec<_>, _>>()?;
        let level = PolyMesh::from(input.clone());
        let coverage = cameras
            .iter()
            .map(|c| Ok(covered(&render(&scene(&level), c, &plain())?)))
            .collect::<Result<Vec<_>, RenderError>>()?;
        Ok(SilhouetteReference { cameras, coverage })
    }

    /// The silhouette difference between the input and `level`.
    pub fn difference(&self, level: &PolyMesh) -> Result<ImageDifference, RenderError> {
        let (mut differing, mut union) = (0u64, 0u64);
        for (camera, reference) in self.cameras.iter().zip(&self.coverage) {
            let image = render(&scene(level), camera, &plain())?;
            for (&a, &b) in reference.iter().zip(&covered(&image)) {
                differing += (a != b) as u64;
                union += (a || b) as u64;
            }
        }
        Ok(ImageDifference {
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

fn plain() -> RenderOptions {
    RenderOptions::default()
}

/// The three-quarter view of the previews: from the front right, a little above.
pub const PREVIEW_DIRECTION: DVec3 = DVec3::new(-0.55, -0.45, -1.0);

/// `input` then each of `levels`, `size` pixels square each, side by side, framed alike (the
/// input's box) and shaded alike: flat per face for every mesh, whatever normals it carries
/// (marching cubes' gradient normals would smooth-shade the voxel levels beside a flat input and
/// make sharp-edged levels look blotchy).
pub fn preview_strip(
    input: &TriangleMesh,
    levels: &[&PolyMesh],
    size: u32,
) -> Result<Image, RenderError> {
    let bounds: Bounds = input.bounds();
    let camera = Camera::fit(PREVIEW_DIRECTION, &bounds, size, size, None)?;
    let options = RenderOptions {
        supersample: 2,
        ..RenderOptions::default()
    };
    let flat = |mesh: &PolyMesh| {
        let mut mesh = mesh.clone();
        mesh.mesh.normals.clear();
        mesh
    };
    let input = flat(&PolyMesh::from(input.clone()));
    let mut images = vec![render(&scene(&input), &camera, &options)?];
    for level in levels {
        images.push(render(&scene(&flat(level)), &camera, &options)?);
    }
    let refs: Vec<&Image> = images.iter().collect();
    Ok(Image::side_by_side(&refs, 4, options.background))
}
