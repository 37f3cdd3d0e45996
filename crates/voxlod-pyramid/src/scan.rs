//! A scanned volume opened for the levels (paper §4), held whole or read blockwise, window by
//! window ([`crate::blockwise`]). A scan for the threshold route is read blockwise when asked,
//! when it is a Zarr array, or when it is too large to hold ([`too_large_to_hold`]: as 32-bit
//! floats more than the narrow band's [`BAND_ABOVE_BYTES`], or, with its stored samples, more
//! than the memory limit); a scan filtered directly is held whole. The levels are the same
//! either way; the choice, and its reason ([`BlockwiseReason`]), decide only the peak memory.
//!
//! Beyond the paper (which holds the whole volume). Cost: opening reads the file's header; a
//! scan held whole is read by the caller.

use std::path::Path;

use serde::Serialize;
use voxlod_core::{memory, Frame, Grid, Volume, WorldTransform};
use voxlod_io::{BlockwiseVolume, RawLayout, VolumeFormat};

use crate::blockwise::BlockwiseScan;
use crate::error::PyramidError;
use crate::lod::BAND_ABOVE_BYTES;
use crate::source::{ScanRoute, Source};

/// Why a scan is read blockwise.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum BlockwiseReason {
    /// The caller asked for it.
    Asked,
    /// A Zarr array is always read blockwise.
    ZarrArray,
    /// The scan is too large to hold ([`too_large_to_hold`]).
    TooLarge,
}

/// A scanned volume ready to be a [`Source`].
pub enum Scan {
    /// Held whole.
    Whole {
        /// The samples.
        volume: Box<Volume>,
        /// Thresholded or filtered directly.
        route: ScanRoute,
    },
    /// Read window by window and thresholded ([`Source::BlockwiseThreshold`]).
    Blockwise {
        /// The scan.
        scan: Box<dyn BlockwiseScan>,
        /// The inside's lowest value, in the data's units.
        threshold: f32,
        /// Why it is read so.
        reason: BlockwiseReason,
    },
}

impl Scan {
    /// A scan read whole, entering by `route`.
    pub fn whole(volume: Volume, route: ScanRoute) -> Scan {
        Scan::Whole {
            volume: Box::new(volume),
            route,
        }
    }

    /// The scan at `path` (a headerless raw file described by `layout`) to read blockwise for
    /// `threshold`, or `None` when it is to be read whole (by the caller, whose reader then
    /// gives the errors about a broken file). `asked` asks for blockwise reading: refused
    /// without a threshold ([`PyramidError::BlockwiseNeedsThreshold`]) and for a file whose
    /// samples have no random access ([`PyramidError::NoRandomAccess`]). Its grid is checked
    /// against 32-bit mesh coordinates when its source is prepared ([`Source::prepare`]).
    pub fn open_blockwise(
        path: &Path,
        layout: Option<&RawLayout>,
        threshold: Option<f32>,
        asked: bool,
    ) -> Result<Option<Scan>, PyramidError> {
        let Some(threshold) = threshold else {
            return match asked {
                true => Err(PyramidError::BlockwiseNeedsThreshold),
                false => Ok(None),
            };
        };
        let blockwise = |scan: Box<dyn BlockwiseScan>, reason| {
            Ok(Some(Scan::Blockwise {
                scan,
                threshold,
                reason,
            }))
        };
        if voxlod_io::volume_format_of(path).ok() == Some(VolumeFormat::Zarr) {
            let zarr = voxlod_io::open_zarr(path)?;
            return blockwise(Box::new(zarr), BlockwiseReason::ZarrArray);
        }
        match voxlod_io::open_volume_blockwise(path, layout) {
            Ok(Some(scan)) if asked => blockwise(Box::new(scan), BlockwiseReason::Asked),
            Ok(Some(scan)) if too_large_to_hold(&scan) => {
                blockwise(Box::new(scan), BlockwiseReason::TooLarge)
            }
            Ok(None) if asked => Err(PyramidError::NoRandomAccess),
            Err(e) if asked => Err(e.into()),
            _ => Ok(None),
        }
    }

    /// The scan as the levels' source.
    pub fn source(&self) -> Source<'_> {
        match self {
            Scan::Whole { volume, route } => route.source(volume),
            Scan::Blockwise {
                scan, threshold, ..
            } => Source::BlockwiseThreshold {
                scan: scan.as_ref(),
                threshold: *threshold,
            },
        }
    }

    /// The whole scan's grid.
    pub fn grid(&self) -> Grid {
        match self {
            Scan::Whole { volume, .. } => volume.grid,
            Scan::Blockwise { scan, .. } => scan.grid(),
        }
    }

    /// Why the scan is read blockwise; `None` when it is held whole.
    pub fn blockwise_reason(&self) -> Option<BlockwiseReason> {
        match self {
            Scan::Whole { .. } => None,
            Scan::Blockwise { reason, .. } => Some(*reason),
        }
    }

    /// The scan's index-to-world transform in `frame` (its own when `None`): where the levels'
    /// meshes are, with [`crate::LodOptions::frame`] the same `frame`.
    pub fn world(&self, frame: Option<Frame>) -> WorldTransform {
        let world = match self {
            Scan::Whole { volume, .. } => volume.world(),
            Scan::Blockwise { scan, .. } => WorldTransform::of(&scan.grid(), &scan.orientation()),
        };
        frame.map_or(world, |f| world.in_frame(f))
    }
}

/// Whether a scan is better read blockwise: as 32-bit floats it would take more than the
/// narrow band's [`BAND_ABOVE_BYTES`], or, with its stored samples, more than the memory limit.
pub fn too_large_to_hold(scan: &BlockwiseVolume) -> bool {
    let count = scan.grid().len() as u64;
    let dense = count.saturating_mul(4);
    let read = dense.saturating_add(count.saturating_mul(scan.sample_bytes() as u64));
    dense > BAND_ABOVE_BYTES || memory::check_allocation("the volume", read).is_err()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small NRRD is read whole unless asked; asked, it is read blockwise and gives the same
    /// world; asking without a threshold, or for a compressed file, is refused.
    #[test]
    fn blockwise_reading_is_chosen_and_refused_as_documented() {
        let dir = std::env::temp_dir().join(format!("voxlod-scan-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let grid = Grid::new([6, 5, 4], [0.5, 0.5, 2.0], [1.0, 2.0, 3.0]).unwrap();
        let volume = Volume::filled(grid, 3.0, "test").unwrap();
        let (plain, packed) = (dir.join("v.nrrd"), dir.join("v-gz.nrrd"));
        voxlod_io::write_volume(&plain, &volume).unwrap();
        let gzip = voxlod_io::VolumeWriteOptions { compress: true };
        voxlod_io::write_volume_with(&packed, &volume, &gzip).unwrap();
        assert!(Scan::open_blockwise(&plain, None, Some(1.0), false)
            .unwrap()
            .is_none());
        let scan = Scan::open_blockwise(&plain, None, Some(1.0), true)
            .unwrap()
            .unwrap();
        assert_eq!(scan.blockwise_reason(), Some(BlockwiseReason::Asked));
        assert_eq!(scan.grid(), volume.grid);
        let whole = Scan::whole(volume, ScanRoute::Threshold(1.0));
        assert_eq!(scan.world(None), whole.world(None));
        assert!(matches!(
            Scan::open_blockwise(&plain, None, None, true),
            Err(PyramidError::BlockwiseNeedsThreshold)
        ));
        assert!(matches!(
            Scan::open_blockwise(&packed, None, Some(1.0), true),
            Err(PyramidError::NoRandomAccess)
        ));
        assert!(Scan::open_blockwise(&packed, None, Some(1.0), false)
            .unwrap()
            .is_none());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
