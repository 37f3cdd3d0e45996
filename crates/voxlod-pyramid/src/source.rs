//! What a level of detail is made from, and its preparation (paper §2 and §4).
//!
//! A [`Source`] is a polygon mesh, a scanned volume thresholded into a solid (§4, first route),
//! a scanned volume filtered directly (§4, second route), or any implicit solid. Preparing it
//! ([`Source::prepare`]) does what sampling needs first: a mesh is checked, welded, cleared of
//! degenerate and duplicate triangles, its holes closed with fans and a BVH built
//! ([`MeshSolid`], cost O(T log T)); a volume's grid is checked against the range of 32-bit mesh
//! coordinates, and a threshold at or below every sample is reported as a warning. The
//! prepared source also gives the iso value: 0.5 by default for solids, which must lie strictly
//! between 0 and 1; required, and checked against the data's range, for direct filtering.

use std::fmt;

use serde::Serialize;
use voxlod_core::{Bounds, Frame, Grid, Placement, Volume};
use voxlod_sampling::{MeshPreparation, MeshSolid, SamplingError, Solid, ThresholdSolid};

use crate::blockwise::{BlockwiseScan, BlockwiseSource};

use crate::error::{InvalidOption, PyramidError};
use crate::lod::LodSource;
use voxlod_core::TriangleMesh;

/// What the levels are made from.
#[derive(Clone, Copy)]
pub enum Source<'a> {
    /// A polygon mesh: welded, holes closed, then its inside function filtered.
    Mesh(&'a TriangleMesh),
    /// A scanned volume: inside where the trilinearly interpolated data is `>= threshold`; the
    /// solid is filtered, so the iso value stays a density between 0 and 1.
    Threshold {
        /// The scan.
        volume: &'a Volume,
        /// The inside's lowest value, in the data's units.
        threshold: f32,
    },
    /// A scanned volume whose data is filtered itself; the iso value is in the data's units.
    Direct(&'a Volume),
    /// Any solid with an inside test (CSG, the sphereflake).
    Solid(&'a dyn Solid),
    /// A scan too large to hold, read window by window and thresholded like `Threshold` (the
    /// same levels; no warning about the threshold, which would need a pass over the data).
    BlockwiseThreshold {
        /// The scan.
        scan: &'a dyn BlockwiseScan,
        /// The inside's lowest value, in the data's units.
        threshold: f32,
    },
}

impl fmt::Debug for Source<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Source::Mesh(m) => write!(f, "Source::Mesh({} triangles)", m.triangle_count()),
            Source::Threshold { volume, threshold } => write!(
                f,
                "Source::Threshold({:?} samples, threshold {threshold})",
                volume.grid.dims
            ),
            Source::Direct(v) => write!(f, "Source::Direct({:?} samples)", v.grid.dims),
            Source::Solid(_) => write!(f, "Source::Solid"),
            Source::BlockwiseThreshold { scan, threshold } => write!(
                f,
                "Source::BlockwiseThreshold({:?} samples, threshold {threshold})",
                scan.grid().dims
            ),
        }
    }
}

/// How a scanned volume becomes a [`Source`]: thresholded into a solid, or filtered directly.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ScanRoute {
    /// Inside where the data is `>= threshold` ([`Source::Threshold`]).
    Threshold(f32),
    /// The data filtered itself ([`Source::Direct`]).
    Direct,
}

impl ScanRoute {
    /// The route asked for: `threshold` when given, else `direct`; a volume asked neither is
    /// refused ([`PyramidError::NoVolumeRoute`]).
    pub fn of(threshold: Option<f32>, direct: bool) -> Result<ScanRoute, PyramidError> {
        match (threshold, direct) {
            (Some(t), _) => Ok(ScanRoute::Threshold(t)),
            (None, true) => Ok(ScanRoute::Direct),
            (None, false) => Err(PyramidError::NoVolumeRoute),
        }
    }

    /// `volume` entering by this route.
    pub fn source(self, volume: &Volume) -> Source<'_> {
        match self {
            ScanRoute::Threshold(threshold) => Source::Threshold { volume, threshold },
            ScanRoute::Direct => Source::Direct(volume),
        }
    }
}

/// How a source enters the pipeline, for reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Route {
    /// A polygon mesh.
    Mesh,
    /// A thresholded volume.
    Threshold,
    /// A volume filtered directly.
    Direct,
    /// An implicit solid.
    Solid,
}

impl Route {
    /// `"mesh"`, `"threshold"`, `"direct"` or `"solid"`.
    pub fn name(self) -> &'static str {
        match self {
            Route::Mesh => "mesh",
            Route::Threshold => "threshold",
            Route::Direct => "direct",
            Route::Solid => "solid",
        }
    }
}

impl<'a> Source<'a> {
    /// How this source enters the pipeline.
    pub fn route(&self) -> Route {
        match self {
            Source::Mesh(_) => Route::Mesh,
            Source::Threshold { .. } | Source::BlockwiseThreshold { .. } => Route::Threshold,
            Source::Direct(_) => Route::Direct,
            Source::Solid(_) => Route::Solid,
        }
    }

    /// The change of frame that moves this source's finished meshes (in its own world) into
    /// `frame`: none for `None`; refused for a source without an anatomical frame (a mesh, a
    /// solid, a scan whose file does not say which frame it uses).
    pub fn to_frame(&self, frame: Option<Frame>) -> Result<Placement, PyramidError> {
        let Some(target) = frame else {
            return Ok(Placement::IDENTITY);
        };
        let own = match self {
            Source::Threshold { volume, .. } | Source::Direct(volume) => volume.orientation.frame,
            Source::BlockwiseThreshold { scan, .. } => scan.orientation().frame,
            Source::Mesh(_) | Source::Solid(_) => {
                let problem = "a frame applies to volumes with an anatomical frame (NRRD, NIfTI, \
                               MetaImage, VTI, DICOM); a mesh or a solid has none";
                return Err(InvalidOption::new("frame", target.name(), problem).into());
            }
        };
        if own == Frame::Unknown && target != Frame::Unknown {
            let problem = "the file does not say which anatomical frame it uses, so it cannot \
                           be converted";
            return Err(InvalidOption::new("frame", target.name(), problem).into());
        }
        Ok(Placement::between_frames(own, target))
    }

    /// Prepares the source for sampling (see the module documentation).
    ///
    /// ```
    /// # fn main() -> Result<(), voxlod_pyramid::PyramidError> {
    /// let volume = voxlod_core::Volume::filled(
    ///     voxlod_core::Grid::new([4, 4, 4], [1.0; 3], [0.0; 3])?, 3.0, "doc")?;
    /// // A threshold at or below every sample: all of the volume is inside, and it says so.
    /// let prepared = voxlod_pyramid::Source::Threshold { volume: &volume, threshold: 1.0 }.prepare()?;
    /// assert!(prepared.warnings()[0].contains("at or below every sample"));
    /// assert_eq!(prepared.iso(None)?, 0.5);
    /// assert!(prepared.iso(Some(1.5)).is_err());
    /// # Ok(())
    /// # }
    /// ```
    pub fn prepare(&self) -> Result<Prepared<'a>, PyramidError> {
        let mut warnings = Vec::new();
        let (inner, preparation) = match *self {
            Source::Mesh(mesh) => {
                let solid = MeshSolid::new(mesh)?;
                warnings.extend(voxlod_core::rounding::rounding_warning(mesh));
                let preparation = solid.preparation;
                (Inner::Mesh(Box::new(solid)), Some(preparation))
            }
            Source::Threshold { volume, threshold } => {
                check_grid_range(volume)?;
                warnings.extend(threshold_warning(volume, threshold));
                warnings.extend(volume.nan_warning("the threshold counts NaN as outside"));
                (
                    Inner::Threshold(Box::new(ThresholdSolid::new(volume, threshold)?)),
                    None,
                )
            }
            Source::Direct(volume) => {
                check_grid_range(volume)?;
                let fate = "the filter spreads NaN, and every sample it reaches counts as outside";
                warnings.extend(volume.nan_warning(fate));
                (Inner::Direct(volume), None)
            }
            Source::Solid(solid) => (Inner::Solid(solid), None),
            Source::BlockwiseThreshold { scan, threshold } => {
                if !threshold.is_finite() {
                    return Err(SamplingError::InvalidOption(format!(
                        "the threshold {threshold} is not a finite number"
                    ))
                    .into());
                }
                check_grid_reach(&scan.grid())?;
                let blockwise = BlockwiseSource { scan, threshold };
                (Inner::Blockwise(Box::new(blockwise)), None)
            }
        };
        Ok(Prepared {
            inner,
            route: self.route(),
            preparation,
            warnings,
        })
    }
}

/// A source ready for sampling; see [`Source::prepare`].
pub struct Prepared<'a> {
    inner: Inner<'a>,
    route: Route,
    preparation: Option<MeshPreparation>,
    warnings: Vec<String>,
}

enum Inner<'a> {
    Mesh(Box<MeshSolid>),
    Threshold(Box<ThresholdSolid<'a>>),
    Direct(&'a Volume),
    Solid(&'a dyn Solid),
    Blockwise(Box<BlockwiseSource<'a>>),
}

impl Prepared<'_> {
    /// What the levels are sampled from ([`crate::lod::build_level`]).
    pub fn lod_source(&self) -> LodSource<'_> {
        match &self.inner {
            Inner::Mesh(s) => LodSource::Solid(s.as_ref()),
            Inner::Threshold(s) => LodSource::Solid(s.as_ref()),
            Inner::Direct(v) => LodSource::Direct(v),
            Inner::Solid(s) => LodSource::Solid(*s),
            Inner::Blockwise(c) => LodSource::Blockwise(c.as_ref()),
        }
    }

    /// The solid, unless the source is a volume filtered directly.
    pub fn solid(&self) -> Option<&dyn Solid> {
        match self.lod_source() {
            LodSource::Solid(s) => Some(s),
            LodSource::Direct(_) | LodSource::Blockwise(_) => None,
        }
    }

    /// The box the levels cover.
    pub fn bounds(&self) -> Bounds {
        self.lod_source().bounds()
    }

    /// How the source entered the pipeline.
    pub fn route(&self) -> Route {
        self.route
    }

    /// What the preparation of a mesh did (welding, holes closed), for a mesh source.
    pub fn preparation(&self) -> Option<&MeshPreparation> {
        self.preparation.as_ref()
    }

    /// Warnings about the source (a threshold at or below every sample).
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// The iso value to contour at: `given`, checked, or the default 0.5 of solids. A solid's
    /// density runs from 0 to 1, so its iso value must lie strictly between; a volume filtered
    /// directly needs one in its units at which some samples are inside and some are not.
    pub fn iso(&self, given: Option<f32>) -> Result<f32, PyramidError> {
        match &self.inner {
            Inner::Direct(volume) => {
                let iso = given.ok_or(PyramidError::IsoRequired)?;
                match iso_outside_data(iso, volume)? {
                    Some(e) => Err(e),
                    None => Ok(iso),
                }
            }
            _ => solid_iso(given),
        }
    }
}

/// The isodensity of a solid's filtered density: `given` or 0.5, strictly between 0 and 1.
pub(crate) fn solid_iso(given: Option<f32>) -> Result<f32, PyramidError> {
    let iso = given.unwrap_or(0.5);
    let why = if !iso.is_finite() {
        "it is not a finite number"
    } else if iso <= 0.0 {
        "at or below 0 every sample is inside (the density is 0 far outside the object), so \
         there is no surface"
    } else if iso >= 1.0 {
        "at or above 1 only samples of full density (deep inside) could be inside, which \
         rounding makes unreliable"
    } else {
        return Ok(iso);
    };
    Err(InvalidOption::new(
        "iso",
        iso,
        format!(
            "the filtered density runs from 0 (outside) to 1 (deep inside); {why}. Choose an \
             isodensity strictly between 0 and 1 (0.5 follows the object's surface)"
        ),
    )
    .into())
}

/// [`PyramidError::IsoOutsideData`] when no sample of `volume` is on one side of `iso` (a sample is
/// inside when its value is `>= iso`), `None` when a surface can exist; fails when the volume
/// has no finite sample.
pub fn iso_outside_data(iso: f32, volume: &Volume) -> Result<Option<PyramidError>, PyramidError> {
    let (min, max) = volume.range().ok_or(PyramidError::NoFiniteSamples)?;
    Ok((iso <= min || iso > max).then_some(PyramidError::IsoOutsideData { iso, min, max }))
}

/// A warning when `threshold` is at or below every sample: all of the volume is inside, and
/// the surfaces are those of its box.
fn threshold_warning(volume: &Volume, threshold: f32) -> Option<String> {
    // A finite sample below the threshold (a scan's first, usually) rules the warning out
    // without a pass over the whole scan; the range is found only for the message.
    let below = |v: &f32| v.is_finite() && *v < threshold;
    if volume.as_slice().iter().any(below) {
        return None;
    }
    let (lo, hi) = volume.range()?;
    (threshold <= lo).then(|| {
        format!(
            "`threshold` {threshold} is at or below every sample (the data runs from {lo} to \
             {hi}): all of the volume is inside, so the surfaces are those of its box"
        )
    })
}

/// The largest coordinate a mesh can hold (its positions are 32-bit floats).
const LARGEST_COORDINATE: f64 = f32::MAX as f64;

/// Refuses a volume whose samples lie beyond the 32-bit range of mesh coordinates, before any
/// work: its surfaces would have infinite vertices.
pub fn check_grid_range(volume: &Volume) -> Result<(), PyramidError> {
    check_grid_reach(&volume.grid)
}

/// [`check_grid_range`] for a scan known by its grid (one read window by window).
pub fn check_grid_reach(g: &Grid) -> Result<(), PyramidError> {
    for (axis, name) in ['x', 'y', 'z'].into_iter().enumerate() {
        let far = g.origin[axis] + g.spacing[axis] * (g.dims[axis].max(1) - 1) as f64;
        let reach = if g.origin[axis].abs() > far.abs() {
            g.origin[axis]
        } else {
            far
        };
        if reach.is_nan() || reach.abs() > LARGEST_COORDINATE {
            return Err(PyramidError::GridBeyondCoordinates {
                axis: name,
                reach,
                origin: g.origin[axis],
                spacing: g.spacing[axis],
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use voxlod_core::Grid;

    /// The warning is given exactly when the smallest finite sample reaches the threshold (the
    /// definition by the range), NaNs and infinities left out, and names the range.
    #[test]
    fn the_threshold_warning_follows_the_smallest_finite_sample() {
        let values = vec![f32::NAN, 7.0, f32::NEG_INFINITY, 5.0, 9.0, f32::INFINITY];
        let volume = Volume::from_vec(Grid::unit([6, 1, 1]).unwrap(), values).unwrap();
        for threshold in [-1.0, 4.0, 5.0, 5.5, 9.0, 10.0] {
            let by_range = volume.range().is_some_and(|(lo, _)| threshold <= lo);
            let warning = threshold_warning(&volume, threshold);
            assert_eq!(warning.is_some(), by_range, "{threshold}");
            if let Some(text) = warning {
                assert!(text.contains("runs from 5 to 9"), "{text}");
            }
        }
        let nothing = Volume::from_vec(Grid::unit([2, 1, 1]).unwrap(), vec![f32::NAN; 2]).unwrap();
        assert_eq!(threshold_warning(&nothing, 0.0), None);
    }

    /// A volume without a route is refused; a change of frame is refused for a mesh and for a
    /// scan that names no frame, and between LPS and RAS is the half turn about z.
    #[test]
    fn routes_and_frames_are_checked() {
        assert!(matches!(
            ScanRoute::of(None, false),
            Err(PyramidError::NoVolumeRoute)
        ));
        assert_eq!(
            ScanRoute::of(Some(2.0), true).unwrap(),
            ScanRoute::Threshold(2.0)
        );
        let volume = Volume::filled(Grid::unit([2, 2, 2]).unwrap(), 1.0, "test").unwrap();
        let unknown = ScanRoute::Direct.source(&volume);
        assert!(unknown.to_frame(None).unwrap().is_identity());
        let refused = |e: Result<Placement, PyramidError>| match e {
            Err(PyramidError::InvalidOption(o)) => o.option == "frame",
            _ => false,
        };
        assert!(refused(unknown.to_frame(Some(Frame::Ras))));
        let mesh = TriangleMesh::default();
        assert!(refused(Source::Mesh(&mesh).to_frame(Some(Frame::Lps))));
        let orientation = voxlod_core::Orientation {
            frame: Frame::Lps,
            ..Default::default()
        };
        let lps = volume.oriented(orientation);
        let to_ras = ScanRoute::Direct
            .source(&lps)
            .to_frame(Some(Frame::Ras))
            .unwrap();
        assert_eq!(to_ras, Placement::between_frames(Frame::Lps, Frame::Ras));
        assert!(!to_ras.is_identity());
    }
}
