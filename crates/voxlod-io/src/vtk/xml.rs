//! The binary data of VTK XML files (`.vtp`, `.vti`), decoded here and handed to vtkio as plain
//! base64: the one place where voxlod works around vtkio 0.7.0-rc2's XML reader.
//!
//! VTK's XML writers store a data array as text (`format="ascii"`), as base64 inside the
//! element (`format="binary"`), or at an offset into an `<AppendedData>` section that is
//! either base64 or raw bytes (`encoding="raw"`). Binary data starts with a header of
//! `header_type` integers (`UInt32`, or `UInt64` since VTK 6): the byte count, or for
//! compressed files (`compressor="vtkZLibDataCompressor"`, `vtkLZ4DataCompressor`,
//! `vtkLZMADataCompressor`) the block count `nb`, the block size `nu`, the size `np` of a
//! partial last block (0 when the last block is full) and the compressed size of every block.
//! VTK 9's default is appended, base64, zlib, `UInt32` headers (`vtkXMLWriter`'s constructor).
//!
//! vtkio 0.7.0-rc2 reads ascii and base64 data, but not raw appended data (its `raw` encoding
//! sits behind a `binary` feature the crate does not declare: "unknown variant `raw`"), and
//! its decompressor computes `nu * (nb - 1)`, which overflows for the empty arrays VTK writes
//! for a mesh without verts, lines or strips ("capacity overflow"); it also slices binary data
//! by header values without checking them. So every `binary` and `appended` array is decoded
//! here, with every header value checked against the data present and every size against the
//! memory budget, and written back inline as uncompressed base64 with a `UInt64` header; the
//! `<AppendedData>` section and the `compressor` attribute are dropped. vtkio then parses a
//! document it handles fully. Ascii arrays, and everything else, pass through unchanged.
//!
//! While at it, the arrays of `PolyData` and `ImageData` pieces are checked against the sizes
//! the piece declares (`NumberOfPoints`, the cell counts, the `Extent`): vtkio silently drops
//! an attribute array of the wrong length, which would surface later as a misleading "no
//! array" error. Extents are checked to be ordered.
//!
//! Cost: one pass over the file, one decode and one base64 encode of the binary data, so about
//! twice the decoded data in memory beside the file (checked against the budget first).

mod binary;

use std::path::Path;

use base64::Engine;
use quick_xml::events::{BytesStart, Event};
use quick_xml::Reader;

use crate::{budget, IoError};
use binary::{decode_array, Compressor, Layout, Stream, BASE64};

/// The `<AppendedData>` section: its stream, and where it starts in the file.
struct Appended<'a> {
    stream: Stream<'a>,
    tag_start: usize,
}

fn find(haystack: &[u8], needle: &[u8]) -> Option<usize> {
    haystack.windows(needle.len()).position(|w| w == needle)
}

fn appended_section<'a>(path: &Path, bytes: &'a [u8]) -> Result<Option<Appended<'a>>, IoError> {
    let Some(tag_start) = find(bytes, b"<AppendedData") else {
        return Ok(None);
    };
    let tag_end = bytes[tag_start..]
        .iter()
        .position(|&b| b == b'>')
        .map(|p| tag_start + p + 1)
        .ok_or_else(|| IoError::truncated(path, "the file ends within the <AppendedData> tag"))?;
    let mut reader = Reader::from_reader(&bytes[tag_start..tag_end]);
    let encoding = match reader.read_event() {
        Ok(Event::Start(e)) | Ok(Event::Empty(e)) => attribute(&e, b"encoding"),
        _ => None,
    };
    let after = &bytes[tag_end..];
    let underscore = after
        .iter()
        .position(|b| !b.is_ascii_whitespace())
        .filter(|&p| after[p] == b'_')
        .ok_or_else(|| {
            IoError::malformed(
                path,
                "the appended data does not start with '_' as VTK's does",
            )
        })?;
    let data_start = tag_end + underscore + 1;
    let data_end = bytes
        .windows(b"</AppendedData".len())
        .rposition(|w| w == b"</AppendedData")
        .filter(|&end| end >= data_start)
        .ok_or_else(|| {
            IoError::truncated(
                path,
                "the appended data has no </AppendedData> end: the file is cut short",
            )
        })?;
    let data = &bytes[data_start..data_end];
    let stream = match encoding.as_deref() {
        Some("raw") => Stream::Raw(data),
        Some("base64") => Stream::Base64(data),
        other => {
            return Err(IoError::unsupported(
                path,
                format!(
                    "appended data encoding '{}' (VTK writes raw or base64)",
                    other.unwrap_or("")
                ),
            ))
        }
    };
    Ok(Some(Appended { stream, tag_start }))
}

/// An attribute's unescaped value (`None` if missing or not decodable).
fn attribute(e: &BytesStart<'_>, key: &[u8]) -> Option<String> {
    e.attributes()
        .flatten()
        .find(|a| a.key.as_ref() == key)
        .and_then(|a| a.unescape_value().ok().map(|v| v.into_owned()))
}

/// Bytes per value of a VTK XML `type`.
fn type_size(name: &str) -> Option<u64> {
    Some(match name {
        "Int8" | "UInt8" => 1,
        "Int16" | "UInt16" => 2,
        "Int32" | "UInt32" | "Float32" => 4,
        "Int64" | "UInt64" | "Float64" => 8,
        _ => return None,
    })
}

/// An `Extent` or `WholeExtent`: six integers, each axis's end not before its start.
fn parse_extent(path: &Path, what: &str, text: &str) -> Result<[i64; 6], IoError> {
    let values: Vec<i64> = text
        .split_ascii_whitespace()
        .map(|t| t.parse().ok())
        .collect::<Option<_>>()
        .filter(|v: &Vec<i64>| v.len() == 6)
        .ok_or_else(|| IoError::malformed(path, format!("{what} '{text}' is not six integers")))?;
    for (axis, name) in ["x", "y", "z"].iter().enumerate() {
        let (lo, hi) = (values[2 * axis], values[2 * axis + 1]);
        if hi < lo {
            return Err(IoError::malformed(
                path,
                format!("{what} '{text}' ends before it starts along {name} ({hi} < {lo})"),
            ));
        }
    }
    Ok([0, 1, 2, 3, 4, 5].map(|i| values[i]))
}

fn extent_points(extent: &[i64; 6]) -> u64 {
    (0..3)
        .map(|a| (extent[2 * a + 1] - extent[2 * a] + 1) as u64)
        .fold(1u64, u64::saturating_mul)
}

/// The sizes the current piece declares, for checking its arrays.
#[derive(Default)]
struct Piece {
    points: Option<u64>,
    /// All cells: verts, lines, strips and polys (PolyData only).
    cells: Option<u64>,
    has_points: bool,
    number: usize,
}

/// The state of one pass over the XML part of a file.
struct Rewrite<'a> {
    path: &'a Path,
    xml: &'a [u8],
    appended: Option<Stream<'a>>,
    layout: Layout,
    data_set: String,
    whole_extent: Option<[i64; 6]>,
    piece: Piece,
    pieces: usize,
    /// Names of the open elements.
    open: Vec<Vec<u8>>,
    out: Vec<u8>,
    copied_to: usize,
    changed: bool,
    decoded: u64,
}

/// `bytes` with every binary array decoded and written back as plain base64 (see the module
/// documentation); `None` when the file has no binary data, so vtkio can take it as it is.
pub(crate) fn rewrite(path: &Path, bytes: &[u8]) -> Result<Option<Vec<u8>>, IoError> {
    let appended = appended_section(path, bytes)?;
    let xml_end = appended.as_ref().map_or(bytes.len(), |a| a.tag_start);
    let mut state = Rewrite {
        path,
        xml: &bytes[..xml_end],
        appended: appended.as_ref().map(|a| a.stream),
        layout: Layout {
            big_endian: false,
            header: 4,
            compressor: Compressor::None,
        },
        data_set: String::new(),
        whole_extent: None,
        piece: Piece::default(),
        pieces: 0,
        open: Vec::new(),
        out: Vec::new(),
        copied_to: 0,
        changed: appended.is_some(),
        decoded: 0,
    };
    state.run()?;
    if !state.changed {
        return Ok(None);
    }
    let mut out = std::mem::take(&mut state.out);
    out.extend_from_slice(&state.xml[state.copied_to..]);
    if appended.is_some() {
        out.extend_from_slice(b"\n</VTKFile>\n");
    }
    Ok(Some(out))
}

impl<'a> Rewrite<'a> {
    fn run(&mut self) -> Result<(), IoError> {
        let mut reader = Reader::from_reader(self.xml);
        loop {
            let start = reader.buffer_position() as usize;
            let event = reader
                .read_event()
                .map_err(|e| IoError::from_xml(self.path, &e, reader.error_position()))?;
            match event {
                Event::Start(e) if e.name().as_ref() == b"DataArray" => {
                    let content = self.array_content(&mut reader, &e)?;
                    let end = reader.buffer_position() as usize;
                    self.data_array(&e, &content, start..end)?;
                }
                Event::Empty(e) if e.name().as_ref() == b"DataArray" => {
                    let end = reader.buffer_position() as usize;
                    self.data_array(&e, &[], start..end)?;
                }
                Event::Start(e) => {
                    let end = reader.buffer_position() as usize;
                    self.element(&e, start..end, false)?;
                    self.open.push(e.name().as_ref().to_vec());
                }
                Event::Empty(e) => {
                    let end = reader.buffer_position() as usize;
                    self.element(&e, start..end, true)?;
                    self.close(e.name().as_ref())?;
                }
                Event::End(e) => {
                    self.open.pop();
                    self.close(e.name().as_ref())?;
                }
                Event::Eof => return Ok(()),
                _ => {}
            }
        }
    }

    /// The text of a `<DataArray>` up to its end tag (nested elements, such as VTK's
    /// `<InformationKey>`, are skipped; their separate texts joined by spaces).
    fn array_content(
        &self,
        reader: &mut Reader<&'a [u8]>,
        start: &BytesStart<'_>,
    ) -> Result<Vec<u8>, IoError> {
        let mut content = Vec::new();
        let mut depth = 0usize;
        loop {
            let event = reader
                .read_event()
                .map_err(|e| IoError::from_xml(self.path, &e, reader.error_position()))?;
            match event {
                Event::Text(t) if depth == 0 => {
                    content.extend_from_slice(&t);
                    content.push(b' ');
                }
                Event::CData(t) if depth == 0 => {
                    content.extend_from_slice(&t);
                    content.push(b' ');
                }
                Event::Start(_) => depth += 1,
                Event::End(_) if depth > 0 => depth -= 1,
                Event::End(_) => return Ok(content),
                Event::Eof => {
                    return Err(IoError::truncated(
                        self.path,
                        format!(
                            "the file ends within data array '{}'",
                            attribute(start, b"Name").unwrap_or_default()
                        ),
                    ))
                }
                _ => {}
            }
        }
    }

    /// Bookkeeping for the elements around the arrays.
    fn element(
        &mut self,
        e: &BytesStart<'_>,
        range: std::ops::Range<usize>,
        empty: bool,
    ) -> Result<(), IoError> {
        match e.name().as_ref() {
            b"VTKFile" => self.vtk_file(e, range, empty)?,
            b"ImageData" => {
                if let Some(text) = attribute(e, b"WholeExtent") {
                    self.whole_extent = Some(parse_extent(self.path, "WholeExtent", &text)?);
                }
            }
            b"Piece" => self.start_piece(e)?,
            b"Points" if self.open.last().is_some_and(|n| n == b"Piece") => {
                self.piece.has_points = true
            }
            _ => {}
        }
        Ok(())
    }

    /// Checks on closing an element: a PolyData piece must have points.
    fn close(&mut self, name: &[u8]) -> Result<(), IoError> {
        if name == b"Piece" && self.data_set == "PolyData" && !self.piece.has_points {
            return Err(IoError::malformed(
                self.path,
                format!("piece {} has no <Points>", self.piece.number),
            ));
        }
        Ok(())
    }
}

impl Rewrite<'_> {
    /// Reads the layout from `<VTKFile>` and rewrites the tag without `compressor`, with
    /// `header_type="UInt64"` (what the rewritten arrays use).
    fn vtk_file(
        &mut self,
        e: &BytesStart<'_>,
        range: std::ops::Range<usize>,
        empty: bool,
    ) -> Result<(), IoError> {
        let path = self.path;
        self.data_set = attribute(e, b"type").unwrap_or_default();
        let byte_order = attribute(e, b"byte_order");
        self.layout.big_endian = match byte_order.as_deref() {
            None | Some("LittleEndian") => false,
            Some("BigEndian") => true,
            Some(other) => {
                return Err(IoError::malformed(
                    path,
                    format!("byte_order '{other}' is neither LittleEndian nor BigEndian"),
                ))
            }
        };
        self.layout.header = match attribute(e, b"header_type").as_deref() {
            None | Some("UInt32") => 4,
            Some("UInt64") => 8,
            Some(other) => {
                return Err(IoError::malformed(
                    path,
                    format!("header_type '{other}' is neither UInt32 nor UInt64"),
                ))
            }
        };
        self.layout.compressor = match attribute(e, b"compressor").as_deref() {
            None | Some("") => Compressor::None,
            Some("vtkZLibDataCompressor") => Compressor::Zlib,
            Some("vtkLZ4DataCompressor") => Compressor::Lz4,
            Some("vtkLZMADataCompressor") => Compressor::Lzma,
            Some(other) => {
                return Err(IoError::unsupported(
                    path,
                    format!("compressor '{other}' (VTK's are zlib, LZ4 and LZMA)"),
                ))
            }
        };
        let mut tag = String::from("<VTKFile");
        for a in e.attributes().flatten() {
            let key = String::from_utf8_lossy(a.key.as_ref()).into_owned();
            if key == "compressor" || key == "header_type" {
                continue;
            }
            let value = a
                .unescape_value()
                .map(|v| v.into_owned())
                .unwrap_or_default();
            tag.push_str(&format!(" {key}=\"{}\"", quick_xml::escape::escape(&value)));
        }
        if byte_order.is_none() {
            // vtkio insists on it; VTK's writers always say it. Little-endian, as VTK's reader
            // assumes on the machines that write such files.
            tag.push_str(" byte_order=\"LittleEndian\"");
        }
        tag.push_str(if empty {
            " header_type=\"UInt64\"/>"
        } else {
            " header_type=\"UInt64\">"
        });
        self.replace(range, tag.as_bytes());
        Ok(())
    }

    /// Takes the sizes a `<Piece>` declares, checked against the budget.
    fn start_piece(&mut self, e: &BytesStart<'_>) -> Result<(), IoError> {
        let path = self.path;
        self.pieces += 1;
        self.piece = Piece {
            number: self.pieces - 1,
            ..Piece::default()
        };
        let count = |key: &str| -> Result<u64, IoError> {
            match attribute(e, key.as_bytes()) {
                None => Ok(0),
                Some(text) => text.trim().parse().map_err(|_| {
                    IoError::malformed(path, format!("Piece {key}='{text}' is not a count"))
                }),
            }
        };
        match self.data_set.as_str() {
            "PolyData" => {
                let points = count("NumberOfPoints")?;
                let mut cells = 0u64;
                for key in [
                    "NumberOfVerts",
                    "NumberOfLines",
                    "NumberOfStrips",
                    "NumberOfPolys",
                ] {
                    let n = count(key)?;
                    budget::check_count(
                        path,
                        &format!("the cells of piece {}", self.piece.number),
                        n,
                        16,
                    )?;
                    cells = cells.saturating_add(n);
                }
                // Coordinates as read and as f64, then as f32 in the mesh.
                budget::check_count(path, "the points of a piece", points, 3 * (8 + 8 + 4))?;
                self.piece.points = Some(points);
                self.piece.cells = Some(cells);
            }
            "ImageData" => {
                let extent = match attribute(e, b"Extent") {
                    Some(text) => parse_extent(path, "the piece's Extent", &text)?,
                    None => self.whole_extent.ok_or_else(|| {
                        IoError::malformed(
                            path,
                            "the image has neither a WholeExtent nor a piece Extent",
                        )
                    })?,
                };
                let points = extent_points(&extent);
                // The samples as read, and as f32 in the volume.
                budget::check_count(path, "the points of the image", points, 8 + 4)?;
                self.piece.points = Some(points);
            }
            _ => {}
        }
        Ok(())
    }

    /// Copies the file up to `range` and writes `with` in its place.
    fn replace(&mut self, range: std::ops::Range<usize>, with: &[u8]) {
        self.out
            .extend_from_slice(&self.xml[self.copied_to..range.start]);
        self.out.extend_from_slice(with);
        self.copied_to = range.end;
        self.changed = true;
    }

    /// Decodes one array (unless it is ascii), checks its length against its piece, and
    /// writes it back as plain base64.
    fn data_array(
        &mut self,
        e: &BytesStart<'_>,
        content: &[u8],
        range: std::ops::Range<usize>,
    ) -> Result<(), IoError> {
        let path = self.path;
        let name = attribute(e, b"Name").unwrap_or_default();
        let label = self.label(&name);
        let type_name = attribute(e, b"type").unwrap_or_default();
        let size = type_size(&type_name).ok_or_else(|| {
            IoError::unsupported(
                path,
                format!("{label} has type '{type_name}', which is not a numeric VTK type"),
            )
        })?;
        let components = match attribute(e, b"NumberOfComponents") {
            None => 1,
            Some(text) => text
                .trim()
                .parse::<u64>()
                .ok()
                .filter(|&c| c > 0)
                .ok_or_else(|| {
                    IoError::malformed(path, format!("{label} has NumberOfComponents '{text}'"))
                })?,
        };
        let Some(bytes) = self.binary_bytes(e, &label, content, components)? else {
            return Ok(());
        };
        if !(bytes.len() as u64).is_multiple_of(size) {
            return Err(IoError::malformed(
                path,
                format!(
                    "{label} holds {} bytes, not a whole number of {type_name} values",
                    bytes.len()
                ),
            ));
        }
        self.check_length(&label, bytes.len() as u64 / size, components)?;
        self.decoded = self.decoded.saturating_add(bytes.len() as u64);
        budget::check_bytes(
            path,
            "the decoded VTK data",
            (self.xml.len() as u64).saturating_add(self.decoded.saturating_mul(3)),
        )?;
        let mut payload = Vec::with_capacity(8 + bytes.len());
        let header = Layout {
            header: 8,
            ..self.layout
        };
        payload.extend_from_slice(&header.encode_number(bytes.len() as u64));
        payload.extend_from_slice(&bytes);
        drop(bytes);
        let element = format!(
            "<DataArray type=\"{type_name}\" Name=\"{}\" NumberOfComponents=\"{components}\" format=\"binary\">{}</DataArray>",
            quick_xml::escape::escape(&name),
            BASE64.encode(&payload)
        );
        self.replace(range, element.as_bytes());
        Ok(())
    }

    /// The decoded bytes of a `binary` or `appended` array; an `ascii` one is only counted
    /// (and gives `None`).
    fn binary_bytes(
        &self,
        e: &BytesStart<'_>,
        label: &str,
        content: &[u8],
        components: u64,
    ) -> Result<Option<Vec<u8>>, IoError> {
        let path = self.path;
        let format = attribute(e, b"format").unwrap_or_default();
        let bytes = match format.as_str() {
            "ascii" => {
                // vtkio drops an attribute array it cannot parse without a word; say which.
                let integer = attribute(e, b"type").is_some_and(|t| t.contains("Int"));
                let mut values = 0u64;
                for token in content
                    .split(|b| b.is_ascii_whitespace())
                    .filter(|t| !t.is_empty())
                {
                    let text = String::from_utf8_lossy(token);
                    let number = if integer {
                        text.parse::<i128>().is_ok()
                    } else {
                        text.parse::<f64>().is_ok()
                    };
                    if !number {
                        return Err(IoError::malformed(
                            path,
                            format!(
                                "{label}: value {values} is '{}', not {}",
                                text.chars().take(40).collect::<String>(),
                                if integer { "an integer" } else { "a number" }
                            ),
                        ));
                    }
                    values += 1;
                }
                self.check_length(label, values, components)?;
                return Ok(None);
            }
            "binary" => {
                let text: Vec<u8> = content
                    .iter()
                    .copied()
                    .filter(|b| !b.is_ascii_whitespace())
                    .collect();
                decode_array(path, label, Stream::Base64(&text), 0, &self.layout)?
            }
            "appended" => {
                let stream = self.appended.ok_or_else(|| {
                    IoError::malformed(
                        path,
                        format!(
                            "{label} refers to appended data, but the file has no <AppendedData>"
                        ),
                    )
                })?;
                let offset = match attribute(e, b"offset") {
                    None => 0,
                    Some(text) => text.trim().parse::<u64>().map_err(|_| {
                        IoError::malformed(path, format!("{label} has offset '{text}'"))
                    })?,
                };
                decode_array(path, label, stream, offset, &self.layout)?
            }
            other => {
                return Err(IoError::malformed(
                    path,
                    format!("{label} has format '{other}' (ascii, binary or appended)"),
                ))
            }
        };
        Ok(Some(bytes))
    }

    /// Point and cell arrays must have one tuple per point or cell of their piece.
    /// How messages name an array: by its `Name`, or by where it is.
    fn label(&self, name: &str) -> String {
        if name.is_empty() {
            let section = self
                .open
                .last()
                .map(|s| String::from_utf8_lossy(s).into_owned());
            format!(
                "the unnamed data array in <{}>",
                section.unwrap_or_default()
            )
        } else {
            format!("data array '{name}'")
        }
    }

    fn check_length(&self, label: &str, values: u64, components: u64) -> Result<(), IoError> {
        let section = self.open.last().map(Vec::as_slice).unwrap_or_default();
        let (what, count) = match section {
            b"Points" => ("points", self.piece.points),
            b"PointData" => ("points", self.piece.points),
            b"CellData" => ("cells", self.piece.cells),
            _ => return Ok(()),
        };
        let Some(count) = count else {
            return Ok(());
        };
        let expected = count.saturating_mul(components);
        if values == expected {
            return Ok(());
        }
        let message = format!(
            "{label} of piece {} holds {values} values where its {count} {what} of {components} component{} need {expected}",
            self.piece.number,
            if components == 1 { "" } else { "s" }
        );
        Err(if values < expected {
            IoError::truncated(self.path, message)
        } else {
            IoError::malformed(self.path, message)
        })
    }
}
