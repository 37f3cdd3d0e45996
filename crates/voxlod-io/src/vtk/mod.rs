//! What the VTK mesh and image modules share: loading a file through `vtkio` (legacy `.vtk` or
//! XML), saving one through the atomic writer, and converting vtkio's typed buffers.
//!
//! vtkio chooses legacy or XML by the (lower-case) extension and writes straight to the path;
//! we choose ourselves (extensions are case-insensitive here) and give it the file's bytes or
//! the temporary file's writer instead. XML files first go through [`xml`], which decodes
//! the binary data vtkio 0.7.0-rc2 cannot (raw appended data, compressed empty arrays) and
//! checks the rest; legacy files get their header lines checked, since vtkio cannot say where
//! a parse failed, and their cell topology put in the one integer type vtkio reads
//! ([`legacy_topology`]). vtkio's parsers are third-party code fed arbitrary bytes, so a panic inside
//! them is caught, silently, and reported as a corrupt file ([`guard`]); its errors are
//! translated into plain words ([`IoError::from_vtkio`]). Legacy files are written binary
//! big-endian, as the legacy format prescribes; XML files with base64 data, zlib-compressed
//! when asked.
//!
//! Cost: vtkio parses the whole file into its own model before we convert it: O(file size)
//! time, and about twice the data's memory at the peak.

pub(crate) mod image;
mod legacy_topology;
pub(crate) mod mesh;
pub(crate) mod unstructured;
mod xml;

use std::path::Path;

use vtkio::model::{IOBuffer, Vtk};
use vtkio::xml::Compressor;

use crate::atomic::{stage, TempFile};
use crate::{budget, guard, IoError};

/// Which of the two VTK encodings a file uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Flavor {
    /// `.vtk`: the legacy format.
    Legacy,
    /// `.vtp`, `.vtu`, `.vti`: the XML formats.
    Xml,
}

/// Loads a VTK file of either flavour: the whole file in memory (after the budget check), XML
/// binary data decoded by [`xml`], then vtkio under [`guard::quietly`].
pub(crate) fn load(path: &Path, flavor: Flavor) -> Result<Vtk, IoError> {
    let bytes = crate::read_file(path)?;
    let parsed = match flavor {
        Flavor::Legacy => {
            let binary = check_legacy_header(path, &bytes)?;
            let rewritten = legacy_topology::rewrite(path, &bytes, binary)?;
            let document = rewritten.as_deref().unwrap_or(&bytes);
            // vtkio copies the file, then holds the decoded arrays.
            budget::check_bytes(
                path,
                "parsing the VTK file",
                (document.len() as u64).saturating_mul(4),
            )?;
            // Legacy binary data is big-endian by definition.
            guard::quietly(|| Vtk::parse_legacy_be(document))
        }
        Flavor::Xml => {
            let rewritten = xml::rewrite(path, &bytes)?;
            let document = rewritten.as_deref().unwrap_or(&bytes);
            budget::check_bytes(
                path,
                "parsing the VTK file",
                (document.len() as u64).saturating_mul(3),
            )?;
            guard::quietly(|| Vtk::parse_xml(document))
        }
    };
    match parsed {
        Some(result) => result.map_err(|e| IoError::from_vtkio(path, e)),
        None => Err(IoError::malformed(
            path,
            "the VTK file is corrupt: its data cannot be decoded",
        )),
    }
}

/// The four header lines of a legacy file, checked here because vtkio reports a failure
/// without saying where; whether the file is binary.
fn check_legacy_header(path: &Path, bytes: &[u8]) -> Result<bool, IoError> {
    let head = &bytes[..bytes.len().min(4096)];
    let text = String::from_utf8_lossy(head);
    let mut lines = text.lines();
    let first = lines.next().unwrap_or("").trim();
    let words: Vec<String> = first
        .trim_start_matches('#')
        .split_whitespace()
        .map(str::to_ascii_lowercase)
        .collect();
    if !first.starts_with('#') || words.len() < 4 || words[..3] != ["vtk", "datafile", "version"] {
        return Err(IoError::malformed(
            path,
            "line 1 is not '# vtk DataFile Version x.y': not a legacy VTK file",
        ));
    }
    if lines.next().is_none_or(|title| title.trim().is_empty()) {
        return Err(IoError::malformed(
            path,
            "line 2, the title, is empty or missing (the legacy format needs one)",
        ));
    }
    let kind = lines.next().unwrap_or("").trim();
    if !(kind.eq_ignore_ascii_case("ascii") || kind.eq_ignore_ascii_case("binary")) {
        return Err(IoError::malformed(
            path,
            format!("line 3 must say ASCII or BINARY, it says '{}'", clip(kind)),
        ));
    }
    let dataset = lines.find(|l| !l.trim().is_empty()).unwrap_or("").trim();
    if !dataset.to_ascii_uppercase().starts_with("DATASET") {
        return Err(IoError::malformed(
            path,
            format!(
                "expected 'DATASET <type>' after the header, found '{}'",
                clip(dataset)
            ),
        ));
    }
    Ok(kind.eq_ignore_ascii_case("binary"))
}

/// At most 40 characters of a line of the file, for a message.
fn clip(text: &str) -> String {
    text.chars().take(40).collect()
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
            let file = xml_file(path, vtk, compress)?;
            stage(path, |w| {
                file.write(w)
                    .map_err(|e| std::io::Error::other(e.to_string()))
            })
        }
    }
}

/// vtkio's XML model of `vtk`, zlib-compressed when asked.
fn xml_file(path: &Path, vtk: Vtk, compress: bool) -> Result<vtkio::xml::VTKFile, IoError> {
    let (compressor, level) = if compress {
        (Compressor::ZLib, 6)
    } else {
        (Compressor::None, 0)
    };
    vtk.try_into_xml_format(compressor, level)
        .map_err(|e| IoError::unsupported(path, format!("cannot express as VTK XML: {e}")))
}

/// Saves VTK XML through the atomic writer after `patch` has changed vtkio's text (for what
/// vtkio's model cannot hold, such as an image's `Direction`). The whole file is held in memory
/// once more.
pub(crate) fn save_patched(
    path: &Path,
    vtk: Vtk,
    compress: bool,
    patch: impl FnOnce(Vec<u8>) -> Result<Vec<u8>, String>,
) -> Result<TempFile, IoError> {
    let file = xml_file(path, vtk, compress)?;
    let mut text = Vec::new();
    file.write(&mut text)
        .map_err(|e| IoError::unsupported(path, format!("cannot write VTK XML: {e}")))?;
    let text = patch(text).map_err(|e| IoError::unsupported(path, e))?;
    stage(path, |w| std::io::Write::write_all(w, &text))
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
