//! Layer extraction: one pass equals one run per layer; every layer is a closed shell at its
//! isodensity, nested inside the next; empty input is refused.

mod common;

use voxlod_contouring::{marching_cubes, ContourOptions};
use voxlod_core::{mesh_topology, Grid, Volume};
use voxlod_layers::{
    extract_layers, layer_volume, plan_layers, ExtractOptions, LayersError, PlanOptions,
};
use voxlod_sampling::{filtered_density, level_grid, CsgSolid, DensityOptions, Filter, Solid};

fn bolt_volume(resolution: usize) -> Volume {
    let solid = CsgSolid::new(voxlod_layers::bolt()).unwrap();
    let bounds = solid.bounds();
    let r = bounds.longest_extent() / resolution as f64;
    let grid = level_grid(&bounds, resolution, r).unwrap();
    filtered_density(&solid, &grid, &DensityOptions::new(Filter::Hypercone, r))
        .unwrap()
        .0
}

#[test]
fn one_pass_gives_the_per_layer_meshes() {
    let volume = bolt_volume(48);
    let plan = plan_layers(&PlanOptions::default()).unwrap();
    let one = extract_layers(&volume, &plan, &ExtractOptions::default()).unwrap();
    let per = extract_layers(&volume, &plan, &ExtractOptions::per_layer()).unwrap();
    assert_eq!(one, per);
    for (layer, p) in one.layers.iter().zip(&plan.layers) {
        let plain = marching_cubes(&volume, &ContourOptions::at(p.isodensity as f32)).unwrap();
        assert_eq!(layer.mesh, plain);
    }
}

#[test]
fn layers_are_closed_nested_shells_at_their_isodensities() {
    let volume = bolt_volume(48);
    let plan = plan_layers(&PlanOptions::new(Filter::Hypercone, 0.02)).unwrap();
    assert_eq!(plan.len(), 6);
    let layered = extract_layers(&volume, &plan, &ExtractOptions::default()).unwrap();
    let g = volume.grid;
    let mut last_volume = 0.0;
    for (i, l) in layered.layers.iter().enumerate() {
        let t = mesh_topology(&l.mesh);
        assert!(
            t.is_closed_manifold() && t.is_consistently_oriented(),
            "layer {i}"
        );
        // Vertices sit on the isosurface of the trilinear field to within interpolation error.
        for p in l.mesh.positions.iter().step_by(97) {
            let f = (p.as_dvec3() - g.origin_vec()) / g.spacing_vec();
            let v = volume.sample_trilinear(f.x, f.y, f.z);
            assert!(
                (v - l.isodensity).abs() < 0.05,
                "layer {i}: {v} vs {}",
                l.isodensity
            );
        }
        // Each shell encloses the one inside it.
        let enclosed = l.mesh.signed_volume();
        assert!(
            enclosed > last_volume,
            "layer {i} encloses {enclosed} <= {last_volume}"
        );
        last_volume = enclosed;
        assert_eq!(l.cells.len(), l.mesh.triangles.len());
    }
    assert_eq!(layered.layers[0].alpha, 1.0);
    assert!(layered
        .layers
        .windows(2)
        .all(|w| w[1].translucency > w[0].translucency));
}

#[test]
fn empty_volumes_are_refused() {
    let grid = Grid::unit([8, 8, 8]).unwrap();
    let zero = Volume::filled(grid, 0.0, "test").unwrap();
    let plan = PlanOptions::default();
    let e = layer_volume(&zero, &plan, &ExtractOptions::default()).unwrap_err();
    assert!(matches!(e, LayersError::EmptyVolume), "{e}");
    assert!(e.to_string().contains("empty"));
    let nan = Volume::filled(grid, f32::NAN, "test").unwrap();
    assert!(matches!(
        layer_volume(&nan, &plan, &ExtractOptions::default()),
        Err(LayersError::EmptyVolume)
    ));
    let bad = PlanOptions::new(Filter::Hypercone, 0.0);
    assert!(matches!(
        layer_volume(&zero, &bad, &ExtractOptions::default()),
        Err(LayersError::NonPositiveError(_))
    ));
}
