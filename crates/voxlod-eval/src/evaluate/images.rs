//! Image-space measurements and previews of simplified levels, drawn with voxlod-render.
//!
//! **Silhouette difference** (voxlod-render's [`voxlod::render::silhouette`]): the share of
//! pixels covered in exactly one of the input's and a level's images among those covered in
//! either, over up to 14 orthographic views framing the input's box. The input's coverage is
//! rendered once ([`SilhouetteReference`]) and reused for every level.
//!
//! **Previews.** [`preview_strip`] draws the input and a method's levels side by side from one
//! three-quarter view, 2 × 2 supersampled, for the report.
//!
//! Cost: one render per view and level, O(V + T + covered pixels); at 256² and 14 views, a few
//! tens of milliseconds per level of tens of thousands of triangles.

use glam::DVec3;
use voxlod::core::{Bounds, PolyMesh, TriangleMesh};
pub use voxlod::render::silhouette::{
    level_scene, view_directions, SilhouetteDifference, SilhouetteReference,
};
use voxlod::render::{render, Camera, Image, RenderError, RenderOptions};

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

/// The silhouette difference of one level (voxlod-render's [`SilhouetteDifference`]).
pub type ImageDifference = SilhouetteDifference;

/// The input's silhouettes under `options`, rendered once, against which levels are compared.
pub fn silhouette_reference(
    input: &TriangleMesh,
    options: &ImageOptions,
) -> Result<SilhouetteReference, RenderError> {
    SilhouetteReference::new(input, options.views, options.size)
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
    let mut images = vec![render(&level_scene(&input), &camera, &options)?];
    for level in levels {
        images.push(render(&level_scene(&flat(level)), &camera, &options)?);
    }
    let refs: Vec<&Image> = images.iter().collect();
    Ok(Image::side_by_side(&refs, 4, options.background))
}
