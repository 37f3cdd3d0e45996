//! A [`Candidate`] level for one budget: a mesh, the method that made it, its topology, and
//! what measuring and checking it found, filled in as the portfolio ([`crate::select`]) needs.
//!
//! Every candidate is made an oriented manifold as it is made ([`make_manifold`]): a thin part
//! that a collapse flattened into two triangles on the same three vertices is dropped, sheets
//! that a collapse pinched together along an edge are taken apart again as closed surfaces,
//! and what cannot be paired (edges of three or more triangles that an input had) is cut.
//! Then every copy of a vertex, and any other vertex at the same coordinates in another fan,
//! moves a tiny step into its own fan ([`separate_coincident`]: a thousandth of the fan's
//! smallest height over an opposite edge, no triangle's normal turned by more than 0.094 rad),
//! so that a reader welding vertices by position sees the same manifold as the indices; copies
//! a weld joins into one fan (seams) stay together. Where a cut opens a level that had to be
//! closed, the promise of closedness rules it out.

use serde::Serialize;
use voxlod_core::manifold::make_manifold;
use voxlod_core::{mesh_topology, Topology, TriangleMesh};

use crate::measure::Distance;
use crate::separate::separate_coincident;

/// The method that made a candidate.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// The input's own quadric collapse, as gltfpack makes it (meshoptimizer `simplify`, border
    /// free, no error limit): Garland and Heckbert's edge collapse, of the input with its
    /// coincident vertices merged.
    Collapse,
    /// The same collapse of the input exactly as given, where merging its coincident vertices
    /// changed it (seams a collapse treats as borders: sometimes closer, sometimes not).
    CollapseAsGiven,
    /// The input's quadric collapse with its topology kept and no new crossing triangles
    /// (voxlod-quadric's checked collapse), where the plain collapse broke a promise.
    CollapseKept,
    /// The input's plain collapse with its crossing triangles taken apart by edge flips
    /// (`voxlod_core::uncross`), where the plain one only crossed itself.
    CollapseUncrossed,
    /// The input's plain collapse made in two steps, to twice the budget and then on to it
    /// (`collapse::in_two_steps`), where the one-step collapse only crossed itself.
    CollapseInTwoSteps,
    /// meshoptimizer `simplifySloppy`: vertex clustering on a grid sized for the count. Kept
    /// only where its result happens to keep every promise.
    Sloppy,
    /// The input's solid low-pass filtered and contoured (He et al. 1995 §2–4), then collapsed
    /// to the budget with its topology kept (§5).
    Voxel,
    /// A thin shell around the input's surface contoured, then collapsed to the budget: the
    /// voxel level of a surface with no inside (an open sheet, open parts, a soup).
    Shell,
    /// A closed plate far thinner than its size simplified as a sheet: one side moved to the
    /// mid-surface, collapsed with its border free and thickened again (module `plate`).
    Plate,
    /// The level of the next larger budget, collapsed to this one with its topology kept.
    Above,
    /// The level of the next smaller budget with its edges split to this budget and fitted to
    /// the input, where the chain's choice here was farther than it (module `below`).
    Below,
}

impl Method {
    /// The method's name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Method::Collapse => "collapse",
            Method::CollapseAsGiven => "collapse-as-given",
            Method::CollapseKept => "collapse-kept",
            Method::CollapseInTwoSteps => "collapse-in-two-steps",
            Method::CollapseUncrossed => "collapse-uncrossed",
            Method::Sloppy => "sloppy",
            Method::Voxel => "voxel",
            Method::Shell => "shell",
            Method::Plate => "plate",
            Method::Above => "above",
            Method::Below => "below",
        }
    }

    /// Whether the method keeps the vertices where the input surface is (a collapse of the
    /// input) rather than where a filtered volume put them (the fit applies to the latter).
    pub fn is_voxel(self) -> bool {
        matches!(self, Method::Voxel | Method::Shell)
    }
}

/// What of the input's inside a voxel candidate's solid filled (module `chain`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Fill {
    /// Nothing: the input as given.
    #[default]
    None,
    /// Its closed cavities (voids inside its material).
    Cavities,
    /// The hollows its material nearly encloses (module `enclosed`).
    Hollows,
    /// Only the lining of those hollows, within the closing's radius of the material.
    HollowLining,
    /// Nothing; the closed parts sampled as a solid and the open parts as shells around them
    /// (module `open_parts`).
    OpenShells,
}

impl Fill {
    /// The name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Fill::None => "none",
            Fill::Cavities => "cavities filled",
            Fill::Hollows => "hollows filled",
            Fill::HollowLining => "hollows lined",
            Fill::OpenShells => "open parts as shells",
        }
    }

    /// Whether the solid filled some of the input's inside (cavities or hollows).
    pub fn fills_inside(self) -> bool {
        matches!(self, Fill::Cavities | Fill::Hollows | Fill::HollowLining)
    }
}

/// One candidate level.
#[derive(Clone, Debug)]
pub struct Candidate {
    /// The method.
    pub method: Method,
    /// The level.
    pub mesh: TriangleMesh,
    /// Its topology.
    pub topology: Topology,
    /// The voxel resolution (samples across the longest side) of a voxel or shell candidate.
    pub resolution: Option<usize>,
    /// The isodensity it was contoured at.
    pub iso: Option<f32>,
    /// Parts the quadric stage dropped because the budget could not carry them all.
    pub parts_dropped: usize,
    /// Whether its voxel level was collapsed in two stages with a fit between
    /// (`voxel::staged`).
    pub staged: bool,
    /// Whether its vertices were fitted to the input.
    pub fitted: bool,
    /// Vertices split to make it a manifold (module docs).
    pub cut_vertices: usize,
    /// Vertices moved off coordinates they shared with a vertex of another fan (module docs).
    #[allow(dead_code)] // for inspection and tests; the reports do not carry it
    pub separated_vertices: usize,
    /// What of the input's inside was filled before sampling a voxel candidate.
    pub fill: Fill,
    /// The input's lost parts put back beside it (module `restore`).
    pub parts_restored: usize,
    /// The quick distance, once measured (`None` also when rejected early).
    pub quick: Option<Distance>,
    /// The careful distance, once measured.
    pub careful: Option<Distance>,
    /// Crossing triangle pairs, once counted.
    pub crossings: Option<usize>,
}

impl Candidate {
    /// A candidate made by `method`, cut into an oriented manifold where it is not one and its
    /// coincident vertices of different fans moved apart (module docs), its topology found
    /// here (O(F log F)).
    pub fn new(method: Method, mut mesh: TriangleMesh) -> Candidate {
        mesh.remove_unreferenced_vertices();
        let cut = make_manifold(&mut mesh);
        mesh.remove_unreferenced_vertices();
        let separated = separate_coincident(&mut mesh);
        Candidate {
            cut_vertices: cut.split_vertices,
            separated_vertices: separated.moved,
            fill: Fill::None,
            parts_restored: 0,
            method,
            topology: mesh_topology(&mesh),
            mesh,
            resolution: None,
            iso: None,
            parts_dropped: 0,
            staged: false,
            fitted: false,
            quick: None,
            careful: None,
            crossings: None,
        }
    }

    /// The same candidate from a voxel level of `resolution` contoured at `iso`.
    pub fn at(self, resolution: usize, iso: f32) -> Candidate {
        Candidate {
            resolution: Some(resolution),
            iso: Some(iso),
            ..self
        }
    }

    /// Triangles.
    pub fn triangles(&self) -> usize {
        self.mesh.triangle_count()
    }

    /// The candidate's name in reports: its method, and for a voxel level its resolution and
    /// isodensity.
    pub fn label(&self) -> String {
        let mut label = self.method.name().to_string();
        if let (Some(r), Some(iso)) = (self.resolution, self.iso) {
            label += &format!(" {r}@{iso}");
        }
        if self.fill != Fill::None {
            label += &format!(" {}", self.fill.name());
        }
        if self.staged {
            label += " staged";
        }
        if self.fitted {
            label += " fitted";
        }

        if self.parts_restored > 0 {
            label += &format!(" +{} parts", self.parts_restored);
        }
        label
    }
}
