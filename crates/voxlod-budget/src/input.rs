//! The input as every method sees it ([`Input`]): checked, coincident vertices merged (after
//! coordinates within a hundred-millionth of the diagonal of zero are set to zero: CAD
//! exporters' rounding noise, `voxlod_core::weld::zero_rounding_noise`), zero-area slivers
//! mended (an edge turned or collapsed, the mesh kept closed), triangles
//! that repeat a vertex and duplicates dropped, each piece oriented as most of its triangles are
//! ([`orient_consistently`]), turned right side out where the whole of it is inside out, with
//! its topology and connected parts. No vertex moves further than that noise. Edges of three or more triangles stay:
//! cut before a collapse, they would become borders the collapse cannot cross; the levels are
//! cut instead (module `candidate`). Cost: O(F log F) (the weld's hash, the repair's sort, the
//! edge sort).

use std::sync::OnceLock;

use serde::Serialize;
use voxlod_core::components::triangle_components;
use voxlod_core::glam::DVec3;
use voxlod_core::manifold::orient_consistently;
use voxlod_core::repair::remove_degenerate_and_duplicate_triangles;
use voxlod_core::validate::validate_mesh;
use voxlod_core::weld::{weld_vertices, zero_rounding_noise};
use voxlod_core::{crossing_pairs, mesh_topology, Bounds, Topology, TriangleMesh};

use voxlod_contouring::clean_mesh::without_zero_area;

use crate::BudgetError;

/// Triangles of `mesh` with three distinct corners and no area.
fn zero_area_slivers(mesh: &TriangleMesh) -> usize {
    (mesh.triangles.iter())
        .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
        .filter(|t| {
            let [a, b, c] = t.map(|v| mesh.positions[v as usize].as_dvec3());
            (b - a).cross(c - a).length_squared() == 0.0
        })
        .count()
}

/// The prepared input.
pub struct Input {
    /// The mesh every candidate is made from and measured against.
    pub mesh: TriangleMesh,
    /// Its topology.
    pub topology: Topology,
    /// The triangles of each connected part.
    pub parts: Vec<Vec<u32>>,
    /// Its box, and the box's diagonal (the unit of the reports' fractions).
    pub bounds: Bounds,
    /// See [`Input::bounds`].
    pub diagonal: f64,
    /// What preparing it changed.
    pub preparation: Preparation,
    /// What of it is seen from outside, where hidden surfaces are left out of measuring
    /// (module `visible`); `None`: every triangle counts.
    pub seen: Option<Seen>,
    /// Where its triangle pairs cross ([`crossing_place`]), found on first use.
    crossings: OnceLock<Vec<DVec3>>,
}

/// The input's triangles seen from outside (module `visible`).
pub struct Seen {
    /// Whether each of the input's triangles is seen.
    pub mask: Vec<bool>,
    /// The seen triangles alone: the surface candidates are measured against.
    pub mesh: TriangleMesh,
    /// Parts no view saw, dropped from the input.
    pub hidden_parts: usize,
}

/// What [`Input::prepare`] changed, for the report.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Preparation {
    /// Vertices merged into another at the same coordinates.
    pub welded_vertices: usize,
    /// Triangles dropped for a repeated vertex or zero area, or mended (zero-area slivers
    /// with three distinct corners: an edge turned or collapsed, the mesh kept closed).
    pub degenerate_triangles: usize,
    /// Triangles dropped as copies of another.
    pub duplicate_triangles: usize,
    /// Triangles turned to agree with the orientation of their piece.
    pub flipped_triangles: usize,
    /// Whether the whole mesh was inside out (closed, negative volume) and was turned right
    /// side out.
    pub turned_right_side_out: bool,
}

impl Input {
    /// Prepares `mesh` (module docs). Fails on non-finite coordinates, indices out of range, and
    /// a mesh left without triangles.
    pub fn prepare(mesh: &TriangleMesh) -> Result<Input, BudgetError> {
        validate_mesh(mesh, &Default::default())?;
        let mut clean = TriangleMesh::new(mesh.positions.clone(), mesh.triangles.clone());
        // CAD exporters' rounding noise near zero would keep copies of a vertex apart.
        zero_rounding_noise(&mut clean);
        let weld = weld_vertices(&mut clean);
        // Zero-area triangles with three distinct corners are mended, not dropped: dropping one
        // would open a crack in a closed mesh (a printed part's one collinear sliver).
        let slivers = zero_area_slivers(&clean);
        if slivers > 0 {
            let cell = clean.bounds().diagonal() * 1e-3;
            clean = without_zero_area(clean, cell);
        }
        let repair = remove_degenerate_and_duplicate_triangles(&mut clean);
        clean.remove_unreferenced_vertices();
        if clean.triangles.is_empty() {
            return Err(BudgetError::EmptyMesh {
                triangles: mesh.triangles.len(),
            });
        }
        let flipped_triangles = orient_consistently(&mut clean);
        let topology = mesh_topology(&clean);
        let inside_out = topology.is_closed_manifold() && clean.signed_volume() < 0.0;
        if inside_out {
            clean.flip_orientation();
        }
        let bounds = clean.bounds();
        Ok(Input {
            parts: triangle_components(&clean),
            topology,
            diagonal: bounds.diagonal(),
            bounds,
            preparation: Preparation {
                welded_vertices: weld.vertices_before - weld.vertices_after,
                degenerate_triangles: repair.degenerate_triangles + slivers,
                duplicate_triangles: repair.duplicate_triangles,
                flipped_triangles,
                turned_right_side_out: inside_out,
            },
            mesh: clean,
            seen: None,
            crossings: OnceLock::new(),
        })
    }

    /// The surface candidates are measured against and fitted to: the seen triangles where
    /// hidden ones are left out ([`Input::seen`]), else the whole input.
    pub fn measured(&self) -> &TriangleMesh {
        self.seen.as_ref().map_or(&self.mesh, |s| &s.mesh)
    }

    /// Whether the input's triangle `t` counts in measuring ([`Input::measured`]).
    pub fn is_measured(&self, t: u32) -> bool {
        self.seen.as_ref().is_none_or(|s| s.mask[t as usize])
    }

    /// The voxel of a grid of `resolution` samples along the input's longest side, which is also
    /// the radius its filter smooths over (module `grids`).
    pub fn voxel(&self, resolution: usize) -> f64 {
        self.bounds.longest_extent() / resolution as f64
    }

    /// The length that judges a degenerate triangle of a collapse of the input: a thousandth of
    /// its diagonal, the voxel of a 1000-sample grid.
    pub fn cell(&self) -> f64 {
        self.diagonal * 1e-3
    }

    /// Whether preparing the input changed what a collapse sees: vertices merged, triangles
    /// dropped or turned against their neighbours. Unreferenced vertices do not count, nor does
    /// the whole input turned right side out: a quadric's plane and meshoptimizer's test of a
    /// collapse for flipped triangles do not depend on the orientation, so the collapse of the
    /// input turned is the collapse of the input as given, turned.
    pub fn changed_by_preparation(&self) -> bool {
        let p = &self.preparation;
        p.welded_vertices + p.degenerate_triangles + p.duplicate_triangles + p.flipped_triangles > 0
    }

    /// Pairs of the input's triangles that cross (parts passing through each other), counted
    /// on the first call: O(F log F) on all threads. Calls side by side before the count is
    /// kept each count (none waits on another: a waiting rayon thread could be handed a task
    /// that asks again and wait on itself), so a caller that foresees them counts first.
    pub fn crossings(&self) -> usize {
        self.crossing_places().len()
    }

    /// Where the input's crossing pairs are ([`crossing_place`]), one point a pair; found with
    /// [`Input::crossings`].
    pub fn crossing_places(&self) -> &[DVec3] {
        if let Some(places) = self.crossings.get() {
            return places;
        }
        let places = (crossing_pairs(&self.mesh).iter())
            .map(|&pair| crossing_place(&self.mesh, pair).0)
            .collect();
        let _ = self.crossings.set(places);
        self.crossings.get().map_or(&[], Vec::as_slice)
    }

    /// Whether the input is a closed, consistently oriented manifold: its levels must be too.
    pub fn is_closed(&self) -> bool {
        self.topology.is_closed_manifold() && self.topology.is_consistently_oriented()
    }
}

/// Where the triangles `s` and `t` of `mesh` cross, and how far that may be from the curve along
/// which they cut each other: the mean of their six corners, and its distance to the farthest
/// corner. Cost: O(1).
pub fn crossing_place(mesh: &TriangleMesh, (s, t): (u32, u32)) -> (DVec3, f64) {
    let corners: Vec<DVec3> = [s, t]
        .iter()
        .flat_map(|&k| mesh.corners(k as usize))
        .collect();
    let centre = corners.iter().sum::<DVec3>() / 6.0;
    let reach = corners
        .iter()
        .map(|p| p.distance(centre))
        .fold(0.0, f64::max);
    (centre, reach)
}
