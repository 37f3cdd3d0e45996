//! Level selection from the object-space size of a pixel, and the JSON report.

use voxlod::clustering::{reports, rossignac_borrel, ClusterOptions};
use voxlod::select::{pixel_size, select, select_from_reports, SelectOptions, Selection};
use voxlod_testkit::shapes::torus;

#[test]
fn picks_the_coarsest_level_that_fits_a_pixel() {
    let sizes = [0.5, 1.0, 2.0, 4.0];
    let side = SelectOptions::side();
    let pick = |px: f64, o: &SelectOptions| select(&sizes, px, o).unwrap();
    assert_eq!(pick(0.3, &side), Selection::Original);
    assert_eq!(pick(0.5, &side), Selection::Level(0));
    assert_eq!(pick(0.99, &side), Selection::Level(0));
    assert_eq!(pick(1.5, &side), Selection::Level(1));
    assert_eq!(pick(2.0, &side), Selection::Level(2));
    assert_eq!(pick(100.0, &side), Selection::Level(3));
    // The cell's diagonal must fit: 1.5 / √3 ≈ 0.87.
    assert_eq!(pick(1.5, &SelectOptions::diagonal()), Selection::Level(0));
    assert_eq!(pick(0.8, &SelectOptions::diagonal()), Selection::Original);
    // Cells up to 2 pixels.
    assert_eq!(pick(1.5, &SelectOptions::pixels(2.0)), Selection::Level(2));
    // Order does not matter.
    assert_eq!(
        select(&[4.0, 0.5, 2.0, 1.0], 1.5, &side).unwrap(),
        Selection::Level(3)
    );
    assert_eq!(select(&[], 1.5, &side).unwrap(), Selection::Original);
}

#[test]
fn selects_among_a_real_series() {
    let mesh = torus(80, 24, 1.0, 0.3);
    let levels = rossignac_borrel(&mesh, &ClusterOptions::series(64, 4)).unwrap();
    let r = reports(&levels);
    let s = r[0].cell_size;
    assert!((s - 2.6 / 64.0).abs() < 1e-6, "{s}");
    let pick = |px: f64| select_from_reports(&r, px, &SelectOptions::default()).unwrap();
    assert_eq!(pick(0.5 * s), Selection::Original);
    assert_eq!(pick(3.0 * s), Selection::Level(1));
    assert_eq!(pick(100.0 * s), Selection::Level(3));

    // 1000 pixels high, 60° field of view: a pixel at distance 10 covers 2·10·tan 30° / 1000.
    let px = pixel_size(10.0, 60f64.to_radians(), 1000).unwrap();
    assert!((px - 0.011_547_005).abs() < 1e-8, "{px}");
    // From 10 units a pixel is 0.0115, finer than every level (0.041 and up): the original.
    // From 100 units it is 0.115: level 1 (0.081) fits, level 2 (0.16) does not.
    assert_eq!(pick(px), Selection::Original);
    assert_eq!(
        pick(pixel_size(100.0, 60f64.to_radians(), 1000).unwrap()),
        Selection::Level(1)
    );
}

#[test]
fn bad_selection_input_is_refused() {
    let o = SelectOptions::default();
    for px in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let e = select(&[1.0], px, &o).unwrap_err().to_string();
        assert!(
            e.starts_with("the pixel size must be positive and finite"),
            "{e}"
        );
    }
    assert!(select(&[1.0, 0.0], 1.0, &o).is_err());
    assert!(select(&[1.0], 1.0, &SelectOptions::pixels(0.0)).is_err());
    assert!(pixel_size(10.0, 4.0, 1000).is_err());
    assert!(pixel_size(10.0, 1.0, 0).is_err());
    assert!(pixel_size(-1.0, 1.0, 10).is_err());
}

#[test]
fn reports_serialise_with_the_issue_s_field_names() {
    let mesh = torus(40, 12, 1.0, 0.3);
    let levels = rossignac_borrel(&mesh, &ClusterOptions::series(16, 2)).unwrap();
    let json = serde_json::to_value(reports(&levels)).unwrap();
    let first = &json[0];
    for key in [
        "triangles",
        "dangling_edges",
        "isolated_points",
        "cluster_seconds",
        "cell_size",
        "cells",
        "level",
    ] {
        assert!(first.get(key).is_some(), "{key} missing from {first}");
    }
    assert_eq!(first["method"], "rossignac-borrel");
    assert_eq!(json[1]["level"], 1);
    assert_eq!(first["triangles"], levels[0].mesh.mesh.triangles.len());
}
