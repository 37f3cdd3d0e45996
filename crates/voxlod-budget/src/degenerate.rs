//! Zero-area triangles taken out of a collapsed level without changing its topology.
//!
//! On a flat region every collapse costs the quadric nothing, and meshoptimizer can leave a
//! corner on the opposite edge: a triangle of zero area whose neighbours touch a triangle they
//! share no vertex with. voxlod-contouring's cleaning, with thresholds only the degenerate meet
//! (an edge under 1e-3 of a cell, an area under 1e-5 of its square), flips such a triangle's
//! longest edge or collapses its shortest, keeping the mesh closed, manifold and oriented.
//! Cost: one parallel scan of the triangles; a cleaning only where it finds one.

use voxlod_contouring::clean_mesh::has_defects;
use voxlod_contouring::{clean_mesh, CleanOptions};
use voxlod_core::TriangleMesh;

/// `mesh` without zero-area triangles, judged against `cell` (a voxel; for a collapse of the
/// input, a thousandth of its diagonal); the mesh itself when it has none or cleaning fails.
pub fn without_degenerate(mesh: TriangleMesh, cell: f64) -> TriangleMesh {
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
