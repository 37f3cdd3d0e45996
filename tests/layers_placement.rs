//! Layered shells (paper §3) of an oblique, flipped scan land where `voxlod::lod` puts the
//! scan's surfaces: each layer is its axis-aligned twin's moved by the scan's index-to-world
//! transform (`voxlod_core::world`), winding outwards still; the eight stored back-to-front
//! orders hold for view octants in the world; and a layered `.glb` records what computing an
//! order afresh from its vertices needs (the grid and its placement).

use voxlod::core::glam::{DMat3, DVec3};
use voxlod::core::{mesh_topology, Bounds, Frame, Grid, Orientation, Placement, TriangleMesh};
use voxlod::core::{Volume, WorldTransform};
use voxlod::layers::{
    check_order, octant_orders, recover_cells, scene_order, CellTriangles, Octant, View,
};
use voxlod::sampling::Filter;
use voxlod::{LayersOptions, LodOptions, Source};

const DIMS: [usize; 3] = [30, 26, 20];
const SPACING: [f64; 3] = [0.8, 1.1, 1.5];
const ORIGIN: [f64; 3] = [-20.5, 13.25, -7.0];
/// The ellipsoid's centre (fractional index) and semi-axes along the index axes (mm).
const CENTRE: [f64; 3] = [14.3, 12.6, 9.7];
const AXES: [f64; 3] = [7.0, 5.0, 4.0];
const RESOLUTION: usize = 24;

/// 30° about z, 8° about the new x, and index axis i run against the first column: a
/// left-handed index-to-world map.
fn direction() -> DMat3 {
    DMat3::from_rotation_z(30f64.to_radians())
        * DMat3::from_rotation_x(8f64.to_radians())
        * DMat3::from_diagonal(DVec3::new(-1.0, 1.0, 1.0))
}

/// An ellipsoid (positive inside), axis-aligned or placed by [`direction`].
fn scan(oriented: bool) -> Volume {
    let grid = Grid::new(DIMS, SPACING, ORIGIN).unwrap();
    let mut values = Vec::with_capacity(DIMS.iter().product());
    for k in 0..DIMS[2] {
        for j in 0..DIMS[1] {
            for i in 0..DIMS[0] {
                let ijk = DVec3::new(i as f64, j as f64, k as f64);
                let mm = (ijk - DVec3::from(CENTRE)) * DVec3::from(SPACING);
                values.push((1.0 - (mm / DVec3::from(AXES)).length()) as f32);
            }
        }
    }
    let volume = Volume::from_vec(grid, values).unwrap();
    if !oriented {
        return volume;
    }
    volume.oriented(Orientation {
        direction: direction(),
        frame: Frame::Lps,
    })
}

fn options() -> LayersOptions {
    LayersOptions {
        resolution: RESOLUTION,
        ..Default::default()
    }
}

fn layers_of(volume: &Volume) -> voxlod::layers::Layered {
    let source = Source::Threshold {
        volume,
        threshold: 0.0,
    };
    voxlod::layers(&source, &options()).unwrap().layered
}

/// Volume-weighted centroid of a closed mesh.
fn centroid(mesh: &TriangleMesh) -> DVec3 {
    let (mut sum, mut volume) = (DVec3::ZERO, 0.0);
    for t in 0..mesh.triangles.len() {
        let [a, b, c] = mesh.corners(t);
        let v = a.dot(b.cross(c)) / 6.0;
        sum += (a + b + c) / 4.0 * v;
        volume += v;
    }
    sum / volume
}

fn inside(inner: &Bounds, outer: &Bounds, slack: f64) -> bool {
    (0..3).all(|a| inner.min[a] >= outer.min[a] - slack && inner.max[a] <= outer.max[a] + slack)
}

#[test]
fn the_layers_of_an_oblique_flipped_scan_are_its_twins_placed_and_face_outwards() {
    let oblique = scan(true);
    let world = WorldTransform::of(&oblique.grid, &oblique.orientation);
    assert!(world.flips_handedness());
    // The scan's map from its grid space (where the twin's layers lie) to the world.
    let to_world = Placement::of(&world, None);
    let (twin, placed) = (layers_of(&scan(false)), layers_of(&oblique));
    // The layers' own grid is the twin's with its first sample moved to the world, and their
    // placement takes that grid's samples where the scan's transform takes the twin's.
    let (g, h) = (&placed.mesh.grid, &twin.mesh.grid);
    assert_eq!((g.dims, g.spacing), (h.dims, h.spacing));
    let p = placed.mesh.placement;
    assert_eq!(p.linear, direction());
    for ijk in [[0.0; 3], [3.0, 1.0, 2.0], [9.5, 7.0, 4.25]] {
        let here = p.linear * g.position(ijk[0], ijk[1], ijk[2]) + p.translation;
        let there = to_world.linear * h.position(ijk[0], ijk[1], ijk[2]) + to_world.translation;
        assert!((here - there).length() < 1e-9, "{ijk:?}: {here} vs {there}");
    }
    assert_eq!(placed.mesh.layers.len(), twin.mesh.layers.len());
    for (i, (a, b)) in twin.mesh.layers.iter().zip(&placed.mesh.layers).enumerate() {
        assert_eq!(a.cells, b.cells, "layer {i}");
        assert_eq!(a.mesh.positions.len(), b.mesh.positions.len(), "layer {i}");
        // Every vertex moved by the scan's transform (f32 rounding of ~30 mm coordinates).
        let moved = a
            .mesh
            .positions
            .iter()
            .zip(&b.mesh.positions)
            .map(|(p, q)| {
                let want = to_world.linear * p.as_dvec3() + to_world.translation;
                (want - q.as_dvec3()).length()
            })
            .fold(0.0, f64::max);
        assert!(moved < 1e-4, "layer {i}: a vertex is {moved} mm off");
        // The transform flips handedness: every triangle rewound, so outward still.
        let rewound = a.mesh.triangles.iter().map(|t| [t[0], t[2], t[1]]);
        assert!(rewound.eq(b.mesh.triangles.iter().copied()), "layer {i}");
        let t = mesh_topology(&b.mesh);
        assert!(
            t.is_closed_manifold() && t.is_consistently_oriented(),
            "layer {i}: {t:?}"
        );
        let (va, vb) = (a.mesh.signed_volume(), b.mesh.signed_volume());
        assert!(vb > 0.0, "layer {i}: inside out ({vb})");
        assert!((vb / va - 1.0).abs() < 1e-4, "layer {i}: {vb} vs {va}");
    }
}

#[test]
fn the_layers_land_around_the_surface_lod_gives() {
    let oblique = scan(true);
    let layered = layers_of(&oblique);
    let source = Source::Threshold {
        volume: &oblique,
        threshold: 0.0,
    };
    let lod = voxlod::lod(
        &source,
        &LodOptions::halving(RESOLUTION, 1, Filter::Hypercone),
    )
    .unwrap();
    let surface = &lod.levels[0].mesh;
    let voxel = layered
        .mesh
        .grid
        .spacing
        .iter()
        .copied()
        .fold(0.0, f64::max);
    // The shells lie just outside the level's surface (all isodensities below its 0.5), each
    // around the one inside it, every one centred where the level is.
    let layers = &layered.mesh.layers;
    assert!(layers.iter().all(|l| l.isodensity < 0.5));
    let slack = 0.05 * voxel;
    assert!(inside(&surface.bounds(), &layers[0].mesh.bounds(), slack));
    for pair in layers.windows(2) {
        assert!(inside(
            &pair[0].mesh.bounds(),
            &pair[1].mesh.bounds(),
            slack
        ));
    }
    let expected = centroid(surface);
    for (i, l) in layers.iter().enumerate() {
        let miss = (centroid(&l.mesh) - expected).length();
        assert!(
            miss < 0.1 * voxel,
            "layer {i}: {miss} mm from the level's centroid"
        );
    }
    // And that is where the scan's transform puts the ellipsoid's centre.
    let world = WorldTransform::of(&oblique.grid, &oblique.orientation);
    let centre = world.index_to_world(DVec3::from(CENTRE));
    assert!((expected - centre).length() < 0.5 * voxel);
}

#[test]
fn stored_orders_hold_for_world_octants_and_need_the_placement() {
    let layered = layers_of(&scan(true));
    let all = layered.mesh.concatenated();
    let (positions, triangles) = (&all.mesh.positions, &all.mesh.triangles);
    let mut unplaced_violations = 0;
    let unplaced = octant_orders(&CellTriangles {
        grid: layered.mesh.grid,
        placement: Placement::IDENTITY,
        positions,
        triangles,
        cells: &all.cells,
    })
    .unwrap();
    for octant in Octant::ALL {
        let order = &layered.orders[octant.index()];
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert!(sorted.iter().copied().eq(0..triangles.len() as u32));
        let view = View::Orthographic {
            direction: octant.diagonal(),
        };
        let check = check_order(positions, triangles, order, &view).unwrap();
        assert!(check.overlapping_pairs > 0);
        assert_eq!(check.violations, 0, "{}: {check:?}", octant.name());
        let wrong = check_order(positions, triangles, &unplaced[octant.index()], &view).unwrap();
        unplaced_violations += wrong.violations;
    }
    // Walking the cells as if the grid were the world puts some triangles before ones behind
    // them: the check above can tell.
    assert!(unplaced_violations > 0);
}

#[test]
fn a_layered_glb_records_the_placement_and_orders_computed_afresh_hold() {
    let layered = layers_of(&scan(true));
    let bytes = voxlod::layered_glb(&layered, 1.0).unwrap();
    let scene = voxlod::gltf::parse_glb(&bytes).unwrap();
    assert!(scene.is_layered());
    assert_eq!(scene.grid, Some(layered.mesh.grid));
    let placement = scene.placement;
    let p = layered.mesh.placement;
    assert!(!p.is_identity());
    assert!(placement.linear.abs_diff_eq(p.linear, 1e-12));
    assert!(placement.translation.abs_diff_eq(p.translation, 1e-9));
    // The cells come back from the placed vertices, and a perspective order computed from them
    // (as `voxlod render` does) holds.
    let all = layered.mesh.concatenated();
    let grid = scene.grid.unwrap();
    let cells = recover_cells(
        &grid,
        &placement,
        &scene.mesh.positions,
        &scene.mesh.triangles,
    );
    assert_eq!(cells, all.cells);
    let object = CellTriangles {
        grid,
        placement,
        positions: &scene.mesh.positions,
        triangles: &scene.mesh.triangles,
        cells: &cells,
    };
    let centre = scene.mesh.bounds().center();
    for eye in [
        DVec3::new(60.0, -35.0, 45.0),
        DVec3::new(-50.0, 70.0, -40.0),
    ] {
        let view = View::Perspective { eye: centre + eye };
        let order: Vec<u32> = scene_order(&[object], &view)
            .unwrap()
            .order
            .into_iter()
            .map(|(_, t)| t)
            .collect();
        let check =
            check_order(&scene.mesh.positions, &scene.mesh.triangles, &order, &view).unwrap();
        assert!(check.overlapping_pairs > 0);
        assert_eq!(check.violations, 0, "{eye}: {check:?}");
    }
}
