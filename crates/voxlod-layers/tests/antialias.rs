//! The paper's claim, measured: near silhouettes, the layered shells at one sample per pixel are
//! closer to the 16×16-supersampled single surface than the single surface at one sample per
//! pixel is — for the bolt-like CSG part and for the bunny.

mod common;

use voxlod_layers::compare::{bolt, compare_antialiasing, CompareOptions};
use voxlod_sampling::{CsgSolid, Solid};

fn check(solid: &dyn Solid, name: &str) {
    let c = compare_antialiasing(solid, &CompareOptions::default()).unwrap();
    let r = &c.report;
    println!("{name}: {}", serde_json::to_string(r).unwrap());
    assert_eq!(r.layers, 5);
    assert!(r.silhouette_pixels > 500, "{name}: {r:?}");
    assert!(
        r.rms_layered < r.rms_single,
        "{name}: layered {} is not closer than single {}",
        r.rms_layered,
        r.rms_single
    );
    // The single surface at one sample per pixel really aliases.
    assert!(r.rms_single > 0.02);
    let m = c.montage();
    assert_eq!((m.width, m.height), (3 * 128 + 8, 128));
}

#[test]
fn layered_bolt_is_closer_to_the_reference() {
    check(&CsgSolid::new(bolt()).unwrap(), "bolt");
}

#[test]
fn layered_bunny_is_closer_to_the_reference() {
    let Some(solid) = common::bunny_solid("layered_bunny_is_closer_to_the_reference") else {
        return;
    };
    check(&solid, "bunny");
}
