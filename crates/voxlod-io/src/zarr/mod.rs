//! Zarr arrays (format 2 and 3) and OME-Zarr multiscale images (0.4 and 0.5) as volumes, read
//! whole or region by region, through the `zarrs` crate.
//!
//! **What is read.** A path that holds a Zarr array (`zarr.json` with `node_type: array`, or
//! `.zarray`) is that array. A group (`zarr.json` with `node_type: group`, or `.zgroup`) must carry
//! OME-Zarr `multiscales` metadata (0.5 under `attributes.ome`, 0.4 in `.zattrs`): its first
//! dataset, the highest resolution, is read. A group without it is refused (it does not say which
//! array is the image). The axes are named by OME-Zarr's `axes`, else by the array's dimension
//! names (v3 `dimension_names`, v2 xarray `_ARRAY_DIMENSIONS`), else the last three dimensions
//! are z, y, x as OME-Zarr orders them. The array's x axis becomes ours (fastest), so a C-order
//! `z, y, x` array maps onto a [`Volume`] without reordering; other orders are transposed. Axes
//! besides x, y, z (time, channel) must hold one value.
//!
//! **Geometry.** OME-Zarr's `scale` and `translation` of the dataset, then those of the whole
//! multiscale, give spacing and origin; an axis `unit` of micrometres, nanometres, metres … turns
//! them into millimetres, like the other readers. Plain arrays have unit spacing and origin 0.
//!
//! **Samples.** uint8, int8, uint16, int16, uint32, int32, uint64, int64, float32 and float64,
//! converted to `f32`, or for a label map ([`ZarrVolume::read_labels`]) to exact `u32` labels
//! (`decode_target.rs`), one layer of chunks at a time; any other type is refused naming it. A chunk missing from the store reads as the
//! array's fill value (Zarr's rule), chunks at the upper edges may be partial (zarrs cuts them),
//! and a codec voxlod's build of zarrs lacks is refused naming it. Codecs built in: gzip, zlib
//! (v2), zstd, blosc (v2 and v3), crc32c, transpose, sharding.
//!
//! Not in the voxel paper (He et al. 1995): it is the way in for the chunked stacks of micro-CT
//! and connectomics. **Cost.** Reading a region decodes every chunk it touches (whole chunks:
//! zarrs decodes a compressed chunk entirely), O(chunk bytes); memory is the region's stored
//! samples plus its `f32` copy, checked against the budget first.

mod errors;
pub(crate) mod write;

use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde_json::Value;
use voxlod_core::{memory, Grid, LabelVolume, Volume};
use zarrs::array::{Array, ArrayError, DataType};
use zarrs::array_subset::ArraySubset;
use zarrs::filesystem::FilesystemStore;

use crate::decode_target::{labels_of, BadLabel};
use crate::samples::{self, SampleType};
use crate::{IoError, IoErrorKind};

/// The sample types voxlod reads from Zarr, for messages.
const SUPPORTED_TYPES: &str =
    "uint8, int8, uint16, int16, uint32, int32, uint64, int64, float32, float64";

/// A Zarr array opened as a volume: its geometry is known, its samples are read on demand,
/// region by region ([`ZarrVolume::read_region`]) or whole ([`ZarrVolume::read_all`]).
pub struct ZarrVolume {
    path: PathBuf,
    array: Array<FilesystemStore>,
    /// Array dimension of x, y and z.
    spatial: [usize; 3],
    sample: SampleType,
    grid: Grid,
    chunk: [usize; 3],
    /// Where the array sits in the store ("/" or the dataset's path), for messages.
    array_path: String,
}

/// Opens the Zarr array or OME-Zarr image at `path` (a folder) without reading its samples.
pub fn open_zarr(path: &Path) -> Result<ZarrVolume, IoError> {
    let meta = std::fs::metadata(path).map_err(|e| IoError::access(path, "cannot open", &e))?;
    if !meta.is_dir() {
        return Err(IoError::malformed(
            path,
            "a Zarr store is a folder (holding zarr.json, or .zarray/.zgroup), not a file",
        ));
    }
    let node = Node::find(path)?;
    let (array_path, ome) = match node {
        Node::Array => ("/".to_string(), None),
        Node::Group(attributes) => {
            let multiscale = multiscale_of(path, &attributes)?;
            (dataset_path(path, &multiscale)?, Some(multiscale))
        }
    };
    let store = FilesystemStore::new(path).map_err(|_| {
        IoError::new(
            path,
            IoErrorKind::Access,
            "cannot open the folder as a Zarr store",
        )
    })?;
    let array = Array::open(Arc::new(store), &array_path)
        .map_err(|e| crate::zarr::errors::opening(path, &array_path, e))?;
    let sample = sample_type(path, array.data_type())?;
    let names = axis_names(&array, ome.as_ref());
    let shape: Vec<u64> = array.shape().to_vec();
    let spatial = spatial_axes(path, &shape, names.as_deref())?;
    let dims = spatial.map(|d| shape[d] as usize);
    let (spacing, origin) = match &ome {
        Some(m) => ome_geometry(path, m, &shape, spatial)?,
        None => ([1.0; 3], [0.0; 3]),
    };
    samples::check_geometry(path, spacing, origin)?;
    let grid = Grid::new(dims, spacing, origin).map_err(|e| IoError::from_core(path, e))?;
    let chunk = chunk_shape(path, &array, spatial, sample)?;
    Ok(ZarrVolume {
        path: path.to_path_buf(),
        array,
        spatial,
        sample,
        grid,
        chunk,
        array_path,
    })
}

impl ZarrVolume {
    /// The samples' grid: dimensions x, y, z, spacing and origin (millimetres when the file
    /// names a unit).
    pub fn grid(&self) -> Grid {
        self.grid
    }

    /// Samples per chunk along x, y, z (the first chunk's; edge chunks may be cut).
    pub fn chunk_shape(&self) -> [usize; 3] {
        self.chunk
    }

    /// The stored sample type, as Zarr names it ("uint8", …).
    pub fn sample_type(&self) -> &'static str {
        self.sample.name()
    }

    /// Bytes one stored sample takes.
    pub fn sample_bytes(&self) -> usize {
        self.sample.size()
    }

    /// The store's folder.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Every sample, as one volume (checked against the memory budget first).
    pub fn read_all(&self) -> Result<Volume, IoError> {
        self.read_region([0; 3], self.grid.dims)
    }

    /// The samples `start .. start + dims` (x, y, z indices) as a volume whose grid is the
    /// region's: same spacing, origin moved to the region's first sample. The region must lie
    /// inside the array; its size is checked against the memory budget before reading.
    pub fn read_region(&self, start: [usize; 3], dims: [usize; 3]) -> Result<Volume, IoError> {
        let whole = self.grid.dims;
        if (0..3).any(|a| dims[a] == 0 || start[a] + dims[a] > whole[a]) {
            return Err(IoError::malformed(
                &self.path,
                format!(
                    "the region from sample ({}, {}, {}) of {}x{}x{} samples is not inside the \
                     {}x{}x{} array",
                    start[0],
                    start[1],
                    start[2],
                    dims[0],
                    dims[1],
                    dims[2],
                    whole[0],
                    whole[1],
                    whole[2]
                ),
            ));
        }
        let (count, _) = samples::check_volume_size(&self.path, dims, self.sample)?;
        let stored = self.retrieve(&self.subset(start, dims))?;
        let values = reorder(stored, dims, self.spatial, self.array.shape().len());
        debug_assert_eq!(values.len(), count);
        let origin =
            [0, 1, 2].map(|a| self.grid.origin[a] + start[a] as f64 * self.grid.spacing[a]);
        let grid = Grid::new(dims, self.grid.spacing, origin)
            .map_err(|e| IoError::from_core(&self.path, e))?;
        Volume::from_vec(grid, values).map_err(|e| IoError::from_core(&self.path, e))
    }

    /// Every sample as an exact `u32` label (`decode_target.rs`), read one layer of chunks
    /// (the chunks' depth along z) at a time, so that the peak is the labels plus one layer of
    /// stored samples (both checked against the memory budget first). A value that is not a
    /// label is refused naming its voxel; so is an empty array.
    pub fn read_labels(&self) -> Result<LabelVolume, IoError> {
        let path = self.path.as_path();
        let dims = self.grid.dims;
        let (count, _) = samples::check_decoded_size(path, dims, self.sample, "label map")?;
        let [nx, ny, nz] = dims;
        let depth = self.chunk[2].clamp(1, nz);
        let layer = (nx * ny).saturating_mul(depth);
        let what = format!("one layer of {nx}x{ny}x{depth} stored samples");
        let layer_bytes =
            memory::bytes_of::<u8>(layer).saturating_mul(2 * self.sample.size() as u64);
        crate::budget::check_bytes(path, &what, layer_bytes)?;
        let mut values = vec![0u32; count];
        for (n, out) in values.chunks_mut(layer).enumerate() {
            let z = n * depth;
            let region = [nx, ny, out.len() / (nx * ny)];
            let subset = self.subset([0, 0, z], region);
            self.retrieve_labels(&subset, region, out)
                .map_err(|e| e.unwrap_or_else(|bad| bad.error(path, dims, z * nx * ny)))?;
        }
        LabelVolume::from_vec(self.grid, values).map_err(|e| IoError::from_core(path, e))
    }

    /// The array subset of the region `start .. start + dims` (x, y, z), one value along the
    /// other dimensions.
    fn subset(&self, start: [usize; 3], dims: [usize; 3]) -> ArraySubset {
        let mut ranges: Vec<std::ops::Range<u64>> = vec![0..1; self.array.shape().len()];
        for a in 0..3 {
            let (s, n) = (start[a] as u64, dims[a] as u64);
            ranges[self.spatial[a]] = s..s + n;
        }
        ArraySubset::new_with_ranges(&ranges)
    }

    /// The labels of the subset (a region of `dims`) into `out`, x fastest: a Zarr failure,
    /// or the first value that is not a label.
    fn retrieve_labels(
        &self,
        subset: &ArraySubset,
        dims: [usize; 3],
        out: &mut [u32],
    ) -> Result<(), Result<IoError, BadLabel>> {
        let ndim = self.array.shape().len();
        let failed = |e| {
            Ok(crate::zarr::errors::reading(
                &self.path,
                &self.array_path,
                e,
            ))
        };
        macro_rules! labels {
            ($t:ty) => {{
                let stored = self
                    .array
                    .retrieve_array_subset_elements::<$t>(subset)
                    .map_err(failed)?;
                labels_of(&reorder(stored, dims, self.spatial, ndim), out).map_err(Err)
            }};
        }
        match self.sample {
            SampleType::U8 => labels!(u8),
            SampleType::I8 => labels!(i8),
            SampleType::U16 => labels!(u16),
            SampleType::I16 => labels!(i16),
            SampleType::U32 => labels!(u32),
            SampleType::I32 => labels!(i32),
            SampleType::U64 => labels!(u64),
            SampleType::I64 => labels!(i64),
            SampleType::F32 => labels!(f32),
            SampleType::F64 => labels!(f64),
        }
    }

    /// The subset's samples as `f32`, in the array's C order.
    fn retrieve(&self, subset: &ArraySubset) -> Result<Vec<f32>, IoError> {
        macro_rules! elements {
            ($t:ty) => {
                self.array
                    .retrieve_array_subset_elements::<$t>(subset)
                    .map(|v| v.into_iter().map(|x| x as f32).collect())
            };
        }
        let result: Result<Vec<f32>, ArrayError> = match self.sample {
            SampleType::U8 => elements!(u8),
            SampleType::I8 => elements!(i8),
            SampleType::U16 => elements!(u16),
            SampleType::I16 => elements!(i16),
            SampleType::U32 => elements!(u32),
            SampleType::I32 => elements!(i32),
            SampleType::U64 => elements!(u64),
            SampleType::I64 => elements!(i64),
            SampleType::F32 => self.array.retrieve_array_subset_elements::<f32>(subset),
            SampleType::F64 => elements!(f64),
        };
        result.map_err(|e| crate::zarr::errors::reading(&self.path, &self.array_path, e))
    }
}

/// Samples in the array's C order over `ndim` dimensions (one value on the non-spatial ones)
/// to x-fastest order: a plain move when the array's last three dimensions are z, y, x.
fn reorder<T: Copy>(stored: Vec<T>, dims: [usize; 3], spatial: [usize; 3], ndim: usize) -> Vec<T> {
    if spatial == [ndim - 1, ndim - 2, ndim - 3] {
        return stored;
    }
    // C-order strides of the subset: a dimension's stride is the product of the later ones.
    let mut extent = vec![1usize; ndim];
    for a in 0..3 {
        extent[spatial[a]] = dims[a];
    }
    let mut stride = vec![1usize; ndim];
    for d in (0..ndim.saturating_sub(1)).rev() {
        stride[d] = stride[d + 1] * extent[d + 1];
    }
    let s = spatial.map(|d| stride[d]);
    let mut out = Vec::with_capacity(stored.len());
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                out.push(stored[i * s[0] + j * s[1] + k * s[2]]);
            }
        }
    }
    out
}

/// What the store's root is.
enum Node {
    Array,
    /// A group, with its attributes (v3 `attributes`, v2 `.zattrs`).
    Group(Value),
}

impl Node {
    fn find(path: &Path) -> Result<Node, IoError> {
        let v3 = path.join("zarr.json");
        if v3.is_file() {
            let json = read_json(&v3)?;
            return match json.get("node_type").and_then(Value::as_str) {
                Some("array") => Ok(Node::Array),
                Some("group") => Ok(Node::Group(
                    json.get("attributes").cloned().unwrap_or(Value::Null),
                )),
                _ => Err(IoError::malformed(
                    &v3,
                    "zarr.json has no node_type of \"array\" or \"group\"",
                )),
            };
        }
        if path.join(".zarray").is_file() {
            return Ok(Node::Array);
        }
        if path.join(".zgroup").is_file() {
            let attrs = path.join(".zattrs");
            let attributes = if attrs.is_file() {
                read_json(&attrs)?
            } else {
                Value::Null
            };
            return Ok(Node::Group(attributes));
        }
        Err(IoError::malformed(
            path,
            "not a Zarr store: the folder holds no zarr.json, .zarray or .zgroup",
        ))
    }
}

/// A small JSON metadata file, parsed.
pub(crate) fn read_json(path: &Path) -> Result<Value, IoError> {
    let bytes = crate::read_file(path)?;
    serde_json::from_slice(&bytes).map_err(|e| {
        IoError::malformed(
            path,
            format!("not valid JSON (line {}, column {})", e.line(), e.column()),
        )
    })
}

/// The first entry of OME-Zarr's `multiscales` (0.5 under `ome`, 0.4 at the top).
fn multiscale_of(path: &Path, attributes: &Value) -> Result<Value, IoError> {
    let list = attributes
        .get("ome")
        .and_then(|o| o.get("multiscales"))
        .or_else(|| attributes.get("multiscales"));
    match list.and_then(Value::as_array).and_then(|l| l.first()) {
        Some(m) => Ok(m.clone()),
        None => Err(IoError::unsupported(
            path,
            "a Zarr group without OME-Zarr multiscales metadata: it does not say which of its \
             arrays is the image; give the path of the array itself",
        )),
    }
}

/// The path of the multiscale's first (highest resolution) dataset.
fn dataset_path(path: &Path, multiscale: &Value) -> Result<String, IoError> {
    let dataset = multiscale
        .get("datasets")
        .and_then(Value::as_array)
        .and_then(|d| d.first())
        .and_then(|d| d.get("path"))
        .and_then(Value::as_str);
    match dataset {
        Some(p) if !p.is_empty() && !p.split('/').any(|s| s == "..") => {
            Ok(format!("/{}", p.trim_start_matches('/')))
        }
        _ => Err(IoError::malformed(
            path,
            "the OME-Zarr multiscales metadata names no dataset path",
        )),
    }
}

/// The sample type, or an error naming the one voxlod does not read.
fn sample_type(path: &Path, data_type: &DataType) -> Result<SampleType, IoError> {
    Ok(match data_type {
        DataType::UInt8 => SampleType::U8,
        DataType::Int8 => SampleType::I8,
        DataType::UInt16 => SampleType::U16,
        DataType::Int16 => SampleType::I16,
        DataType::UInt32 => SampleType::U32,
        DataType::Int32 => SampleType::I32,
        DataType::UInt64 => SampleType::U64,
        DataType::Int64 => SampleType::I64,
        DataType::Float32 => SampleType::F32,
        DataType::Float64 => SampleType::F64,
        other => {
            return Err(IoError::unsupported(
                path,
                format!(
                    "samples of type {} are not supported (voxlod reads {SUPPORTED_TYPES})",
                    other.name()
                ),
            ))
        }
    })
}

/// Axis names: OME-Zarr's `axes` (objects with `name`, or plain strings in 0.3), else the
/// array's dimension names (v3), else xarray's `_ARRAY_DIMENSIONS` (v2).
fn axis_names(array: &Array<FilesystemStore>, ome: Option<&Value>) -> Option<Vec<String>> {
    if let Some(axes) = ome.and_then(|m| m.get("axes")).and_then(Value::as_array) {
        return axes
            .iter()
            .map(|a| {
                a.get("name")
                    .and_then(Value::as_str)
                    .or_else(|| a.as_str())
                    .map(str::to_string)
            })
            .collect();
    }
    if let Some(names) = array.dimension_names() {
        return names
            .iter()
            .map(|n| n.clone().map(|s| s.to_string()))
            .collect();
    }
    array
        .attributes()
        .get("_ARRAY_DIMENSIONS")
        .and_then(Value::as_array)
        .and_then(|l| l.iter().map(|n| n.as_str().map(str::to_string)).collect())
}

/// The array dimensions of x, y and z; every other dimension must hold one value.
fn spatial_axes(
    path: &Path,
    shape: &[u64],
    names: Option<&[String]>,
) -> Result<[usize; 3], IoError> {
    let ndim = shape.len();
    if ndim < 3 {
        return Err(IoError::unsupported(
            path,
            format!("the array has {ndim} dimensions; a volume needs three (z, y, x)"),
        ));
    }
    let names = names.filter(|n| n.len() == ndim);
    let spatial = match names {
        Some(names) => {
            let find = |axis: &str| names.iter().position(|n| n.eq_ignore_ascii_case(axis));
            match (find("x"), find("y"), find("z")) {
                (Some(x), Some(y), Some(z)) => [x, y, z],
                _ => {
                    return Err(IoError::unsupported(
                        path,
                        format!(
                            "the axes are named {}; a volume needs axes named x, y and z",
                            names.join(", ")
                        ),
                    ))
                }
            }
        }
        None => [ndim - 1, ndim - 2, ndim - 3],
    };
    for (d, &n) in shape.iter().enumerate() {
        if !spatial.contains(&d) && n != 1 {
            let name = names.map_or_else(|| format!("{d}"), |n| format!("'{}'", n[d]));
            return Err(IoError::unsupported(
                path,
                format!(
                    "axis {name} holds {n} values; voxlod reads one 3-D volume, so every axis \
                     besides x, y and z must hold one"
                ),
            ));
        }
    }
    Ok(spatial)
}

/// Samples per chunk along x, y, z: the shape of the first chunk, whose decoded bytes are
/// checked against the memory budget (zarrs decodes a chunk whole, and multiplies its shape
/// without a check: a chunk shape from a broken file must not reach it).
fn chunk_shape(
    path: &Path,
    array: &Array<FilesystemStore>,
    spatial: [usize; 3],
    sample: SampleType,
) -> Result<[usize; 3], IoError> {
    let origin = vec![0u64; array.shape().len()];
    let shape = array.chunk_shape_usize(&origin).map_err(|_| {
        IoError::unsupported(
            path,
            "the array's chunk grid gives no shape for its first chunk",
        )
    })?;
    let shown: Vec<String> = shape.iter().map(usize::to_string).collect();
    let what = format!("one decoded chunk of {} samples", shown.join("x"));
    let bytes = shape
        .iter()
        .try_fold(sample.size() as u64, |acc, &n| acc.checked_mul(n as u64))
        .filter(|&b| usize::try_from(b).is_ok());
    let Some(bytes) = bytes else {
        return Err(IoError::new(
            path,
            IoErrorKind::TooLarge,
            format!("{what} has more bytes than memory can address"),
        ));
    };
    crate::budget::check_bytes(path, &what, bytes)?;
    Ok(spatial.map(|d| shape[d]))
}

/// Spacing and origin (x, y, z) from OME-Zarr's coordinate transformations: the first dataset's
/// scale and translation, then the multiscale's own, in millimetres when the axes name a unit.
fn ome_geometry(
    path: &Path,
    multiscale: &Value,
    shape: &[u64],
    spatial: [usize; 3],
) -> Result<([f64; 3], [f64; 3]), IoError> {
    let ndim = shape.len();
    let dataset = multiscale
        .get("datasets")
        .and_then(Value::as_array)
        .and_then(|d| d.first());
    let mut scale = vec![1.0; ndim];
    let mut offset = vec![0.0; ndim];
    for transforms in [
        dataset.and_then(|d| d.get("coordinateTransformations")),
        multiscale.get("coordinateTransformations"),
    ]
    .into_iter()
    .flatten()
    {
        let (s, t) = transformations(path, transforms, ndim)?;
        // x ↦ s·(scale·i + offset) + t
        for d in 0..ndim {
            scale[d] *= s[d];
            offset[d] = s[d] * offset[d] + t[d];
        }
    }
    let units = multiscale.get("axes").and_then(Value::as_array);
    let mm = |d: usize| {
        units
            .and_then(|a| a.get(d))
            .and_then(|a| a.get("unit"))
            .and_then(Value::as_str)
            .and_then(millimetres_per)
            .unwrap_or(1.0)
    };
    let spacing = spatial.map(|d| scale[d] * mm(d));
    let origin = spatial.map(|d| offset[d] * mm(d));
    Ok((spacing, origin))
}

/// One list of OME-Zarr coordinate transformations: its scale and translation vectors.
fn transformations(
    path: &Path,
    transforms: &Value,
    ndim: usize,
) -> Result<(Vec<f64>, Vec<f64>), IoError> {
    let mut scale = vec![1.0; ndim];
    let mut translation = vec![0.0; ndim];
    for t in transforms.as_array().into_iter().flatten() {
        let kind = t.get("type").and_then(Value::as_str).unwrap_or("");
        let (target, key) = match kind {
            "scale" => (&mut scale, "scale"),
            "translation" => (&mut translation, "translation"),
            "identity" => continue,
            other => {
                return Err(IoError::unsupported(
                    path,
                    format!(
                        "OME-Zarr coordinate transformation '{other}' is not supported (only \
                         scale and translation)"
                    ),
                ))
            }
        };
        let values: Option<Vec<f64>> = t
            .get(key)
            .and_then(Value::as_array)
            .map(|l| l.iter().map(Value::as_f64).collect::<Option<_>>())
            .unwrap_or(None);
        match values {
            Some(v) if v.len() == ndim => *target = v,
            _ => {
                return Err(IoError::malformed(
                    path,
                    format!("the OME-Zarr {key} is not a list of {ndim} numbers"),
                ))
            }
        }
    }
    Ok((scale, translation))
}

/// Millimetres per OME-Zarr (UDUNITS-2) length unit; `None` for units voxlod does not know.
fn millimetres_per(unit: &str) -> Option<f64> {
    samples::millimetres_per(unit).or(match unit {
        "nanometer" => Some(1e-6),
        "picometer" => Some(1e-9),
        "decimeter" => Some(100.0),
        "kilometer" => Some(1e6),
        _ => None,
    })
}
