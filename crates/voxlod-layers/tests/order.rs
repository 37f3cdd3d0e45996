//! The back-to-front orders are right on real shapes: no triangle is drawn before a triangle
//! that lies behind it, over every pair whose projections overlap (checked by
//! `voxlod_layers::check_order`, which knows nothing of cells).

mod common;

use glam::DVec3;
use voxlod_core::Placement;
use voxlod_layers::{
    check_order, index_cells, octant_order, scene_order, view_order, CellTriangles, Layered,
    Octant, View,
};

fn cat(l: &Layered) -> voxlod_layers::Concatenated {
    l.mesh.concatenated()
}

fn obj<'a>(l: &Layered, c: &'a voxlod_layers::Concatenated) -> CellTriangles<'a> {
    CellTriangles {
        grid: l.mesh.grid,
        placement: l.mesh.placement,
        positions: &c.mesh.positions,
        triangles: &c.mesh.triangles,
        cells: &c.cells,
    }
}

/// The stored octant orders are exact for the octants' diagonals.
fn octant_orders_are_exact(l: &Layered, name: &str) {
    let c = cat(l);
    let mut pairs = 0;
    for o in Octant::ALL {
        let view = View::Orthographic {
            direction: o.diagonal(),
        };
        let check = check_order(
            &c.mesh.positions,
            &c.mesh.triangles,
            &l.orders[o.index()],
            &view,
        )
        .unwrap();
        println!("{name} {}: {check:?}", o.name());
        assert_eq!(check.violations, 0, "{name} {}: {check:?}", o.name());
        assert!(
            check.overlapping_pairs > 1000,
            "{name}: too few pairs checked"
        );
        pairs += check.overlapping_pairs;
    }
    println!("{name}: {pairs} overlapping pairs checked over the eight octants");
}

#[test]
fn bolt_octant_orders_have_no_violation() {
    let l = common::layered_bolt(48);
    assert_eq!(l.plan.len(), 5);
    octant_orders_are_exact(&l, "bolt");
}

#[test]
fn bunny_octant_orders_have_no_violation() {
    let Some(l) = common::layered_bunny(64, "bunny_octant_orders_have_no_violation") else {
        return;
    };
    octant_orders_are_exact(&l, "bunny");
}

/// Pseudo-random unit directions (no rand dependency needed).
fn directions(n: usize) -> Vec<DVec3> {
    (0..n)
        .map(|i| {
            let t = i as f64 + 0.5;
            let z = 1.0 - 2.0 * (t / n as f64);
            let phi = t * 2.399_963_229_728_653;
            let r = (1.0 - z * z).sqrt();
            DVec3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect()
}

#[test]
fn exact_view_orders_have_no_violation_for_any_direction() {
    let l = common::layered_bolt(48);
    let c = cat(&l);
    let o = obj(&l, &c);
    let index = index_cells(&o).unwrap();
    let mut stored_violations = 0u64;
    let mut stored_pairs = 0u64;
    for d in directions(12) {
        let view = View::Orthographic { direction: d };
        let order = voxlod_layers::order::view_order_indexed(&o, &index, &view).unwrap();
        let check = check_order(&c.mesh.positions, &c.mesh.triangles, &order, &view).unwrap();
        assert_eq!(check.violations, 0, "direction {d}: {check:?}");
        // The stored order of the octant, sorted inside cells for the diagonal: right between
        // cells for every direction; inside cells it may differ off the diagonal.
        let stored = octant_order(&o, &index, Octant::of(d).unwrap());
        let s = check_order(&c.mesh.positions, &c.mesh.triangles, &stored, &view).unwrap();
        stored_violations += s.violations;
        stored_pairs += s.overlapping_pairs;
    }
    let rate = stored_violations as f64 / stored_pairs as f64;
    println!("stored octant orders off the diagonal: {stored_violations} of {stored_pairs} pairs ({rate:.2e})");
    assert!(rate < 1e-2, "{rate}");
}

#[test]
fn perspective_orders_split_at_the_eye() {
    let l = common::layered_bolt(48);
    let c = cat(&l);
    let o = obj(&l, &c);
    let b = l.mesh.bounds();
    let centre = b.center();
    let size = b.size();
    // Outside the grid on several sides, and inside the grid's box beside the shank.
    let eyes = [
        centre + DVec3::new(3.0, 2.0, 1.5) * size.max_element(),
        centre - DVec3::new(0.5, 2.5, -1.0) * size.max_element(),
        centre + DVec3::new(0.0, 0.0, 2.0) * size.max_element(),
        DVec3::new(centre.x + 0.45, centre.y + 0.1, centre.z - 0.4),
    ];
    for eye in eyes {
        let view = View::Perspective { eye };
        let order = view_order(&o, &view).unwrap();
        let check = check_order(&c.mesh.positions, &c.mesh.triangles, &order, &view).unwrap();
        println!("eye {eye}: {check:?}");
        assert!(check.overlapping_pairs > 100);
        assert_eq!(check.violations, 0, "eye {eye}: {check:?}");
    }
}

#[test]
fn the_checker_catches_wrong_orders() {
    let l = common::layered_bolt(32);
    let c = cat(&l);
    let view = View::Orthographic {
        direction: Octant::ALL[3].diagonal(),
    };
    let mut reversed = l.orders[3].clone();
    reversed.reverse();
    let check = check_order(&c.mesh.positions, &c.mesh.triangles, &reversed, &view).unwrap();
    assert!(check.violations * 2 > check.overlapping_pairs, "{check:?}");
    // The order of the opposite octant is wrong for this one.
    let opposite = check_order(&c.mesh.positions, &c.mesh.triangles, &l.orders[4], &view).unwrap();
    assert!(opposite.violations > 0);
}

#[test]
fn several_objects_interleave_exactly() {
    let l = common::layered_bolt(40);
    let c = cat(&l);
    let g = l.mesh.grid;
    let h = g.spacing[0];
    // A copy shifted by a whole number of cells so that the buffers overlap (shared lattice:
    // its shank passes beside the first one's head, 0.09 apart, so the parts do not touch), and
    // one far away (ordered by boxes).
    let shift = DVec3::new((0.9 / h).round() * h, 0.0, (0.8 / h).round() * h);
    let far = DVec3::new(0.0, 0.0, 90.0 * h);
    let moved = |d: DVec3| -> Vec<glam::Vec3> {
        c.mesh
            .positions
            .iter()
            .map(|p| (p.as_dvec3() + d).as_vec3())
            .collect()
    };
    let (p1, p2) = (moved(shift), moved(far));
    let grid_at = |d: DVec3| {
        voxlod_core::Grid::new(
            g.dims,
            g.spacing,
            [g.origin[0] + d.x, g.origin[1] + d.y, g.origin[2] + d.z],
        )
        .unwrap()
    };
    let objects = [
        obj(&l, &c),
        CellTriangles {
            grid: grid_at(shift),
            placement: Placement::IDENTITY,
            positions: &p1,
            triangles: &c.mesh.triangles,
            cells: &c.cells,
        },
        CellTriangles {
            grid: grid_at(far),
            placement: Placement::IDENTITY,
            positions: &p2,
            triangles: &c.mesh.triangles,
            cells: &c.cells,
        },
    ];
    // Everything in one mesh, for the checker.
    let n = c.mesh.positions.len() as u32;
    let t = c.mesh.triangles.len() as u32;
    let mut positions = c.mesh.positions.clone();
    positions.extend_from_slice(&p1);
    positions.extend_from_slice(&p2);
    let mut triangles = c.mesh.triangles.clone();
    for k in 1..3u32 {
        triangles.extend(c.mesh.triangles.iter().map(|tri| tri.map(|v| v + k * n)));
    }
    let mut naive_violations = 0;
    for direction in [
        DVec3::new(1.0, 0.3, 0.6),
        DVec3::new(-0.2, 1.0, -0.7),
        DVec3::new(0.1, -0.4, -1.0),
    ] {
        let view = View::Orthographic { direction };
        let s = scene_order(&objects, &view).unwrap();
        assert_eq!(
            (s.groups, s.merged_groups, s.approximate_groups),
            (2, 1, 0),
            "{:?}",
            (s.groups, s.merged_groups, s.approximate_groups)
        );
        let order: Vec<u32> = s.order.iter().map(|&(o, tri)| o * t + tri).collect();
        let check = check_order(&positions, &triangles, &order, &view).unwrap();
        println!("{direction}: {check:?}");
        assert!(check.overlapping_pairs > 1000);
        assert_eq!(check.violations, 0, "{direction}: {check:?}");
        // Drawing each object whole, in the order of the groups, is not enough where the
        // buffers overlap.
        let mut first_seen = Vec::new();
        for &(o, _) in &s.order {
            if !first_seen.contains(&o) {
                first_seen.push(o);
            }
        }
        let whole: Vec<u32> = first_seen
            .iter()
            .flat_map(|&o| s.order.iter().filter(move |x| x.0 == o))
            .map(|&(o, tri)| o * t + tri)
            .collect();
        let naive = check_order(&positions, &triangles, &whole, &view).unwrap();
        println!("  objects drawn whole: {naive:?}");
        naive_violations += naive.violations;
    }
    assert!(
        naive_violations > 0,
        "the test scene does not need interleaving"
    );
}
