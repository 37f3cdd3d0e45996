//! Each label's mesh taken out of simplified patches: its patches' triangles (turned to face out
//! of the label where it is the patch's outside), its vertices compacted, and each singular
//! corner (where the label's surface has several sheets) split into one coincident copy per
//! sheet, as [`SharedSurface::label_mesh`] splits them.
//!
//! The sheets are found from the triangles around the corner, which the patches kept as the
//! voxels' faces (`patches.rs` locks them): two of the label's triangles there are on one sheet
//! when they bound the same voxel of the label, or when they are the label's only two
//! triangles on an edge leaving the corner. So voxels of the label that meet only along an edge
//! or at the corner are kept apart, as the surface nets' extraction keeps them.
//!
//! Cost: per label O(its triangles) with a hash map from shared to own vertices, plus a sort of
//! the few triangles at its singular corners; the labels in parallel.

use rayon::prelude::*;
use rustc_hash::FxHashMap;
use voxlod_core::TriangleMesh;

use super::patches::Patch;
use crate::surface_nets::SharedSurface;

/// The meshes of `labels`, in that order, from `patches` of `surface`; a label without
/// triangles gets an empty mesh. Each is closed and consistently oriented when the patches are
/// (`patches.rs`), its vertices at the shared vertices' positions.
pub(crate) fn label_meshes(
    surface: &SharedSurface,
    patches: &[Patch],
    labels: &[u32],
) -> Vec<TriangleMesh> {
    let mut of_label: FxHashMap<u32, Vec<(usize, bool)>> = FxHashMap::default();
    for (p, patch) in patches.iter().enumerate() {
        let [inside, outside] = patch.sides;
        of_label.entry(inside).or_default().push((p, false));
        if outside != inside {
            of_label.entry(outside).or_default().push((p, true));
        }
    }
    labels
        .par_iter()
        .map(|label| match of_label.get(label) {
            Some(own) => label_mesh(surface, patches, own),
            None => TriangleMesh::default(),
        })
        .collect()
}

/// One label's mesh from its patches (`own`: patch and whether the label is its outside).
fn label_mesh(surface: &SharedSurface, patches: &[Patch], own: &[(usize, bool)]) -> TriangleMesh {
    let oriented = own.iter().flat_map(|&(p, outside)| {
        patches[p]
            .triangles
            .iter()
            .map(move |&t| if outside { [t[0], t[2], t[1]] } else { t })
    });
    let size: usize = own.iter().map(|&(p, _)| patches[p].triangles.len()).sum();
    let mut local: FxHashMap<u32, u32> =
        FxHashMap::with_capacity_and_hasher(size / 2 + 16, Default::default());
    let mut sources: Vec<u32> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::with_capacity(size);
    // (shared vertex, output triangle, corner, the triangle over shared vertices).
    let mut singular: Vec<(u32, u32, u8, [u32; 3])> = Vec::new();
    for tri in oriented {
        let out = triangles.len() as u32;
        let ids = std::array::from_fn(|c| {
            let v = tri[c];
            if surface.flags[v as usize].is_singular() {
                singular.push((v, out, c as u8, tri));
                return u32::MAX;
            }
            *local.entry(v).or_insert_with(|| {
                sources.push(v);
                sources.len() as u32 - 1
            })
        });
        triangles.push(ids);
    }
    singular.sort_unstable_by_key(|s| s.0);
    let mut sheets = Sheets::default();
    let mut copies: Vec<(usize, u32)> = Vec::new();
    for group in singular.chunk_by(|a, b| a.0 == b.0) {
        sheets.find(surface, group);
        copies.clear();
        for (&(v, out, c, _), &root) in group.iter().zip(&sheets.roots) {
            let id = match copies.iter().find(|p| p.0 == root) {
                Some(p) => p.1,
                None => {
                    sources.push(v);
                    copies.push((root, sources.len() as u32 - 1));
                    sources.len() as u32 - 1
                }
            };
            triangles[out as usize][c as usize] = id;
        }
    }
    let positions = sources
        .iter()
        .map(|&v| surface.positions[v as usize])
        .collect();
    TriangleMesh::new(positions, triangles)
}

/// The sheets of a label at its singular corners, with buffers kept from corner to corner.
#[derive(Default)]
struct Sheets {
    /// Per triangle at the corner, the representative of its sheet (an index into the group).
    roots: Vec<usize>,
    voxels: Vec<Option<[i64; 3]>>,
    ends: Vec<(u32, usize)>,
}

impl Sheets {
    /// Fills [`Sheets::roots`] for `group`: a label's triangles (wound out of the label, the
    /// fourth member) at one shared vertex (the first), as [`label_mesh`] lists them (module
    /// docs).
    fn find(&mut self, surface: &SharedSurface, group: &[(u32, u32, u8, [u32; 3])]) {
        let v = group[0].0;
        let parent = &mut self.roots;
        parent.clear();
        parent.extend(0..group.len());
        fn root(parent: &mut [usize], mut i: usize) -> usize {
            while parent[i] != i {
                parent[i] = parent[parent[i]];
                i = parent[i];
            }
            i
        }
        let join = |parent: &mut Vec<usize>, a: usize, b: usize| {
            let (ra, rb) = (root(parent, a), root(parent, b));
            parent[ra.max(rb)] = ra.min(rb);
        };
        self.voxels.clear();
        self.voxels
            .extend(group.iter().map(|g| voxel_of(surface, &g.3)));
        for a in 0..group.len() {
            if let Some(b) =
                (0..a).find(|&b| self.voxels[a].is_some() && self.voxels[a] == self.voxels[b])
            {
                join(parent, a, b);
            }
        }
        self.ends.clear();
        for (i, g) in group.iter().enumerate() {
            self.ends
                .extend(g.3.iter().filter(|&&w| w != v).map(|&w| (w, i)));
        }
        self.ends.sort_unstable();
        for edge in self.ends.chunk_by(|a, b| a.0 == b.0) {
            if let [(_, a), (_, b)] = edge {
                join(parent, *a, *b);
            }
        }
        for i in 0..group.len() {
            let r = root(parent, i);
            parent[i] = r;
        }
    }
}

/// The voxel of the label that triangle `tri` (wound out of the label) bounds, in voxel
/// indices, when its corners are three corners of one voxel face (as the nets made it).
fn voxel_of(surface: &SharedSurface, tri: &[u32; 3]) -> Option<[i64; 3]> {
    let c = tri.map(|v| surface.corners[v as usize].map(i64::from));
    let axis = (0..3).find(|&a| c[0][a] == c[1][a] && c[1][a] == c[2][a])?;
    let (u, w) = (
        [0, 1, 2].map(|a| c[1][a] - c[0][a]),
        [0, 1, 2].map(|a| c[2][a] - c[0][a]),
    );
    let normal = u[(axis + 1) % 3] * w[(axis + 2) % 3] - u[(axis + 2) % 3] * w[(axis + 1) % 3];
    let outward = if surface.world.flips_handedness() {
        -normal
    } else {
        normal
    };
    Some(std::array::from_fn(|a| {
        if a == axis {
            c[0][a] - (outward > 0) as i64
        } else {
            c.iter().map(|p| p[a]).min().unwrap_or(0)
        }
    }))
}
