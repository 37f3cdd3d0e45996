//! Extraction of every layer from one filtered volume (paper §3: "several layers of triangle
//! meshes with increasing translucency from the innermost layer to the outermost one").
//!
//! Each layer is the marching cubes isosurface of the same volume at its planned isodensity,
//! with the cell of every triangle kept for the back-to-front traversal ([`crate::order`]).
//! Nested isosurfaces of one field do not cross (the higher isodensity lies inside the lower), so
//! the shells are nested like the paper's Figure 1b.
//!
//! **Placement** (beyond the paper). Marching cubes works in the volume's axis-aligned grid
//! space; the finished layers are moved to where the volume's index-to-world transform puts
//! them (spacing, origin and the direction cosines of an oblique or flipped scan,
//! `voxlod_core::world`), as `voxlod::contour` and the pyramid's levels are, rewound when the
//! transform flips handedness so every shell still faces outwards. The grid and the cells stay
//! in grid space; [`LayeredMesh::placement`] says how to get from there to the vertices.
//!
//! **One pass** (beyond the paper). With [`ExtractOptions::one_pass`] the volume is read once to
//! classify every sample against all isodensities
//! ([`voxlod_contouring::marching_cubes_multi`]); the later passes work on bits and read the
//! floats only at crossed edges. Otherwise each layer runs marching cubes on its own, reading
//! the volume once per layer. The meshes are identical either way; the one-pass form saves
//! `L − 1` reads of the volume, which is what dominates once the surfaces are small against the
//! grid. Cost: one read of N³ floats plus O(L N³ / 64 + output).

use glam::Vec3;
use rayon::prelude::*;
use serde::Serialize;
use voxlod_contouring::{marching_cubes_multi, marching_cubes_with_cells, ContourOptions};
use voxlod_core::{Grid, Placement, TriangleMesh, Volume};

use crate::plan::LayerPlan;
use crate::LayersError;

/// One shell: an isosurface of the filtered volume with its translucency.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Layer {
    /// The density level of this shell's surface (between 0 and 1 for a filtered solid).
    pub isodensity: f32,
    /// `1 − isodensity / m` (paper equation 4): 0 for the innermost layer.
    pub translucency: f32,
    /// The alpha to blend with (see [`crate::plan::Blending`]): 1 for the innermost layer.
    pub alpha: f32,
    /// The isosurface: closed where the volume's density falls to 0 at its border.
    pub mesh: TriangleMesh,
    /// The cell of each triangle in the volume's grid (see
    /// [`voxlod_contouring::CellMesh::cells`]).
    pub cells: Vec<u32>,
}

/// All the shells of one object, innermost (opaque) first, and the grid they were cut from.
#[derive(Clone, Debug, PartialEq)]
pub struct LayeredMesh {
    /// The sample grid of the filtered volume, in its axis-aligned grid space (`origin + spacing
    /// · index`); its cells are `dims − 1` per axis.
    pub grid: Grid,
    /// The map from the grid's space to the space of the layers' vertices: the volume's
    /// index-to-world transform without its spacing and origin (the identity for an
    /// axis-aligned volume, where grid space is the world).
    pub placement: Placement,
    /// The shells, innermost first.
    pub layers: Vec<Layer>,
}

/// Every layer's vertices and triangles in one mesh, layers in order; what the orders and the
/// exports index.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Concatenated {
    /// All layers' vertices (normals when every layer has them) and triangles.
    pub mesh: TriangleMesh,
    /// Cell of each triangle.
    pub cells: Vec<u32>,
    /// Layer of each triangle.
    pub triangle_layer: Vec<u16>,
    /// First vertex of each layer, and the total at the end.
    pub vertex_start: Vec<u32>,
    /// First triangle of each layer, and the total at the end.
    pub triangle_start: Vec<u32>,
}

impl LayeredMesh {
    /// Triangles in all layers.
    pub fn triangle_count(&self) -> usize {
        self.layers.iter().map(|l| l.mesh.triangles.len()).sum()
    }

    /// Vertices in all layers.
    pub fn vertex_count(&self) -> usize {
        self.layers.iter().map(|l| l.mesh.positions.len()).sum()
    }

    /// The layers' meshes one after the other (vertex indices offset accordingly).
    pub fn concatenated(&self) -> Concatenated {
        let mut out = Concatenated::default();
        let with_normals = self.layers.iter().all(|l| !l.mesh.normals.is_empty());
        let (v, t) = (self.vertex_count(), self.triangle_count());
        out.mesh.positions.reserve(v);
        out.mesh.triangles.reserve(t);
        out.cells.reserve(t);
        out.triangle_layer.reserve(t);
        for (i, layer) in self.layers.iter().enumerate() {
            let base = out.mesh.positions.len() as u32;
            out.vertex_start.push(base);
            out.triangle_start.push(out.mesh.triangles.len() as u32);
            out.mesh.positions.extend_from_slice(&layer.mesh.positions);
            if with_normals {
                out.mesh.normals.extend_from_slice(&layer.mesh.normals);
            }
            out.mesh
                .triangles
                .extend(layer.mesh.triangles.iter().map(|t| t.map(|x| x + base)));
            out.cells.extend_from_slice(&layer.cells);
            out.triangle_layer
                .extend(std::iter::repeat_n(i as u16, layer.mesh.triangles.len()));
        }
        out.vertex_start.push(out.mesh.positions.len() as u32);
        out.triangle_start.push(out.mesh.triangles.len() as u32);
        out
    }

    /// Checks what the orders and exports assume: one cell per triangle, cells inside the grid,
    /// normals either everywhere or nowhere, at most 65 535 layers.
    pub fn validate(&self) -> Result<(), LayersError> {
        let cells = self.grid.cell_count() as u64;
        if self.layers.len() > u16::MAX as usize {
            return Err(LayersError::Invalid(format!(
                "{} layers, at most {} allowed",
                self.layers.len(),
                u16::MAX
            )));
        }
        if self.vertex_count() as u64 >= u32::MAX as u64 {
            return Err(LayersError::Invalid(format!(
                "{} vertices in all layers, more than 32-bit indices can address",
                self.vertex_count()
            )));
        }
        for (i, l) in self.layers.iter().enumerate() {
            l.mesh
                .validate()
                .map_err(|e| LayersError::Invalid(format!("layer {i}: {e}")))?;
            if l.cells.len() != l.mesh.triangles.len() {
                return Err(LayersError::Invalid(format!(
                    "layer {i}: {} cells for {} triangles",
                    l.cells.len(),
                    l.mesh.triangles.len()
                )));
            }
            if let Some(&c) = l.cells.iter().find(|&&c| c as u64 >= cells) {
                return Err(LayersError::Invalid(format!(
                    "layer {i}: cell {c} is outside the grid's {cells} cells"
                )));
            }
        }
        Ok(())
    }

    /// Bounds of all vertices.
    pub fn bounds(&self) -> voxlod_core::Bounds {
        voxlod_core::Bounds::from_points(
            self.layers
                .iter()
                .flat_map(|l| l.mesh.positions.iter())
                .collect::<Vec<&Vec3>>(),
        )
    }
}

/// How to extract.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct ExtractOptions {
    /// Gradient normals on every layer.
    pub normals: bool,
    /// Classify all layers in one read of the volume (see the module documentation).
    pub one_pass: bool,
}

impl Default for ExtractOptions {
    /// Normals, one pass.
    fn default() -> Self {
        ExtractOptions {
            normals: true,
            one_pass: true,
        }
    }
}

impl ExtractOptions {
    /// One marching cubes run per layer (for comparison; the output is the same).
    pub fn per_layer() -> Self {
        ExtractOptions {
            one_pass: false,
            ..Default::default()
        }
    }
}

/// Cuts every planned layer out of `volume`, each placed where the volume's index-to-world
/// transform puts it (see the module documentation). Fails with [`LayersError::EmptyVolume`]
/// when the innermost layer has no triangle (nothing of the object reached the grid).
pub fn extract_layers(
    volume: &Volume,
    plan: &LayerPlan,
    options: &ExtractOptions,
) -> Result<LayeredMesh, LayersError> {
    if plan.layers.is_empty() {
        return Err(LayersError::Invalid("the plan has no layers".into()));
    }
    let isos = plan.isodensities();
    let meshes = if options.one_pass {
        marching_cubes_multi(volume, &isos, options.normals)?
    } else {
        isos.par_iter()
            .map(|&iso| {
                marching_cubes_with_cells(
                    volume,
                    &ContourOptions {
                        iso,
                        normals: options.normals,
                        ..ContourOptions::default()
                    },
                )
            })
            .collect::<Result<Vec<_>, _>>()?
    };
    if meshes[0].mesh.triangles.is_empty() {
        return Err(LayersError::EmptyVolume);
    }
    let placement = Placement::of(&volume.world(), None);
    let layers = meshes
        .into_iter()
        .zip(&plan.layers)
        .map(|(mut m, p)| {
            placement.apply(&mut m.mesh);
            Layer {
                isodensity: p.isodensity as f32,
                translucency: p.translucency as f32,
                alpha: p.alpha as f32,
                mesh: m.mesh,
                cells: m.cells,
            }
        })
        .collect();
    let out = LayeredMesh {
        grid: volume.grid,
        placement,
        layers,
    };
    debug_assert!(out.validate().is_ok());
    Ok(out)
}
