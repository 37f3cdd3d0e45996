//! The index-to-world transform of a NIfTI-1 header, chosen as nibabel's `get_best_affine`
//! chooses it: the sform when `sform_code > 0`, else the qform (quaternion, `pixdim`, `qfac`)
//! when `qform_code > 0`, else nibabel's base affine (the `pixdim` diagonal with x flipped and
//! the centre of the grid at 0). Units come from `xyzt_units` (metres and micrometres to
//! millimetres); the frame is RAS, NIfTI's own. Cost: constant.

use std::path::Path;

use ::nifti::NiftiHeader;
use glam::{DMat3, DVec3};
use voxlod_core::{Frame, WorldTransform};

use crate::IoError;

/// Millimetres per unit of `xyzt_units`' spatial code (unknown is taken as millimetres).
fn unit_in_mm(xyzt_units: u8) -> f64 {
    match xyzt_units & 0o7 {
        1 => 1000.0,
        3 => 1e-3,
        _ => 1.0,
    }
}

/// `pixdim[1..=3]` for the axes present; an absent axis (or a zero size in a 2-D image) is 1.
fn zooms(header: &NiftiHeader, dims: [usize; 3]) -> DVec3 {
    let axes = (header.dim[0] as i16).clamp(1, 3) as usize;
    DVec3::from(std::array::from_fn::<f64, 3, _>(|a| {
        let z = header.pixdim[a + 1] as f64;
        if a >= axes || (dims[a] == 1 && !(z.is_finite() && z != 0.0)) {
            1.0
        } else {
            z
        }
    }))
}

/// The rotation of the qform's quaternion (NIfTI-1 `nifti1.h`, method 2).
fn quaternion_rotation(b: f64, c: f64, d: f64) -> DMat3 {
    let (b, c, d, a) = match 1.0 - (b * b + c * c + d * d) {
        rest if rest > 1e-7 => (b, c, d, rest.sqrt()),
        _ => {
            let n = (b * b + c * c + d * d).sqrt().max(f64::MIN_POSITIVE);
            (b / n, c / n, d / n, 0.0)
        }
    };
    DMat3::from_cols(
        DVec3::new(
            a * a + b * b - c * c - d * d,
            2.0 * (b * c + a * d),
            2.0 * (b * d - a * c),
        ),
        DVec3::new(
            2.0 * (b * c - a * d),
            a * a + c * c - b * b - d * d,
            2.0 * (c * d + a * b),
        ),
        DVec3::new(
            2.0 * (b * d + a * c),
            2.0 * (c * d - a * b),
            a * a + d * d - c * c - b * b,
        ),
    )
}

/// The header's transform, in millimetres and RAS.
pub(crate) fn world_of(
    path: &Path,
    header: &NiftiHeader,
    dims: [usize; 3],
) -> Result<WorldTransform, IoError> {
    let unit = unit_in_mm(header.xyzt_units);
    let zooms = zooms(header, dims);
    let (origin, steps) = if header.sform_code > 0 {
        let rows = [header.srow_x, header.srow_y, header.srow_z].map(|r| r.map(f64::from));
        let steps: [DVec3; 3] =
            std::array::from_fn(|c| DVec3::new(rows[0][c], rows[1][c], rows[2][c]));
        (DVec3::new(rows[0][3], rows[1][3], rows[2][3]), steps)
    } else if header.qform_code > 0 {
        let r = quaternion_rotation(
            header.quatern_b as f64,
            header.quatern_c as f64,
            header.quatern_d as f64,
        );
        let qfac = if header.pixdim[0] < 0.0 { -1.0 } else { 1.0 };
        let z = DVec3::new(zooms.x.abs(), zooms.y.abs(), zooms.z.abs() * qfac);
        let offset = DVec3::new(
            header.quatern_x as f64,
            header.quatern_y as f64,
            header.quatern_z as f64,
        );
        (offset, [r.x_axis * z.x, r.y_axis * z.y, r.z_axis * z.z])
    } else {
        let z = DVec3::new(-zooms.x.abs(), zooms.y.abs(), zooms.z.abs());
        let centre = DVec3::new(
            dims[0] as f64 - 1.0,
            dims[1] as f64 - 1.0,
            dims[2] as f64 - 1.0,
        ) / 2.0;
        (
            -(centre * z),
            [DVec3::X * z.x, DVec3::Y * z.y, DVec3::Z * z.z],
        )
    };
    WorldTransform::from_columns(origin * unit, steps.map(|s| s * unit), Frame::Ras).map_err(|e| {
        let which = if header.sform_code > 0 {
            "the sform"
        } else if header.qform_code > 0 {
            "the qform"
        } else {
            "pixdim"
        };
        IoError::malformed(path, format!("{which} gives no usable geometry: {e}"))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_identity_quaternion_is_the_identity_and_a_half_turn_flips_x_and_y() {
        assert!(quaternion_rotation(0.0, 0.0, 0.0).abs_diff_eq(DMat3::IDENTITY, 1e-12));
        let half_turn_about_z = quaternion_rotation(0.0, 0.0, 1.0);
        let expected = DMat3::from_diagonal(DVec3::new(-1.0, -1.0, 1.0));
        assert!(half_turn_about_z.abs_diff_eq(expected, 1e-12));
    }
}
