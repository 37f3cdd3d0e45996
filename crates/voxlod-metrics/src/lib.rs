//! Measurements of meshes for voxlod: how far two surfaces are from each other, and what shape
//! a mesh is in.
//!
//! - [`closest_point`]: the nearest point of a mesh to a query point, through a BVH.
//! - [`surface_sampling`]: seeded, area-uniform random points on a mesh.
//! - [`distance`]: two-sided Hausdorff, mean and RMS distance between two meshes by sampling
//!   both surfaces, absolute and as a fraction of the bounding-box diagonal.
//! - [`health`]: topology (from [`voxlod_core::topology`]) with area, enclosed volume,
//!   bounding box and zero-area triangles, as one serialisable report.
//! - [`spatial_order`]: Z-order sorting that keeps batches of queries coherent.
//! - [`error`]: [`MetricsError`], what the measurements refuse and why.

pub mod closest_point;
pub mod distance;
pub mod error;
pub mod health;
pub mod spatial_order;
pub mod surface_sampling;

pub use closest_point::{closest_point_on_triangle, ClosestPoint, MeshDistance, QueryHint};
pub use distance::{
    mesh_distance, one_sided_distance, DistanceOptions, DistanceReport, OneSidedDistance,
};
pub use error::MetricsError;
pub use health::{mesh_report, welded_mesh_report, BoxReport, MeshReport, WeldSummary};
pub use spatial_order::z_order;
pub use surface_sampling::{
    sample_surface, SampleLayout, SamplingOptions, SurfaceSample, SurfaceSampler,
};
