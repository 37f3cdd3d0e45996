//! The names and colours of a label map's structures, from 3D Slicer's `.seg.nrrd` segment
//! fields (`Segment0_Name:=liver`, `Segment0_LabelValue:=1`, `Segment0_Color:=0.8 0.2 0.1`,
//! `Segment0_Layer:=0`, NRRD key/value pairs), or from a DICOM Segmentation's Segment Sequence
//! (`dicom/seg.rs`; [`crate::read_label_map`] chooses). Other formats, and NRRDs without segments, give
//! an empty table. Only the header is read (at most 1 MiB of it); a table whose fields do not parse
//! is an error naming the field. Cost: one pass over the header.

use std::collections::BTreeMap;
use std::io::{BufRead, BufReader, Read};
use std::path::Path;

use voxlod_core::LabelVolume;

use crate::{IoError, IoErrorKind};

/// A label map: its exact `u32` labels, its label table, and what reading it warned of.
#[derive(Clone, Debug)]
pub struct LabelMap {
    /// The labels, one per voxel, x fastest (0 is the background).
    pub labels: LabelVolume,
    /// Names and colours of the labels the file names.
    pub table: Vec<LabelName>,
    /// Warnings, each a line naming the file (overlapping DICOM segments).
    pub warnings: Vec<String>,
}

/// One named structure of a label map.
#[derive(Clone, Debug, PartialEq)]
pub struct LabelName {
    /// The label value in the map.
    pub value: i64,
    /// The segment's name (may be empty).
    pub name: String,
    /// Red, green, blue in 0..=1, when the file gives them.
    pub color: Option<[f32; 3]>,
}

/// The longest header read for a label table.
const HEADER_LIMIT: u64 = 1 << 20;

/// The key/value pairs (`key:=value`) of a NRRD header.
fn key_values(path: &Path) -> Result<Vec<(String, String)>, IoError> {
    let file = std::fs::File::open(path).map_err(|e| IoError::access(path, "cannot open", &e))?;
    let mut reader = BufReader::new(file.take(HEADER_LIMIT));
    let mut pairs = Vec::new();
    let mut line = Vec::new();
    loop {
        line.clear();
        let n = reader
            .read_until(b'\n', &mut line)
            .map_err(|e| IoError::access(path, "cannot read", &e))?;
        let text = String::from_utf8_lossy(&line);
        let text = text.trim_end_matches(['\r', '\n']);
        if n == 0 || text.is_empty() {
            break;
        }
        if let Some((k, v)) = text.split_once(":=") {
            pairs.push((k.trim().to_string(), v.trim().to_string()));
        }
    }
    Ok(pairs)
}

/// The label table of a label map: Slicer's segment fields of a NRRD, else empty.
pub fn read_label_table(path: &Path) -> Result<Vec<LabelName>, IoError> {
    let name = path.to_string_lossy().to_ascii_lowercase();
    if !(name.ends_with(".nrrd") || name.ends_with(".nhdr")) {
        return Ok(Vec::new());
    }
    let mut segments: BTreeMap<usize, BTreeMap<String, String>> = BTreeMap::new();
    for (key, value) in key_values(path)? {
        let Some(rest) = key.strip_prefix("Segment") else {
            continue;
        };
        let Some((index, field)) = rest.split_once('_') else {
            continue;
        };
        if let Ok(index) = index.parse::<usize>() {
            segments
                .entry(index)
                .or_default()
                .insert(field.to_string(), value);
        }
    }
    let bad = |field: String, value: &str| {
        IoError::new(
            path,
            IoErrorKind::Malformed,
            format!("the segment field {field}:={value} cannot be understood"),
        )
    };
    segments
        .into_iter()
        .filter_map(|(index, fields)| {
            let value = fields.get("LabelValue")?;
            Some((index, fields.clone(), value.clone()))
        })
        .map(|(index, fields, value)| {
            let label = value
                .parse::<i64>()
                .map_err(|_| bad(format!("Segment{index}_LabelValue"), &value))?;
            let color = match fields.get("Color") {
                None => None,
                Some(text) => {
                    let rgb: Vec<f32> = text
                        .split_whitespace()
                        .map(|c| c.parse::<f32>())
                        .collect::<Result<_, _>>()
                        .map_err(|_| bad(format!("Segment{index}_Color"), text))?;
                    (rgb.len() == 3).then(|| [rgb[0], rgb[1], rgb[2]])
                }
            };
            Ok(LabelName {
                value: label,
                name: fields.get("Name").cloned().unwrap_or_default(),
                color,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_slicer_segment_fields_and_ignores_the_rest() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.seg.nrrd");
        std::fs::write(
            &path,
            "NRRD0004\ntype: uchar\nSegment0_Name:=liver\nSegment0_LabelValue:=1\nSegment0_Color:=0.5 0.25 1\nSegment1_LabelValue:=4\nSegment1_Name:=left kidney\nSegment2_Name:=no value\nother:=x\n\nDATA:=ignored\n",
        )
        .unwrap();
        let table = read_label_table(&path).unwrap();
        assert_eq!(table.len(), 2);
        assert_eq!(
            table[0],
            LabelName {
                value: 1,
                name: "liver".into(),
                color: Some([0.5, 0.25, 1.0])
            }
        );
        assert_eq!(table[1].name, "left kidney");
        assert_eq!(table[1].value, 4);
        std::fs::write(&path, "NRRD0004\nSegment0_LabelValue:=one\n\n").unwrap();
        assert!(read_label_table(&path)
            .unwrap_err()
            .message
            .contains("Segment0_LabelValue"));
        assert!(read_label_table(Path::new("map.nii.gz"))
            .unwrap()
            .is_empty());
    }
}
