//! A level that is the input's own collapse, with its looks: meshoptimizer's
//! `simplifyWithAttributes` (through the `meshopt` crate) on the asset's unwelded vertices,
//! weighing normals, texture coordinates and colours beside the quadric of the positions, as
//! gltfpack's `-si` does. The level's vertices are a subset of the input's, so every attribute
//! survives unchanged (the property Varshney et al.'s envelopes are built for): UV seams, normal
//! creases and material borders stay where they were, because meshoptimizer keeps vertices that
//! share a position with a vertex of other attributes on their seam, and a vertex used by two
//! materials is split first so that every material border is such a seam.
//!
//! Two steps go beyond gltfpack's `-si`:
//! - Point seams ([`crate::seams`]): the vertices of a sphere's pole or a cone's apex, one per
//!   segment with its own texture coordinate, are welded into one vertex for the collapse and
//!   take back their own attributes per triangle after it, so that the fan collapses as one
//!   vertex instead of staying whole. Where that loses a whole material (a part whose fans
//!   let it collapse to nothing while other parts stop at their seams), the collapse with the
//!   fans apart is taken if it keeps more materials.
//! - Below the seams' minimum: where the collapse that keeps every seam stops above the count
//!   (by more than [`SEAM_MINIMUM_SLACK`]), it runs again in meshoptimizer's permissive mode,
//!   which collapses across texture seams where the attribute error allows (material borders
//!   stay protected); its level is taken where it gets closer to the count. Its vertices are
//!   still the input's.
//!
//! Cost: O(T log T) for T input triangles (meshoptimizer's collapse, twice below the seams'
//! minimum), plus linear copies and hash maps.

use std::collections::HashMap;

use meshopt::{SimplifyOptions, SimplifyVertex, VertexDataAdapter};
use voxlod_core::memory::{bytes_of, check_allocation};

use crate::seams::{point_seams, resolve, weld, PointSeams, SeamOptions};
use crate::{Asset, AssetError, AssetMesh};

/// How far above the count (a fraction of it) the collapse that keeps every seam may stop
/// before the collapse across seams is tried.
pub const SEAM_MINIMUM_SLACK: f64 = 0.10;

/// How much each attribute weighs against the positions' quadric error (which meshoptimizer
/// measures relative to the mesh's extent, so 1 weighs a unit of the attribute like the whole
/// extent). Zero leaves an attribute out of the error; it is still carried.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AttributeWeights {
    /// Per normal component.
    pub normal: f32,
    /// Per texture coordinate (set 0; set 1 weighs the same).
    pub uv: f32,
    /// Per colour channel.
    pub color: f32,
}

impl Default for AttributeWeights {
    fn default() -> Self {
        AttributeWeights {
            normal: 0.5,
            uv: 1.0,
            color: 1.0,
        }
    }
}

/// Options of [`collapse_with`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CollapseOptions {
    /// The attributes' weights.
    pub weights: AttributeWeights,
    /// Largest error meshoptimizer may reach, relative to the mesh's extent; the default (1)
    /// lets the triangle count decide.
    pub target_error: f32,
    /// Point seams to weld for the collapse ([`crate::seams`]); `None` keeps every vertex
    /// apart, as gltfpack does.
    pub point_seams: Option<SeamOptions>,
    /// Whether a collapse that stops above the count at the seams' minimum may run again
    /// across texture seams (module docs).
    pub cross_seams: bool,
}

impl Default for CollapseOptions {
    fn default() -> Self {
        CollapseOptions {
            weights: AttributeWeights::default(),
            target_error: 1.0,
            point_seams: Some(SeamOptions::default()),
            cross_seams: true,
        }
    }
}

impl CollapseOptions {
    /// gltfpack's `-si` rule: every seam kept, no vertex welded, no collapse across seams.
    pub fn seams_kept() -> Self {
        CollapseOptions {
            point_seams: None,
            cross_seams: false,
            ..Self::default()
        }
    }
}

/// The asset collapsed to about `triangles` triangles with its looks, with default options.
pub fn collapse(asset: &Asset, triangles: usize) -> Result<Asset, AssetError> {
    collapse_with(asset, triangles, &CollapseOptions::default())
}

/// The asset collapsed towards `triangles` triangles (meshoptimizer stops above the count where
/// a further collapse would break a seam or the topology it keeps, unless
/// [`CollapseOptions::cross_seams`] lets it cross texture seams); its vertices are a subset of
/// the input's, with all their attributes, and each triangle keeps its material. Refuses an
/// invalid asset ([`Asset::validate`]) and asks the memory limit for the copies.
pub fn collapse_with(
    asset: &Asset,
    triangles: usize,
    options: &CollapseOptions,
) -> Result<Asset, AssetError> {
    asset.validate()?;
    let split = split_material_borders(asset)?;
    let mesh = &split.mesh;
    let (attributes, weights) = attribute_table(mesh, &options.weights);
    check_allocation(
        "the collapse's attribute table",
        bytes_of::<f32>(attributes.len()),
    )?;
    let seams = match &options.point_seams {
        Some(o) => point_seams(mesh, o)?,
        None => PointSeams::none(mesh.positions.len()),
    };
    let table = Table {
        mesh,
        attributes: &attributes,
        weights: &weights,
        seams: &seams,
    };
    let mut kept = table.collapse(triangles, options.target_error, false)?;
    // Welded fans let a part collapse further, and the count then takes whole parts where
    // others stop at their seams: a material lost that way is kept by leaving fans apart.
    let materials = {
        let mut m = mesh.material.clone();
        m.sort_unstable();
        m.dedup();
        m.len().max(1)
    };
    if seams.groups() > 0 && materials_in(mesh, &kept) < materials {
        let none = PointSeams::none(mesh.positions.len());
        let apart = Table {
            seams: &none,
            ..table
        }
        .collapse(triangles, options.target_error, false)?;
        if materials_in(mesh, &apart) > materials_in(mesh, &kept) {
            kept = apart;
        }
    }
    let slack = triangles as f64 * (1.0 + SEAM_MINIMUM_SLACK);
    if options.cross_seams && kept.len() / 3 > slack as usize {
        let crossed = table.collapse(triangles, options.target_error, true)?;
        if crossed.len() < kept.len() && materials_in(mesh, &crossed) >= materials_in(mesh, &kept) {
            kept = crossed;
        }
    }
    Ok(keep_triangles(&split, &kept))
}

/// How many materials the triangles `indices` (three per triangle) use; 1 without materials.
fn materials_in(mesh: &AssetMesh, indices: &[u32]) -> usize {
    if mesh.material.is_empty() {
        return usize::from(!indices.is_empty());
    }
    let of = vertex_materials(mesh);
    let mut used: Vec<u32> = indices.chunks_exact(3).map(|c| of[c[0] as usize]).collect();
    used.sort_unstable();
    used.dedup();
    used.len()
}

/// A split asset's vertices as meshoptimizer reads them, with the point seams to weld.
#[derive(Clone, Copy)]
struct Table<'a> {
    mesh: &'a AssetMesh,
    attributes: &'a [f32],
    weights: &'a [f32],
    seams: &'a PointSeams,
}

impl Table<'_> {
    /// The kept triangles (three input vertex indices each) of one collapse towards
    /// `triangles`: point seams welded before and resolved after; with `across`, in
    /// meshoptimizer's permissive mode with the material borders' vertices protected.
    fn collapse(&self, triangles: usize, error: f32, across: bool) -> Result<Vec<u32>, AssetError> {
        let mesh = self.mesh;
        let stride = self.weights.len().max(1);
        let positions: Vec<[f32; 3]> = mesh.positions.iter().map(|p| p.to_array()).collect();
        let adapter = VertexDataAdapter::new(meshopt::typed_to_bytes(&positions), 12, 0)
            .map_err(|e| AssetError::Invalid(format!("meshoptimizer refused the vertices: {e}")))?;
        let indices: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
        let indices = weld(&indices, self.seams);
        let (flags, locks) = if across {
            (SimplifyOptions::Permissive, material_borders(mesh))
        } else {
            (
                SimplifyOptions::empty(),
                vec![SimplifyVertex::None; positions.len()],
            )
        };
        let mut kept = meshopt::simplify_with_attributes_and_locks(
            &indices,
            &adapter,
            self.attributes,
            self.weights,
            stride * 4,
            &locks,
            triangles.saturating_mul(3),
            error,
            flags,
            None,
        );
        resolve(&mut kept, self.seams, self.attributes, stride);
        Ok(kept)
    }
}

/// meshoptimizer's vertex flags protecting every vertex whose position a vertex of another
/// material shares (after [`split_material_borders`], the material borders' vertices).
fn material_borders(mesh: &AssetMesh) -> Vec<SimplifyVertex> {
    let mut flags = vec![SimplifyVertex::None; mesh.positions.len()];
    let key = |v: u32| mesh.positions[v as usize].to_array().map(f32::to_bits);
    // Per position: the first material seen, and whether another one uses it too.
    let mut seen: HashMap<[u32; 3], (u32, bool)> = HashMap::new();
    for (corners, &m) in mesh.triangles.iter().zip(&mesh.material) {
        for &v in corners {
            let entry = seen.entry(key(v)).or_insert((m, false));
            entry.1 |= entry.0 != m;
        }
    }
    for &v in mesh.triangles.iter().flatten() {
        if seen.get(&key(v)).is_some_and(|e| e.1) {
            flags[v as usize] = SimplifyVertex::Protect;
        }
    }
    flags
}

/// The attributes as meshoptimizer reads them, one row per vertex, and their weights. An
/// asset without attributes gets one zero column of weight 0 (meshoptimizer needs a row).
fn attribute_table(mesh: &AssetMesh, w: &AttributeWeights) -> (Vec<f32>, Vec<f32>) {
    let mut columns: Vec<(Vec<f32>, usize, f32)> = Vec::new();
    let mut add = |values: Vec<f32>, width: usize, weight: f32| {
        if !values.is_empty() {
            columns.push((values, width, weight));
        }
    };
    add(
        mesh.normals.iter().flat_map(|n| n.to_array()).collect(),
        3,
        w.normal,
    );
    for set in &mesh.uv {
        add(set.iter().flat_map(|t| t.to_array()).collect(), 2, w.uv);
    }
    add(
        mesh.colors.iter().flat_map(|c| c.to_array()).collect(),
        4,
        w.color,
    );
    let n = mesh.positions.len();
    if columns.is_empty() {
        return (vec![0.0; n], vec![0.0]);
    }
    let weights: Vec<f32> = columns
        .iter()
        .flat_map(|(_, width, weight)| std::iter::repeat_n(*weight, *width))
        .collect();
    let mut table = Vec::with_capacity(n * weights.len());
    for v in 0..n {
        for (values, width, _) in &columns {
            table.extend_from_slice(&values[v * width..(v + 1) * width]);
        }
    }
    (table, weights)
}

/// The asset with every vertex that triangles of two materials share copied once per material,
/// so that a material border is an attribute seam. Cost: linear (a hash map of the copies).
fn split_material_borders(asset: &Asset) -> Result<Asset, AssetError> {
    let mesh = &asset.mesh;
    if mesh.material.is_empty() {
        return Ok(asset.clone());
    }
    let n = mesh.positions.len();
    let mut owner: Vec<u32> = vec![u32::MAX; n];
    let mut copy_of: HashMap<(u32, u32), u32> = HashMap::new();
    let mut from: Vec<usize> = (0..n).collect();
    let mut triangles = mesh.triangles.clone();
    for (corners, &m) in triangles.iter_mut().zip(&mesh.material) {
        for i in corners.iter_mut() {
            let v = *i as usize;
            if owner[v] == u32::MAX {
                owner[v] = m;
            } else if owner[v] != m {
                *i = *copy_of.entry((*i, m)).or_insert_with(|| {
                    from.push(v);
                    (from.len() - 1) as u32
                });
            }
        }
    }
    check_allocation("the split vertices", bytes_of::<[f32; 16]>(from.len()))?;
    Ok(Asset {
        mesh: gather(mesh, &from, triangles, mesh.material.clone()),
        materials: asset.materials.clone(),
        images: asset.images.clone(),
        parts: Vec::new(),
    })
}

/// The triangles `kept` (three indices each, into `asset`'s vertices) with only the vertices
/// they use, in first-use order, and the material of each kept triangle.
fn keep_triangles(asset: &Asset, kept: &[u32]) -> Asset {
    let mesh = &asset.mesh;
    let mut new_index = vec![u32::MAX; mesh.positions.len()];
    let mut from: Vec<usize> = Vec::new();
    let mut triangles = Vec::with_capacity(kept.len() / 3);
    for corners in kept.chunks_exact(3) {
        let mut t = [0u32; 3];
        for (slot, &v) in t.iter_mut().zip(corners) {
            if new_index[v as usize] == u32::MAX {
                new_index[v as usize] = from.len() as u32;
                from.push(v as usize);
            }
            *slot = new_index[v as usize];
        }
        triangles.push(t);
    }
    // Every vertex belongs to one material after the split: a triangle's is its first corner's.
    let vertex_material = vertex_materials(mesh);
    let material = if mesh.material.is_empty() {
        Vec::new()
    } else {
        kept.chunks_exact(3)
            .map(|c| vertex_material[c[0] as usize])
            .collect()
    };
    Asset {
        mesh: gather(mesh, &from, triangles, material),
        materials: asset.materials.clone(),
        images: asset.images.clone(),
        parts: Vec::new(),
    }
}

/// The material of each vertex (of the triangles that use it; any one where the asset was not
/// split), or none without materials.
fn vertex_materials(mesh: &AssetMesh) -> Vec<u32> {
    let mut of = vec![0u32; mesh.positions.len()];
    for (t, corners) in mesh.triangles.iter().enumerate() {
        if let Some(&m) = mesh.material.get(t) {
            for &v in corners {
                of[v as usize] = m;
            }
        }
    }
    of
}

/// A mesh of the vertices `from` (indices into `mesh`) with all their attributes.
fn gather(
    mesh: &AssetMesh,
    from: &[usize],
    triangles: Vec<[u32; 3]>,
    material: Vec<u32>,
) -> AssetMesh {
    fn pick<T: Copy>(values: &[T], from: &[usize]) -> Vec<T> {
        if values.is_empty() {
            return Vec::new();
        }
        from.iter().map(|&v| values[v]).collect()
    }
    AssetMesh {
        positions: pick(&mesh.positions, from),
        triangles,
        normals: pick(&mesh.normals, from),
        tangents: pick(&mesh.tangents, from),
        uv: [pick(&mesh.uv[0], from), pick(&mesh.uv[1], from)],
        colors: pick(&mesh.colors, from),
        material,
    }
}
