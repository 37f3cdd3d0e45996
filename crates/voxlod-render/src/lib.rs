//! A software rasterizer for voxlod's pictures: orthographic and perspective [`Camera`]s, Lambert
//! shading from vertex normals, a z-buffer for opaque meshes, alpha blending in a given order
//! for layered translucent meshes (paper §3), thick lines and points (the clustering baselines'
//! dangling edges), and N×N supersampling for reference images; PNG output and image metrics.
//!
//! - [`camera`]: cameras framing a box.
//! - [`raster`]: exact integer rasterization of one triangle into a tile of samples.
//! - [`render`]: the scene, binning into tiles, parallel drawing, the box filter.
//! - [`image`]: the image, PNG, side-by-side montage; [`metrics`]: RMS and silhouette masks.

pub mod camera;
pub mod error;
pub mod image;
pub mod metrics;
pub mod raster;
pub mod render;

pub use camera::{Camera, Projection};
pub use error::RenderError;
pub use image::Image;
pub use metrics::{rms_difference, silhouette_mask};
pub use render::{render, LineItem, MeshItem, PointItem, RenderOptions, Scene};
