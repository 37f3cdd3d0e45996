//! `marching_cubes_of_samples`, the borrowed-samples form the Python package uses: the same
//! mesh and cells as `marching_cubes_with_cells` on a volume of the same samples, and per-vertex
//! corner ranges equal to scikit-image's definition (the largest range of the cells whose
//! triangles use the vertex), computed here the slow way, triangle by triangle.

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use voxlod_contouring::marching_cubes::{marching_cubes_of_samples, Wanted};
use voxlod_contouring::tables::{tables, EDGE_CORNERS};
use voxlod_contouring::{marching_cubes_with_cells, ContourError, ContourOptions};
use voxlod_core::{Grid, TriangleMesh, Volume};

const ALL: Wanted = Wanted {
    normals: true,
    cells: true,
    corner_ranges: true,
};

/// scikit-image's `values`: per vertex, the largest (max − min over the eight corners) of the
/// cells of the triangles that use it.
fn ranges_by_triangle(
    samples: &[f32],
    dims: [usize; 3],
    mesh: &TriangleMesh,
    cells: &[u32],
) -> Vec<f32> {
    let [nx, ny, _] = dims;
    let mut values = vec![f32::NEG_INFINITY; mesh.positions.len()];
    for (triangle, &cell) in mesh.triangles.iter().zip(cells) {
        let c = cell as usize;
        let (i, j, k) = (
            c % (nx - 1),
            (c / (nx - 1)) % (ny - 1),
            c / ((nx - 1) * (ny - 1)),
        );
        let mut lo = f32::INFINITY;
        let mut hi = f32::NEG_INFINITY;
        for corner in 0..8 {
            let (a, b, d) = (i + (corner & 1), j + ((corner >> 1) & 1), k + (corner >> 2));
            let v = samples[a + nx * (b + ny * d)];
            lo = lo.min(v);
            hi = hi.max(v);
        }
        for &v in triangle {
            values[v as usize] = values[v as usize].max(hi - lo);
        }
    }
    values
}

/// Noise (every case of the table, ambiguous faces included), a smooth field and a shell.
fn fields(dims: [usize; 3], seed: u64) -> Vec<Vec<f32>> {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let n = dims.iter().product::<usize>();
    let noise: Vec<f32> = (0..n).map(|_| rng.random_range(-1.0f32..1.0)).collect();
    let at = |f: &dyn Fn(f32, f32, f32) -> f32| -> Vec<f32> {
        (0..n)
            .map(|s| {
                let (i, j, k) = (
                    s % dims[0],
                    (s / dims[0]) % dims[1],
                    s / (dims[0] * dims[1]),
                );
                f(i as f32 * 0.37, j as f32 * 0.41, k as f32 * 0.29)
            })
            .collect()
    };
    let wavy = at(&|x, y, z| x.sin() * y.cos() + y.sin() * z.cos() + z.sin() * x.cos());
    let shell = at(&|x, y, z| {
        let r = ((x - 3.0).powi(2) + (y - 2.0).powi(2) + (z - 3.5).powi(2)).sqrt();
        0.6 - (r - 2.5).abs()
    });
    vec![noise, wavy, shell]
}

#[test]
fn borrowed_samples_give_the_volumes_mesh_and_ranges() {
    let mut checked = 0;
    for (seed, dims) in [[23, 17, 29], [70, 9, 12], [2, 2, 2], [65, 3, 4]]
        .into_iter()
        .enumerate()
    {
        for samples in fields(dims, seed as u64) {
            let grid = Grid::new(dims, [0.5, 2.0, 1.0], [-3.0, 1.0, 2.0]).unwrap();
            let volume = Volume::from_vec(grid, samples.clone()).unwrap();
            for iso in [-0.3f32, 0.0, 0.25] {
                let want = marching_cubes_with_cells(&volume, &ContourOptions::at(iso)).unwrap();
                let got = marching_cubes_of_samples(&samples, &grid, iso, ALL).unwrap();
                assert_eq!(got.mesh, want.mesh, "{dims:?} iso {iso}");
                assert_eq!(got.cells, want.cells);
                let ranges = ranges_by_triangle(&samples, dims, &want.mesh, &want.cells);
                assert_eq!(got.corner_ranges, ranges, "{dims:?} iso {iso}");
                checked += got.mesh.triangles.len();

                let bare = Wanted {
                    corner_ranges: true,
                    ..Wanted::default()
                };
                let only = marching_cubes_of_samples(&samples, &grid, iso, bare).unwrap();
                assert_eq!(only.mesh.triangles, want.mesh.triangles);
                assert_eq!(only.mesh.positions, want.mesh.positions);
                assert!(only.mesh.normals.is_empty() && only.cells.is_empty());
                assert_eq!(only.corner_ranges, ranges);
            }
        }
    }
    assert!(checked > 50_000, "only {checked} triangles compared");
}

#[test]
fn every_crossed_edge_of_a_cell_is_used_by_its_triangles() {
    // What makes the per-edge ranges equal to the per-triangle ones.
    let table = tables();
    for case in 0..256usize {
        let crossed: Vec<u8> = (0..12u8)
            .filter(|&e| {
                let (a, b) = EDGE_CORNERS[e as usize];
                ((case >> a) & 1) != ((case >> b) & 1)
            })
            .collect();
        let mut used: Vec<u8> = table.triangles[case][..table.triangle_count[case] as usize]
            .iter()
            .flatten()
            .copied()
            .collect();
        used.sort_unstable();
        used.dedup();
        assert_eq!(used, crossed, "case {case}");
    }
}

#[test]
fn hand_checked_ranges_and_bad_input() {
    // One cell, samples 0..8: every vertex's only cell spans 0 to 7.
    let samples: Vec<f32> = (0..8).map(|v| v as f32).collect();
    let grid = Grid::unit([2, 2, 2]).unwrap();
    let got = marching_cubes_of_samples(&samples, &grid, 3.5, ALL).unwrap();
    // Corners 0-3 (z = 0) outside, 4-7 inside: the four z edges are crossed.
    assert_eq!(got.mesh.positions.len(), 4);
    assert_eq!(got.corner_ranges, vec![7.0; 4]);

    // Two cells along x with ranges 2.5 and 9.5 (the sample 10 at (2, 1, 0)), at iso 1.5:
    // the z = 1 samples and that one inside. The z edges at x = 0 belong to the first cell
    // only (2.5); those at x = 1 to both (9.5); the edges crossed around the 10 and the z
    // edge at (2, 0) to the second only (9.5).
    let lower = [0.0, 0.5, 1.0, 0.0, 0.5, 10.0];
    let upper = [2.0, 2.5, 3.0, 2.0, 2.5, 3.0];
    let samples: Vec<f32> = lower.iter().chain(&upper).copied().collect();
    let grid = Grid::unit([3, 2, 2]).unwrap();
    let got = marching_cubes_of_samples(&samples, &grid, 1.5, ALL).unwrap();
    let mut values = got.corner_ranges.clone();
    values.sort_by(f32::total_cmp);
    assert_eq!(values, [2.5, 2.5, 9.5, 9.5, 9.5, 9.5, 9.5]);
    let want = ranges_by_triangle(&samples, [3, 2, 2], &got.mesh, &got.cells);
    assert_eq!(got.corner_ranges, want);

    let short = marching_cubes_of_samples(&samples[..11], &grid, 1.5, ALL);
    assert!(matches!(
        short,
        Err(ContourError::SampleCount {
            given: 11,
            dims: [3, 2, 2]
        })
    ));
    let nan = marching_cubes_of_samples(&samples, &grid, f32::NAN, ALL);
    assert!(matches!(nan, Err(ContourError::NonFiniteIso(_))));
    let flat = marching_cubes_of_samples(&[0.0; 4], &Grid::unit([2, 2, 1]).unwrap(), 0.5, ALL);
    assert!(flat.unwrap().mesh.triangles.is_empty());
}
