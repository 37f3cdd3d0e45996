//! The plate candidates (module `plate`): on the thin closed plate of the known misses, the
//! levels at the targets' budgets, with the border free and spaced, are closed, manifold,
//! outward, free of crossings and within 10 % of the budget, and the better of the two meets
//! the targets beside meshoptimizer's `simplify` and `simplifySloppy` (the independent measure
//! of `targets_common`) at three of the four budgets; every level the chain chooses meets them; a thin-walled tube (genus 1) is
//! a plate too; ordinary solids, open sheets, thin tubes and the corpus's cases are no plates.

mod targets_common;

use targets_common::{measured, target_budgets, verdict};
use voxlod_budget::plate::{Border, Plate};
use voxlod_budget::{levels, Method, PortfolioOptions};
use voxlod_core::{crossing_pairs, mesh_topology, TriangleMesh};
use voxlod_quadric::{simplify_sloppy, simplify_unchecked};
use voxlod_testkit::corpus::{sheet, thin_shell, thin_tubes};
use voxlod_testkit::shapes::{icosphere, torus};

fn within(count: usize, budget: usize) -> bool {
    (count as f64 - budget as f64).abs() <= 0.1 * budget as f64
}

/// `level` keeps every promise of a closed input's level at `budget`: closed, manifold,
/// oriented outwards, genus `genus`, no crossing pairs, within 10 % of the budget.
fn keeps_the_promises(level: &TriangleMesh, budget: usize, genus: i64) {
    let t = mesh_topology(level);
    assert!(
        t.is_closed_manifold() && t.is_consistently_oriented() && t.genus == Some(genus),
        "{budget}: {t:?}"
    );
    assert_eq!(
        t.degenerate_triangles + t.duplicate_triangles,
        0,
        "{budget}"
    );
    assert!(level.signed_volume() > 0.0, "{budget}: facing inwards");
    assert_eq!(crossing_pairs(level).len(), 0, "{budget}: crossing pairs");
    let count = level.triangle_count();
    assert!(within(count, budget), "{budget}: {count}");
}

/// The verdict of the targets on `level` of `input` at `budget` (module `targets_common`).
fn verdict_on(input: &TriangleMesh, level: &TriangleMesh, budget: usize) -> String {
    let simplify = simplify_unchecked(input, budget, false).unwrap().0;
    let sloppy = simplify_sloppy(input, budget).unwrap();
    let (s, sl) = (measured(input, &simplify), measured(input, &sloppy));
    let ours = measured(input, level).unwrap();
    let v = verdict(budget, &ours, s.as_ref(), sl.as_ref());
    let ratio = v.hausdorff_ratio.unwrap_or(f64::NAN);
    format!(
        "{} {ratio:.2} {v:?}, ours {ours:?}, simplify {s:?}",
        v.met()
    )
}

#[test]
fn the_thin_shell_is_a_plate_of_its_thickness_with_one_side_as_sheet() {
    let input = thin_shell();
    let plate = Plate::detect(&input).expect("a plate");
    // One side of the 40 × 20 grid, every vertex half the thickness (10⁻⁴, less the slope)
    // from the side it came from.
    assert_eq!(plate.sheet.triangle_count(), 1_600);
    assert_eq!(plate.sheet.positions.len(), 41 * 21);
    for &t in &plate.thickness {
        assert!(t > 0.6e-4 && t < 1.01e-4, "{t}");
    }
    let t = mesh_topology(&plate.sheet);
    assert!(t.is_manifold() && t.boundary_loops == 1, "{t:?}");
}

/// The Hausdorff ratio to the better eligible peer that each border's level of the thin shell
/// is held to at the targets' budgets (measured: free 1.63, 1.25, 0.44, 0.70; spaced 0.97,
/// 1.12, 0.32, 1.92), and whether the better of the two meets every target. The free border's
/// long edges cost it at 430 and 300, the spaced border's locks at 26. At 300 neither does
/// (the chain's level there, the 430 level collapsed further, does).
const HAUSDORFF_RATIO: [(usize, f64, f64, bool); 4] = [
    (430, 1.7, 1.1, true),
    (300, 1.35, 1.2, false),
    (107, 1.1, 1.1, true),
    (26, 1.1, 2.1, true),
];

#[test]
fn the_thin_shell_plate_levels_keep_every_promise_and_come_within_the_targets() {
    let input = thin_shell();
    let plate = Plate::detect(&input).expect("a plate");
    assert_eq!(target_budgets(input.triangle_count()), [430, 300, 107, 26]);
    for (b, free_most, spaced_most, meets) in HAUSDORFF_RATIO {
        let mut met = Vec::new();
        for (border, most) in [(Border::Free, free_most), (Border::Spaced, spaced_most)] {
            let level = plate.level(b, border).expect("a level");
            keeps_the_promises(&level, b, 0);
            let v = verdict_on(&input, &level, b);
            let ratio: f64 = v.split(' ').nth(1).unwrap().parse().unwrap();
            assert!(ratio <= most, "{b} {border:?}: {v}");
            met.push(v.starts_with("true"));
        }
        assert!(
            !meets || met.contains(&true),
            "{b}: neither border meets the targets"
        );
    }
}

#[test]
fn the_chain_gives_the_thin_shell_levels_that_meet_the_targets() {
    let input = thin_shell();
    let budgets = target_budgets(input.triangle_count());
    let run = levels(&input, &PortfolioOptions::for_triangles(&budgets)).unwrap();
    for (level, &b) in run.levels.iter().zip(&budgets) {
        let r = &level.report;
        assert!(level.topology.is_closed_manifold(), "{b}");
        assert_eq!(r.self_intersections, 0, "{b}");
        assert!(within(r.triangles, b), "{b}: {}", r.triangles);
        // The plate candidates at every budget, beside what was made from them (above).
        let plates = r.candidates.iter().filter(|c| c.candidate == "plate");
        assert_eq!(plates.count(), 2, "{b}");
        let v = verdict_on(&input, &level.mesh, b);
        assert!(v.starts_with("true"), "{b} {:?}: {v}", r.method);
    }
    assert_eq!(run.levels[0].report.method, Method::Plate);
}

#[test]
fn no_case_of_the_corpus_but_the_thin_shell_is_a_plate() {
    for (name, mesh) in voxlod_testkit::corpus::corpus() {
        let plate = Plate::detect(&mesh);
        assert_eq!(plate.is_some(), name == "thin-shell", "{name}");
    }
}

#[test]
fn ordinary_solids_open_sheets_and_thin_tubes_are_no_plates() {
    assert!(Plate::detect(&icosphere(4)).is_none());
    assert!(Plate::detect(&torus(64, 32, 1.0, 0.3)).is_none());
    assert!(Plate::detect(&sheet()).is_none());
    assert!(Plate::detect(&thin_tubes()).is_none());
}

/// A closed thin-walled tube: cylinders of radius 1 and 1 − `wall` around the z axis, height
/// 0.5, joined by flat rings at both ends; `n` quads around, `m` along. Genus 1.
fn thin_walled_tube(n: u32, m: u32, wall: f32) -> TriangleMesh {
    use voxlod_core::glam::Vec3;
    let index = |side: u32, i: u32, j: u32| side * n * (m + 1) + (i % n) * (m + 1) + j;
    let mut positions = Vec::new();
    for side in 0..2 {
        let r = 1.0 - side as f32 * wall;
        for i in 0..n {
            let a = std::f32::consts::TAU * i as f32 / n as f32;
            for j in 0..=m {
                positions.push(Vec3::new(
                    r * a.cos(),
                    r * a.sin(),
                    0.5 * j as f32 / m as f32,
                ));
            }
        }
    }
    let mut triangles = Vec::new();
    for i in 0..n {
        for j in 0..m {
            let q =
                |s| [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)].map(|(a, b)| index(s, a, b));
            // Outside faces away from the axis, inside towards it.
            let [a, b, c, d] = q(0);
            triangles.extend([[a, b, c], [a, c, d]]);
            let [a, b, c, d] = q(1);
            triangles.extend([[a, c, b], [a, d, c]]);
        }
        // The rings at both ends.
        let (o0, o1, i0, i1) = (
            index(0, i, 0),
            index(0, i + 1, 0),
            index(1, i, 0),
            index(1, i + 1, 0),
        );
        triangles.extend([[o0, i0, i1], [o0, i1, o1]]);
        let (o0, o1, i0, i1) = (
            index(0, i, m),
            index(0, i + 1, m),
            index(1, i, m),
            index(1, i + 1, m),
        );
        triangles.extend([[o0, o1, i1], [o0, i1, i0]]);
    }
    TriangleMesh::new(positions, triangles)
}

#[test]
fn a_thin_walled_tube_is_a_plate_whose_levels_keep_its_handle() {
    let input = thin_walled_tube(96, 12, 0.004);
    let t = mesh_topology(&input);
    assert!(t.is_closed_manifold() && t.genus == Some(1) && input.signed_volume() > 0.0);
    let plate = Plate::detect(&input).expect("a plate");
    assert_eq!(mesh_topology(&plate.sheet).boundary_loops, 2);
    for b in [1_000, 300] {
        for border in [Border::Free, Border::Spaced] {
            let level = plate.level(b, border).expect("a level");
            keeps_the_promises(&level, b, 1);
            let ours = measured(&input, &level).unwrap();
            assert!(ours.hausdorff < 0.01, "{b} {border:?}: {ours:?}");
        }
    }
}
