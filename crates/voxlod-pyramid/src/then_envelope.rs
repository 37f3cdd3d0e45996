//! The envelope step of [`crate::lod()`]: each marching-cubes level simplified within ε by
//! simplification envelopes (Varshney et al. 1995), the paper's proposed use of the two methods
//! together (He et al. §5): the voxel filter removes the small features and holes, the envelope
//! then removes the many small triangles marching cubes leaves on smooth parts, keeping genus,
//! components and the ε bound. ε is a distance, a fraction of the level's diagonal, or voxels of
//! the level. Cost: the envelope's, O(T log T) per level.

use std::fmt;
use std::str::FromStr;

use serde::Serialize;
use voxlod_core::TriangleMesh;
use voxlod_envelope::{simplify_envelope, EnvelopeError, EnvelopeOptions, Epsilon};

/// ε of the envelope step of a level.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub enum LevelEpsilon {
    /// A distance, or a fraction of the level's bounding-box diagonal.
    Epsilon(Epsilon),
    /// Voxels of the level: `1.0` is one voxel of that level's grid.
    Voxels(f64),
}

impl LevelEpsilon {
    /// ε of a level whose voxels are `voxel_size` wide.
    pub fn for_level(self, voxel_size: f64) -> Epsilon {
        match self {
            LevelEpsilon::Epsilon(e) => e,
            LevelEpsilon::Voxels(v) => Epsilon::Absolute(v * voxel_size),
        }
    }
}

impl FromStr for LevelEpsilon {
    type Err = String;

    /// `0.5` (a distance), `1%` (of the diagonal) or `1vox` (voxels of the level).
    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let t = text.trim();
        if let Some(v) = t.strip_suffix("vox") {
            return match v.trim().parse::<f64>() {
                Ok(x) if x > 0.0 && x.is_finite() => Ok(LevelEpsilon::Voxels(x)),
                _ => Err(format!("'{text}': the number of voxels must be positive")),
            };
        }
        t.parse::<Epsilon>()
            .map(LevelEpsilon::Epsilon)
            .map_err(|_| {
                format!(
                    "'{text}': ε must be a positive distance (0.5) or percentage of the \
                     bounding-box diagonal (1%)"
                )
            })
    }
}

impl fmt::Display for LevelEpsilon {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LevelEpsilon::Epsilon(Epsilon::Absolute(d)) => write!(f, "{d}"),
            LevelEpsilon::Epsilon(Epsilon::DiagonalFraction(x)) => write!(f, "{}%", x * 100.0),
            LevelEpsilon::Voxels(v) => write!(f, "{v}vox"),
        }
    }
}

/// The envelope step: ε and the envelope's options.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ThenEnvelope {
    /// ε of each level.
    pub epsilon: LevelEpsilon,
    /// How to simplify (the paper's order and offsets by default).
    pub options: EnvelopeOptions,
}

impl ThenEnvelope {
    /// The paper's envelope within `epsilon`, each level's distance to its marching-cubes
    /// surface measured with 50 000 points per side.
    pub fn new(epsilon: LevelEpsilon) -> Self {
        ThenEnvelope {
            epsilon,
            options: EnvelopeOptions::paper().with_measure_samples(50_000),
        }
    }

    /// Within `voxels` voxels of each level (one voxel is what He et al. §5 suggest).
    pub fn voxels(voxels: f64) -> Self {
        ThenEnvelope::new(LevelEpsilon::Voxels(voxels))
    }
}

/// What the envelope step did to one level.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EnvelopeStep {
    /// ε in mesh units.
    pub epsilon: f64,
    /// Triangles of the marching-cubes surface.
    pub triangles_before: usize,
    /// Triangles after the step.
    pub triangles: usize,
    /// How many fewer, in percent.
    pub reduction_percent: f64,
    /// Wall time of the step.
    pub seconds: f64,
    /// Measured two-sided distance to the marching-cubes surface, when measured.
    pub hausdorff: Option<f64>,
    /// Genus after the step (the same as before).
    pub genus: Option<i64>,
}

/// Simplifies a marching-cubes level within `step` (voxels of size `voxel_size`); an empty
/// level stays empty.
pub(crate) fn simplify_level(
    mesh: &TriangleMesh,
    step: &ThenEnvelope,
    voxel_size: f64,
) -> Result<(TriangleMesh, Option<EnvelopeStep>), EnvelopeError> {
    if mesh.triangles.is_empty() {
        return Ok((mesh.clone(), None));
    }
    let epsilon = step.epsilon.for_level(voxel_size);
    let level = simplify_envelope(mesh, epsilon, &step.options)?;
    let r = &level.report;
    let report = EnvelopeStep {
        epsilon: r.epsilon,
        triangles_before: r.input_triangles,
        triangles: r.triangles,
        reduction_percent: r.reduction_percent,
        seconds: r.seconds,
        hausdorff: r.distance.map(|d| d.hausdorff),
        genus: r.topology.genus,
    };
    Ok((level.mesh, Some(report)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn level_epsilons_parse_and_print_as_written() {
        for text in ["1.5vox", "2%", "0.25"] {
            let e: LevelEpsilon = text.parse().unwrap();
            assert_eq!(e.to_string(), text);
        }
        assert_eq!("1.5vox".parse(), Ok(LevelEpsilon::Voxels(1.5)));
        assert_eq!(
            "0.25".parse(),
            Ok(LevelEpsilon::Epsilon(Epsilon::Absolute(0.25)))
        );
        assert_eq!(
            LevelEpsilon::Voxels(2.0).for_level(0.5),
            Epsilon::Absolute(1.0)
        );
        for bad in ["0vox", "-1vox", "0", "-1%", "x"] {
            assert!(bad.parse::<LevelEpsilon>().is_err(), "{bad}");
        }
    }
}
