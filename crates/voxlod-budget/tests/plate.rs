//! The plate candidate (module `plate`): on the thin closed plate of the known misses, its
//! levels at the targets' budgets are closed, manifold, outward, free of crossings, within
//! 10 % of the budget, within the targets beside meshoptimizer's `simplify` and
//! `simplifySloppy` (the independent measure of `targets_common`) at 107 and 26 triangles and
//! within the stated gap at 430 and 300; ordinary solids, open sheets, thin tubes and the
//! corpus's cases are no plates.

mod targets_common;

use targets_common::{measured, target_budgets, verdict};
use voxlod_budget::plate::Plate;
use voxlod_budget::{levels, Method, PortfolioOptions};
use voxlod_core::{crossing_pairs, mesh_topology};
use voxlod_quadric::{simplify_sloppy, simplify_unchecked};
use voxlod_testkit::corpus::{sheet, thin_shell, thin_tubes};
use voxlod_testkit::shapes::{icosphere, torus};

fn within(count: usize, budget: usize) -> bool {
    (count as f64 - budget as f64).abs() <= 0.1 * budget as f64
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

/// The Hausdorff ratio to the better eligible peer each of the targets' budgets of the thin
/// shell is held to: the targets' 1.1 at 107 and 26; at 430 and 300 the remaining gap
/// (measured 1.63 and 1.35). There `simplify`'s level crosses itself: its two sides are two
/// different collapses of the plate, 10⁻⁴ apart, and a point of the input is as near as the
/// nearer of them; a level without crossings has one surface's worth of vertices.
const HAUSDORFF_RATIO: [(usize, f64); 4] = [(430, 1.7), (300, 1.4), (107, 1.1), (26, 1.1)];

#[test]
fn the_thin_shell_plate_levels_keep_every_promise_and_come_near_the_targets() {
    let input = thin_shell();
    let plate = Plate::detect(&input).expect("a plate");
    assert_eq!(target_budgets(input.triangle_count()), [430, 300, 107, 26]);
    for (b, most) in HAUSDORFF_RATIO {
        let level = plate.level(b).expect("a level");
        let t = mesh_topology(&level);
        assert!(
            t.is_closed_manifold() && t.is_consistently_oriented() && t.genus == Some(0),
            "{b}: {t:?}"
        );
        assert_eq!(t.degenerate_triangles + t.duplicate_triangles, 0, "{b}");
        assert!(level.signed_volume() > 0.0, "{b}: facing inwards");
        assert_eq!(crossing_pairs(&level).len(), 0, "{b}: crossing pairs");
        assert!(
            within(level.triangle_count(), b),
            "{b}: {}",
            level.triangle_count()
        );
        let ours = measured(&input, &level).unwrap();
        let simplify = simplify_unchecked(&input, b, false).unwrap().0;
        let sloppy = simplify_sloppy(&input, b).unwrap();
        let (s, sl) = (measured(&input, &simplify), measured(&input, &sloppy));
        let v = verdict(b, &ours, s.as_ref(), sl.as_ref());
        let report = format!("{b}: {v:?}, ours {ours:?}, simplify {s:?}, sloppy {sl:?}");
        assert!(v.hausdorff_ratio.is_some_and(|r| r <= most), "{report}");
        assert!(v.mean_ratio.is_some_and(|r| r <= 1.25), "{report}");
        if most <= 1.1 {
            assert!(v.met(), "{report}");
        }
    }
}

#[test]
fn the_chain_gives_the_thin_shell_plate_levels() {
    let input = thin_shell();
    let budgets = target_budgets(input.triangle_count());
    let run = levels(&input, &PortfolioOptions::for_triangles(&budgets)).unwrap();
    for (level, &b) in run.levels.iter().zip(&budgets) {
        let r = &level.report;
        assert!(level.topology.is_closed_manifold(), "{b}");
        assert_eq!(r.self_intersections, 0, "{b}");
        assert!(within(r.triangles, b), "{b}: {}", r.triangles);
        // The plate, or a level made from it (above, below), at every budget.
        let plate = r.candidates.iter().find(|c| c.candidate == "plate");
        assert!(plate.is_some(), "{b}: no plate candidate");
        assert!(
            r.hausdorff_fraction < 0.03,
            "{b}: {:?} {}",
            r.method,
            r.hausdorff_fraction
        );
    }
    assert_eq!(run.levels[0].report.method, Method::Plate);
}

#[test]
fn no_case_of_the_corpus_is_a_plate() {
    for (name, mesh) in voxlod_testkit::corpus::corpus() {
        assert!(Plate::detect(&mesh).is_none(), "{name}");
    }
}

#[test]
fn ordinary_solids_open_sheets_and_thin_tubes_are_no_plates() {
    assert!(Plate::detect(&icosphere(4)).is_none());
    assert!(Plate::detect(&torus(64, 32, 1.0, 0.3)).is_none());
    assert!(Plate::detect(&sheet()).is_none());
    assert!(Plate::detect(&thin_tubes()).is_none());
}
