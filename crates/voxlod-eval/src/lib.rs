//! Measurement that is not the product: how voxlod and the baselines compare, and how close we
//! come to the voxel paper (He, Hong, Kaufman, Varshney, Wang 1995).
//!
//! - [`evaluate`]: every simplifier on one mesh, error against triangle count, with plots and a
//!   written report (`voxlod evaluate`).
//! - [`methods`]: the simplifiers it compares, each behind the [`methods::Simplifier`] trait
//!   (the voxel pipeline with either filter, Rossignac–Borrel and Low–Tan clustering,
//!   simplification envelopes, and the voxel pipeline followed by envelopes).
//! - [`paper_tables`]: the paper's three results tables (§4), regenerated (`voxlod demo` and the
//!   workspace's `table*` examples).
//! - [`antialias`]: the paper's antialiasing claim (§3, Figure 7) measured in images.
//! - [`appearance`]: how a level of an asset looks beside its input (PSNR and SSIM of renders
//!   with their looks from 14 views).
//!
//! Built on the facade `voxlod`; nothing in the library depends on this crate.
//!
//! # Example
//!
//! Clustering against the voxel pipeline on a small torus, at two budgets:
//!
//! ```
//! use voxlod::metrics::DistanceOptions;
//! use voxlod_eval::evaluate::{evaluate, report, Budgets, EvaluateOptions, ImageOptions};
//!
//! # let mesh = voxlod_testkit::shapes::torus(48, 24, 2.0, 0.7);
//! // `mesh`: a torus of 2304 triangles (or any mesh, say from `voxlod::io::read_mesh`).
//! let options = EvaluateOptions {
//!     methods: vec!["rossignac-borrel".parse()?, "voxel-gaussian".parse()?],
//!     budgets: Budgets::Explicit(vec![500, 250]),
//!     distance: DistanceOptions::for_samples(2_000),
//!     images: ImageOptions::off(),
//!     ..EvaluateOptions::quick()
//! };
//! let evaluation = evaluate(&mesh, &options, |method, point| {
//!     println!("{method}: {} triangles", point.triangles);
//! })?;
//! assert_eq!(evaluation.curves.len(), 2);
//! // Fewer triangles, a larger error: along each curve the Hausdorff distance grows.
//! for curve in &evaluation.curves {
//!     assert_eq!(curve.points.len(), 2, "{curve:?}");
//!     assert!(curve.points[1].hausdorff >= curve.points[0].hausdorff);
//! }
//! let markdown = report::markdown(&evaluation, &report::ReportContext::default());
//! assert!(markdown.contains("## rossignac-borrel"));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![warn(missing_docs)]

pub mod antialias;
pub mod appearance;
pub mod evaluate;
pub mod methods;
pub mod paper_tables;
