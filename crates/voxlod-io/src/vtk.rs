//! What the VTK mesh and image modules share: loading a file through `vtkio` (legacy `.vtk` or
//! XML), saving one through the atomic writer, and converting vtkio's typed buffers.
//!
//! vtkio chooses legacy or XML by the (lower-case) extension and writes straight to the path;
//! we choose ourselves (extensions are case-insensitive here) and give it a reader or the
//! temporary file's writer instead. Legacy files are written binary big-endian, as the legacy
//! format prescribes; XML files with raw (base64) data, zlib-compressed when asked. vtkio's
//! parsers are third-party code fed arbitrary bytes, so a panic inside them is caught and
//! reported as a malformed file rather than taking the program down.

use std::io::BufReader;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

use vtkio::model::{IOBuffer, Vtk};
use vtkio::xml::Compressor;

use crate::atomic::{stage, TempFile};
use crate::{IoError, IoErrorKind};

/// Which of the two VTK encodings a file uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Flavor {
    /// `.vtk`: the legacy format.
    Legacy,
    /// `.vtp`, `.vti`: the XML formats.
    Xml,
}

fn vtkio_error(path: &Path, e: vtkio::Error) -> IoError {
    let (kind, message) = match &e {
        vtkio::Error::IO(io) if io.kind() == std::io::ErrorKind::UnexpectedEof => (
            IoErrorKind::Truncated,
            format!("the VTK data ends early: {io}"),
        ),
        vtkio::Error::IO(io) => (IoErrorKind::Access, format!("cannot read: {io}")),
        vtkio::Error::Unknown => (
            IoErrorKind::Truncated,
            "the legacy VTK data ends before what its header announces (or cannot be parsed)"
                .to_string(),
        ),
        other => (
            IoErrorKind::Malformed,
            format!("not a readable VTK file: {other}"),
        ),
    };
    IoError::new(path, kind, message)
}

/// Loads a VTK file of either flavour.
pub(crate) fn load(path: &Path, flavor: Flavor) -> Result<Vtk, IoError> {
    let file = std::fs::File::open(path).map_err(|e| IoError::access(path, "cannot open", &e))?;
    // vtkio holds the whole file, and then the decoded arrays, in memory.
    let len = file
        .metadata()
        .map_err(|e| IoError::access(path, "cannot read", &e))?
        .len();
    voxlod_core::memory::check_allocation("reading the VTK file", len.saturating_mul(2))
        .map_err(|e| IoError::from_core(path, e))?;
    let reader = BufReader::with_capacity(1 << 20, file);
    let parsed = catch_unwind(AssertUnwindSafe(|| match flavor {
        // Legacy binary data is big-endian by definition.
        Flavor::Legacy => Vtk::parse_legacy_be(reader),
        Flavor::Xml => Vtk::parse_xml(reader),
    }));
    match parsed {
        Ok(result) => result.map_err(|e| vtkio_error(path, e)),
        Err(_) => Err(IoError::malformed(
            path,
            "the VTK parser (vtkio) failed on this file: it is corrupt or uses a feature vtkio does not handle",
        )),
    }
}

/// Saves through the atomic writer.
pub(crate) fn save(
    path: &Path,
    vtk: Vtk,
    flavor: Flavor,
    compress: bool,
) -> Result<TempFile, IoError> {
    let to_io = |e: vtkio::Error| std::io::Error::other(e.to_string());
    match flavor {
        Flavor::Legacy => stage(path, |w| vtk.write_legacy(w).map_err(to_io)),
        Flavor::Xml => {
            let (compressor, level) = if compress {
                (Compressor::ZLib, 6)
            } else {
                (Compressor::None, 0)
            };
            let file = vtk.try_into_xml_format(compressor, level).map_err(|e| {
                IoError::unsupported(path, format!("cannot express as VTK XML: {e}"))
            })?;
            stage(path, |w| {
                file.write(w)
                    .map_err(|e| std::io::Error::other(e.to_string()))
            })
        }
    }
}

/// Any numeric buffer as `f64`.
pub(crate) fn to_f64(buffer: &IOBuffer) -> Vec<f64> {
    match buffer {
        IOBuffer::Bit(v) | IOBuffer::U8(v) => v.iter().map(|&x| x as f64).collect(),
        IOBuffer::I8(v) => v.iter().map(|&x| x as f64).collect(),
        IOBuffer::U16(v) => v.iter().map(|&x| x as f64).collect(),
        IOBuffer::I16(v) => v.iter().map(|&x| x as f64).collect(),
        IOBuffer::U32(v) => v.iter().map(|&x| x as f64).collect(),
        IOBuffer::I32(v) => v.iter().map(|&x| x as f64).collect(),
        IOBuffer::U64(v) => v.iter().map(|&x| x as f64).collect(),
        IOBuffer::I64(v) => v.iter().map(|&x| x as f64).collect(),
        IOBuffer::F32(v) => v.iter().map(|&x| x as f64).collect(),
        IOBuffer::F64(v) => v.clone(),
    }
}

/// Any numeric buffer as `f32`, without a copy when it already is.
pub(crate) fn into_f32(buffer: IOBuffer) -> Vec<f32> {
    match buffer {
        IOBuffer::F32(v) => v,
        other => to_f64(&other).into_iter().map(|x| x as f32).collect(),
    }
}
