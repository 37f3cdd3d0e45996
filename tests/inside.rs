//! The inside function of meshes, as the filtered density and its surface show it: closed
//! meshes, inside-out shells, duplicates, holes (closed by fans, or left to the majority vote),
//! non-manifold fins, nested shells, and thresholded volumes.
//!
//! End to end (sampling, then marching cubes), so it lives here rather than in voxlod-sampling,
//! which does not depend on voxlod-contouring.

use voxlod::contouring::{marching_cubes, ContourOptions};
use voxlod::core::glam::Vec3;
use voxlod::core::{mesh_topology, Grid, TriangleMesh, Volume};
use voxlod::sampling::{
    filtered_density, level_grid, DensityOptions, DensityReport, Filter, MeshSolid,
    MeshSolidOptions, Solid, ThresholdSolid,
};
use voxlod_testkit::shapes::{append, icosphere_at};

const RESOLUTION: usize = 40;

/// Samples a solid over `bounds_of`'s box at RESOLUTION and contours it at 0.5.
fn surface_of(solid: &dyn Solid, bounds_of: &dyn Solid) -> (Volume, TriangleMesh, DensityReport) {
    let b = bounds_of.bounds();
    let h = b.longest_extent() / RESOLUTION as f64;
    let grid = level_grid(&b, RESOLUTION, h).unwrap();
    let (density, report) =
        filtered_density(solid, &grid, &DensityOptions::new(Filter::Hypercone, h)).unwrap();
    let mesh = marching_cubes(&density, &ContourOptions::default()).unwrap();
    (density, mesh, report)
}

fn sphere_volume(r: f64) -> f64 {
    4.0 / 3.0 * std::f64::consts::PI * r.powi(3)
}

#[test]
fn a_closed_mesh_keeps_its_volume_and_genus() {
    let sphere = icosphere_at(4, 1.0, Vec3::ZERO);
    let solid = MeshSolid::new(&sphere).unwrap();
    assert!(solid.is_exact());
    let (_, mesh, report) = surface_of(&solid, &solid);
    assert!(report.majority.is_none());
    let t = mesh_topology(&mesh);
    assert!(t.is_closed_manifold() && t.genus == Some(0));
    let (got, want) = (mesh.signed_volume(), sphere.signed_volume());
    assert!((got / want - 1.0).abs() < 0.02, "volume {got} vs {want}");
}

#[test]
fn inside_out_and_duplicated_meshes_sample_identically() {
    let sphere = icosphere_at(3, 1.0, Vec3::ZERO);
    let reference = MeshSolid::new(&sphere).unwrap();
    let (density, ..) = surface_of(&reference, &reference);

    let mut inside_out = sphere.clone();
    inside_out.flip_orientation();
    let solid = MeshSolid::new(&inside_out).unwrap();
    assert_eq!(surface_of(&solid, &reference).0, density);

    let mut doubled = sphere.clone();
    let copy = sphere.clone();
    doubled
        .triangles
        .extend(copy.triangles.iter().map(|&[a, b, c]| [a, c, b]));
    let solid = MeshSolid::new(&doubled).unwrap();
    assert_eq!(solid.preparation.duplicate_triangles, copy.triangles.len());
    assert_eq!(surface_of(&solid, &reference).0, density);

    // An unwelded soup of the same triangles: welded back to the same solid.
    let mut soup = TriangleMesh::default();
    for t in 0..sphere.triangles.len() {
        let base = soup.positions.len() as u32;
        soup.positions
            .extend(sphere.triangles[t].map(|v| sphere.positions[v as usize]));
        soup.triangles.push([base, base + 1, base + 2]);
    }
    let solid = MeshSolid::new(&soup).unwrap();
    assert!(solid.is_exact());
    assert_eq!(surface_of(&solid, &reference).0, density);
}

/// The sphere with the triangles of a polar cap removed: one hole.
fn holed_sphere() -> (TriangleMesh, TriangleMesh) {
    let sphere = icosphere_at(4, 1.0, Vec3::ZERO);
    let mut holed = sphere.clone();
    holed.triangles.retain(|t| {
        let centre = t
            .iter()
            .map(|&v| sphere.positions[v as usize])
            .sum::<Vec3>()
            / 3.0;
        centre.z > -0.8
    });
    assert!(holed.triangles.len() < sphere.triangles.len() - 20);
    (sphere, holed)
}

#[test]
fn holes_are_closed_before_sampling() {
    let (sphere, holed) = holed_sphere();
    let solid = MeshSolid::new(&holed).unwrap();
    assert_eq!(solid.preparation.holes_closed, 1);
    assert!(solid.is_exact());
    let (_, mesh, _) = surface_of(&solid, &solid);
    let t = mesh_topology(&mesh);
    assert!(t.is_closed_manifold() && t.genus == Some(0), "{t:?}");
    // The fan is flat where the cap below z = -0.8 was round: the cap's 2.8 % is lost.
    let cap = std::f64::consts::PI * 0.04 * (3.0 - 0.2) / 3.0;
    let want = sphere.signed_volume() - cap;
    let ratio = mesh.signed_volume() / want;
    assert!(
        (ratio - 1.0).abs() < 0.015,
        "volume ratio {ratio} to the capped sphere"
    );
}

#[test]
fn the_majority_vote_alone_gives_the_solid_a_person_sees() {
    let (sphere, holed) = holed_sphere();
    let solid = MeshSolid::new_with(&holed, MeshSolidOptions::majority_only()).unwrap();
    assert!(!solid.is_exact());
    let (_, mesh, report) = surface_of(&solid, &solid);
    let majority = report.majority.expect("a vote ran");
    assert!(majority.lines_repaired > 0 && majority.points_outvoted > 0);
    let t = mesh_topology(&mesh);
    assert!(t.is_closed_manifold(), "{t:?}");
    assert_eq!(t.components, 1, "{t:?}");
    assert_eq!(t.genus, Some(0), "{t:?}");
    let ratio = mesh.signed_volume() / sphere.signed_volume();
    assert!(ratio > 0.95 && ratio < 1.02, "volume ratio {ratio}");
}

#[test]
fn a_non_manifold_fin_is_outvoted() {
    let sphere = icosphere_at(4, 1.0, Vec3::ZERO);
    let mut finned = sphere.clone();
    // A third triangle on edge (a, b), reaching outside the sphere: the edge is used 3 times.
    let [a, b, _] = finned.triangles[0];
    let tip = (finned.positions[a as usize] + finned.positions[b as usize]) * 0.8;
    finned.positions.push(tip);
    let tip_index = finned.positions.len() as u32 - 1;
    finned.triangles.push([a, b, tip_index]);
    let solid = MeshSolid::new(&finned).unwrap();
    assert!(!solid.is_exact());
    let (_, mesh, report) = surface_of(&solid, &solid);
    assert!(report.majority.is_some());
    let t = mesh_topology(&mesh);
    assert!(
        t.is_closed_manifold() && t.genus == Some(0) && t.components == 1,
        "{t:?}"
    );
    let ratio = mesh.signed_volume() / sphere.signed_volume();
    assert!((ratio - 1.0).abs() < 0.02, "volume ratio {ratio}");
}

#[test]
fn nested_shells_leave_a_cavity() {
    let mut shells = icosphere_at(4, 1.0, Vec3::ZERO);
    append(&mut shells, &icosphere_at(4, 0.5, Vec3::ZERO));
    let solid = MeshSolid::new(&shells).unwrap();
    assert!(solid.is_exact());
    let (_, mesh, _) = surface_of(&solid, &solid);
    let t = mesh_topology(&mesh);
    assert_eq!(t.components, 2, "outer surface and cavity");
    // The cavity's surface faces inwards, so the enclosed volumes subtract.
    let want = sphere_volume(1.0) - sphere_volume(0.5);
    let got = mesh.signed_volume();
    assert!((got / want - 1.0).abs() < 0.03, "volume {got} vs {want}");
}

#[test]
fn a_thresholded_volume_is_the_solid_its_isosurface_bounds() {
    // A sphere of radius 10 as a distance field on a 32³ grid with spacing 0.75.
    let n = 32;
    let grid = Grid::new([n; 3], [0.75; 3], [-11.625; 3]).unwrap();
    let mut data = Vec::new();
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let p = grid.position(i as f64, j as f64, k as f64);
                data.push((10.0 - p.length()) as f32);
            }
        }
    }
    let volume = Volume::from_vec(grid, data).unwrap();
    let solid = ThresholdSolid::new(&volume, 0.0).unwrap();
    let (_, mesh, _) = surface_of(&solid, &solid);
    let t = mesh_topology(&mesh);
    assert!(t.is_closed_manifold() && t.genus == Some(0));
    let ratio = mesh.signed_volume() / sphere_volume(10.0);
    assert!((ratio - 1.0).abs() < 0.02, "volume ratio {ratio}");
    // Meshes come out in world units (the grid's spacing and origin).
    let b = mesh.bounds();
    assert!(
        (b.min.x + 10.0).abs() < 0.3 && (b.max.z - 10.0).abs() < 0.3,
        "{b:?}"
    );
    assert!(ThresholdSolid::new(&volume, 99.0).is_err());
}
