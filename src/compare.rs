//! How far apart two surfaces are, in one call: the two-sided distance between triangle meshes
//! measured on area-uniform, stratified, seeded samples of both surfaces, each sample's exact
//! distance found through a BVH ([`voxlod_metrics::distance`]); the figures are what Table 1 of
//! He et al. (1995) leaves out, added here to compare levels with their original. Beyond the
//! figures, [`compare`] warns when the two meshes do not seem to share a frame or units. Cost:
//! O(T log T) to build each BVH, then about O(S log T) for S samples per side.

use serde::Serialize;
use voxlod_core::TriangleMesh;
use voxlod_metrics::{mesh_distance, DistanceOptions, DistanceReport};

use crate::error::Error;
use voxlod_pyramid::InvalidOption;

/// Options of [`compare`]: how densely to sample the two surfaces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CompareOptions {
    /// Samples per side, seed, layout.
    pub distance: DistanceOptions,
}

impl Default for CompareOptions {
    /// 100 000 samples per side ([`CompareOptions::standard`]).
    fn default() -> Self {
        CompareOptions::standard()
    }
}

impl CompareOptions {
    /// 10 000 samples per side: a quick look.
    pub fn quick() -> Self {
        CompareOptions {
            distance: DistanceOptions::quick(),
        }
    }

    /// 100 000 samples per side (the default).
    pub fn standard() -> Self {
        CompareOptions {
            distance: DistanceOptions::standard(),
        }
    }

    /// 1 000 000 samples per side: for final figures.
    pub fn precise() -> Self {
        CompareOptions {
            distance: DistanceOptions::precise(),
        }
    }

    /// `samples` points on each surface.
    pub fn for_samples(samples: usize) -> Self {
        CompareOptions {
            distance: DistanceOptions::for_samples(samples),
        }
    }
}

/// The distance between two surfaces, and signs that they are not comparable.
#[derive(Clone, Debug, Serialize)]
pub struct Comparison {
    /// Hausdorff, mean and RMS distance, absolute and in percent of the common diagonal.
    #[serde(flatten)]
    pub distance: DistanceReport,
    /// The boxes do not overlap, or the sizes differ by more than a factor of ten.
    pub warnings: Vec<String>,
}

/// The two-sided distance between the surfaces of `a` and `b`.
///
/// ```
/// # fn main() -> Result<(), voxlod::Error> {
/// use voxlod::core::glam::Vec3;
/// use voxlod::core::TriangleMesh;
/// // Two parallel unit squares 0.25 apart: every sample is exactly 0.25 from the other.
/// let square = |z: f32| TriangleMesh::new(
///     vec![Vec3::new(0.0, 0.0, z), Vec3::new(1.0, 0.0, z), Vec3::new(1.0, 1.0, z), Vec3::new(0.0, 1.0, z)],
///     vec![[0, 1, 2], [0, 2, 3]],
/// );
/// let c = voxlod::compare(&square(0.0), &square(0.25), &voxlod::CompareOptions::quick())?;
/// assert!((c.distance.hausdorff - 0.25).abs() < 1e-6);
/// // Two flat boxes 0.25 apart do not overlap, and the report says so.
/// assert!(c.warnings[0].contains("do not overlap"));
/// # Ok(())
/// # }
/// ```
pub fn compare(
    a: &TriangleMesh,
    b: &TriangleMesh,
    options: &CompareOptions,
) -> Result<Comparison, Error> {
    if options.distance.samples_per_side == 0 {
        let problem = "at least one sample on each surface";
        return Err(InvalidOption::new("samples_per_side", 0, problem).into());
    }
    let distance = mesh_distance(a, b, &options.distance)?;
    Ok(Comparison {
        distance,
        warnings: frame_warnings(a, b),
    })
}

/// Signs that the two meshes are not in the same frame or units.
fn frame_warnings(a: &TriangleMesh, b: &TriangleMesh) -> Vec<String> {
    let (ba, bb) = (a.bounds(), b.bounds());
    let mut warnings = Vec::new();
    let disjoint = (0..3).any(|k| ba.max[k] < bb.min[k] || bb.max[k] < ba.min[k]);
    if disjoint {
        warnings.push(
            "the two meshes' bounding boxes do not overlap: are they in the same frame?".into(),
        );
    }
    let (da, db) = (ba.diagonal(), bb.diagonal());
    if da > 0.0 && db > 0.0 && (da / db).max(db / da) > 10.0 {
        warnings.push(format!(
            "the two meshes differ in size by a factor of {:.0} (diagonals {da:.4e} and \
             {db:.4e}): are they in the same units?",
            (da / db).max(db / da)
        ));
    }
    warnings
}
