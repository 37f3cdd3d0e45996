//! The PLY header, checked line by line before ply-rs-bw parses it, so that a broken header
//! gets a message naming its line and what is wrong there (ply-rs-bw's own messages quote its
//! grammar's internal types).
//!
//! The grammar, as ply-rs-bw accepts it: `ply`; `format ascii|binary_little_endian|
//! binary_big_endian M.N`; `comment …` and `obj_info …` anywhere; `element NAME COUNT`;
//! `property TYPE NAME` or `property list COUNT_TYPE TYPE NAME` after an element; `end_header`.
//! Names start with a letter or `_`; types are the C names (`char`, `uchar`, `short`, `ushort`,
//! `int`, `uint`, `float`, `double`) or the sized ones (`int8` … `float64`). Cost: one pass
//! over the header's lines.

use std::path::Path;

use crate::IoError;

/// The longest header we look through: real ones are a few hundred bytes.
const MAX_HEADER_BYTES: usize = 1 << 20;

const SCALARS: [&str; 16] = [
    "char", "int8", "uchar", "uint8", "short", "int16", "ushort", "uint16", "int", "int32", "uint",
    "uint32", "float", "float32", "double", "float64",
];

fn is_name(token: &str) -> bool {
    let mut chars = token.chars();
    chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
}

fn is_version(token: &str) -> bool {
    token
        .split_once('.')
        .is_some_and(|(a, b)| a.parse::<u16>().is_ok() && b.parse::<u8>().is_ok())
}

/// Checks the header at the start of `bytes` (the file, or its first part).
pub(crate) fn check(path: &Path, bytes: &[u8]) -> Result<(), IoError> {
    let head = &bytes[..bytes.len().min(MAX_HEADER_BYTES)];
    let mut all: Vec<&[u8]> = head.split(|&b| b == b'\n').collect();
    if all.last().is_some_and(|l| l.is_empty()) {
        // The end of the input, not an empty line.
        all.pop();
    }
    let mut lines = all.into_iter();
    let magic = lines.next().unwrap_or_default();
    if magic.trim_ascii() != b"ply" {
        return Err(IoError::malformed(
            path,
            "line 1 is not 'ply': not a PLY file",
        ));
    }
    let mut format_seen = false;
    let mut element_seen = false;
    for (index, raw) in lines.enumerate() {
        let line_no = index + 2;
        let text = String::from_utf8_lossy(raw);
        let mut tokens = text.split_ascii_whitespace();
        let keyword = tokens.next().unwrap_or("");
        let rest: Vec<&str> = tokens.collect();
        let problem = match keyword {
            "end_header" if !format_seen => {
                Some("the header ends before its 'format' line".to_string())
            }
            "end_header" => return Ok(()),
            "comment" | "obj_info" => None,
            "format" => {
                format_seen = true;
                format_problem(&rest)
            }
            "element" => {
                element_seen = true;
                match rest.as_slice() {
                    [name, count] if is_name(name) && count.parse::<u64>().is_ok() => None,
                    [name, count] if is_name(name) => Some(format!(
                        "the count of element '{name}' is '{count}', not a whole number"
                    )),
                    _ => Some("expected 'element NAME COUNT'".to_string()),
                }
            }
            "property" if !element_seen => {
                Some("a property comes before any 'element' line".to_string())
            }
            "property" => property_problem(&rest),
            "" => Some("an empty line inside the header".to_string()),
            other => Some(format!(
                "'{}' is not a header keyword (format, element, property, comment, end_header)",
                other.chars().take(40).collect::<String>()
            )),
        };
        if let Some(problem) = problem {
            return Err(IoError::malformed(
                path,
                format!("line {line_no} of the header: {problem}"),
            ));
        }
    }
    Err(if bytes.len() > MAX_HEADER_BYTES {
        IoError::malformed(
            path,
            format!("no 'end_header' line within the first {MAX_HEADER_BYTES} bytes"),
        )
    } else {
        IoError::truncated(path, "the file ends before the header's 'end_header' line")
    })
}

fn format_problem(rest: &[&str]) -> Option<String> {
    match rest {
        [encoding, version]
            if ["ascii", "binary_little_endian", "binary_big_endian"].contains(encoding) =>
        {
            (!is_version(version)).then(|| format!("format version '{version}' is not like 1.0"))
        }
        [encoding, ..]
            if !["ascii", "binary_little_endian", "binary_big_endian"].contains(encoding) =>
        {
            Some(format!(
                "format '{}' is not ascii, binary_little_endian or binary_big_endian",
                encoding.chars().take(40).collect::<String>()
            ))
        }
        _ => Some("expected 'format ENCODING 1.0'".to_string()),
    }
}

fn property_problem(rest: &[&str]) -> Option<String> {
    let unknown = |t: &str| {
        format!(
            "'{}' is not a PLY type (char, uchar, short, ushort, int, uint, float, double, or int8 ... float64)",
            t.chars().take(40).collect::<String>()
        )
    };
    match rest {
        ["list", count, item, name] => {
            if !SCALARS.contains(count) {
                Some(unknown(count))
            } else if !SCALARS.contains(item) {
                Some(unknown(item))
            } else if !is_name(name) {
                Some(format!("'{name}' is not a property name"))
            } else {
                None
            }
        }
        [ty, name] if *ty != "list" => {
            if !SCALARS.contains(ty) {
                Some(unknown(ty))
            } else if !is_name(name) {
                Some(format!("'{name}' is not a property name"))
            } else {
                None
            }
        }
        _ => Some(
            "expected 'property TYPE NAME' or 'property list COUNT_TYPE TYPE NAME'".to_string(),
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn problem(header: &str) -> String {
        check(Path::new("h.ply"), header.as_bytes())
            .err()
            .map(|e| e.message)
            .unwrap_or_default()
    }

    #[test]
    fn good_headers_pass_and_bad_lines_are_named() {
        let good = "ply\r\nformat binary_little_endian 1.0\ncomment made by hand\nelement vertex 3\nproperty float x\nproperty float32 y\nproperty double z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
        assert_eq!(problem(good), "");
        for (header, needle) in [
            ("plx\n", "line 1"),
            (
                "ply\nformat ascii 1.0\nelement vertex x\nend_header\n",
                "line 3 of the header: the count of element 'vertex' is 'x'",
            ),
            (
                "ply\nformat ascii 1.0\nproperty float x\nend_header\n",
                "line 3 of the header: a property comes before",
            ),
            (
                "ply\nformat ascii 1.0\nelement vertex 1\nproperty float3 x\nend_header\n",
                "line 4 of the header: 'float3' is not a PLY type",
            ),
            ("ply\nformat text 1.0\nend_header\n", "format 'text'"),
            ("ply\nformat ascii one\nend_header\n", "version 'one'"),
            (
                "ply\nformat ascii 1.0\nelement vertex 1\nproperty list uchar int\nend_header\n",
                "property list",
            ),
            (
                "ply\nelement vertex 1\nend_header\n",
                "before its 'format' line",
            ),
            ("ply\nformat ascii 1.0\nelement vertex 1\n", "ends before"),
            (
                "ply\nformat ascii 1.0\nvertex 1\nend_header\n",
                "'vertex' is not a header keyword",
            ),
        ] {
            let p = problem(header);
            assert!(p.contains(needle), "{needle}: {p}");
        }
    }
}
