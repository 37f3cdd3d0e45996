//! `voxlod_budget::levels` on generated inputs: the promises hold on every level, budgets are
//! met, the chain's genus never rises, bad requests are refused, and where a promise rules out
//! a closer candidate the report says so.

use voxlod_budget::{levels, BudgetError, Method, PortfolioOptions, Promise};
use voxlod_core::glam::Vec3;
use voxlod_core::{mesh_topology, TriangleMesh};
use voxlod_testkit::corpus;

fn within(triangles: usize, budget: usize) -> bool {
    (triangles as f64 - budget as f64).abs() <= (0.1 * budget as f64).max(1.0)
}

/// Every level of `mesh` at `budgets`: within its budget, an oriented manifold, closed when
/// `closed`, no more handles than the level above (the input's genus first, when it has one).
fn check_chain(mesh: &TriangleMesh, budgets: &[usize], closed: bool) -> voxlod_budget::Budgeted {
    let run = levels(mesh, &PortfolioOptions::for_triangles(budgets)).unwrap();
    let mut cap = run.input.genus;
    for (level, &b) in run.levels.iter().zip(budgets) {
        let r = &level.report;
        assert_eq!(r.budget, b);
        assert!(
            within(level.mesh.triangle_count(), b),
            "{b}: {}",
            level.mesh.triangle_count()
        );
        let t = mesh_topology(&level.mesh);
        assert!(
            t.is_manifold() && t.is_consistently_oriented(),
            "{b}: {t:?}"
        );
        assert_eq!(t.degenerate_triangles + t.duplicate_triangles, 0, "{b}");
        if closed {
            assert!(t.is_closed_manifold(), "{b}: {t:?}");
        }
        if let (Some(cap), Some(g)) = (cap, t.genus) {
            assert!(g <= cap, "{b}: genus {g} above {cap}");
        }
        assert_eq!((r.genus, r.boundary_loops), (t.genus, t.boundary_loops));
        cap = t.genus.or(cap);
    }
    run
}

#[test]
fn an_open_sheet_gets_every_level_and_keeps_its_border() {
    let sheet = corpus::sheet();
    let run = check_chain(&sheet, &[2500, 600, 150, 40], false);
    for level in &run.levels {
        assert!(
            level.report.hausdorff_fraction < 0.02,
            "{:?}",
            level.report.hausdorff_fraction
        );
        assert_eq!(level.report.boundary_loops, 1);
    }
}

#[test]
fn a_closed_part_with_handles_keeps_closed_levels_whose_genus_never_rises() {
    let run = check_chain(&corpus::cad_handles(), &[1000, 300, 100, 30], true);
    assert_eq!(run.input.genus, Some(4));
    // The budget affords the handles at 1000: the input's own collapse (or its chain) keeps
    // all four.
    assert_eq!(run.levels[0].report.genus, Some(4));
}

#[test]
fn a_surface_with_hundreds_of_handles_gets_closed_levels_at_small_budgets() {
    let run = check_chain(&corpus::genus_rich(), &[1000, 300], true);
    assert!(run.input.genus.unwrap() >= 100);
    for level in &run.levels {
        assert!(level.report.handles_removed.unwrap() > 0);
    }
}

#[test]
fn no_level_is_farther_than_the_level_below_it() {
    // The lattice's voxel levels at its larger budgets lose more of it than the smallest
    // one's: those levels come from the level below, refined and fitted.
    let budgets = [2478, 1000, 619, 300, 154];
    let run = check_chain(&corpus::genus_rich(), &budgets, true);
    assert!(run.levels.iter().any(|l| l.report.method == Method::Below));
    for pair in run.levels.windows(2) {
        let (larger, smaller) = (&pair[0].report, &pair[1].report);
        assert!(
            larger.hausdorff <= 1.05 * smaller.hausdorff,
            "{}: {} against {} at {}",
            larger.budget,
            larger.hausdorff,
            smaller.hausdorff,
            smaller.budget
        );
    }
    // A level refined from below is listed among its candidates.
    for level in run
        .levels
        .iter()
        .filter(|l| l.report.method == Method::Below)
    {
        assert!(level
            .report
            .candidates
            .iter()
            .any(|c| c.candidate.starts_with("below")));
    }
}

#[test]
fn a_level_below_refined_and_fitted_can_beat_the_input_s_collapse() {
    // A fine sphere at 1 000 triangles: the level at 640, its edges split to 1 000 and fitted,
    // comes out far closer than every collapse of the input, although the level it replaces
    // was not farther than the level below it.
    let run = check_chain(&corpus::sphere_fine(), &[1000, 640], true);
    let level = &run.levels[0].report;
    assert_eq!(level.method, Method::Below, "{:?}", level.candidates);
    let others = (level.candidates.iter())
        .filter(|c| !c.candidate.starts_with("below") && c.broken.is_empty())
        .filter_map(|c| c.careful_hausdorff);
    let closest = others.fold(f64::INFINITY, f64::min);
    assert!(
        level.hausdorff < 0.8 * closest,
        "{} against {closest}",
        level.hausdorff
    );
}

#[test]
fn an_inside_out_shell_gives_outward_levels_and_says_so() {
    let run = check_chain(&corpus::inside_out(), &[1500, 200], true);
    assert!(run.input.preparation.turned_right_side_out);
    assert!(run.warnings.iter().any(|w| w.contains("inside out")));
    for level in &run.levels {
        assert!(level.mesh.signed_volume() > 0.0);
    }
}

/// A budget above the input's triangles is answered by the input itself (its own triangles,
/// none farther than it), with a warning, not by a remeshed level with more triangles.
#[test]
fn a_budget_above_the_input_gets_the_input() {
    let bracket = corpus::cad_bracket();
    let n = bracket.triangle_count();
    let run = levels(&bracket, &PortfolioOptions::for_triangles(&[4 * n, n / 4])).unwrap();
    let top = &run.levels[0];
    assert_eq!(top.report.budget, 4 * n);
    assert_eq!(top.mesh.triangle_count(), n);
    assert!(
        top.report.hausdorff_fraction < 1e-9,
        "{}",
        top.report.hausdorff_fraction
    );
    let warning = format!("{} triangles: the input has only {n}", 4 * n);
    assert!(
        run.warnings.iter().any(|w| w.starts_with(&warning)),
        "{:?}",
        run.warnings
    );
    assert!(within(run.levels[1].mesh.triangle_count(), n / 4));
}

/// A closed mesh with a zero-area sliver (an edge split at its midpoint on one side only, the
/// sliver closing the crack, as a printed part's STL may have) stays closed: the sliver is
/// mended, not dropped, and a budget above the input gets a closed level.
#[test]
fn a_closed_mesh_with_a_zero_area_sliver_keeps_closed_levels() {
    // A cube (corners at 0 and 1: the midpoint is exact, the sliver exactly flat), its faces
    // split finely enough for budgets.
    let cube = voxlod_testkit::shapes::unit_cube();
    let mut mesh = voxlod_testkit::shapes::subdivided(
        cube.positions.iter().map(|p| p.as_dvec3()).collect(),
        cube.triangles,
        3,
        |p| p,
    );
    let [a, c, x] = mesh.triangles[0];
    let mid = (mesh.positions[a as usize] + mesh.positions[c as usize]) * 0.5;
    mesh.positions.push(mid);
    let b = mesh.positions.len() as u32 - 1;
    mesh.triangles[0] = [a, b, x];
    mesh.triangles.push([b, c, x]);
    mesh.triangles.push([a, c, b]);
    assert!(mesh_topology(&mesh).is_closed_manifold());
    let n = mesh.triangle_count();
    let run = levels(&mesh, &PortfolioOptions::for_triangles(&[2 * n, n / 4])).unwrap();
    assert_eq!(run.input.preparation.degenerate_triangles, 1);
    assert!(run.input.closed);
    for level in &run.levels {
        let t = mesh_topology(&level.mesh);
        assert!(
            t.is_closed_manifold() && t.degenerate_triangles == 0,
            "{t:?}"
        );
    }
    assert!(run.levels[0].mesh.triangle_count() >= n - 2);
    assert!(within(run.levels[1].mesh.triangle_count(), n / 4));
}

#[test]
fn a_triangle_soup_gets_manifold_oriented_levels() {
    let soup = corpus::soup();
    let mut welded = soup.clone();
    voxlod_core::weld::weld_vertices(&mut welded);
    assert!(mesh_topology(&welded).non_manifold_edges > 0);
    check_chain(&soup, &[400, 100, 25], false);
}

#[test]
fn asked_for_closed_levels_of_a_sheet_the_report_says_what_closedness_cost() {
    let options = PortfolioOptions {
        closed: true,
        ..PortfolioOptions::for_triangles(&[600])
    };
    let run = levels(&corpus::sheet(), &options).unwrap();
    let level = &run.levels[0];
    assert!(mesh_topology(&level.mesh).is_closed_manifold());
    assert_ne!(level.report.method, Method::Collapse);
    // The sheet's own collapse is far closer, and open: ruled out by closedness, at a cost.
    let collapse = level
        .report
        .ruled_out
        .iter()
        .find(|r| r.candidate == "collapse")
        .expect("the collapse is reported as ruled out");
    assert!(collapse.broken.contains(&Promise::Closed));
    assert!(collapse.cost > 1.0, "{}", collapse.cost);
}

#[test]
fn the_level_of_each_budget_is_the_closest_candidate_that_keeps_the_promises() {
    let run = levels(
        &corpus::two_spheres(),
        &PortfolioOptions::for_triangles(&[800, 120]),
    )
    .unwrap();
    for level in &run.levels {
        let r = &level.report;
        let kept: Vec<f64> = (r.candidates.iter())
            .filter(|c| c.broken.is_empty())
            .filter_map(|c| c.careful_hausdorff)
            .collect();
        assert!(!kept.is_empty());
        let best = kept.iter().cloned().fold(f64::INFINITY, f64::min);
        assert!(
            r.hausdorff <= best * 1.01 + 1e-12,
            "{} > {best}",
            r.hausdorff
        );
    }
}

#[test]
fn bad_requests_are_refused_with_what_is_wrong() {
    let cube = voxlod_testkit::shapes::unit_cube();
    for budgets in [vec![], vec![100, 3]] {
        let e = levels(&cube, &PortfolioOptions::for_triangles(&budgets)).unwrap_err();
        assert!(matches!(e, BudgetError::InvalidBudgets(_)), "{e}");
    }
    let flat = TriangleMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::X * 2.0], vec![[0, 1, 2]]);
    let e = levels(&flat, &PortfolioOptions::for_triangles(&[10])).unwrap_err();
    assert!(matches!(e, BudgetError::EmptyMesh { triangles: 1 }), "{e}");
    let nan = TriangleMesh::new(vec![Vec3::NAN, Vec3::X, Vec3::Y], vec![[0, 1, 2]]);
    assert!(levels(&nan, &PortfolioOptions::for_triangles(&[10])).is_err());
}

#[test]
fn stopping_from_the_progress_callback_ends_the_run() {
    let stop = |done: usize, _: usize| done == 0;
    let e = voxlod_budget::levels_with(
        &corpus::sphere_fine(),
        &PortfolioOptions::for_triangles(&[1000]),
        &stop,
    )
    .unwrap_err();
    assert!(matches!(e, BudgetError::Cancelled));
}

#[test]
fn remesh_levels_are_new_closed_surfaces_that_merge_interpenetrating_parts() {
    // Three spheres that pass through each other, and a fourth apart: seven or more triangles
    // per input part at every budget would keep four components; the remeshed levels are the
    // union's surface, one component for the three, the fourth apart.
    let mut mesh = voxlod_testkit::shapes::icosphere_at(4, 1.0, Vec3::ZERO);
    for centre in [Vec3::new(1.2, 0.0, 0.0), Vec3::new(0.6, 1.0, 0.0)] {
        let part = voxlod_testkit::shapes::icosphere_at(4, 1.0, centre);
        voxlod_testkit::shapes::append(&mut mesh, &part);
    }
    let apart = voxlod_testkit::shapes::icosphere_at(3, 0.6, Vec3::new(5.0, 0.0, 0.0));
    voxlod_testkit::shapes::append(&mut mesh, &apart);
    assert_eq!(mesh_topology(&mesh).components, 4);
    let budgets = [2000, 500, 120];
    let run = levels(&mesh, &PortfolioOptions::remesh(&budgets)).unwrap();
    for (level, &b) in run.levels.iter().zip(&budgets) {
        let r = &level.report;
        assert!(
            matches!(r.method, Method::Voxel | Method::Shell | Method::Above),
            "{b}: {:?}",
            r.method
        );
        let t = mesh_topology(&level.mesh);
        assert!(
            t.is_closed_manifold() && t.is_consistently_oriented(),
            "{b}: {t:?}"
        );
        assert_eq!(t.components, 2, "{b}: {t:?} {r:?}");
        assert!(within(level.mesh.triangle_count(), b), "{b}: {t:?}");
    }
    // The same budgets without `remesh` answer the largest with the input's own collapse,
    // which keeps the four parts apart.
    let plain = levels(&mesh, &PortfolioOptions::for_triangles(&budgets[..1])).unwrap();
    assert_eq!(mesh_topology(&plain.levels[0].mesh).components, 4);
}

/// Two unit cubes side by side along x with a gap of `gap` between them.
fn two_cubes(gap: f32) -> TriangleMesh {
    let mut mesh = voxlod_testkit::shapes::unit_cube();
    let mut other = voxlod_testkit::shapes::unit_cube();
    other.positions.iter_mut().for_each(|p| p.x += 1.0 + gap);
    voxlod_testkit::shapes::append(&mut mesh, &other);
    mesh
}

#[test]
fn close_gaps_joins_parts_closer_than_the_distance_and_only_those() {
    // At 2 000 triangles the grid is fine enough to keep a 0.3 gap open (about 60 samples
    // across the 2.3 long side: the gap is 8 samples wide).
    let mesh = two_cubes(0.3);
    let components = |close_gaps: Option<f64>| {
        let options = PortfolioOptions {
            close_gaps,
            ..PortfolioOptions::remesh(&[2000])
        };
        let run = levels(&mesh, &options).unwrap();
        let t = mesh_topology(&run.levels[0].mesh);
        assert!(
            t.is_closed_manifold() && t.is_consistently_oriented(),
            "{t:?}"
        );
        t.components
    };
    assert_eq!(components(None), 2);
    assert_eq!(components(Some(0.2)), 2);
    assert_eq!(components(Some(0.5)), 1);
    let bad = PortfolioOptions {
        close_gaps: Some(f64::NAN),
        ..PortfolioOptions::remesh(&[2000])
    };
    assert!(matches!(
        levels(&mesh, &bad),
        Err(BudgetError::InvalidOption {
            name: "close_gaps",
            ..
        })
    ));
}

#[test]
fn open_cards_beside_a_closed_part_survive_as_shells() {
    // A closed cube and, one unit above it, forty open cards (two triangles each, no
    // thickness): sampled as one solid the cards bound nothing and vanish; as shells they stay.
    let mut mesh = voxlod_testkit::shapes::unit_cube();
    for i in 0..40 {
        let mut card = voxlod_testkit::shapes::unit_cube();
        card.positions.truncate(4);
        card.triangles = vec![[0, 1, 3], [0, 3, 2]];
        let (x, y) = ((i % 8) as f32 * 0.25, (i / 8) as f32 * 0.25);
        for p in card.positions.iter_mut() {
            *p = Vec3::new(x + 0.2 * p.x, y + 0.2 * p.y, 2.0 + 0.1 * p.x);
        }
        voxlod_testkit::shapes::append(&mut mesh, &card);
    }
    let run = levels(&mesh, &PortfolioOptions::remesh(&[1500])).unwrap();
    let level = &run.levels[0];
    assert_eq!(
        level.report.fill,
        voxlod_budget::Fill::OpenShells,
        "{:?}",
        level.report
    );
    let t = mesh_topology(&level.mesh);
    assert!(t.is_closed_manifold(), "{t:?}");
    // The level reaches up to the cards (z about 2.1) and down to the cube (z = 0).
    let b = level.mesh.bounds();
    assert!(b.max[2] > 2.05 && b.min[2] < 0.05, "{b:?}");
}

/// The unit cube scaled by `size` and moved to `at`, facing outwards or, `inverted`, inwards.
fn cube_at(at: f32, size: f32, inverted: bool) -> TriangleMesh {
    let mut cube = voxlod_testkit::shapes::unit_cube();
    cube.positions
        .iter_mut()
        .for_each(|p| *p = *p * size + Vec3::splat(at));
    if inverted {
        cube.flip_orientation();
    }
    cube
}

#[test]
fn hidden_parts_are_dropped_and_left_out_of_measuring() {
    // A closed room: walls 0.5 thick around a hollow (an inward-facing inner box), and a
    // crate in the hollow. From outside only the outer box shows: the hollow's walls and the
    // crate are dropped, and the level is the outer box, measured against it alone.
    let mut mesh = cube_at(0.0, 3.0, false);
    voxlod_testkit::shapes::append(&mut mesh, &cube_at(0.5, 2.0, true));
    voxlod_testkit::shapes::append(&mut mesh, &cube_at(1.2, 0.6, false));
    let run = levels(&mesh, &PortfolioOptions::remesh(&[600])).unwrap();
    assert_eq!(run.input.hidden_parts, 2, "{:?}", run.input);
    assert_eq!(run.input.triangles, 12);
    assert!(run
        .warnings
        .iter()
        .any(|w| w.contains("2 parts seen from none")));
    let level = &run.levels[0];
    let t = mesh_topology(&level.mesh);
    assert!(t.is_closed_manifold() && t.components == 1, "{t:?}");
    let volume = level.mesh.signed_volume();
    assert!((volume / 27.0 - 1.0).abs() < 0.1, "{volume}");
    // Kept, the hidden parts leave the hollow in the solid sampled.
    let kept = PortfolioOptions {
        drop_hidden: false,
        ..PortfolioOptions::remesh(&[600])
    };
    let run = levels(&mesh, &kept).unwrap();
    assert_eq!(run.input.hidden_parts, 0);
    assert_eq!(run.input.triangles, 36);
}

/// The box from `min` to `max`, facing outwards.
fn box_between(min: Vec3, max: Vec3) -> TriangleMesh {
    let mut cube = voxlod_testkit::shapes::unit_cube();
    cube.positions
        .iter_mut()
        .for_each(|p| *p = min + *p * (max - min));
    cube
}

#[test]
fn a_face_buried_but_for_a_sliver_is_measured_only_where_it_shows() {
    // A CAD assembly's two blocks stacked: the lower one's top face (two large triangles)
    // shows only along a strip 0.1 wide beside the upper block, so both its triangles count
    // as seen. Measured whole, their buried middle lies a unit inside the union, about a fifth
    // of the diagonal from any candidate; measured where they show, the proxy is the union's
    // box, within a few per cent.
    let mut mesh = box_between(Vec3::ZERO, Vec3::new(4.0, 2.0, 1.0));
    let upper = box_between(Vec3::new(0.0, 0.0, 1.0), Vec3::new(3.9, 2.0, 2.0));
    voxlod_testkit::shapes::append(&mut mesh, &upper);
    let run = levels(&mesh, &PortfolioOptions::remesh(&[500])).unwrap();
    let r = &run.levels[0].report;
    assert!(r.hausdorff_fraction < 0.03, "{r:?}");
    let t = mesh_topology(&run.levels[0].mesh);
    assert!(t.is_closed_manifold() && t.components == 1, "{t:?}");
}

#[test]
fn a_small_level_of_a_cad_part_keeps_its_sharp_edges() {
    // At 30 triangles the plates with handles are a voxel level, fitted: the filter rounded
    // their edges and corners, and the vertices beside them go back onto them
    // (`voxlod_fit::snap_to_features`): a mean distance of 0.51 % of the diagonal, where the
    // level left rounded measured 1.47 %.
    let part = corpus::cad_handles();
    let run = check_chain(&part, &[488, 300, 122, 30], true);
    let small = &run.levels[3].report;
    let diagonal = part.bounds().diagonal();
    let mean = small.mean_distance / diagonal;
    assert!(
        small.method == Method::Voxel && small.fitted_to_input,
        "{small:?}"
    );
    assert!(mean < 0.009, "{mean}");
}

#[test]
fn a_proxy_of_boxes_keeps_their_corners() {
    // Two boxes apart at 400 triangles: the filter rounds their edges over a voxel, and a
    // proxy's levels get them back before the collapse (`voxel::sharpened`), so every corner
    // of both boxes has a vertex of the level on it.
    let mesh = two_cubes(1.0);
    let run = levels(&mesh, &PortfolioOptions::remesh(&[400])).unwrap();
    let level = &run.levels[0].mesh;
    let t = mesh_topology(level);
    assert!(t.is_closed_manifold() && t.components == 2, "{t:?}");
    let nearest =
        |c: Vec3| (level.positions.iter().map(|p| p.distance(c))).fold(f32::MAX, f32::min);
    let worst = (mesh.positions.iter().map(|&c| nearest(c))).fold(0.0, f32::max);
    assert!(worst < 0.01, "a corner {worst} from the level");
}

#[test]
fn a_budget_next_to_a_larger_one_shares_its_voxel_search() {
    // 300 is within 5 % of 310: only 310 samples voxels; 300 gets 310's level collapsed
    // further (and the input's collapses). Both are closed levels of the handle-rich surface.
    let run = check_chain(&corpus::genus_rich(), &[310, 300], true);
    let voxels = |k: usize| {
        let candidates = &run.levels[k].report.candidates;
        candidates
            .iter()
            .filter(|c| c.candidate.starts_with("voxel"))
            .count()
    };
    assert!(voxels(0) > 0);
    assert_eq!(voxels(1), 0, "{:#?}", run.levels[1].report.candidates);
    assert!(run.levels[1]
        .report
        .candidates
        .iter()
        .any(|c| c.candidate.starts_with("above")));
}

#[test]
fn an_input_far_from_the_origin_for_its_size_is_warned_of() {
    let run = check_chain(&corpus::far_away(), &[300], true);
    assert!(
        run.warnings.iter().any(|w| w.contains("rounded away")),
        "{:?}",
        run.warnings
    );
    let near = check_chain(&corpus::genus_rich(), &[300], true);
    assert!(near.warnings.iter().all(|w| !w.contains("rounded away")));
}

#[test]
fn a_remeshed_level_that_crosses_itself_says_so() {
    // The room's furniture passes through itself; the scene's crossings license none of a
    // new surface's. Each level's report counts its own crossing pairs exactly, and a warning
    // names every level that has any (the room's level at 5 % does, from its collapse).
    let room = voxlod_testkit::scenes::room().mesh.geometry();
    let budget = room.triangles.len() / 20;
    let run = levels(&room, &PortfolioOptions::remesh(&[budget])).unwrap();
    let level = &run.levels[0];
    let pairs = voxlod_core::crossing_pairs(&level.mesh).len();
    assert_eq!(level.report.self_intersections, pairs);
    let said = format!("{budget} triangles: the level crosses itself in {pairs} triangle pairs");
    assert_eq!(
        run.warnings.contains(&said),
        pairs > 0,
        "{:?}",
        run.warnings
    );
    assert!(
        pairs > 0,
        "the room's level no longer crosses itself: pick a case that does"
    );
}

#[test]
fn a_collapse_that_only_crossed_close_by_is_fixed_without_a_voxel_search() {
    // The scan with holes at an eighth of its triangles: its plain collapse crosses itself
    // but measures within half a voxel of the input, and its checked collapse keeps every
    // promise, so no voxel level is made for it (`chain::add_all_voxels`).
    let scan = corpus::scan_holes();
    let budget = scan.triangle_count() / 8;
    let run = levels(&scan, &PortfolioOptions::for_triangles(&[budget])).unwrap();
    let report = &run.levels[0].report;
    let named = |name: &str| report.candidates.iter().find(|c| c.candidate == name);
    let plain = named("collapse").expect("the plain collapse");
    assert_eq!(plain.broken, [Promise::NoCrossings], "{plain:?}");
    let kept = named("collapse-kept").expect("the checked collapse");
    assert!(kept.broken.is_empty(), "{kept:?}");
    let voxel = |c: &&voxlod_budget::CandidateReport| c.candidate.starts_with("voxel");
    assert!(
        !report.candidates.iter().any(|c| voxel(&c)),
        "{:?}",
        report.candidates
    );
}

#[test]
fn collapse_levels_are_fitted_to_the_input_where_that_measures_closer() {
    // Interpenetrating parts: their levels at 1 000 and 300 are collapses of the input.
    let part = corpus::interpenetrating();
    let budgets = [1000, 300];
    let fitted = levels(&part, &PortfolioOptions::for_triangles(&budgets)).unwrap();
    let plain_options = PortfolioOptions {
        fit_collapses: false,
        ..PortfolioOptions::for_triangles(&budgets)
    };
    let plain = levels(&part, &plain_options).unwrap();
    let mut any = false;
    for (f, p) in fitted.levels.iter().zip(&plain.levels) {
        let (f, p) = (&f.report, &p.report);
        if p.resolution.is_none() && !p.fitted_to_input {
            // The same level, fitted where that measured no farther.
            assert_eq!((f.method, f.triangles), (p.method, p.triangles));
            assert!(f.hausdorff <= p.hausdorff && f.mean_distance <= p.mean_distance);
            any |= f.fitted_to_input && f.mean_distance < p.mean_distance;
        }
    }
    assert!(any, "no collapse level was fitted");
    // A level with more than a tenth of the input's triangles is left as collapsed.
    let eighth = [part.triangle_count() / 8];
    let large = levels(&part, &PortfolioOptions::for_triangles(&eighth)).unwrap();
    let r = &large.levels[0].report;
    assert_eq!((r.method, r.fitted_to_input), (Method::Collapse, false));
}

#[test]
fn a_small_budget_collapses_its_far_grid_in_two_stages() {
    // The inside-out shell at 300 triangles alone: the far finer grid's levels compete
    // collapsed straight to the budget and collapsed to 750 triangles, fitted, then on to the
    // budget (`voxel::staged`); the staged ones measure closer (quick shape distance 0.055
    // against 0.062), and one of them is the level.
    let run = check_chain(&corpus::inside_out(), &[300], true);
    let r = &run.levels[0].report;
    assert!(r.staged && r.method == Method::Voxel, "{r:?}");
    let grid = format!("voxel {}@", r.resolution.unwrap());
    // The closest quick shape distance of the grid's levels collapsed straight and staged.
    let closest = |staged: bool| {
        (r.candidates.iter())
            .filter(|c| c.candidate.starts_with(&grid) && !c.candidate.contains("fitted"))
            .filter(|c| c.candidate.ends_with(" staged") == staged)
            .filter_map(|c| c.shape)
            .fold(f64::INFINITY, f64::min)
    };
    let (straight, staged) = (closest(false), closest(true));
    assert!(
        staged < 0.95 * straight,
        "straight {straight}, staged {staged}"
    );
}

#[test]
fn a_refined_voxel_search_gets_no_far_grid() {
    // The linked rings at 300 triangles: the input's own solid has too few triangles for the
    // budget at its first grid (15) and is refined to 34, whose levels already have about 24
    // times the budget's triangles; it gets the neighbours 48 and 23 but not the far grid 68
    // (60–120 times the budget).
    // The solid with its hollows filled is not refined: grid 15, its finer neighbour 21 (the
    // coarser one's levels out of reach), and its far grid 30, staged too.
    let run = levels(&corpus::rings(), &PortfolioOptions::for_triangles(&[300])).unwrap();
    let labels: Vec<&str> = (run.levels[0].report.candidates.iter())
        .map(|c| c.candidate.as_str())
        .filter(|l| l.starts_with("voxel "))
        .collect();
    let grid = |label: &str| -> usize { label[6..].split('@').next().unwrap().parse().unwrap() };
    let mut given: Vec<usize> = (labels.iter())
        .filter(|l| !l.contains("hollows"))
        .map(|l| grid(l))
        .collect();
    given.sort();
    given.dedup();
    assert_eq!(given, [23, 34, 48], "{labels:?}");
    let far = |l: &&str| l.starts_with("voxel 30@") && l.contains("hollows filled staged");
    assert!(labels.iter().any(far), "{labels:?}");
}

#[test]
fn an_input_only_turned_right_side_out_is_collapsed_once() {
    // The inside-out shell is turned right side out and nothing else: its collapse as given
    // would be the same collapse turned, and is not made. Given as a soup (every triangle its
    // own three vertices, which preparing it welds), it is made.
    let shell = corpus::inside_out();
    let as_given = |mesh: &TriangleMesh| {
        let run = levels(mesh, &PortfolioOptions::for_triangles(&[300])).unwrap();
        assert!(run.input.preparation.turned_right_side_out);
        (run.levels[0].report.candidates.iter()).any(|c| c.candidate == "collapse-as-given")
    };
    assert!(!as_given(&shell));
    let mut soup = TriangleMesh::default();
    for t in &shell.triangles {
        let base = soup.positions.len() as u32;
        soup.positions
            .extend(t.map(|v| shell.positions[v as usize]));
        soup.triangles.push([base, base + 1, base + 2]);
    }
    assert!(as_given(&soup));
}
