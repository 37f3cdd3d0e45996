//! The paper's claim, measured: near silhouettes, the layered shells at one sample per pixel are
//! closer to the 16×16-supersampled single surface than the single surface at one sample per
//! pixel is — for the bolt-like CSG part and for the bunny.

use voxlod::layers::bolt;
use voxlod::sampling::{CsgSolid, MeshSolid, Solid};
use voxlod_eval::antialias::{compare_antialiasing, CompareOptions};
use voxlod_testkit::data::shared_data_or_skip;

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
    let Some(path) = shared_data_or_skip(
        "meshes/stanford-bunny.obj",
        "layered_bunny_is_closer_to_the_reference",
    ) else {
        return;
    };
    let mesh = voxlod::io::read_mesh(&path).unwrap().mesh;
    check(&MeshSolid::new(&mesh).unwrap(), "bunny");
}
