//! Levels 0 and 1 of the bunny, of the CT skull (the head thresholded at 1500) and of the CT
//! head's skin (at 500), raw, cleaned, and contoured with the snapping clamp
//! ([`CleanOptions::contour_clamp`], what `voxlod lod` does; cleaning then changes nothing):
//! crossing pairs by the testkit's intersection test, triangles under a thousandth of a cell²,
//! and, where the peers' Python with Open3D is installed, Open3D's self-intersecting pairs
//! (`scripts/open3d-self-intersections.py`). Ignored by default (Open3D's test is quadratic);
//! run with `cargo test -p voxlod-contouring --test clean_real_data -- --ignored --nocapture`.
//! Skips with a printed reason when `../shared/data` is absent.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;

use voxlod_contouring::{clean_mesh, marching_cubes, CleanOptions, ContourOptions};
use voxlod_core::{mesh_topology, TriangleMesh, Volume};
use voxlod_sampling::{filtered_density, plan_levels, MeshSolid, PyramidOptions, Solid};
use voxlod_sampling::{Filter, ThresholdSolid};
use voxlod_testkit::data::shared_data_or_skip;
use voxlod_testkit::intersections::{self_intersections, triangles_smaller_than};
use voxlod_testkit::readers::read_obj;
use voxlod_testkit::volumes::shared_ct_head;

/// Level `level` of the default six-level hyper-cone pyramid from 256, and its cell size.
fn level_of(solid: &dyn Solid, level: usize) -> (Volume, f64) {
    let pyramid = PyramidOptions::halving(256, 6, Filter::Hypercone);
    let plan = plan_levels(&solid.bounds(), &pyramid).unwrap()[level];
    let (density, _) =
        filtered_density(solid, &plan.grid, &plan.density_options(&pyramid)).unwrap();
    (density, plan.voxel_size)
}

fn write_obj(path: &Path, mesh: &TriangleMesh) {
    let mut out = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    for p in &mesh.positions {
        writeln!(out, "v {} {} {}", p.x, p.y, p.z).unwrap();
    }
    for t in &mesh.triangles {
        writeln!(out, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1).unwrap();
    }
}

/// Prints the counts of the raw, cleaned and snapped level and returns the meshes' files.
fn report(name: &str, volume: &Volume, cell: f64, dir: &Path) -> Vec<PathBuf> {
    let raw = marching_cubes(volume, &ContourOptions::at(0.5)).unwrap();
    let (clean, cleaning) = clean_mesh(&raw, cell, &CleanOptions::default()).unwrap();
    let clamp = CleanOptions::default().contour_clamp();
    let snapped = marching_cubes(volume, &ContourOptions::at(0.5).with_clamp(clamp)).unwrap();
    let (snapped_clean, snapped_cleaning) =
        clean_mesh(&snapped, cell, &CleanOptions::default()).unwrap();
    assert_eq!(snapped_cleaning.collapsed_edges, 0, "{name}");
    assert_eq!(snapped_cleaning.flipped_edges, 0, "{name}");
    assert_eq!(snapped_clean.triangles.len(), snapped.triangles.len());
    let limit = CleanOptions::default().min_area * cell * cell;
    let mut files = Vec::new();
    for (what, mesh) in [("raw", &raw), ("clean", &clean), ("snapped", &snapped)] {
        let t = mesh_topology(mesh);
        eprintln!(
            "{name} {what}: {} triangles, crossing pairs {}, under 1e-3 cell² {}, genus {:?}, closed manifold {}, volume {:.6e}",
            mesh.triangles.len(),
            self_intersections(mesh).len(),
            triangles_smaller_than(mesh, limit),
            t.genus,
            t.is_closed_manifold(),
            mesh.signed_volume()
        );
        for (i, j) in self_intersections(mesh) {
            let area = |t: usize| {
                let [a, b, c] = mesh.corners(t);
                0.5 * (b - a).cross(c - a).length() / (cell * cell)
            };
            let shared = (mesh.triangles[i].iter())
                .filter(|v| mesh.triangles[j].contains(v))
                .count();
            eprintln!(
                "  crossing {i} {j}: areas {:.1e} {:.1e} cells², {shared} shared vertices",
                area(i),
                area(j)
            );
        }
        let path = dir.join(format!("{name}-{what}.obj"));
        write_obj(&path, mesh);
        files.push(path);
    }
    eprintln!("{name}: {cleaning:?}");
    files
}

#[test]
#[ignore = "slow: Open3D's self-intersection test is quadratic"]
fn bunny_and_ct_head_levels_0_and_1_raw_clean_and_snapped() {
    let Some(bunny) = shared_data_or_skip("meshes/stanford-bunny.obj", "clean_real_data") else {
        return;
    };
    let dir = std::env::temp_dir().join(format!("voxlod-clean-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let solid = MeshSolid::new(&read_obj(&bunny)).unwrap();
    let mut files = Vec::new();
    for level in [0, 1] {
        let (volume, cell) = level_of(&solid, level);
        files.extend(report(&format!("bunny-level-{level}"), &volume, cell, &dir));
    }
    if let Some(ct) = shared_ct_head("clean_real_data") {
        for (name, threshold) in [("skull", 1500.0), ("skin", 500.0)] {
            let solid = ThresholdSolid::new(&ct, threshold).unwrap();
            for level in [0, 1] {
                let (volume, cell) = level_of(&solid, level);
                let name = format!("{name}-level-{level}");
                files.extend(report(&name, &volume, cell, &dir));
            }
        }
    }
    let python = std::env::var_os("HOME")
        .map(|h| PathBuf::from(h).join(".cache/voxlod-peers/bin/python"))
        .filter(|p| p.is_file());
    let script =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scripts/open3d-self-intersections.py");
    match python {
        Some(python) => {
            let out = Command::new(python)
                .arg(script)
                .args(&files)
                .output()
                .unwrap();
            eprintln!(
                "{}{}",
                String::from_utf8_lossy(&out.stdout),
                String::from_utf8_lossy(&out.stderr)
            );
        }
        None => eprintln!(
            "skipping the Open3D cross-check: ~/.cache/voxlod-peers/bin/python is missing"
        ),
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
