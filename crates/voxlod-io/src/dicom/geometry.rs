//! The geometry of a DICOM series: slices sorted along their normal, spacing measured and
//! checked, and the index-to-world transform in LPS (DICOM PS3.3 C.7.6.2.1.1).
//!
//! Every slice gives ImagePositionPatient `p` (the world position of its first pixel),
//! ImageOrientationPatient (the row direction `r`, along which the column index grows, and the
//! column direction `c`) and PixelSpacing (between rows, then between columns). The slices are
//! ordered by `p · (r × c)`, never by file name or InstanceNumber. A series is refused, naming
//! the problem, when its slices disagree in orientation, when two slices share a position, when
//! the step between slices leaves the normal (gantry tilt), or when the steps differ beyond a
//! tolerance (a step that is a multiple of the others is reported as missing slices). The cost
//! is one sort of the slices.

use std::path::{Path, PathBuf};

use glam::DVec3;
use voxlod_core::{Frame, WorldTransform};

use crate::IoError;

/// What the geometry needs of one slice.
#[derive(Clone, Debug)]
pub(crate) struct SliceGeometry {
    pub path: PathBuf,
    pub position: Option<DVec3>,
    /// Row direction, then column direction.
    pub orientation: Option<[DVec3; 2]>,
    /// Between rows (along the column direction), then between columns.
    pub pixel_spacing: [f64; 2],
    pub thickness: Option<f64>,
}

/// Geometry checks: how far a step may stray from the mean step, as a fraction of it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SpacingTolerance {
    pub relative: f64,
}

/// Sorts `slices` along their normal and returns the transform of the stacked volume (`x`
/// along the rows, `y` down the columns, `z` along the normal).
pub(crate) fn stack(
    series_path: &Path,
    slices: &mut [SliceGeometry],
    tolerance: SpacingTolerance,
) -> Result<WorldTransform, IoError> {
    let first = slices
        .first()
        .ok_or_else(|| IoError::malformed(series_path, "the series has no slices"))?;
    let [row, col] = first.orientation.unwrap_or([DVec3::X, DVec3::Y]);
    for s in slices.iter() {
        let [r, c] = s.orientation.unwrap_or([DVec3::X, DVec3::Y]);
        if r.angle_between(row) > 1e-3 || c.angle_between(col) > 1e-3 {
            return Err(IoError::unsupported(
                &s.path,
                "its ImageOrientationPatient differs from the other slices of the series",
            ));
        }
        if s.pixel_spacing != first.pixel_spacing {
            return Err(IoError::unsupported(
                &s.path,
                "its PixelSpacing differs from the other slices of the series",
            ));
        }
    }
    let normal = row.cross(col);
    if normal.length() < 0.5 {
        return Err(IoError::malformed(
            &first.path,
            "ImageOrientationPatient does not hold two perpendicular unit directions",
        ));
    }
    let normal = normal.normalize();
    let depth = |s: &SliceGeometry| s.position.unwrap_or(DVec3::ZERO).dot(normal);
    slices.sort_by(|a, b| depth(a).total_cmp(&depth(b)));
    let step = slice_step(series_path, slices, normal, tolerance)?;
    let [dy, dx] = slices[0].pixel_spacing;
    WorldTransform::from_columns(
        slices[0].position.unwrap_or(DVec3::ZERO),
        [row * dx, col * dy, normal * step],
        Frame::Lps,
    )
    .map_err(|e| IoError::malformed(&slices[0].path, e.to_string()))
}

/// The distance between successive sorted slices, checked for tilt, gaps and duplicates. A
/// single slice takes its SliceThickness (or 1 mm).
fn slice_step(
    series_path: &Path,
    slices: &[SliceGeometry],
    normal: DVec3,
    tolerance: SpacingTolerance,
) -> Result<f64, IoError> {
    if slices.len() == 1 {
        return Ok(slices[0].thickness.filter(|t| *t > 0.0).unwrap_or(1.0));
    }
    if let Some(s) = slices.iter().find(|s| s.position.is_none()) {
        return Err(IoError::malformed(
            &s.path,
            "ImagePositionPatient is missing, so the slice cannot be placed in the series",
        ));
    }
    let positions: Vec<DVec3> = slices.iter().filter_map(|s| s.position).collect();
    let steps: Vec<DVec3> = positions.windows(2).map(|w| w[1] - w[0]).collect();
    let along: Vec<f64> = steps.iter().map(|d| d.dot(normal)).collect();
    if let Some(k) = along.iter().position(|&d| d.abs() < 1e-4) {
        return Err(IoError::malformed(
            &slices[k + 1].path,
            format!(
                "it lies at the same position as {} (two slices at one place: a duplicate, or two acquisitions in one series)",
                slices[k].path.display()
            ),
        ));
    }
    for (k, d) in steps.iter().enumerate() {
        let sideways = (*d - normal * along[k]).length();
        if sideways > 1e-3 * along[k].abs().max(1.0) + 1e-3 {
            return Err(IoError::unsupported(
                series_path,
                format!(
                    "the slices are sheared ({sideways:.3} mm sideways over a {:.3} mm step): gantry tilt is not supported; resample the series first",
                    along[k]
                ),
            ));
        }
    }
    check_even_steps(series_path, &along, tolerance)
}

/// The mean step, after checking that every step is within the tolerance of the median.
fn check_even_steps(
    series_path: &Path,
    along: &[f64],
    tolerance: SpacingTolerance,
) -> Result<f64, IoError> {
    let mut sorted = along.to_vec();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    let allowed = tolerance.relative * median;
    if let Some((k, &d)) = along
        .iter()
        .enumerate()
        .find(|(_, d)| (**d - median).abs() > allowed)
    {
        let ratio = d / median;
        let missing = ratio.round() >= 2.0 && (ratio - ratio.round()).abs() < 0.1;
        let message = if missing {
            format!(
                "about {} slices are missing after slice {} (a {d:.3} mm gap where the series steps {median:.3} mm)",
                ratio.round() as i64 - 1,
                k + 1
            )
        } else {
            format!(
                "the slice spacing is uneven: {d:.3} mm after slice {} where the series steps {median:.3} mm (tolerance {:.1} %)",
                k + 1,
                tolerance.relative * 100.0
            )
        };
        return Err(IoError::unsupported(series_path, message));
    }
    Ok(along.iter().sum::<f64>() / along.len() as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn slice(z: f64, x: f64) -> SliceGeometry {
        SliceGeometry {
            path: PathBuf::from(format!("s{z}.dcm")),
            position: Some(DVec3::new(x, 0.0, z)),
            orientation: Some([DVec3::X, DVec3::Y]),
            pixel_spacing: [0.5, 0.75],
            thickness: None,
        }
    }

    const TOL: SpacingTolerance = SpacingTolerance { relative: 0.01 };

    #[test]
    fn sorts_along_the_normal_and_measures_the_step() {
        let mut s = vec![slice(4.0, 0.0), slice(0.0, 0.0), slice(2.0, 0.0)];
        let t = stack(Path::new("dir"), &mut s, TOL).unwrap();
        assert_eq!(s[0].position.unwrap().z, 0.0);
        assert!((t.spacing - DVec3::new(0.75, 0.5, 2.0)).length() < 1e-12);
        assert_eq!(t.frame, Frame::Lps);
    }

    #[test]
    fn refuses_tilt_gaps_uneven_steps_and_duplicates() {
        let dir = Path::new("dir");
        let mut tilted = vec![slice(0.0, 0.0), slice(2.0, 0.5), slice(4.0, 1.0)];
        let e = stack(dir, &mut tilted, TOL).unwrap_err();
        assert!(e.message.contains("gantry tilt"), "{e}");
        let mut gap = vec![
            slice(0.0, 0.0),
            slice(2.0, 0.0),
            slice(4.0, 0.0),
            slice(8.0, 0.0),
        ];
        let e = stack(dir, &mut gap, TOL).unwrap_err();
        assert!(e.message.contains("1 slices are missing"), "{e}");
        let mut uneven = vec![
            slice(0.0, 0.0),
            slice(2.0, 0.0),
            slice(4.0, 0.0),
            slice(7.0, 0.0),
        ];
        let e = stack(dir, &mut uneven, TOL).unwrap_err();
        assert!(e.message.contains("uneven"), "{e}");
        let mut twice = vec![slice(0.0, 0.0), slice(2.0, 0.0), slice(2.0, 0.0)];
        let e = stack(dir, &mut twice, TOL).unwrap_err();
        assert!(e.message.contains("same position"), "{e}");
    }
}
