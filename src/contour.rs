//! Marching cubes on any volume in one call (paper §2's extraction step, on a scan or a filtered
//! density): the iso value checked against the data, optional closing at the volume's boundary,
//! the surface checked and its topology counted.
//!
//! A sample is inside when its value is `>= iso`. An iso value at or below every sample (all
//! inside) or above every sample (none inside) gives no surface and is refused, except with
//! [`ContourOptions::close`], where all-inside is the box around the volume (a warning says
//! so). Closing pads the volume with one layer of samples below the iso value, so surfaces that
//! touch the boundary are closed there. Cost: O(N³) for N³ samples.

use std::time::Instant;

use voxlod_contouring::marching_cubes;
use voxlod_core::validate::{find_defect, Requirements};
use voxlod_core::{mesh_topology, Grid, Placement, Topology, TriangleMesh, Volume};

use crate::error::Error;
use crate::source::{check_grid_range, iso_outside_data};

/// Options of [`contour`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContourOptions {
    /// The iso value, in the data's units.
    pub iso: f32,
    /// Per-vertex normals from the data's gradient.
    pub normals: bool,
    /// Pad the volume with samples below `iso` so that surfaces touching its boundary close.
    pub close: bool,
}

impl Default for ContourOptions {
    /// Isodensity 0.5 (the surface of a filtered solid), with normals, not closed.
    fn default() -> Self {
        ContourOptions {
            iso: 0.5,
            normals: true,
            close: false,
        }
    }
}

impl ContourOptions {
    /// At `iso`, with normals.
    pub fn at(iso: f32) -> Self {
        ContourOptions {
            iso,
            ..Default::default()
        }
    }

    /// At `iso`, closed at the volume's boundary.
    pub fn closed(iso: f32) -> Self {
        ContourOptions {
            iso,
            close: true,
            ..Default::default()
        }
    }
}

/// The surface of a volume.
#[derive(Clone, Debug)]
pub struct Contour {
    /// Shared vertices, counter-clockwise triangles seen from outside.
    pub mesh: TriangleMesh,
    /// Components, Euler characteristic, genus, manifoldness of `mesh`.
    pub topology: Topology,
    /// Samples of the volume contoured (the padded one when closed).
    pub dims: [usize; 3],
    /// An iso value at or below every sample with `close`.
    pub warnings: Vec<String>,
    /// Wall time of the checks, the padding and marching cubes.
    pub seconds: f64,
}

/// The isosurface of `volume` at `options.iso`.
///
/// ```
/// # fn main() -> Result<(), voxlod::Error> {
/// use voxlod::core::{Grid, Volume};
/// // A 4³ block of 1s in the middle of an 8³ volume of 0s: a closed box surface.
/// let mut volume = Volume::filled(Grid::new([8; 3], [1.0; 3], [0.0; 3])?, 0.0, "doc")?;
/// for k in 2..6 { for j in 2..6 { for i in 2..6 { volume.values[[k, j, i]] = 1.0; } } }
/// let surface = voxlod::contour(&volume, &voxlod::ContourOptions::at(0.5))?;
/// assert!(surface.topology.is_closed_manifold());
/// assert_eq!(surface.topology.genus, Some(0));
/// // No sample reaches 2: no surface, and the error says so.
/// let e = voxlod::contour(&volume, &voxlod::ContourOptions::at(2.0)).unwrap_err();
/// assert!(e.to_string().contains("above the data's maximum"));
/// # Ok(())
/// # }
/// ```
pub fn contour(volume: &Volume, options: &ContourOptions) -> Result<Contour, Error> {
    let start = Instant::now();
    check_grid_range(volume)?;
    let mut warnings = Vec::new();
    if let Some(problem) = iso_outside_data(options.iso, volume)? {
        // Closed, an iso value at or below every sample is the volume's box: say so.
        let all_inside = volume.range().is_some_and(|(lo, _)| options.iso <= lo);
        if !(options.close && all_inside) {
            return Err(problem);
        }
        warnings.push(format!(
            "`iso` {} is at or below every sample: all of the volume is inside, so the surface \
             is the box `close` puts around it",
            options.iso
        ));
    }
    let padded;
    let volume = if options.close {
        padded = pad_below(volume, options.iso)?;
        &padded
    } else {
        volume
    };
    let contour = voxlod_contouring::ContourOptions {
        iso: options.iso,
        normals: options.normals,
        ..Default::default()
    };
    let mut mesh = marching_cubes(volume, &contour)?;
    // An oblique or flipped scan's mesh goes to its world (`voxlod_core::world`).
    Placement::of(&volume.world(), None).apply(&mut mesh);
    if let Some(defect) = find_defect(&mesh, &Requirements::computed()) {
        return Err(Error::ComputedBeyondRange {
            defect,
            cause: "the volume's spacing or origin is too large",
        });
    }
    Ok(Contour {
        topology: mesh_topology(&mesh),
        mesh,
        dims: volume.grid.dims,
        warnings,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// The volume with one more sample on every side, all below `iso`.
fn pad_below(volume: &Volume, iso: f32) -> Result<Volume, Error> {
    let g = volume.grid;
    let dims = g.dims.map(|d| d + 2);
    let origin = [0, 1, 2].map(|a| g.origin[a] - g.spacing[a]);
    let grid = Grid::new(dims, g.spacing, origin)?;
    let (lo, _) = volume.range().unwrap_or((iso, iso));
    let below = lo.min(iso) - 1.0;
    let mut padded = Volume::filled(grid, below, "the padded volume")?;
    for k in 0..g.dims[2] {
        for j in 0..g.dims[1] {
            for i in 0..g.dims[0] {
                padded.values[[k + 1, j + 1, i + 1]] = volume.get(i, j, k);
            }
        }
    }
    Ok(padded)
}
