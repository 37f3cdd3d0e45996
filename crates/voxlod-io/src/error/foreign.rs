//! Plain words for the failures of the third-party parsers.
//!
//! vtkio, ply-rs-bw and stl_io build their messages with `{:?}` of their own types (nom error
//! kinds, peg locations, token vectors), and vtkio's `Display` wraps every inner error in its
//! `Debug` form. So no foreign message is passed through as it is: each constructor here looks
//! at the *kind* of failure (the variant, the `io::ErrorKind`, the line number the parser
//! knows) and says in its own words what is wrong with the file. Only texts known to be plain
//! are quoted: the operating system's message of an `io::Error`, and quick-xml's description
//! of an ill-formed document (it names tags, not types).
//!
//! Cost: O(1) per translation, plus the message text.

use std::io::ErrorKind;
use std::path::Path;

use crate::{IoError, IoErrorKind};

impl IoError {
    /// An `io::Error` met while reading: an early end is [`IoErrorKind::Truncated`], a corrupt
    /// compressed stream [`IoErrorKind::Malformed`], anything else an access error.
    pub(crate) fn reading(path: &Path, what: &str, e: &std::io::Error) -> IoError {
        match e.kind() {
            ErrorKind::UnexpectedEof => {
                IoError::truncated(path, format!("the file ends within the {what}"))
            }
            ErrorKind::InvalidData | ErrorKind::InvalidInput => {
                IoError::malformed(path, format!("the {what} is corrupt ({e})"))
            }
            _ => IoError::access(path, &format!("cannot read the {what}"), e),
        }
    }

    /// A failure of vtkio, legacy or XML.
    pub(crate) fn from_vtkio(path: &Path, e: vtkio::Error) -> IoError {
        match e {
            vtkio::Error::IO(io) => IoError::reading(path, "VTK data", &io),
            vtkio::Error::Parse(kind) => legacy_parse(path, kind),
            vtkio::Error::XML(x) => vtk_xml(path, x),
            vtkio::Error::Unknown => IoError::truncated(
                path,
                "the legacy VTK data ends before all that its section headers announce",
            ),
            vtkio::Error::Load(_) => IoError::malformed(
                path,
                "the VTK data set refers to pieces that are missing or of another type",
            ),
            vtkio::Error::Write(_) | vtkio::Error::UnknownFileExtension(_) => {
                IoError::malformed(path, "not a readable VTK file")
            }
        }
    }

    /// A quick-xml failure at `byte` of the (XML part of the) file.
    pub(crate) fn from_xml(path: &Path, e: &quick_xml::Error, byte: u64) -> IoError {
        IoError::malformed(
            path,
            format!(
                "the XML is not well-formed near byte {byte}: {}",
                xml_words(e)
            ),
        )
    }

    /// A ply-rs-bw failure while reading `element` (empty: in the header).
    pub(crate) fn from_ply(
        path: &Path,
        element: &str,
        binary: bool,
        e: &ply_rs_bw::parser::ParseError,
    ) -> IoError {
        let at = e.line().map(|l| format!("line {l}: ")).unwrap_or_default();
        if e.kind() == ErrorKind::UnexpectedEof {
            let place = if element.is_empty() {
                "the header".to_string()
            } else {
                format!("the '{element}' elements")
            };
            return IoError::truncated(path, format!("the file ends within {place}"));
        }
        if element.is_empty() {
            return IoError::malformed(path, format!("{at}the header is not valid PLY"));
        }
        let problem = if binary {
            format!("the '{element}' elements hold a negative list length, or a list length of a float type")
        } else {
            format!("{at}this '{element}' element does not match the header's properties (a value is missing, extra, or not a number of the declared type)")
        };
        IoError::malformed(path, problem)
    }

    /// A failure of stl_io reading triangle `t`.
    pub(crate) fn from_stl(path: &Path, ascii: bool, t: usize, e: &std::io::Error) -> IoError {
        let format = if ascii { "ASCII" } else { "binary" };
        let at = format!(
            "{format} STL, facet {t} (vertices {} to {})",
            3 * t,
            3 * t + 2
        );
        if e.kind() == ErrorKind::UnexpectedEof {
            return IoError::truncated(
                path,
                format!("{at}: the file ends before the facet (or 'endsolid') is complete"),
            );
        }
        // stl_io says what it expected, quoting the tokens it found as a Rust vector; keep the
        // expectation only.
        let text = e.to_string();
        let (kind, problem) = if text.starts_with("expected finite") {
            (IoErrorKind::NonFinite, "a coordinate is not finite")
        } else if text.starts_with("invalid facet header") {
            (
                IoErrorKind::Malformed,
                "expected 'facet normal nx ny nz' or 'endsolid'",
            )
        } else if text.starts_with("vertex") {
            (IoErrorKind::Malformed, "expected 'vertex x y z'")
        } else if text.contains("\"outer\"") {
            (IoErrorKind::Malformed, "expected 'outer loop'")
        } else if text.contains("\"endloop\"") {
            (
                IoErrorKind::Malformed,
                "expected 'endloop' after three vertices",
            )
        } else if text.contains("\"endfacet\"") {
            (IoErrorKind::Malformed, "expected 'endfacet'")
        } else if text.contains("UTF-8") {
            (IoErrorKind::Malformed, "the text is not valid UTF-8")
        } else if text.contains("float") {
            (IoErrorKind::Malformed, "a coordinate is not a number")
        } else {
            (
                IoErrorKind::Malformed,
                "the facet does not follow the STL format",
            )
        };
        IoError::new(path, kind, format!("{at}: {problem}"))
    }

    /// A failure of the `nifti` crate reading the header.
    pub(crate) fn from_nifti(path: &Path, e: &::nifti::NiftiError) -> IoError {
        match e {
            ::nifti::NiftiError::Io(io) if io.kind() == ErrorKind::UnexpectedEof => {
                IoError::truncated(path, "the file ends within the 348-byte NIfTI-1 header")
            }
            ::nifti::NiftiError::Io(io) => IoError::reading(path, "NIfTI header", io),
            ::nifti::NiftiError::InvalidFormat => IoError::malformed(
                path,
                "not a NIfTI-1 file: the header size field is not 348 in either byte order (NIfTI-2 is not supported)",
            ),
            _ => IoError::malformed(path, "the NIfTI-1 header is not valid"),
        }
    }
}

/// A legacy-format failure: vtkio reports only nom's error kind, without a position.
fn legacy_parse(path: &Path, kind: nom::error::ErrorKind) -> IoError {
    use nom::error::ErrorKind as K;
    let (kind, what) = match kind {
        K::ManyMN | K::Eof | K::Count => (
            IoErrorKind::Truncated,
            "a data section holds fewer values than its header announces, or one of them is not a number",
        ),
        K::Digit | K::Float => (
            IoErrorKind::Malformed,
            "a number is missing or is not a number where the format needs one",
        ),
        K::Switch => (
            IoErrorKind::Unsupported,
            "a data type that is not allowed at its place (points must be float or double)",
        ),
        K::Tag | K::Alt | K::Permutation => (
            IoErrorKind::Malformed,
            "a keyword is missing or misspelt (the header needs '# vtk DataFile Version', a title, ASCII or BINARY, and DATASET)",
        ),
        _ => (
            IoErrorKind::Malformed,
            "a section does not follow the format: it ends early, or holds something other than the keywords and values its header announces",
        ),
    };
    IoError::new(path, kind, format!("legacy VTK: {what}"))
}

/// An XML-side failure of vtkio.
fn vtk_xml(path: &Path, e: vtkio::xml::Error) -> IoError {
    use vtkio::xml::Error as X;
    match e {
        X::XML(x) => IoError::malformed(
            path,
            format!("the XML is not well-formed: {}", xml_words(&x)),
        ),
        X::Deserialization(d) => deserialization(path, &d),
        X::Validation(v) => validation(path, v),
        X::IO(io) => IoError::reading(path, "VTK XML data", &io),
        X::Base64Decode(_) => IoError::malformed(path, "binary data is not valid base64"),
        X::InvalidVersion => IoError::malformed(path, "the VTKFile version is not 'major.minor'"),
        X::InvalidByteOrder => {
            IoError::malformed(path, "the byte order is neither LittleEndian nor BigEndian")
        }
        X::TypeExtensionMismatch | X::InvalidType => IoError::malformed(
            path,
            "the VTKFile type does not match the data set the file holds",
        ),
        X::UnexpectedElement(name) => {
            IoError::malformed(path, format!("unexpected element <{name}>"))
        }
        X::Model(_) | X::Unknown => IoError::malformed(path, "not a readable VTK XML file"),
    }
}

fn validation(path: &Path, v: vtkio::xml::ValidationError) -> IoError {
    use vtkio::xml::ValidationError as V;
    let message = match v {
        V::DataArraySizeMismatch {
            name,
            expected,
            actual,
        } => {
            return IoError::new(
                path,
                if actual < expected {
                    IoErrorKind::Truncated
                } else {
                    IoErrorKind::Malformed
                },
                format!(
                "data array '{name}' holds {actual} value{} where its piece declares {expected}",
                if actual == 1 { "" } else { "s" }
            ),
            )
        }
        V::DataSetMismatch => "the VTKFile type does not match the data set element".to_string(),
        V::MissingDataSet => "the file holds no data set".to_string(),
        V::InvalidDataFormat => {
            "a cell array holds negative or fractional offsets or vertex numbers".to_string()
        }
        V::MissingTopologyOffsets => "a cell array has no valid offsets".to_string(),
        V::MissingReferencedAppendedData => {
            "a data array refers to appended data that the file does not have".to_string()
        }
        V::ParseFloat(_) | V::ParseInt(_) => {
            "an ASCII data array holds a value that is not a number of its type".to_string()
        }
        V::TooManyElements(n) => format!("a piece declares {n} elements, more than can be held"),
        V::Base64Decode(_) => "binary data is not valid base64".to_string(),
        V::Deserialize(d) => return deserialization(path, &d),
        V::IO(io) => return IoError::reading(path, "VTK XML data", &io),
        _ => "the binary data of an array cannot be decoded".to_string(),
    };
    IoError::malformed(path, message)
}

/// Serde's messages name fields as `@attribute`, between back-quotes; say it in words.
fn deserialization(path: &Path, d: &quick_xml::DeError) -> IoError {
    use quick_xml::DeError as D;
    match d {
        D::Custom(text) => IoError::malformed(path, serde_words(text)),
        D::InvalidXml(x) => IoError::malformed(
            path,
            format!("the XML is not well-formed: {}", xml_words(x)),
        ),
        D::InvalidInt(_) | D::InvalidFloat(_) | D::InvalidBoolean(_) => {
            IoError::malformed(path, "an attribute or value is not a valid number")
        }
        D::UnexpectedStart(name) => IoError::malformed(
            path,
            format!(
                "unexpected element <{}>",
                String::from_utf8_lossy(name).trim()
            ),
        ),
        D::UnexpectedEof => {
            IoError::truncated(path, "the XML ends before the document is complete")
        }
        _ => IoError::malformed(path, "the XML does not have the structure of a VTK file"),
    }
}

fn serde_words(text: &str) -> String {
    let quoted = |s: &str| s.replace("`@", "'").replace('`', "'");
    if let Some(rest) = text.strip_prefix("missing field `@") {
        let name = rest.trim_end_matches('`');
        return format!("an element lacks its required attribute '{name}'");
    }
    if let Some(rest) = text.strip_prefix("missing field `") {
        let name = rest.trim_end_matches('`');
        return format!("a required element <{name}> is missing");
    }
    if let Some(rest) = text.strip_prefix("unknown variant ") {
        return format!("unknown value {}", quoted(rest));
    }
    format!("the VTK XML structure is not valid: {}", quoted(text))
}

/// quick-xml's descriptions name tags and characters, not Rust types; its escape errors quote
/// byte ranges, which are replaced by words.
fn xml_words(e: &quick_xml::Error) -> String {
    match e {
        quick_xml::Error::EscapeError(_) => {
            "an '&' escape is not a known entity or lacks its ';'".to_string()
        }
        quick_xml::Error::Io(io) => format!("cannot read: {io}"),
        quick_xml::Error::NonDecodable(_) => "the text is not valid UTF-8".to_string(),
        other => other.to_string(),
    }
}
