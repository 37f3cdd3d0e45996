//! Model selection (Low–Tan's display step, also Rossignac–Borrel §5.4): given how much of
//! object space one pixel covers, pick the simplified model whose clustering cells fit in it.
//!
//! The patent's argument: points that fall on the same pixel show as one, so a model whose
//! clustering merged only points closer than a pixel looks like the original. The rule here:
//! the coarsest level whose cell size is at most `tolerance × pixel size`; if even the finest
//! level's cells are larger, the original model. With `tolerance = 1` a cell is no larger than a
//! pixel along an axis; `1/√3` makes the cell's diagonal fit ([`SelectOptions::diagonal`]);
//! values above 1 trade fidelity for speed.
//!
//! It serves both kinds of levels: a clustering series (cell size) and the voxel pyramid of
//! [`crate::lod()`] (a level's cell is its voxel).
//!
//! Cost: O(levels).

use serde::Serialize;

use voxlod_clustering::{ClusteringError, LevelReport};

/// Options of [`select`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SelectOptions {
    /// A level fits when its cell size is at most `tolerance` pixel sizes.
    pub tolerance: f64,
}

impl Default for SelectOptions {
    fn default() -> Self {
        SelectOptions { tolerance: 1.0 }
    }
}

impl SelectOptions {
    /// A cell fits when its side is at most a pixel (the default).
    pub fn side() -> Self {
        Self::default()
    }

    /// A cell fits when its diagonal is at most a pixel: no two vertices merged by a grid cell
    /// are further apart than a pixel.
    pub fn diagonal() -> Self {
        SelectOptions {
            tolerance: 1.0 / 3f64.sqrt(),
        }
    }

    /// A cell fits when its side is at most `pixels` pixels.
    pub fn pixels(pixels: f64) -> Self {
        SelectOptions { tolerance: pixels }
    }
}

/// The model to draw.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Selection {
    /// No level's cells fit in a pixel: draw the original model.
    Original,
    /// Draw this level (an index into the list given to [`select`]).
    Level(usize),
}

/// The coarsest of the levels with the given cell sizes (any order) that fits `pixel_size`:
/// the voxel pyramid's levels (their voxel sizes, [`crate::LodLevel::plan`]) or a clustering
/// series' cell sizes.
///
/// ```
/// # fn main() -> Result<(), voxlod::Error> {
/// // Levels with voxels of 1, 2 and 4 units; a pixel covers 2.5 units: level 1 fits.
/// let choice = voxlod::select(&[1.0, 2.0, 4.0], 2.5, &voxlod::SelectOptions::default())?;
/// assert_eq!(choice, voxlod::Selection::Level(1));
/// // A pixel smaller than the finest voxel: draw the original.
/// let choice = voxlod::select(&[1.0, 2.0, 4.0], 0.5, &voxlod::SelectOptions::side())?;
/// assert_eq!(choice, voxlod::Selection::Original);
/// # Ok(())
/// # }
/// ```
pub fn select(
    cell_sizes: &[f64],
    pixel_size: f64,
    options: &SelectOptions,
) -> Result<Selection, crate::Error> {
    positive("the pixel size", pixel_size)?;
    positive("the selection tolerance", options.tolerance)?;
    for &s in cell_sizes {
        positive("a level's cell size", s)?;
    }
    let limit = options.tolerance * pixel_size;
    Ok(cell_sizes
        .iter()
        .enumerate()
        .filter(|(_, &s)| s <= limit)
        .max_by(|a, b| a.1.total_cmp(b.1).then(b.0.cmp(&a.0)))
        .map_or(Selection::Original, |(i, _)| Selection::Level(i)))
}

/// [`select`] over reports of a series (their `cell_size`).
pub fn select_from_reports(
    reports: &[LevelReport],
    pixel_size: f64,
    options: &SelectOptions,
) -> Result<Selection, crate::Error> {
    let sizes: Vec<f64> = reports.iter().map(|r| r.cell_size).collect();
    select(&sizes, pixel_size, options)
}

/// Object-space size covered by one pixel at `distance` from a perspective camera with a
/// vertical field of view `vertical_fov` (radians) and a viewport `viewport_height` pixels high:
/// `2 · distance · tan(fov / 2) / height`.
pub fn pixel_size(
    distance: f64,
    vertical_fov: f64,
    viewport_height: u32,
) -> Result<f64, crate::Error> {
    positive("the distance", distance)?;
    positive("the field of view", vertical_fov)?;
    if vertical_fov >= std::f64::consts::PI {
        return Err(ClusteringError::InvalidParameter {
            what: "the field of view (below π)",
            value: vertical_fov,
        }
        .into());
    }
    positive("the viewport height", viewport_height as f64)?;
    Ok(2.0 * distance * (0.5 * vertical_fov).tan() / viewport_height as f64)
}

fn positive(what: &'static str, value: f64) -> Result<(), ClusteringError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(ClusteringError::InvalidParameter { what, value })
    }
}

/// A choice among levels of which some have no mesh, and what was passed over.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct DrawnSelection {
    /// The coarsest level with a mesh that fits, or the original model.
    pub selection: Selection,
    /// A level without a mesh that would have fitted, or no level with a mesh at all.
    pub warnings: Vec<String>,
}

/// [`select()`] among the levels that have a mesh (`with_mesh`, one flag per cell size: a level
/// the filter removed has none and cannot be drawn), with a warning when a level without one
/// would have been chosen, or when no level has one.
///
/// ```
/// # fn main() -> Result<(), voxlod::Error> {
/// use voxlod::select::{select_drawn, SelectOptions, Selection};
/// // Cells of 1, 2, 4 and 8; the coarsest level has no mesh.
/// let with_mesh = [true, true, true, false];
/// let s = select_drawn(&[1.0, 2.0, 4.0, 8.0], &with_mesh, 10.0, &SelectOptions::side())?;
/// assert_eq!(s.selection, Selection::Level(2));
/// assert!(s.warnings[0].starts_with("level 3 fits but has no mesh"));
/// # Ok(())
/// # }
/// ```
pub fn select_drawn(
    cell_sizes: &[f64],
    with_mesh: &[bool],
    pixel_size: f64,
    options: &SelectOptions,
) -> Result<DrawnSelection, crate::Error> {
    if with_mesh.len() != cell_sizes.len() {
        let problem = format!("one flag per level: {} levels", cell_sizes.len());
        return Err(crate::InvalidOption::new("with_mesh", with_mesh.len(), problem).into());
    }
    let drawable: Vec<usize> = (0..cell_sizes.len()).filter(|&i| with_mesh[i]).collect();
    let drawable_sizes: Vec<f64> = drawable.iter().map(|&i| cell_sizes[i]).collect();
    let selection = match select(&drawable_sizes, pixel_size, options)? {
        Selection::Level(j) => Selection::Level(drawable[j]),
        Selection::Original => Selection::Original,
    };
    let mut warnings = Vec::new();
    if drawable.is_empty() && !cell_sizes.is_empty() {
        warnings.push(
            "no level has a mesh (the filter removed the object at every level): the original \
             model is chosen"
                .to_string(),
        );
    } else if let Selection::Level(k) = select(cell_sizes, pixel_size, options)? {
        if !with_mesh[k] {
            let instead = match selection {
                Selection::Level(i) => format!("level {i}, the coarsest with a mesh that fits,"),
                Selection::Original => "the original model".to_string(),
            };
            warnings.push(format!(
                "level {k} fits but has no mesh (the filter removed the whole object there): \
                 {instead} is chosen instead"
            ));
        }
    }
    Ok(DrawnSelection {
        selection,
        warnings,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_without_a_mesh_are_passed_over() {
        // Cells of 1, 2, 4, 8; level 3 (the coarsest) has no mesh.
        let sizes = [1.0, 2.0, 4.0, 8.0];
        let options = SelectOptions::pixels(1.0);
        let with_mesh = [true, true, true, false];
        let s = select_drawn(&sizes, &with_mesh, 10.0, &options).unwrap();
        assert_eq!(s.selection, Selection::Level(2));
        assert_eq!(s.warnings.len(), 1, "{:?}", s.warnings);
        assert!(s.warnings[0].starts_with("level 3 fits but has no mesh"));
        // A pixel of 3 fits levels 0 and 1 only: no warning.
        let s = select_drawn(&sizes, &with_mesh, 3.0, &options).unwrap();
        assert_eq!((s.selection, s.warnings.len()), (Selection::Level(1), 0));
        // Nothing drawable: the original, with the reason.
        let s = select_drawn(&sizes, &[false; 4], 10.0, &options).unwrap();
        assert_eq!(s.selection, Selection::Original);
        assert!(
            s.warnings[0].contains("no level has a mesh"),
            "{:?}",
            s.warnings
        );
        // A flag missing: refused.
        assert!(select_drawn(&sizes, &[true; 3], 10.0, &options).is_err());
    }
}
