//! A software rasterizer for voxlod's pictures: orthographic and perspective [`Camera`]s, Lambert
//! shading from vertex normals, a z-buffer for opaque meshes, alpha blending in a given order
//! for layered translucent meshes (paper §3), thick lines and points (the clustering baselines'
//! dangling edges), and N×N supersampling for reference images; PNG output and image metrics.
//!
//! - [`camera`]: cameras framing a box.
//! - [`raster`]: exact integer rasterization of one triangle into a tile of samples.
//! - [`mod@render`]: the scene, binning into tiles, parallel drawing, the box filter.
//! - [`looks`]: assets drawn with their materials, vertex colours and base colour textures;
//!   [`assets`]: assets drawn in one call.
//! - [`image`]: the image, PNG, side-by-side montage; [`metrics`]: RMS and silhouette masks.
//! - [`silhouette`]: the silhouette difference between a mesh and a simplified copy.
//! - [`visibility`]: which triangles a sphere of views sees, for culling what is hidden inside.
//!
//! Cost: O(V + T) to project and bin, plus O(covered samples) to fill; memory is the image and
//! one tile of samples per thread, whatever the supersampling.
//!
//! # Example
//!
//! A square framed by [`Camera::fit`] and drawn at 64×64 pixels with 4×4 samples each: its
//! centre is covered, the image's corner is background, and the picture encodes as a PNG.
//!
//! ```
//! use glam::{DVec3, Vec3};
//! use voxlod_core::TriangleMesh;
//! use voxlod_render::{render, Camera, MeshItem, RenderOptions, Scene};
//!
//! let square = TriangleMesh::new(
//!     vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
//!     vec![[0, 1, 2], [0, 2, 3]],
//! );
//! let camera = Camera::fit(DVec3::new(0.0, 0.0, -1.0), &square.bounds(), 64, 64, None)?;
//! let scene = Scene {
//!     meshes: vec![MeshItem::opaque(&square, [0.8, 0.8, 0.8])],
//!     ..Default::default()
//! };
//! let options = RenderOptions { supersample: 4, ..Default::default() };
//! let image = render(&scene, &camera, &options)?;
//! assert_eq!(image.coverage[image.index(32, 32)], 1.0);
//! assert_eq!(image.coverage[image.index(0, 0)], 0.0);
//! // The corner is the mean of 16 background samples, equal up to rounding.
//! let corner = image.rgb[image.index(0, 0)];
//! assert!((0..3).all(|c| (corner[c] - options.background[c]).abs() < 1e-6));
//! assert!(image.to_png()?.starts_with(b"\x89PNG"));
//! # Ok::<(), voxlod_render::RenderError>(())
//! ```

#![warn(missing_docs)]

pub mod assets;
pub mod camera;
pub mod error;
pub mod image;
pub mod looks;
pub mod metrics;
pub mod raster;
pub mod render;
pub mod silhouette;
pub mod visibility;

pub use assets::{assets_bounds, render_assets};
pub use camera::{Camera, Projection};
pub use error::RenderError;
pub use image::Image;
pub use looks::{decode_normal_maps, decode_textures, AssetItem};
pub use metrics::{rms_difference, silhouette_mask};
pub use render::{render, LineItem, MeshItem, PointItem, RenderOptions, Scene};
pub use silhouette::{view_directions, SilhouetteDifference, SilhouetteReference};
pub use visibility::{
    seen_points, sphere_directions, visible_sample_counts, visible_triangles, VisibilityOptions,
};
