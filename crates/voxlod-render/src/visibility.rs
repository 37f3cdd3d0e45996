//! Which triangles of a scene can be seen from outside: the mesh is drawn from many directions
//! around it and a triangle counts as seen when it is the nearest surface at enough samples.
//!
//! This is how level-of-detail tools cull what a scene proxy need not keep (furniture inside a
//! closed building, faces buried in other parts): render a sphere of views and keep what shows.
//! It is not in He et al. (1995).
//!
//! **Views.** `views` directions spread evenly over the whole sphere ([`sphere_directions`], a
//! Fibonacci sphere), each an orthographic camera of `resolution`² pixels framing the mesh's
//! bounding sphere ([`Camera::fit`]), one sample per pixel centre.
//!
//! **Samples won.** Each view is drawn twice (`snapped.rs`: corners on a 1/256-sample lattice,
//! exact integer coverage, f64 depth on that same geometry). The first pass keeps the nearest
//! depth at every sample; the second credits a sample to every triangle that holds it strictly
//! inside at a depth no more than 10⁻¹² of the scene's farthest depth beyond it. So a sample
//! on an edge is credited to no one: where a buried face meets the outer surface along an edge
//! (two boxes touching, a face flush with another) it ties there with the outer faces, and one
//! wrongly won sample would make it seen. Coincident duplicates (a double-sided card made of
//! two opposite triangles) tie inside and are both credited. Both sides of a triangle count
//! (no back-face culling): an open leaf card seen from behind is seen. [`crate::raster`] is not
//! used because it reports neither edges nor f64 depths.
//!
//! **Resolution.** A triangle is seen only where it holds sample centres: one smaller than a
//! pixel, or seen only through a gap narrower than one, may hold none in any view and be
//! reported hidden. Raise `resolution` until the smallest triangles to keep span a few pixels.
//!
//! **Cost.** O(V + T + rows the triangles span + samples they cover + resolution²) per view,
//! views in parallel on one depth buffer of 8 bytes per sample per worker; zero-area triangles
//! are never seen.

mod points;
mod snapped;

pub use points::seen_points;

use glam::DVec3;
use rayon::prelude::*;
use voxlod_core::memory::{bytes_of, check_allocation};
use voxlod_core::{Bounds, TriangleMesh};

use crate::{Camera, RenderError};
use snapped::{GridPoint, SnappedTriangle};

/// How to look at the mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VisibilityOptions {
    /// View directions, spread evenly on the sphere (at least 1).
    pub views: usize,
    /// Pixels per side of each square view (1 to 16384).
    pub resolution: u32,
    /// Samples a triangle must win, summed over all views, to count as seen (at least 1).
    pub min_samples: u32,
}

impl Default for VisibilityOptions {
    /// 64 views of 512² pixels; one sample won is enough.
    fn default() -> Self {
        VisibilityOptions {
            views: 64,
            resolution: 512,
            min_samples: 1,
        }
    }
}

/// `count` unit directions on the Fibonacci sphere: heights `1 − (2i + 1)/count`, turning by
/// the golden angle, so every region of the sphere gets a share of the points proportional to
/// its area (up to O(1/√count)). Cost: O(count).
pub fn sphere_directions(count: usize) -> Vec<DVec3> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..count)
        .map(|i| {
            let y = 1.0 - (2 * i + 1) as f64 / count as f64;
            let r = (1.0 - y * y).max(0.0).sqrt();
            let phi = golden * i as f64;
            DVec3::new(r * phi.cos(), y, r * phi.sin())
        })
        .collect()
}

/// Whether each triangle of `mesh` is seen from outside: wins at least `min_samples` samples
/// over all views (see the module documentation). One entry per triangle, in order.
///
/// # Errors
///
/// As [`visible_sample_counts`].
///
/// # Example
///
/// A unit cube with a small cube inside: the outer 12 triangles are seen, the inner 12 not.
///
/// ```
/// use glam::Vec3;
/// use voxlod_render::{visible_triangles, VisibilityOptions};
/// use voxlod_testkit::shapes::{append, unit_cube};
///
/// let mut scene = unit_cube();
/// let mut inner = unit_cube();
/// inner.positions.iter_mut().for_each(|p| *p = Vec3::splat(0.4) + *p * 0.2);
/// append(&mut scene, &inner);
/// let seen = visible_triangles(&scene, &VisibilityOptions::default())?;
/// assert!(seen[..12].iter().all(|&s| s) && !seen[12..].iter().any(|&s| s));
/// # Ok::<(), voxlod_render::RenderError>(())
/// ```
pub fn visible_triangles(
    mesh: &TriangleMesh,
    options: &VisibilityOptions,
) -> Result<Vec<bool>, RenderError> {
    let counts = visible_sample_counts(mesh, options)?;
    let min = u64::from(options.min_samples);
    Ok(counts.into_iter().map(|c| c >= min).collect())
}

/// The samples each triangle of `mesh` wins (is the nearest surface at), summed over all the
/// views of `options`; `min_samples` is checked but not applied. Cost: see the module
/// documentation.
///
/// # Errors
///
/// [`RenderError::EmptyScene`] for a mesh without triangles, [`RenderError::Invalid`] for a
/// non-finite coordinate, an index out of range, zero views or a `min_samples` of zero,
/// [`RenderError::BadSize`] for a resolution outside 1 to 16384, and the memory budget's
/// refusal of the buffers ([`RenderError::Core`]).
pub fn visible_sample_counts(
    mesh: &TriangleMesh,
    options: &VisibilityOptions,
) -> Result<Vec<u64>, RenderError> {
    let bounds = check_request(mesh, options)?;
    let what = "visibility buffers";
    let partial = over_views(
        mesh,
        &bounds,
        options,
        mesh.triangles.len(),
        what,
        |view, camera, counts| view.credit(mesh, &bounds, camera, counts),
    )?;
    let mut total = vec![0u64; mesh.triangles.len()];
    for counts in partial {
        for (t, c) in total.iter_mut().zip(counts) {
            *t += c;
        }
    }
    Ok(total)
}

/// Runs `visit` on every view of `options` around `mesh` (whose bounds are `bounds`), the views
/// shared among the workers, each worker with one [`View`] and `len` entries of its own, all
/// `T::default()` at first; returns each worker's entries. The buffers are checked against the
/// memory budget first (`what` names them in the refusal).
fn over_views<T: Clone + Default + Send>(
    mesh: &TriangleMesh,
    bounds: &Bounds,
    options: &VisibilityOptions,
    len: usize,
    what: &str,
    visit: impl Fn(&mut View, &Camera, &mut [T]) + Sync,
) -> Result<Vec<Vec<T>>, RenderError> {
    let res = options.resolution;
    let cameras = sphere_directions(options.views)
        .into_iter()
        .map(|d| Camera::fit(d, bounds, res, res, None))
        .collect::<Result<Vec<_>, _>>()?;
    let workers = rayon::current_num_threads().clamp(1, cameras.len());
    let per_worker = bytes_of::<f64>(res as usize * res as usize)
        .saturating_add(bytes_of::<T>(len))
        .saturating_add(bytes_of::<GridPoint>(mesh.positions.len()));
    check_allocation(
        &format!("{workers} {what} of {res}x{res} samples"),
        per_worker.saturating_mul(workers as u64),
    )?;
    let share = cameras.len().div_ceil(workers);
    Ok(cameras
        .par_chunks(share)
        .map(|chunk| {
            let mut view = View::new(res);
            let mut entries = vec![T::default(); len];
            for camera in chunk {
                visit(&mut view, camera, &mut entries);
            }
            entries
        })
        .collect())
}

/// Refuses what [`visible_sample_counts`] documents; returns the mesh's bounds.
fn check_request(mesh: &TriangleMesh, options: &VisibilityOptions) -> Result<Bounds, RenderError> {
    mesh.validate()
        .map_err(|e| RenderError::Invalid(format!("the mesh: {e}")))?;
    if mesh.triangles.is_empty() {
        return Err(RenderError::EmptyScene);
    }
    if options.views == 0 {
        return Err(RenderError::Invalid(
            "visibility needs at least one view".into(),
        ));
    }
    if !(1..=16384).contains(&options.resolution) {
        return Err(RenderError::BadSize(options.resolution, options.resolution));
    }
    if options.min_samples == 0 {
        return Err(RenderError::Invalid(
            "min_samples must be at least 1: a triangle is seen when it wins a sample".into(),
        ));
    }
    Ok(mesh.bounds())
}

/// Depths within this share of the scene's farthest depth in a view are equal.
const TIE: f64 = 1e-12;

/// One view's buffers: the nearest depth per sample and the mesh's corners on the grid.
struct View {
    side: usize,
    /// Depth (view distance) of the nearest triangle at each sample, row by row.
    depth: Vec<f64>,
    /// The vertices on the grid: pixels x, y (snapped) and view depth.
    grid: Vec<GridPoint>,
}

impl View {
    fn new(res: u32) -> View {
        let side = res as usize;
        View {
            side,
            depth: vec![f64::INFINITY; side * side],
            grid: Vec::new(),
        }
    }

    /// Adds to `counts[t]` the samples triangle `t` wins in `camera`'s view (orthographic,
    /// framing `bounds`, the mesh's, as big as the buffer): nearest depth first, then the
    /// credit (see the module documentation). Cost: O(V + T + rows spanned + samples covered
    /// + samples).
    fn credit(
        &mut self,
        mesh: &TriangleMesh,
        bounds: &Bounds,
        camera: &Camera,
        counts: &mut [u64],
    ) {
        let centre = (bounds.center() - camera.eye).dot(camera.forward);
        let tie = TIE * (centre.abs() + 0.5 * bounds.diagonal());
        self.draw(mesh, camera);
        let (side, grid, depth) = (self.side, &self.grid, &self.depth);
        let triangle = |tri: &[u32; 3]| SnappedTriangle::new(tri.map(|v| grid[v as usize]));
        for (tri, count) in mesh.triangles.iter().zip(counts.iter_mut()) {
            if let Some(t) = triangle(tri) {
                t.for_each_sample(side, |i, z, strictly_inside| {
                    *count += u64::from(strictly_inside && z <= depth[i] + tie);
                });
            }
        }
    }

    /// The nearest depth of `mesh` at every sample of `camera`'s view (orthographic), its
    /// corners snapped onto the grid. Cost: O(V + T + rows spanned + samples covered).
    fn draw(&mut self, mesh: &TriangleMesh, camera: &Camera) {
        self.grid.clear();
        self.grid.extend(mesh.positions.iter().map(|p| {
            let s = camera
                .project(p.as_dvec3())
                .expect("orthographic cameras project all");
            GridPoint::snap(s.x, s.y, s.depth_key)
        }));
        let (side, grid) = (self.side, &self.grid);
        let triangle = |tri: &[u32; 3]| SnappedTriangle::new(tri.map(|v| grid[v as usize]));
        let depth = &mut self.depth;
        depth.fill(f64::INFINITY);
        for t in mesh.triangles.iter().filter_map(triangle) {
            t.for_each_sample(side, |i, z, _| depth[i] = depth[i].min(z));
        }
    }
}
