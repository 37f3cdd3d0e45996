//! What stored samples are decoded into: `f32` samples for volumes ([`AsSamples`]), or exact
//! unsigned 32-bit labels for label maps ([`AsLabels`]), so that every volume reader decodes
//! straight from the file's bytes into the one buffer it returns, whichever is asked for.
//!
//! A label is a whole number from 0 to 4294967295. Unsigned 8-, 16- and 32-bit samples are
//! labels as they are; signed ones are labels unless negative; 64-bit ones unless above
//! 4294967295; floating-point ones only when whole (no fraction, not NaN or infinite) and in
//! that range. The first sample of a block that is not a label stops the decoding with its
//! position and its value as stored ([`BadLabel`]); the reader turns it into an error naming the
//! file and the voxel ([`BadLabel::error`]). NIfTI's `scl_slope`/`scl_inter` are applied in
//! `f64` before that test ([`AsLabels::scale`]), so scaled labels are accepted exactly when the
//! scaled value is a whole number in range.
//!
//! Cost: O(n) for n samples, one pass, no allocation.

use std::fmt::Display;
use std::path::Path;

use crate::samples::{decode_into, SampleType};
use crate::{Endian, IoError};

/// The words of every refused label, after its value and voxel.
pub(crate) const LABEL_RANGE: &str = "labels are whole numbers from 0 to 4294967295";

/// A stored sample that is not a label: where it is in the block being decoded, and its value
/// as the file holds it (with the scaling, when one was applied).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct BadLabel {
    /// Index of the sample in the block (the caller adds the block's first index).
    pub(crate) at: usize,
    /// The value, in the words of the message ("-3", "2.5", "NaN").
    pub(crate) shown: String,
}

impl BadLabel {
    /// The error about voxel `first + self.at` of a map of `dims` (x fastest) in `path`:
    /// "label -3 at (4, 0, 2): labels are whole numbers from 0 to 4294967295".
    pub(crate) fn error(&self, path: &Path, dims: [usize; 3], first: usize) -> IoError {
        let n = first + self.at;
        let [nx, ny, _] = dims;
        let (i, j, k) = (
            n % nx.max(1),
            n / nx.max(1) % ny.max(1),
            n / (nx * ny).max(1),
        );
        IoError::malformed(
            path,
            format!("label {} at ({i}, {j}, {k}): {LABEL_RANGE}", self.shown),
        )
    }
}

/// A stored sample type and how its values become labels.
pub(crate) trait Stored: Copy + Display {
    /// The label, if the value is a whole number from 0 to 2³²−1.
    fn label(self) -> Option<u32>;
    /// The value as `f64` (exact up to 2⁵³), for scaling.
    fn wide(self) -> f64;
}

macro_rules! stored_integer {
    ($($t:ty),*) => {$(
        impl Stored for $t {
            #[inline]
            fn label(self) -> Option<u32> {
                u32::try_from(self).ok()
            }
            #[inline]
            fn wide(self) -> f64 {
                self as f64
            }
        }
    )*};
}
stored_integer!(u8, i8, u16, i16, u32, i32, u64, i64);

impl Stored for f32 {
    #[inline]
    fn label(self) -> Option<u32> {
        f64::from(self).label()
    }
    #[inline]
    fn wide(self) -> f64 {
        f64::from(self)
    }
}

impl Stored for f64 {
    #[inline]
    fn label(self) -> Option<u32> {
        // NaN fails both comparisons; the fraction test rules out infinities too.
        (self >= 0.0 && self <= u32::MAX as f64 && self.fract() == 0.0).then_some(self as u32)
    }
    #[inline]
    fn wide(self) -> f64 {
        self
    }
}

/// Labels of `values` into `out` (as many as both hold): the first value that is not a label
/// stops with its index.
pub(crate) fn labels_of<S: Stored>(values: &[S], out: &mut [u32]) -> Result<(), BadLabel> {
    plain_labels_of(values.iter().copied(), out)
}

/// As [`labels_of`], each value first scaled to `value × slope + inter` in `f64`.
fn scaled_labels_of<S: Stored>(
    values: impl Iterator<Item = S>,
    (slope, inter): (f64, f64),
    out: &mut [u32],
) -> Result<(), BadLabel> {
    for (at, (o, v)) in out.iter_mut().zip(values).enumerate() {
        let scaled = v.wide() * slope + inter;
        *o = scaled.label().ok_or_else(|| BadLabel {
            at,
            shown: format!(
                "{scaled} (stored {v}, scaled by scl_slope {slope} and scl_inter {inter})"
            ),
        })?;
    }
    Ok(())
}

/// What a reader decodes its samples into.
pub(crate) trait DecodeTarget: Sync {
    /// One decoded sample.
    type Item: Copy + Default + Send + Sync;
    /// Decodes the whole samples of `bytes` into `out` (as many as both hold).
    fn decode(
        &self,
        bytes: &[u8],
        ty: SampleType,
        endian: Endian,
        out: &mut [Self::Item],
    ) -> Result<(), BadLabel>;
}

/// `f32` samples, as [`crate::read_volume`] returns them (never fails).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct AsSamples;

impl DecodeTarget for AsSamples {
    type Item = f32;
    fn decode(
        &self,
        bytes: &[u8],
        ty: SampleType,
        endian: Endian,
        out: &mut [f32],
    ) -> Result<(), BadLabel> {
        decode_into(bytes, ty, endian, out);
        Ok(())
    }
}

/// Exact `u32` labels (see the module documentation).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct AsLabels {
    /// NIfTI's `(scl_slope, scl_inter)`, when they are not the identity.
    pub(crate) scale: Option<(f64, f64)>,
}

impl DecodeTarget for AsLabels {
    type Item = u32;
    fn decode(
        &self,
        bytes: &[u8],
        ty: SampleType,
        endian: Endian,
        out: &mut [u32],
    ) -> Result<(), BadLabel> {
        macro_rules! convert {
            ($t:ty, $n:literal) => {{
                let values = bytes.chunks_exact($n).map(|c| {
                    let raw: [u8; $n] = c.try_into().expect("chunks_exact gives whole samples");
                    match endian {
                        Endian::Little => <$t>::from_le_bytes(raw),
                        Endian::Big => <$t>::from_be_bytes(raw),
                    }
                });
                match self.scale {
                    Some(scale) => scaled_labels_of(values, scale, out),
                    None => plain_labels_of(values, out),
                }
            }};
        }
        match ty {
            SampleType::U8 => convert!(u8, 1),
            SampleType::I8 => convert!(i8, 1),
            SampleType::U16 => convert!(u16, 2),
            SampleType::I16 => convert!(i16, 2),
            SampleType::U32 => convert!(u32, 4),
            SampleType::I32 => convert!(i32, 4),
            SampleType::U64 => convert!(u64, 8),
            SampleType::I64 => convert!(i64, 8),
            SampleType::F32 => convert!(f32, 4),
            SampleType::F64 => convert!(f64, 8),
        }
    }
}

/// [`labels_of`] over an iterator (the decoded samples of a block).
#[inline]
fn plain_labels_of<S: Stored>(
    values: impl Iterator<Item = S>,
    out: &mut [u32],
) -> Result<(), BadLabel> {
    for (at, (o, v)) in out.iter_mut().zip(values).enumerate() {
        *o = v.label().ok_or_else(|| BadLabel {
            at,
            shown: v.to_string(),
        })?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn labels(bytes: &[u8], ty: SampleType, endian: Endian) -> Result<Vec<u32>, BadLabel> {
        let mut out = vec![0; bytes.len() / ty.size()];
        AsLabels::default().decode(bytes, ty, endian, &mut out)?;
        Ok(out)
    }

    #[test]
    fn every_type_gives_its_labels_exactly() {
        let big = u32::MAX;
        let bytes: Vec<u8> = [0u32, 1, (1 << 24) + 1, big]
            .iter()
            .flat_map(|v| v.to_be_bytes())
            .collect();
        assert_eq!(
            labels(&bytes, SampleType::U32, Endian::Big).unwrap(),
            [0, 1, (1 << 24) + 1, big]
        );
        let bytes: Vec<u8> = [7i64, i64::from(big)]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        assert_eq!(
            labels(&bytes, SampleType::I64, Endian::Little).unwrap(),
            [7, big]
        );
        let bytes: Vec<u8> = [3.0f64, 4294967295.0]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        assert_eq!(
            labels(&bytes, SampleType::F64, Endian::Little).unwrap(),
            [3, big]
        );
        assert_eq!(
            labels(&[0xff, 0x7f], SampleType::I8, Endian::Little).unwrap_err(),
            BadLabel {
                at: 0,
                shown: "-1".into()
            }
        );
    }

    #[test]
    fn values_that_are_not_labels_are_named() {
        let cases: Vec<(Vec<u8>, SampleType, &str)> = vec![
            ((-3i16).to_le_bytes().to_vec(), SampleType::I16, "-3"),
            (2.5f32.to_le_bytes().to_vec(), SampleType::F32, "2.5"),
            (f32::NAN.to_le_bytes().to_vec(), SampleType::F32, "NaN"),
            (f64::INFINITY.to_le_bytes().to_vec(), SampleType::F64, "inf"),
            (
                4294967296u64.to_le_bytes().to_vec(),
                SampleType::U64,
                "4294967296",
            ),
            (
                (-4294967296i64).to_le_bytes().to_vec(),
                SampleType::I64,
                "-4294967296",
            ),
            (
                4294967296.0f64.to_le_bytes().to_vec(),
                SampleType::F64,
                "4294967296",
            ),
        ];
        for (bytes, ty, shown) in cases {
            let mut all = vec![0u8; ty.size()];
            all.extend(&bytes);
            let bad = labels(&all, ty, Endian::Little).unwrap_err();
            assert_eq!((bad.at, bad.shown.as_str()), (1, shown), "{ty:?}");
        }
        let e = BadLabel {
            at: 3,
            shown: "-3".into(),
        }
        .error(Path::new("m.nrrd"), [5, 2, 3], 21);
        assert_eq!(
            e.to_string(),
            "m.nrrd: label -3 at (4, 0, 2): labels are whole numbers from 0 to 4294967295"
        );
    }

    #[test]
    fn scaled_labels_are_kept_only_when_whole() {
        let scaled = AsLabels {
            scale: Some((2.0, 1.0)),
        };
        let mut out = [0u32; 2];
        scaled
            .decode(&[3, 0, 4, 0], SampleType::U16, Endian::Little, &mut out)
            .unwrap();
        assert_eq!(out, [7, 9]);
        let half = AsLabels {
            scale: Some((0.5, 0.0)),
        };
        let bad = half
            .decode(&[4, 0, 5, 0], SampleType::U16, Endian::Little, &mut out)
            .unwrap_err();
        assert_eq!(bad.at, 1);
        assert!(bad
            .shown
            .starts_with("2.5 (stored 5, scaled by scl_slope 0.5"));
    }
}
