//! The cell-of-triangle and several-surfaces forms give exactly the plain mesh, and each
//! triangle lies in the cell it is said to come from.

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use voxlod_contouring::{
    marching_cubes, marching_cubes_multi, marching_cubes_with_cells, ContourOptions,
};
use voxlod_core::{Grid, Volume};

fn random_smooth_volume(dims: [usize; 3], seed: u64) -> Volume {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let centres: Vec<[f64; 4]> = (0..6)
        .map(|_| {
            [
                rng.random_range(2.0..dims[0] as f64 - 2.0),
                rng.random_range(2.0..dims[1] as f64 - 2.0),
                rng.random_range(2.0..dims[2] as f64 - 2.0),
                rng.random_range(1.5..4.0),
            ]
        })
        .collect();
    let mut data = Vec::new();
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let v: f64 = centres
                    .iter()
                    .map(|c| {
                        let d2 = (i as f64 - c[0]).powi(2)
                            + (j as f64 - c[1]).powi(2)
                            + (k as f64 - c[2]).powi(2);
                        (-d2 / (c[3] * c[3])).exp()
                    })
                    .sum();
                data.push(v as f32);
            }
        }
    }
    let grid = Grid::new(dims, [0.5, 0.5, 0.5], [-3.0, 1.0, 2.0]).unwrap();
    Volume::from_vec(grid, data).unwrap()
}

#[test]
fn cells_and_multi_give_the_plain_mesh() {
    for seed in 0..4 {
        let v = random_smooth_volume([23, 17, 29], seed);
        let isos = [0.2f32, 0.45, 0.7];
        let multi = marching_cubes_multi(&v, &isos, true).unwrap();
        assert_eq!(multi.len(), 3);
        for (layer, &iso) in multi.iter().zip(&isos) {
            let plain = marching_cubes(&v, &ContourOptions::at(iso)).unwrap();
            assert!(!plain.triangles.is_empty());
            assert_eq!(layer.mesh, plain, "seed {seed} iso {iso}");
            let single = marching_cubes_with_cells(&v, &ContourOptions::at(iso)).unwrap();
            assert_eq!(single.mesh, plain);
            assert_eq!(single.cells, layer.cells);
            assert_eq!(layer.cells.len(), plain.triangles.len());
        }
    }
}

#[test]
fn every_triangle_lies_in_its_cell() {
    let v = random_smooth_volume([31, 22, 18], 9);
    let g = v.grid;
    let (cx, cy) = (g.dims[0] - 1, g.dims[1] - 1);
    let out = marching_cubes_with_cells(&v, &ContourOptions::at(0.4)).unwrap();
    assert!(out.cells.windows(2).all(|w| w[0] <= w[1]), "cells in order");
    for (t, &c) in out.mesh.triangles.iter().zip(&out.cells) {
        let c = c as usize;
        let (i, j, k) = (c % cx, (c / cx) % cy, c / (cx * cy));
        let lo = g.position(i as f64, j as f64, k as f64);
        let hi = g.position(i as f64 + 1.0, j as f64 + 1.0, k as f64 + 1.0);
        for &vtx in t {
            let p = out.mesh.positions[vtx as usize].as_dvec3();
            assert!(
                p.cmpge(lo - 1e-5).all() && p.cmple(hi + 1e-5).all(),
                "vertex {p} outside cell {lo}..{hi}"
            );
        }
    }
}

#[test]
fn degenerate_grids_give_empty_surfaces_and_bad_iso_is_refused() {
    let v = Volume::from_vec(Grid::unit([1, 4, 4]).unwrap(), vec![1.0; 16]).unwrap();
    let out = marching_cubes_multi(&v, &[0.5, 0.2], true).unwrap();
    assert_eq!(out.len(), 2);
    assert!(out.iter().all(|m| m.mesh.triangles.is_empty()));
    let v = random_smooth_volume([8, 8, 8], 1);
    assert!(marching_cubes_multi(&v, &[0.5, f32::NAN], true).is_err());
}
