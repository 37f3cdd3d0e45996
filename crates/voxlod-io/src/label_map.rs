//! Label maps (segmentations) in and out as exact unsigned 32-bit labels
//! ([`voxlod_core::LabelVolume`]), in every volume format [`crate::read_volume`] reads.
//!
//! Reading decodes the file's samples straight into `u32` labels (`decode_target.rs`), never
//! through `f32` (exact only up to 2²⁴) and never holding a `f32` copy of the map: NRRD (raw,
//! gzip, ascii; attached or detached), MetaImage (plain or zlib; local or detached), raw files
//! with a [`RawLayout`] (block by block on all threads, or as they are inflated), NIfTI-1 (`.nii`,
//! `.nii.gz`; a `scl_slope`/`scl_inter` other than the identity is applied, and the map read only
//! when every scaled value is a whole label), VTK images (`.vti`, legacy `.vtk`, through vtkio's
//! model), Zarr arrays and OME-Zarr images (one layer of chunks at a time) and DICOM
//! Segmentations (`dicom/seg.rs`). A DICOM series that is not a SEG is read as a volume and its
//! samples taken as labels (exact up to 2²⁴, which its 8- to 16-bit pixels never exceed).
//!
//! Unsigned 8-, 16- and 32-bit samples are labels as stored; signed ones unless negative; 64-bit
//! ones unless above 4294967295; floating-point ones only when every sample is a whole number in
//! that range. A sample that is not a label is an [`IoError`] naming the file, the voxel and the
//! value ("label -3 at (4, 0, 2): labels are whole numbers from 0 to 4294967295"). A map with a
//! fourth axis longer than one is refused naming the axis, an empty map (a zero dimension) as
//! malformed, and every size read from a header meets the memory budget
//! (`voxlod_core::memory::check_allocation`) before the map is allocated.
//!
//! Writing ([`write_label_map`]) gives raw `uint32` NRRD (`.nrrd`) or NIfTI-1 `uint32` (`.nii`,
//! `.nii.gz`), placed as [`crate::write_volume`] places a volume.
//!
//! Not in the voxel paper (He et al. 1995), which meshes one object per volume: the way in for
//! segmentations, whose labels (up to 2³²−1) `f32` samples would not hold exactly.
//! Cost: O(N) for N voxels; memory at the peak the map's 4N bytes plus one block of stored
//! samples per thread (VTK: plus vtkio's model of the file; Zarr: plus one layer of chunks).

use std::path::Path;

use voxlod_core::LabelVolume;

use crate::vtk::Flavor;
use crate::{
    check_readable, find_dicom_seg, read_dicom_seg, read_dicom_series, read_label_table,
    volume_format_of, DicomOptions, IoError, LabelMap, OutputSet, RawLayout, VolumeFormat,
};

/// Reads a label map: a DICOM Segmentation (a SEG file, or a folder holding one) by
/// `dicom/seg.rs`, any other volume format as exact `u32` labels (see the module
/// documentation) with the table of [`read_label_table`]. Headerless raw files need
/// [`read_label_map_with`].
///
/// ```
/// use voxlod_core::{Grid, LabelVolume};
/// use voxlod_io::{read_label_map, write_label_map};
///
/// let folder = tempfile::tempdir()?;
/// let grid = Grid::new([2, 2, 1], [0.5; 3], [1.0, 2.0, 3.0])?;
/// let map = LabelVolume::from_vec(grid, vec![0, 1, (1 << 24) + 1, u32::MAX])?;
/// for name in ["m.nrrd", "m.nii.gz"] {
///     let path = folder.path().join(name);
///     write_label_map(&path, &map)?;
///     assert_eq!(read_label_map(&path)?.labels.values, map.values);
/// }
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn read_label_map(path: &Path) -> Result<LabelMap, IoError> {
    read_label_map_with(path, None)
}

/// [`read_label_map`], with the layout of a headerless raw file (ignored for other formats, as
/// [`crate::read_volume`] ignores it).
pub fn read_label_map_with(path: &Path, raw: Option<&RawLayout>) -> Result<LabelMap, IoError> {
    if raw.is_none() && find_dicom_seg(path)?.is_some() {
        return read_dicom_seg(path);
    }
    Ok(LabelMap {
        labels: read_labels(path, raw)?,
        table: read_label_table(path)?,
        warnings: Vec::new(),
    })
}

/// The labels of any volume format, by [`volume_format_of`] (raw with a layout).
fn read_labels(path: &Path, raw: Option<&RawLayout>) -> Result<LabelVolume, IoError> {
    let format = match volume_format_of(path) {
        Ok(format) => format,
        Err(_) if raw.is_some() => VolumeFormat::Raw,
        Err(e) => return Err(e),
    };
    if !matches!(format, VolumeFormat::Dicom | VolumeFormat::Zarr) {
        check_readable(path)?;
    }
    match format {
        VolumeFormat::Dicom => {
            let volume = read_dicom_series(&[path.to_path_buf()], &DicomOptions::default())?;
            LabelVolume::from_volume(&volume).map_err(|e| IoError::from_core(path, e))
        }
        VolumeFormat::Zarr => crate::open_zarr(path)?.read_labels(),
        VolumeFormat::Nrrd | VolumeFormat::Nhdr => crate::nrrd::read_labels(path),
        VolumeFormat::Vti => crate::vtk::image::read_labels(path, Flavor::Xml),
        VolumeFormat::Vtk => crate::vtk::image::read_labels(path, Flavor::Legacy),
        VolumeFormat::Nifti => crate::nifti::read_labels(path),
        VolumeFormat::Mha | VolumeFormat::Mhd => crate::metaimage::read_labels(path),
        VolumeFormat::Raw => match raw {
            Some(layout) => crate::raw::read_labels(path, layout),
            None => Err(IoError::unsupported(
                path,
                "a headerless raw label map needs its layout (dimensions, sample type, byte order)",
            )),
        },
    }
}

/// Writes a label map by extension: `.nrrd` (raw little-endian `uint32`) or `.nii`/`.nii.gz`
/// (NIfTI-1 `uint32`, gzip by the name), with the geometry [`crate::write_volume`] writes. Any
/// other extension is refused before a file is touched. Atomic, as every writer here
/// ([`OutputSet::label_map`]).
pub fn write_label_map(path: &Path, labels: &LabelVolume) -> Result<(), IoError> {
    let mut set = OutputSet::new();
    set.label_map(path, labels)?;
    set.commit()
}
