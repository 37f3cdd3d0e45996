//! Layered meshes as PLY and VTK PolyData, through `voxlod_io::write_poly_mesh`: one mesh of all
//! layers concatenated (innermost first), with two per-vertex attributes, `opacity` (the blend
//! alpha of the vertex's layer, see [`crate::plan::Blending`]) and `layer` (its index, 0
//! innermost). Triangles are
//! written in a given back-to-front order when one is given, so that a viewer drawing in file
//! order composites correctly for that octant; otherwise layer by layer. Cost: linear.

use std::path::Path;

use voxlod_core::{Attribute, PolyMesh};

use crate::extract::LayeredMesh;
use crate::LayersError;

/// All layers in one mesh with `opacity` and `layer` vertex attributes; triangles in `order`
/// (global triangle indices) when given.
pub fn to_poly_mesh(layered: &LayeredMesh, order: Option<&[u32]>) -> Result<PolyMesh, LayersError> {
    layered.validate()?;
    let cat = layered.concatenated();
    let mut mesh = cat.mesh;
    if let Some(order) = order {
        if order.len() != mesh.triangles.len() {
            return Err(LayersError::Invalid(format!(
                "the order lists {} of {} triangles",
                order.len(),
                mesh.triangles.len()
            )));
        }
        let mut seen = vec![false; order.len()];
        for &t in order {
            if t as usize >= seen.len() || std::mem::replace(&mut seen[t as usize], true) {
                return Err(LayersError::Invalid(format!(
                    "the order is not a permutation (triangle {t})"
                )));
            }
        }
        mesh.triangles = order.iter().map(|&t| mesh.triangles[t as usize]).collect();
    }
    let mut opacity = Vec::with_capacity(mesh.positions.len());
    let mut layer = Vec::with_capacity(mesh.positions.len());
    for (i, l) in layered.layers.iter().enumerate() {
        let n = l.mesh.positions.len();
        opacity.extend(std::iter::repeat_n(l.alpha, n));
        layer.extend(std::iter::repeat_n(i as f32, n));
    }
    Ok(PolyMesh {
        mesh,
        vertex_attributes: vec![
            Attribute {
                name: "opacity".into(),
                values: opacity,
            },
            Attribute {
                name: "layer".into(),
                values: layer,
            },
        ],
        ..Default::default()
    })
}

/// Writes `.ply`, `.vtp` or `.vtk` (atomically, by extension).
pub fn write_layered_mesh(
    path: &Path,
    layered: &LayeredMesh,
    order: Option<&[u32]>,
) -> Result<(), LayersError> {
    let poly = to_poly_mesh(layered, order)?;
    Ok(voxlod_io::write_poly_mesh(path, &poly)?)
}
