//! The cell topology of legacy VTK 5.1 files, put in the one form vtkio 0.7.0-rc2 reads: the
//! one place where voxlod works around vtkio's legacy reader.
//!
//! Since VTK 9 the legacy writer stores each cell section (`POLYGONS n size`,
//! `TRIANGLE_STRIPS`, `LINES`, `VERTICES`, `CELLS`) as an `OFFSETS <type>` array of `n`
//! integers and a `CONNECTIVITY <type>` array of `size` integers, the type being the cell
//! array's own: `vtktypeint64` by default, `int` for a cell array with 32-bit storage, and
//! `vtkIdType` (written as 32-bit integers, as `vtkDataWriter` writes every `vtkIdType`
//! array) for one built on `vtkIdTypeArray`s, as `vtkAppendPolyData` builds them. vtkio reads
//! only `vtktypeint64` ("a number is missing" in ASCII files; in binary ones it reads the
//! 32-bit integers in pairs, as 64-bit offsets). So every other integer type is rewritten
//! here to `vtktypeint64`: the name alone in an ASCII file, and in a binary file each
//! big-endian 32-bit integer widened to 64 bits (signed or not as the type says).
//!
//! Cost: a search of the file for the two tags; where one needs widening, one copy of the file
//! with the widened arrays (checked against the memory budget first).

use std::path::Path;

use crate::{budget, IoError};

/// The bytes of one integer of a topology array's type, and whether it is signed; `None` for
/// a type that is not an integer type of the legacy format.
fn integer_type(name: &str) -> Option<(usize, bool)> {
    match name.to_ascii_lowercase().as_str() {
        "vtktypeint64" | "long" | "vtktypeint64_t" => Some((8, true)),
        "vtktypeuint64" | "unsigned_long" => Some((8, false)),
        "vtktypeint32" | "int" | "vtkidtype" => Some((4, true)),
        "vtktypeuint32" | "unsigned_int" => Some((4, false)),
        _ => None,
    }
}

/// Where a topology array's tag line starts and ends in the file, its type, and how many
/// integers it holds.
struct Tagged {
    line: std::ops::Range<usize>,
    width: usize,
    signed: bool,
    count: usize,
}

/// The file with its topology arrays in `vtktypeint64`, or `None` where they already are
/// (or the file has none). Fails, naming the file, where a section's counts are missing or
/// its binary data runs past the end of the file.
pub(super) fn rewrite(path: &Path, bytes: &[u8], binary: bool) -> Result<Option<Vec<u8>>, IoError> {
    let tagged = tagged_arrays(path, bytes)?;
    if tagged.iter().all(|t| t.width == 8 && t.signed) {
        return Ok(None);
    }
    let widened: usize = (tagged.iter())
        .filter(|t| binary && t.width == 4)
        .map(|t| 4 * t.count)
        .sum();
    budget::check_bytes(
        path,
        "widening the file's cell topology",
        (bytes.len() + widened) as u64,
    )?;
    let mut out = Vec::with_capacity(bytes.len() + widened);
    let mut at = 0;
    for t in &tagged {
        out.extend_from_slice(&bytes[at..t.line.start]);
        out.extend_from_slice(&tag_line(&bytes[t.line.clone()]));
        at = t.line.end;
        if binary && t.width == 4 {
            let data = at..at + 4 * t.count;
            let ints = bytes.get(data.clone()).ok_or_else(|| {
                IoError::truncated(
                    path,
                    "the file ends within a cell section's binary integers",
                )
            })?;
            for b in ints.chunks_exact(4) {
                let b = [b[0], b[1], b[2], b[3]];
                let wide = match t.signed {
                    true => i32::from_be_bytes(b) as i64,
                    false => u32::from_be_bytes(b) as i64,
                };
                out.extend_from_slice(&wide.to_be_bytes());
            }
            at = data.end;
        }
    }
    out.extend_from_slice(&bytes[at..]);
    Ok(Some(out))
}

/// The tag line `OFFSETS <type>` or `CONNECTIVITY <type>` (with its line end) renamed to
/// `vtktypeint64`.
fn tag_line(line: &[u8]) -> Vec<u8> {
    let text = String::from_utf8_lossy(line);
    let tag = text.split_whitespace().next().unwrap_or("");
    let end = &line[line
        .iter()
        .rposition(|b| !b.is_ascii_whitespace())
        .map_or(0, |p| p + 1)..];
    let mut out = format!("{tag} vtktypeint64").into_bytes();
    out.extend_from_slice(end);
    out
}

/// Every `OFFSETS` and `CONNECTIVITY` tag line at the start of a line, with the counts of the
/// cell section line before it (`n` offsets, `size` connectivity entries).
fn tagged_arrays(path: &Path, bytes: &[u8]) -> Result<Vec<Tagged>, IoError> {
    let mut out = Vec::new();
    for tag in [&b"\nOFFSETS "[..], &b"\nCONNECTIVITY "[..]] {
        let mut from = 0;
        while let Some(p) = find(&bytes[from..], tag) {
            let start = from + p + 1;
            let end = (bytes[start..].iter().position(|&b| b == b'\n'))
                .map_or(bytes.len(), |e| start + e + 1);
            from = end.min(bytes.len());
            let text = String::from_utf8_lossy(&bytes[start..end]);
            let Some((width, signed)) = text.split_whitespace().nth(1).and_then(integer_type)
            else {
                continue; // not an integer type: vtkio says so
            };
            let offsets = tag[1] == b'O';
            let count = section_counts(path, bytes, start, offsets)?;
            let count = if offsets { count.0 } else { count.1 };
            out.push(Tagged {
                line: start..end,
                width,
                signed,
                count,
            });
        }
    }
    out.sort_by_key(|t| t.line.start);
    Ok(out)
}

/// The counts `(n, size)` of the cell section that the array tagged at `start` belongs to:
/// from the line before the `OFFSETS` tag, which for `CONNECTIVITY` is the line before the
/// `OFFSETS` tag before it.
fn section_counts(
    path: &Path,
    bytes: &[u8],
    start: usize,
    offsets: bool,
) -> Result<(usize, usize), IoError> {
    let missing = || {
        IoError::malformed(
            path,
            "a cell section's OFFSETS or CONNECTIVITY array has no 'KIND n size' line before it",
        )
    };
    let offsets_at = match offsets {
        true => start,
        false => rfind(&bytes[..start], b"\nOFFSETS ")
            .map(|p| p + 1)
            .ok_or_else(missing)?,
    };
    let before = &bytes[..offsets_at.saturating_sub(1)];
    let line_start = rfind(before, b"\n").map_or(0, |p| p + 1);
    let text = String::from_utf8_lossy(&before[line_start..]);
    let words: Vec<&str> = text.split_whitespace().collect();
    match words.as_slice() {
        [_, n, size] => match (n.parse(), size.parse()) {
            (Ok(n), Ok(size)) => Ok((n, size)),
            _ => Err(missing()),
        },
        _ => Err(missing()),
    }
}

fn find(haystack: &[u8], needle: &[u8]) -> Option<usize> {
    haystack.windows(needle.len()).position(|w| w == needle)
}

fn rfind(haystack: &[u8], needle: &[u8]) -> Option<usize> {
    haystack.windows(needle.len()).rposition(|w| w == needle)
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEAD: &[u8] =
        b"# vtk DataFile Version 5.1\nt\nBINARY\nDATASET POLYDATA\nPOINTS 0 float\n\n";

    fn file(tail: &[u8]) -> Vec<u8> {
        [HEAD, tail].concat()
    }

    #[test]
    fn binary_32_bit_arrays_are_widened_and_renamed() {
        let mut tail = b"POLYGONS 2 3\nOFFSETS int\n".to_vec();
        tail.extend([0, 3].iter().flat_map(|v: &i32| v.to_be_bytes()));
        tail.extend(b"\nCONNECTIVITY vtkIdType\n");
        tail.extend([0, 1, 2].iter().flat_map(|v: &i32| v.to_be_bytes()));
        tail.extend(b"\n");
        let out = rewrite(Path::new("t.vtk"), &file(&tail), true)
            .unwrap()
            .unwrap();
        let mut expected = b"POLYGONS 2 3\nOFFSETS vtktypeint64\n".to_vec();
        expected.extend([0, 3].iter().flat_map(|v: &i64| v.to_be_bytes()));
        expected.extend(b"\nCONNECTIVITY vtktypeint64\n");
        expected.extend([0, 1, 2].iter().flat_map(|v: &i64| v.to_be_bytes()));
        expected.extend(b"\n");
        assert_eq!(out, file(&expected));
    }

    #[test]
    fn ascii_arrays_are_renamed_and_64_bit_ones_left_alone() {
        let tail = b"POLYGONS 2 3\nOFFSETS int\n0 3\nCONNECTIVITY int\n0 1 2\n";
        let out = rewrite(Path::new("t.vtk"), &file(tail), false)
            .unwrap()
            .unwrap();
        let expected =
            b"POLYGONS 2 3\nOFFSETS vtktypeint64\n0 3\nCONNECTIVITY vtktypeint64\n0 1 2\n";
        assert_eq!(out, file(expected));
        let wide = b"POLYGONS 2 3\nOFFSETS vtktypeint64\n0 3\nCONNECTIVITY vtktypeint64\n0 1 2\n";
        assert!(rewrite(Path::new("t.vtk"), &file(wide), false)
            .unwrap()
            .is_none());
    }

    #[test]
    fn short_binary_data_and_missing_counts_are_errors() {
        let tail = b"POLYGONS 2 3\nOFFSETS int\n\x00\x00\x00";
        let e = rewrite(Path::new("t.vtk"), &file(tail), true).unwrap_err();
        assert!(e.to_string().contains("ends within"), "{e}");
        let tail = b"POLYGONS\nOFFSETS int\n0 3\n";
        let e = rewrite(Path::new("t.vtk"), &file(tail), false).unwrap_err();
        assert!(e.to_string().contains("no 'KIND n size' line"), "{e}");
    }
}
