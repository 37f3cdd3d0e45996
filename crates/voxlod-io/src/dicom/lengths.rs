//! The declared lengths of a DICOM file, checked before dicom-object parses it.
//!
//! dicom-object 0.10 (its file meta reader) and dicom-parser 0.10 (its stateful decoder) make
//! room for a value by its declared length before reading it (`try_reserve_exact`, then
//! `resize` with zeros), so one corrupt 32-bit length in a file of a few kilobytes makes them
//! allocate and touch up to 4 GiB: seconds of work where memory allows, an abort where it does
//! not (found by the mutation sweep of a DICOM-SEG seed). This is the one place that works
//! around it: dicom-parser's lazy reader walks the element headers, skipping every value
//! unread, and a value or item declared longer than what is left of the file is refused
//! before the real parse. Files whose data set is deflated are not walked (the inflated length
//! is unknown until inflated). Cost: one pass over the headers of a file already in memory.

use std::io::Cursor;
use std::path::Path;

use dicom_encoding::transfer_syntax::{Codec, TransferSyntaxIndex};
use dicom_parser::dataset::lazy_read::LazyDataSetReader;
use dicom_parser::dataset::LazyDataToken;
use dicom_parser::StatefulDecode;
use dicom_transfer_syntax_registry::{entries, TransferSyntaxRegistry};

use crate::{guard, IoError};

/// The preamble and `DICM`.
const PREAMBLE: usize = 132;

/// Fails when a value or item of the file `bytes` declares more bytes than the file has left.
/// Anything else the walk cannot read is left for the parser to report.
pub(crate) fn check_declared_lengths(path: &Path, bytes: &[u8]) -> Result<(), IoError> {
    if bytes.len() < PREAMBLE || &bytes[128..PREAMBLE] != b"DICM" {
        return Ok(());
    }
    let walked = guard::quietly(|| {
        let meta = &bytes[PREAMBLE..];
        let (meta_len, syntax) = walk(meta, &entries::EXPLICIT_VR_LITTLE_ENDIAN.erased(), true)?;
        let uid = syntax.unwrap_or_default();
        let Some(ts) = TransferSyntaxRegistry.get(&uid) else {
            return Ok((0, None));
        };
        if matches!(ts.codec(), Codec::Dataset(_)) {
            return Ok((0, None));
        }
        walk(&meta[meta_len as usize..], ts, false)
    });
    match walked {
        Some(Err(Overlong { at, declared, left })) => Err(IoError::truncated(
            path,
            format!(
                "a DICOM element at byte {at} declares {declared} bytes but only {left} are left in the file"
            ),
        )),
        _ => Ok(()),
    }
}

/// A value declared longer than what is left.
struct Overlong {
    at: u64,
    declared: u64,
    left: u64,
}

/// Walks the elements of `data` in `ts`, skipping values; with `meta`, stops at the first
/// element outside group 2 and returns how many bytes group 2 took and the transfer syntax it
/// names. A walk that cannot go on ends quietly.
fn walk(
    data: &[u8],
    ts: &dicom_encoding::TransferSyntax,
    meta: bool,
) -> Result<(u64, Option<String>), Overlong> {
    let total = data.len() as u64;
    let Ok(mut reader) = LazyDataSetReader::new_with_ts(Cursor::new(data), ts) else {
        return Ok((0, None));
    };
    let (mut end, mut syntax) = (0u64, None);
    while let Some(Ok(token)) = reader.advance() {
        let (len, decoder, tag) = match token {
            LazyDataToken::LazyValue { header, decoder } => {
                (header.len.get(), decoder, Some(header.tag))
            }
            LazyDataToken::LazyItemValue { len, decoder } => (Some(len), decoder, None),
            LazyDataToken::SequenceStart { tag, .. } if meta && tag.group() != 2 => break,
            _ => continue,
        };
        if meta && tag.is_some_and(|t| t.group() != 2) {
            break;
        }
        let at = decoder.position();
        let declared = u64::from(len.unwrap_or(0));
        if declared > total.saturating_sub(at) {
            return Err(Overlong {
                at,
                declared,
                left: total.saturating_sub(at),
            });
        }
        if meta && tag == Some(dicom_dictionary_std::tags::TRANSFER_SYNTAX_UID) {
            let text = &data[at as usize..(at + declared) as usize];
            let text = String::from_utf8_lossy(text);
            syntax = Some(text.trim_end_matches(['\0', ' ']).to_string());
        }
        if decoder.skip_bytes(declared as u32).is_err() {
            break;
        }
        end = decoder.position();
    }
    Ok((end, syntax))
}
