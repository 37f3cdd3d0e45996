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
use voxlod_core::{mesh_topology, Placement, Topology, TriangleMesh, Volume};

use crate::error::Error;
use voxlod_pyramid::source::{check_grid_range, iso_outside_data};
use voxlod_pyramid::PyramidError;

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
    /// Wall time of the whole call: the checks of the data and of the mesh, the padding,
    /// marching cubes and the topology.
    pub seconds: f64,
    /// Wall time of marching cubes alone.
    pub marching_cubes_seconds: f64,
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
    let nan = volume.nan_warning("marching cubes counts NaN as outside");
    let mut warnings: Vec<String> = nan.into_iter().collect();
    if let Some(problem) = iso_outside_data(options.iso, volume)? {
        // Closed, an iso value at or below every sample is the volume's box: say so.
        let all_inside = volume.range().is_some_and(|(lo, _)| options.iso <= lo);
        if !(options.close && all_inside) {
            return Err(problem.into());
        }
        warnings.push(format!(
            "`iso` {} is at or below every sample: all of the volume is inside, so the surface \
             is the box `close` puts around it",
            options.iso
        ));
    }
    let padded;
    let volume = if options.close {
        padded = volume.padded_below(options.iso)?;
        &padded
    } else {
        volume
    };
    let contour = voxlod_contouring::ContourOptions {
        iso: options.iso,
        normals: options.normals,
        ..Default::default()
    };
    let marching = Instant::now();
    let mut mesh = marching_cubes(volume, &contour)?;
    let marching_cubes_seconds = marching.elapsed().as_secs_f64();
    // An oblique or flipped scan's mesh goes to its world (`voxlod_core::world`).
    Placement::of(&volume.world(), None).apply(&mut mesh);
    if let Some(defect) = find_defect(&mesh, &Requirements::computed()) {
        return Err(PyramidError::ComputedBeyondRange {
            defect,
            cause: "the volume's spacing or origin is too large",
        }
        .into());
    }
    Ok(Contour {
        topology: mesh_topology(&mesh),
        mesh,
        dims: volume.grid.dims,
        warnings,
        seconds: start.elapsed().as_secs_f64(),
        marching_cubes_seconds,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use voxlod_core::glam::{DMat3, DVec3};
    use voxlod_core::{Frame, Grid, Orientation};

    /// A ball of radius 3 (in the grid's units) around index (6, 5, 4) of a 12 × 11 × 10 grid
    /// with unequal spacing, rotated and flipped.
    fn oblique_ball() -> Volume {
        let grid = Grid::new([12, 11, 10], [0.8, 1.1, 1.5], [-20.0, 13.0, -7.0]).unwrap();
        let centre = DVec3::new(6.0, 5.0, 4.0) * grid.spacing_vec();
        let mut values = Vec::with_capacity(grid.len());
        for k in 0..10 {
            for j in 0..11 {
                for i in 0..12 {
                    let p = DVec3::new(i as f64, j as f64, k as f64) * grid.spacing_vec();
                    values.push((3.0 - (p - centre).length()) as f32);
                }
            }
        }
        let direction = DMat3::from_rotation_z(0.5)
            * DMat3::from_rotation_x(0.2)
            * DMat3::from_diagonal(DVec3::new(1.0, -1.0, 1.0));
        Volume::from_vec(grid, values)
            .unwrap()
            .oriented(Orientation {
                direction,
                frame: Frame::Lps,
            })
    }

    fn sorted_positions(mesh: &TriangleMesh) -> Vec<[i64; 3]> {
        let mut p: Vec<[i64; 3]> = mesh
            .positions
            .iter()
            .map(|v| v.to_array().map(|x| (f64::from(x) * 1e3).round() as i64))
            .collect();
        p.sort_unstable();
        p
    }

    #[test]
    fn closing_keeps_an_oblique_flipped_scan_in_place() {
        let volume = oblique_ball();
        let open = contour(&volume, &ContourOptions::at(0.0)).unwrap();
        let closed = contour(&volume, &ContourOptions::closed(0.0)).unwrap();
        assert!(open.topology.is_closed_manifold());
        assert_eq!(closed.dims, [14, 13, 12]);
        assert_eq!(sorted_positions(&closed.mesh), sorted_positions(&open.mesh));
        // And both lie around the ball's centre in the world.
        let centre = volume.world().index_to_world(DVec3::new(6.0, 5.0, 4.0));
        let n = open.mesh.positions.len() as f64;
        let mean = open
            .mesh
            .positions
            .iter()
            .fold(DVec3::ZERO, |s, p| s + p.as_dvec3() / n);
        assert!((mean - centre).length() < 0.1, "{mean} {centre}");
    }
}
