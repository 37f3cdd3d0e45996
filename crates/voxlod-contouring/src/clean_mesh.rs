//! Cleaning a marching-cubes level: no needle, sliver or zero-area triangles, and none of the
//! self-intersections they cause, while the mesh stays closed, manifold and oriented.
//!
//! Beyond the paper (He et al. 1995, §2, contour with plain marching cubes). Where the surface
//! passes close to a grid sample, marching cubes puts several vertices within a tiny fraction of
//! a cell of that sample, on the edges that meet there, and joins them with triangles of area
//! 1e-12 to 1e-6 whose normals are noise; rounded to `f32`, neighbouring slivers can cross.
//! The classic fix snaps such vertices onto the sample; we get the same effect on the mesh:
//!
//! 1. *Collapse short edges*, shortest first: an edge shorter than
//!    [`CleanOptions::min_edge`] cells merges its two vertices at its midpoint, if the **link
//!    condition** holds (the two vertices' common neighbours are exactly the two vertices
//!    opposite the edge, so the mesh stays a closed 2-manifold; Dey, Edelsbrunner et al. 1999),
//!    the component is more than a tetrahedron, and no surviving triangle around it turns over
//!    (its normal keeps a positive component along the neighbourhood's area-weighted normal);
//!    where the midpoint would turn one over, either end is tried. Each vertex moves at most
//!    once per pass, by at most the threshold.
//! 2. *Flip caps*: a triangle still below [`CleanOptions::min_area`] cells² (one corner close to
//!    the opposite edge, no short edge to collapse) has that longest edge flipped when the new
//!    edge is not already in the mesh, neither new triangle turns over, and the smaller quality
//!    of the pair improves; where no flip is allowed, its shortest edge that may be collapsed
//!    as in 1 is, whatever its length; and where none may (a near-pinch, where the link
//!    condition fails), one of its corners moves to the centroid of its neighbours if that
//!    turns nothing over and the triangle grows.
//!
//! Every step is also refused when a triangle it makes would meet a triangle nearby (two sheets
//! of a thin part can lie closer than a step moves a vertex), by the guard in `local_crossings.rs`.
//!
//! Passes repeat until nothing changes (at most [`CleanOptions::max_passes`]). These tests are
//! local, and a component so small that every edge is short has no inside for them to protect:
//! the octahedron marching cubes makes around one sample barely above the isodensity (as at a
//! coarse level of thingi10k-138207) collapses to a tetrahedron, and relaxing one corner of that
//! to the centroid of the others flattens it to zero volume, outward or inward by rounding.
//! So, last, every component whose enclosed volume fell below a quarter of the raw one, or
//! changed sign, gets its raw triangles back (it stays as marching cubes made it). Then dead
//! triangles and vertices are dropped. Orientation is kept by construction: collapses rename a
//! vertex inside oriented triangles, flips replace two oriented triangles by two oriented ones.
//! Normals: a merged vertex takes the normalised mean of the two.
//!
//! Contouring with [`CleanOptions::contour_clamp`] (what `voxlod lod` does) makes no edge and
//! no triangle that these steps would fix, so cleaning first scans the mesh (one parallel read
//! of the triangles, stopping at the first defect) and, finding nothing, only gathers the
//! triangles' vertices in order of first use, as a cleaning that took no step does.
//!
//! Cost: O(F) once to set up (the guard's buckets and each vertex's triangles, on all threads
//! where they can be) and to find the short edges and small triangles; after that, a pass
//! costs O(K log K) for its K candidates and the triangles changed since the last pass (see
//! `clean_mesh/defects.rs`), and O(1) per collapse or flip on a marching-cubes mesh (valences
//! are small); the component-volume check is skipped when no step was taken. The steps'
//! decisions, most of the time, are made on all threads and applied in order, with the result
//! of the one-at-a-time run (see `clean_mesh/passes.rs`), and the guard's searches around
//! them are most of the time. Memory: about 120 bytes per triangle of the input at the peak,
//! besides the input itself (240 before these lists) (positions in `f64`, the triangles, each vertex's triangles in one
//! packed array, the guard's buckets with `f32` boxes); the lists and buckets are dropped
//! before the output is gathered.

use serde::Serialize;
use thiserror::Error;
use voxlod_core::{memory, CoreError, TriangleMesh};

mod changes;
mod defects;
mod fans;
mod passes;
mod restore;
mod steps;
mod work;

use defects::{any_defect, Defects, Scan};
use passes::{collapse_short_edges, fix_small_triangles, Schedule};
use restore::{compact, compact_mesh, restore_flattened};
use work::Work;

/// Bytes cleaning holds per triangle of the input at its peak, besides the input, for the
/// memory check: the example `clean_memory` measures it on a 326 k triangle marching-cubes
/// level (BENCHMARKS.md), rounded up here with room to spare.
pub const CLEAN_BYTES_PER_TRIANGLE: u64 = 144;

/// How [`clean_mesh`] cleans.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CleanOptions {
    /// Edges shorter than this many cells are collapsed.
    pub min_edge: f64,
    /// Triangles smaller than this many square cells are fixed.
    pub min_area: f64,
    /// Passes of both steps at most.
    pub max_passes: usize,
}

impl Default for CleanOptions {
    /// Collapse edges under a tenth of a cell, fix triangles under a thousandth of a cell².
    fn default() -> Self {
        CleanOptions {
            min_edge: 0.1,
            min_area: 1e-3,
            max_passes: 6,
        }
    }
}

impl CleanOptions {
    /// The interpolation clamp ([`crate::ContourOptions::clamp`]) for which marching cubes
    /// makes no edge and no triangle that these options would fix: contour with it and
    /// cleaning finds nothing to do ([`crate::marching_cubes::snap_clamp`]).
    pub fn contour_clamp(&self) -> f32 {
        crate::marching_cubes::snap_clamp(self.min_edge, self.min_area)
    }

    /// Only the degenerate: edges under a thousandth of a cell, areas under 1e-6 cells².
    pub fn degenerate_only() -> Self {
        CleanOptions {
            min_edge: 1e-3,
            min_area: 1e-6,
            ..Default::default()
        }
    }
}

/// What [`clean_mesh`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct CleanReport {
    /// Edges collapsed (short ones, and those of small triangles).
    pub collapsed_edges: usize,
    /// Longest edges of small triangles flipped.
    pub flipped_edges: usize,
    /// Corners of small triangles moved to the centroid of their neighbours.
    pub relaxed_vertices: usize,
    /// Triangles fewer than the input.
    pub removed_triangles: usize,
    /// Vertices fewer than the input.
    pub removed_vertices: usize,
    /// Triangles still below `min_area` (where neither fix was allowed).
    pub small_triangles_left: usize,
    /// Components given back their raw triangles because cleaning flattened them.
    pub restored_components: usize,
    /// Passes run.
    pub passes: usize,
}

/// Why a mesh could not be cleaned.
#[derive(Debug, Error)]
pub enum CleanError {
    #[error("the cell size {0} is not a positive number")]
    /// The cell size is not finite and positive.
    BadCell(f64),
    #[error(transparent)]
    /// The mesh is invalid, or too big for memory.
    Mesh(#[from] CoreError),
}

/// The mesh with short edges collapsed and small triangles flipped away. See the module
/// documentation. `cell` is the grid spacing the mesh was contoured at.
pub fn clean_mesh(
    mesh: &TriangleMesh,
    cell: f64,
    options: &CleanOptions,
) -> Result<(TriangleMesh, CleanReport), CleanError> {
    clean_mesh_with(mesh, cell, options, Schedule::for_threads(), Scan::Changed)
}

/// `mesh` without zero-area triangles, judged against `cell` (a voxel; for a collapse of an
/// input mesh, a length such as a thousandth of its diagonal). On a flat region every collapse
/// costs the quadric nothing, and meshoptimizer can leave a corner on the opposite edge: a
/// triangle of zero area whose neighbours touch a triangle they share no vertex with. The
/// cleaning with thresholds only the degenerate meet (an edge under 1e-3 of a cell, an area
/// under 1e-5 of its square) flips such a triangle's longest edge or collapses its shortest,
/// keeping the mesh closed, manifold and oriented. The mesh itself comes back where it has
/// none or cleaning fails. Cost: one parallel scan of the triangles; a cleaning only where it
/// finds one.
pub fn without_zero_area(mesh: TriangleMesh, cell: f64) -> TriangleMesh {
    let options = CleanOptions {
        min_area: 1e-5,
        ..CleanOptions::degenerate_only()
    };
    if mesh.triangles.is_empty() || !has_defects(&mesh, cell, &options) {
        return mesh;
    }
    match clean_mesh(&mesh, cell, &options) {
        Ok((cleaned, _)) => cleaned,
        Err(_) => mesh,
    }
}

/// Whether [`clean_mesh`] with `options` would find an edge or a triangle of `mesh` to fix
/// (its first scan; `cell` is the grid spacing). A mesh contoured with
/// [`CleanOptions::contour_clamp`] has none, up to rounding. Cost: one parallel read of the
/// triangles, stopping at the first defect; no memory.
pub fn has_defects(mesh: &TriangleMesh, cell: f64, options: &CleanOptions) -> bool {
    let (min_edge, min_area) = (options.min_edge * cell, options.min_area * cell * cell);
    any_defect(mesh, min_edge, min_area)
}

/// [`clean_mesh`] run on `schedule`, its candidates found by `scan`; one at a time over whole
/// scans is the reference that the others must equal bit for bit.
fn clean_mesh_with(
    mesh: &TriangleMesh,
    cell: f64,
    options: &CleanOptions,
    schedule: Schedule,
    scan: Scan,
) -> Result<(TriangleMesh, CleanReport), CleanError> {
    if !(cell.is_finite() && cell > 0.0) {
        return Err(CleanError::BadCell(cell));
    }
    mesh.validate()?;
    let (min_edge, min_area) = (options.min_edge * cell, options.min_area * cell * cell);
    if scan == Scan::Changed && options.max_passes > 0 && !any_defect(mesh, min_edge, min_area) {
        // Nothing to do (a level contoured with `CleanOptions::contour_clamp`): what the passes
        // give without setting them up, one pass that finds nothing.
        return Ok(nothing_to_clean(mesh));
    }
    let triangles = mesh.triangles.len().max(mesh.positions.len()) as u64;
    memory::check_allocation(
        "cleaning a level",
        CLEAN_BYTES_PER_TRIANGLE.saturating_mul(triangles),
    )?;
    let mut work = Work::new(mesh, cell);
    let mut report = CleanReport::default();
    let mut defects = Defects::new(&work, min_edge, min_area, scan);
    let reference = (schedule, scan) == (Schedule::OneAtATime, Scan::Whole);
    for _ in 0..options.max_passes {
        report.passes += 1;
        work.touched.iter_mut().for_each(|t| *t = false);
        let edges = defects.short_edges(&mut work, min_edge);
        let collapsed = collapse_short_edges(&mut work, &edges, schedule);
        drop(edges);
        let small = (!reference).then(|| defects.small_triangles(&mut work, min_area));
        let [flipped, collapsed_small, relaxed] =
            fix_small_triangles(&mut work, min_area, schedule, small);
        report.collapsed_edges += collapsed + collapsed_small;
        report.flipped_edges += flipped;
        report.relaxed_vertices += relaxed;
        if collapsed + flipped + collapsed_small + relaxed == 0 {
            break;
        }
    }
    // The small triangles left, unless a component gets its raw triangles back below.
    let left = (!reference).then(|| defects.small_triangles(&mut work, min_area).len());
    // Only the surface is needed from here on.
    let mut surface = work.surface;
    // A mesh that no step changed has every component's raw volume: none is restored.
    let steps = report.collapsed_edges + report.flipped_edges + report.relaxed_vertices;
    if steps > 0 {
        report.restored_components = restore_flattened(&mut surface, mesh);
    }
    report.small_triangles_left = match left {
        Some(left) if report.restored_components == 0 => left,
        _ => (0..surface.triangles.len() as u32)
            .filter(|&t| surface.alive[t as usize] && surface.area(t) < min_area)
            .count(),
    };
    let cleaned = compact(&surface);
    drop(surface);
    report.removed_triangles = mesh.triangles.len() - cleaned.triangles.len();
    report.removed_vertices = mesh.positions.len() - cleaned.positions.len();
    Ok((cleaned, report))
}

/// The output and report of cleaning `mesh` when its first scan finds nothing: one pass, no
/// step, the triangles and the vertices they use gathered as after any cleaning.
fn nothing_to_clean(mesh: &TriangleMesh) -> (TriangleMesh, CleanReport) {
    let cleaned = compact_mesh(mesh);
    let report = CleanReport {
        passes: 1,
        removed_vertices: mesh.positions.len() - cleaned.positions.len(),
        ..CleanReport::default()
    };
    (cleaned, report)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// A regular tetrahedron with one vertex split in two, 1e-4 apart: the short edge sits in
    /// a component that would collapse to a flat pair of triangles, so it stays.
    fn split_tetrahedron() -> TriangleMesh {
        let p = [
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(1.0, -1.0, -1.0),
            Vec3::new(-1.0, 1.0, -1.0),
            Vec3::new(-1.0, -1.0, 1.0),
        ];
        TriangleMesh::new(p.to_vec(), vec![[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]])
    }

    #[test]
    fn refuses_a_bad_cell_and_keeps_a_tetrahedron() {
        let mesh = split_tetrahedron();
        assert!(matches!(
            clean_mesh(&mesh, 0.0, &CleanOptions::default()),
            Err(CleanError::BadCell(_))
        ));
        assert!(clean_mesh(&mesh, f64::NAN, &CleanOptions::default()).is_err());
        // Every edge is "short" for a cell of 100, but a tetrahedron has nothing to give.
        let (clean, report) = clean_mesh(&mesh, 100.0, &CleanOptions::default()).unwrap();
        assert_eq!(clean, mesh);
        assert_eq!(report.collapsed_edges, 0);
    }

    #[test]
    fn collapses_a_short_edge_of_an_octahedron() {
        // An octahedron with its +x vertex split into two 1e-3 apart along y (a seventh vertex
        // and two more triangles): the short edge collapses back to the octahedron.
        let mut positions = vec![
            Vec3::new(1.0, -5e-4, 0.0),
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::Y,
            Vec3::NEG_Y,
            Vec3::Z,
            Vec3::NEG_Z,
        ];
        positions.push(Vec3::new(1.0, 5e-4, 0.0));
        // Vertex 0 = +x (lower), 6 = +x (upper); 0 keeps the -y side, 6 the +y side.
        let triangles = vec![
            [6, 2, 4],
            [2, 6, 5],
            [0, 4, 3],
            [0, 3, 5],
            [1, 4, 2],
            [1, 2, 5],
            [1, 3, 4],
            [1, 5, 3],
            [0, 6, 4],
            [6, 0, 5],
        ];
        let mesh = TriangleMesh::new(positions, triangles);
        let before = voxlod_core::mesh_topology(&mesh);
        assert!(
            before.is_closed_manifold() && before.is_consistently_oriented(),
            "{before:?}"
        );
        let (clean, report) = clean_mesh(&mesh, 1.0, &CleanOptions::default()).unwrap();
        assert_eq!(report.collapsed_edges, 1);
        assert_eq!((clean.positions.len(), clean.triangles.len()), (6, 8));
        let after = voxlod_core::mesh_topology(&clean);
        assert!(after.is_closed_manifold() && after.is_consistently_oriented());
        assert!((clean.signed_volume() - 4.0 / 3.0).abs() < 1e-3);
    }

    /// The cleaned mesh and report of every schedule and scan: the reference first (one at a
    /// time over whole scans), then one at a time over the changed triangles' scans, and
    /// speculative batches of 1, 16 and 4096 candidates and of the automatic size over either
    /// scan. Large batches put many steps within reach of each other, so that decisions must be
    /// made again.
    fn every_schedule(mesh: &TriangleMesh, cell: f64) -> Vec<(TriangleMesh, CleanReport)> {
        let runs = [
            (Schedule::OneAtATime, Scan::Whole),
            (Schedule::OneAtATime, Scan::Changed),
            (Schedule::Speculative(1), Scan::Changed),
            (Schedule::Speculative(16), Scan::Whole),
            (Schedule::Speculative(4096), Scan::Changed),
            (Schedule::Speculative(0), Scan::Whole),
            (Schedule::Speculative(0), Scan::Changed),
        ];
        (runs.into_iter())
            .map(|(s, scan)| clean_mesh_with(mesh, cell, &CleanOptions::default(), s, scan))
            .map(Result::unwrap)
            .collect()
    }

    /// Every schedule and scan of [`every_schedule`] gives the reference's mesh, bit for bit,
    /// and its report; returns the reference's report.
    fn assert_every_schedule_equal(name: &str, mesh: &TriangleMesh, cell: f64) -> CleanReport {
        let runs = every_schedule(mesh, cell);
        let (reference, report) = &runs[0];
        // Bit for bit: positions and normals compared as bits, not as floats.
        let bits = |v: &[Vec3]| -> Vec<[u32; 3]> {
            v.iter().map(|p| p.to_array().map(f32::to_bits)).collect()
        };
        for (k, (clean, other)) in runs.iter().enumerate().skip(1) {
            assert_eq!(other, report, "{name}, run {k}");
            assert_eq!(clean.triangles, reference.triangles, "{name}, run {k}");
            let (p, q) = (&clean.positions, &reference.positions);
            assert_eq!(bits(p), bits(q), "{name}, run {k}");
            let (n, m) = (&clean.normals, &reference.normals);
            assert_eq!(bits(n), bits(m), "{name}, run {k}");
        }
        *report
    }

    #[test]
    fn speculative_batches_clean_as_one_at_a_time() {
        use crate::{marching_cubes, ContourOptions};
        use voxlod_testkit::fields::{gyroid_field, sphereflake_field};
        for (name, volume) in [
            ("sphereflake-64", sphereflake_field(64).unwrap()),
            ("sphereflake-96", sphereflake_field(96).unwrap()),
            ("gyroid-64", gyroid_field(64).unwrap()),
        ] {
            let mesh = marching_cubes(&volume, &ContourOptions::at(0.0)).unwrap();
            let report = assert_every_schedule_equal(name, &mesh, volume.grid.spacing[0]);
            assert!(report.collapsed_edges > 100, "{name}: {report:?}");
            assert!(report.flipped_edges > 0, "{name}: {report:?}");
        }
    }

    /// A ball of radius √50 cells (many samples exactly on its surface) over 30³ samples, its
    /// density ramping over one cell; with `jitter`, a third of the samples within a fifth of
    /// a cell of the surface move to within 1e-3 of the isodensity (defects next to each
    /// other); and `lone` samples barely above it, outside the ball, among samples below it
    /// (tiny components, some one or two cells from the ball and from each other).
    fn ball_field(seed: u64, jitter: bool, lone: usize) -> voxlod_core::Volume {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
        let n = 30;
        let grid = voxlod_core::Grid::new([n; 3], [1.0; 3], [0.0; 3]).unwrap();
        let centre = glam::DVec3::splat(14.0);
        let mut values = vec![0.0f32; n * n * n];
        for (i, j, k) in
            (0..n).flat_map(|k| (0..n).flat_map(move |j| (0..n).map(move |i| (i, j, k))))
        {
            let p = glam::DVec3::new(i as f64, j as f64, k as f64);
            let d = 50f64.sqrt() - p.distance(centre);
            let mut v = 0.5 + 0.5 * d.clamp(-1.0, 1.0);
            if jitter && d.abs() < 0.2 && rng.random_range(0..3) == 0 {
                v = 0.5 + rng.random_range(-1e-3..1e-3);
            }
            values[grid.index(i, j, k)] = v as f32;
        }
        for _ in 0..lone {
            let at = [0, 1, 2].map(|_| rng.random_range(2..n - 2));
            let p = glam::DVec3::from_array(at.map(|c| c as f64));
            if p.distance(centre) < 50f64.sqrt() + 1.5 {
                continue;
            }
            for d in 0..27 {
                let q = [at[0] + d % 3 - 1, at[1] + d / 3 % 3 - 1, at[2] + d / 9 - 1];
                let v = &mut values[grid.index(q[0], q[1], q[2])];
                if *v == 0.0 {
                    *v = rng.random_range(0.0..0.45);
                }
            }
            values[grid.index(at[0], at[1], at[2])] = 0.5 + rng.random_range(0.002..0.04);
        }
        voxlod_core::Volume::from_vec(grid, values).unwrap()
    }

    /// The candidates found among the last ones and the changed triangles clean as whole scans,
    /// bit for bit: on a mesh with no defect (a step-free run, one scan), with defects next to
    /// each other, and with tiny components next to the ball and to each other (some of which
    /// cleaning flattens and gives back their raw triangles).
    #[test]
    fn changed_scans_clean_as_whole_scans() {
        use crate::{marching_cubes, ContourOptions};
        let mut restored = 0;
        for seed in 0..4 {
            // Samples 0 or 1 only: every vertex halfway along its edge, no defect.
            let mut binary = ball_field(seed, false, 0);
            binary.values.mapv_inplace(f32::round);
            let raw = marching_cubes(&binary, &ContourOptions::at(0.5)).unwrap();
            let report = assert_every_schedule_equal("binary", &raw, 1.0);
            assert_eq!((report.collapsed_edges, report.flipped_edges), (0, 0));
            assert_eq!((report.relaxed_vertices, report.removed_triangles), (0, 0));
            let near = ball_field(seed, true, 0);
            let raw = marching_cubes(&near, &ContourOptions::at(0.5)).unwrap();
            let report = assert_every_schedule_equal("near", &raw, 1.0);
            assert!(report.collapsed_edges > 50, "{seed}: {report:?}");
            // The same samples contoured with the clamp for these options: no defect, so the
            // first scan finds nothing and the passes are not set up (the changed scans), with
            // the whole scans' result.
            let clamp = CleanOptions::default().contour_clamp();
            let snapped = ContourOptions::at(0.5).with_clamp(clamp);
            let raw = marching_cubes(&near, &snapped).unwrap();
            let report = assert_every_schedule_equal("near, snapped", &raw, 1.0);
            let nothing = CleanReport {
                passes: 1,
                ..CleanReport::default()
            };
            assert_eq!(report, nothing, "{seed}");
            let parts = ball_field(seed, true, 60);
            let raw = marching_cubes(&parts, &ContourOptions::at(0.5)).unwrap();
            let report = assert_every_schedule_equal("components", &raw, 1.0);
            eprintln!("{seed}: {report:?}");
            restored += report.restored_components;
        }
        assert!(restored > 0);
    }
}
