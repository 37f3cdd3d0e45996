//! Assets with their looks: a mesh that carries texture coordinates, vertex colours, normals,
//! tangents and a material per triangle ([`Asset`]), with the materials and images it uses,
//! and the stages that keep the looks through a level of detail.
//!
//! The voxel method (He, Hong, Kaufman, Varshney, Wang 1995) makes new surfaces that share no
//! vertex with the input; Varshney et al.'s envelopes keep the levels' vertices a subset of the
//! input's so that colours, normals and texture coordinates survive. The readers (glTF in
//! `voxlod-gltf`, OBJ with MTL and coloured PLY in `voxlod-io`) fill an [`Asset`]; the
//! geometry-only stages (sampling, marching cubes, clustering, envelopes) take
//! [`AssetMesh::geometry`] and never see attributes. Two stages keep the looks of a level:
//! [`collapse`], the input's own collapse with its attributes (its vertices are the input's),
//! and [`transfer`], colours, normals and materials from the nearest input point for a surface
//! that shares no vertex with the input (voxel and clustering levels), textures sampled
//! ([`texture`]).
//!
//! Beyond the papers: the data model follows glTF 2.0's metallic-roughness materials.

#![warn(missing_docs)]

pub mod asset;
pub mod collapse;
pub mod colour_error;
pub mod error;
pub mod join;
pub mod seams;
pub mod texture;
pub mod transfer;

pub use asset::{
    AlphaMode, Asset, AssetMesh, Image, Material, Part, Sampler, TextureRef, TextureTransform, Wrap,
};
pub use collapse::{collapse, collapse_with, AttributeWeights, CollapseOptions};
pub use colour_error::colour_error;
pub use error::AssetError;
pub use join::join;
pub use seams::{point_seams, PointSeams, SeamOptions};
pub use texture::{decode, Texels};
pub use transfer::{transfer, Transferred};
