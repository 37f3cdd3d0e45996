//! Segmentations (label maps) to meshes at the speed of the volume's bytes: every label of a
//! [`voxlod_core::LabelVolume`] meshed in one pass over the volume, not one pass per label.
//!
//! Two surfaces, each its own file:
//! - marching cubes per label on the label's indicator at ½ (the surface zmesh and the paper's
//!   thresholding route give without a filter): each label closed and outward on its own;
//! - surface nets over all labels at once (Frisken 2022, as VTK's `vtkSurfaceNets3D`), whose
//!   every interface between two labels is meshed once and shared by both, then smoothed with
//!   each vertex kept within its voxel's reach and each label's volume kept.
//!
//! Then, when a budget is asked for, each label's mesh reduced to about that many triangles
//! (`budget.rs`), the shared surface patch by patch so neighbours stay joined.
//!
//! The paper's filtered levels per label stay in `voxlod_pyramid::labels`; this crate is the
//! route without a filter, beyond the paper.

pub mod budget;
pub mod error;
pub mod find;
pub mod job;
pub mod marching_cubes;
pub mod smoothing;
pub mod surface_nets;

pub use budget::{budget_meshes, budget_shared, BudgetReport};
pub use error::LabelsError;
pub use find::{find_labels, select_labels, LabelInfo};
pub use job::{
    label_surfaces, label_surfaces_owned, LabelSurface, LabelSurfaces, Surface, SurfaceOptions,
};
pub use marching_cubes::{marching_cubes, marching_cubes_of};
pub use smoothing::{smooth, SmoothingOptions, SmoothingReport};
pub use surface_nets::{surface_nets, SharedSurface, SurfaceNetsOptions};
