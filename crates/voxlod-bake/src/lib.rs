//! The bake stage of scene proxies: a level that shares no vertex with its source (a voxel
//! level of He, Hong, Kaufman, Varshney and Wang 1995, made elsewhere) gets texture
//! coordinates and textures cast from the source asset, so that one mesh with one material
//! looks like the source.
//!
//! One algorithm per module: [`atlas`] (charts cut along creases by [`creases`], made with
//! slivers snapped shut by [`slivers`], packed by xatlas through [`xatlas`]), [`raster`]
//! (which texel stands for which surface point, with conservative coverage at chart borders), [`tangents`] (MikkTSpace), [`cast`] (rays from the
//! level into the source, the nearest point where they miss), [`opacity`] (a texel's opacity
//! where the source lets light through, by view rays), [`source`] (the source's
//! material at a point), [`dilate`] (chart looks pushed into the gutters), [`output`] (the
//! textures and the asset), [`encode`] (the textures as PNG, or JPEG on request), and
//! [`bake`] running them in order.
//!
//! Beyond the papers: the voxel paper's levels carry positions only; baking is what
//! commercial remeshers (Simplygon, InstaLOD) and bakers (xNormal) do to such proxies.

#![warn(missing_docs)]

pub mod atlas;
pub mod bake;
pub mod cast;
pub mod creases;
pub mod dilate;
pub mod encode;
pub mod error;
pub mod mipmaps;
pub mod opacity;
pub mod output;
pub mod pieces;
pub mod raster;
pub mod slivers;
pub mod source;
pub mod tangents;
mod xatlas;

pub use atlas::{atlas, Atlas, AtlasOptions, TextureSize};
pub use bake::{
    atlases, bake, bake_from, bake_levels, bake_on, BakeOptions, BakeReport, BakeSource, Baked,
    OPACITY_RAYS,
};
pub use dilate::Dilation;
pub use encode::ImageFormat;
pub use error::BakeError;
