//! Writing NIfTI-1 volumes (`.nii`, and `.nii.gz` gzip-compressed): one 348-byte header, the
//! empty extension flag, then the samples as little-endian `float32` (label maps as `uint32`).
//!
//! The geometry is written twice, as nibabel and ITK read it: the sform (`srow_x/y/z`, the full
//! index-to-world matrix) and the qform (a rotation quaternion, `pixdim` and `qfac = ±1` for a
//! flip of the third axis), both in RAS and millimetres (a volume in LPS is turned a half turn
//! about z; one whose frame is unknown is written as it is). A direction whose axes are not
//! perpendicular has no quaternion: then only the sform is set and `qform_code` is 0, as
//! nibabel does. The codes are 1 (scanner) for a volume with a known frame, 2 (aligned) when the
//! frame is unknown.
//!
//! The `nifti` crate reads headers but writes only through its `ndarray` writer, which chooses
//! its own output names and writes in place; the header is therefore laid out here (the fixed
//! NIfTI-1 layout of `nifti1.h`), and the file goes through this crate's atomic temporaries.
//! The round trip through the crate's reader, nibabel and SimpleITK is tested.
//!
//! Cost: O(N) for N samples, streamed (no copy of the samples); memory O(1) beyond the volume.

use std::io::Write;
use std::path::Path;

use glam::{DMat3, DQuat};
use voxlod_core::{Frame, Grid, LabelVolume, Orientation, Volume, WorldTransform};

use crate::atomic::{stage, TempFile};
use crate::IoError;

/// Bytes of the NIfTI-1 header.
const HEADER_BYTES: usize = 348;
/// Where the samples start: the header and the 4-byte extension flag.
const DATA_OFFSET: f32 = 352.0;
/// `datatype` of `float32`.
const FLOAT32: i16 = 16;
/// `datatype` of `uint32`.
const UINT32: i16 = 768;
/// `xyzt_units`: millimetres, no time unit.
const MILLIMETRES: u8 = 2;

/// The qform of a direction: the quaternion (b, c, d) and `qfac`, or `None` when the axes are
/// not perpendicular (no rotation, even with the third axis flipped, gives them).
pub(crate) fn quaternion_of(direction: DMat3) -> Option<([f64; 3], f64)> {
    let gram = direction.transpose() * direction;
    if !gram.abs_diff_eq(DMat3::IDENTITY, 1e-5) {
        return None;
    }
    let qfac = if direction.determinant() < 0.0 {
        -1.0
    } else {
        1.0
    };
    let proper = DMat3::from_cols(direction.x_axis, direction.y_axis, direction.z_axis * qfac);
    let mut q = DQuat::from_mat3(&proper).normalize();
    if q.w < 0.0 {
        q = -q;
    }
    Some(([q.x, q.y, q.z], qfac))
}

/// The 348 header bytes, little-endian, for samples of `datatype` (`bitpix` bits each) on
/// `grid` placed by `orientation`.
fn header(
    (grid, orientation): (&Grid, &Orientation),
    (datatype, bitpix): (i16, i16),
) -> [u8; HEADER_BYTES] {
    let mut h = [0u8; HEADER_BYTES];
    let mut put = |at: usize, bytes: &[u8]| h[at..at + bytes.len()].copy_from_slice(bytes);
    let world = WorldTransform::of(grid, orientation).in_frame(Frame::Ras);
    let code: i16 = if world.frame == Frame::Unknown { 2 } else { 1 };
    let dims = grid.dims;

    put(0, &(HEADER_BYTES as i32).to_le_bytes());
    let dim = [3, dims[0], dims[1], dims[2], 1, 1, 1, 1];
    for (i, d) in dim.iter().enumerate() {
        put(40 + 2 * i, &(*d as i16).to_le_bytes());
    }
    put(70, &datatype.to_le_bytes());
    put(72, &bitpix.to_le_bytes());
    let qform = quaternion_of(world.direction);
    let qfac = qform.map_or(1.0, |(_, qfac)| qfac);
    let pixdim = [
        qfac,
        world.spacing.x,
        world.spacing.y,
        world.spacing.z,
        1.0,
        1.0,
        1.0,
        1.0,
    ];
    for (i, p) in pixdim.iter().enumerate() {
        put(76 + 4 * i, &(*p as f32).to_le_bytes());
    }
    put(108, &DATA_OFFSET.to_le_bytes());
    put(112, &1.0f32.to_le_bytes());
    put(123, &[MILLIMETRES]);
    let description = b"voxlod";
    put(148, description);
    if let Some((bcd, _)) = qform {
        put(252, &code.to_le_bytes());
        let origin = world.origin;
        let q = [bcd[0], bcd[1], bcd[2], origin.x, origin.y, origin.z];
        for (i, v) in q.iter().enumerate() {
            put(256 + 4 * i, &(*v as f32).to_le_bytes());
        }
    }
    put(254, &code.to_le_bytes());
    for (r, row) in world.matrix().iter().take(3).enumerate() {
        for (c, v) in row.iter().enumerate() {
            put(280 + 16 * r + 4 * c, &(*v as f32).to_le_bytes());
        }
    }
    put(344, b"n+1\0");
    h
}

/// Writes `path` as NIfTI-1 `float32`, gzip-compressed when `gzip` (a `.nii.gz` name).
pub(crate) fn write(path: &Path, volume: &Volume, gzip: bool) -> Result<TempFile, IoError> {
    check_sizes(path, &volume.grid)?;
    let head = header((&volume.grid, &volume.orientation), (FLOAT32, 32));
    stage(path, |w| {
        with_gzip(w, gzip, |w| {
            w.write_all(&head)?;
            w.write_all(&[0u8; 4])?;
            crate::raw::write_samples_f32_le(w, volume.as_slice())
        })
    })
}

/// Writes a label map to `w` as NIfTI-1 `uint32` (`scl_slope` 1, `scl_inter` 0), with the
/// geometry of [`write`]; gzip-compressed when `gzip`. The sizes must have passed
/// [`check_sizes`].
pub(crate) fn write_labels(
    w: &mut impl Write,
    labels: &LabelVolume,
    gzip: bool,
) -> std::io::Result<()> {
    let head = header((&labels.grid, &labels.orientation), (UINT32, 32));
    with_gzip(w, gzip, |w| {
        w.write_all(&head)?;
        w.write_all(&[0u8; 4])?;
        crate::raw::write_labels_le(w, &labels.values)
    })
}

/// Runs `write` on `w`, through a gzip encoder when `gzip`.
fn with_gzip<W: Write>(
    w: &mut W,
    gzip: bool,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<()> {
    if gzip {
        let mut z = flate2::write::GzEncoder::new(w, flate2::Compression::new(6));
        write(&mut z)?;
        z.finish().map(|_| ())
    } else {
        write(w)
    }
}

/// Fails unless every size fits NIfTI-1's signed 16-bit `dim`.
pub(crate) fn check_sizes(path: &Path, grid: &Grid) -> Result<(), IoError> {
    for (axis, &size) in grid.dims.iter().enumerate() {
        if size > i16::MAX as usize {
            return Err(IoError::unsupported(
                path,
                format!(
                    "{size} samples along axis {axis}: NIfTI-1 sizes are at most {}",
                    i16::MAX
                ),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn a_flipped_third_axis_gives_qfac_minus_one_and_shear_no_quaternion() {
        let ([b, c, d], qfac) = quaternion_of(DMat3::IDENTITY).unwrap();
        assert_eq!((b, c, d, qfac), (0.0, 0.0, 0.0, 1.0));
        let flipped = DMat3::from_diagonal(DVec3::new(1.0, 1.0, -1.0));
        let (bcd, qfac) = quaternion_of(flipped).unwrap();
        assert_eq!(qfac, -1.0);
        assert!(bcd.iter().all(|v| v.abs() < 1e-12), "{bcd:?}");
        // A half turn about z: b = c = 0, d = 1.
        let half_turn = DMat3::from_diagonal(DVec3::new(-1.0, -1.0, 1.0));
        let (bcd, qfac) = quaternion_of(half_turn).unwrap();
        assert_eq!(qfac, 1.0);
        assert!((bcd[2].abs() - 1.0).abs() < 1e-12, "{bcd:?}");
        let sheared = DMat3::from_cols(DVec3::X, DVec3::new(0.6, 0.8, 0.0), DVec3::Z);
        assert!(quaternion_of(sheared).is_none());
    }
}
