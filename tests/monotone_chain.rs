//! `voxlod::lod`'s default chain never gains handles (beyond the paper, see
//! `voxlod_sampling::monotone_topology`): on generated hollow shells and a thin wall whose plain
//! pyramid perforates as the filter grows, every level has at most the genus of the level above,
//! each level reports the handles removed and the components gained or lost, and every level is
//! still a closed, outward-facing manifold without crossing triangles.

use voxlod::core::glam::DVec3;
use voxlod::sampling::{CsgSolid, Filter, PyramidOptions, Shape};
use voxlod::{Finest, Lod, LodOptions, Source};
use voxlod_testkit::intersections::self_intersections;

/// The chain of `shape` at `resolutions` (hyper-cone of one voxel), with the default rules or
/// plain (`monotone: None`).
fn chain(shape: &Shape, resolutions: &[usize], monotone: bool) -> Lod {
    let solid = CsgSolid::new(shape.clone()).unwrap();
    let defaults = LodOptions::default();
    let options = LodOptions {
        pyramid: PyramidOptions::for_resolutions(resolutions.to_vec(), Filter::Hypercone),
        finest: Finest::Given,
        monotone: defaults.monotone.filter(|_| monotone),
        ..defaults
    };
    voxlod::lod(&Source::Solid(&solid), &options).unwrap()
}

fn genera(lod: &Lod) -> Vec<i64> {
    (lod.levels.iter())
        .map(|l| l.topology.genus.expect("an oriented closed manifold"))
        .collect()
}

/// The plain chain gains a handle somewhere; the default one never does, says so per level,
/// and every level is clean.
fn check_never_rises(name: &str, shape: Shape, resolutions: &[usize]) -> Lod {
    let plain = genera(&chain(&shape, resolutions, false));
    let lod = chain(&shape, resolutions, true);
    let kept = genera(&lod);
    eprintln!("{name}: plain genus {plain:?}, monotone {kept:?}");
    assert!(
        plain.windows(2).any(|w| w[1] > w[0]),
        "{name}: the plain chain should perforate: {plain:?}"
    );
    assert!(
        kept.windows(2).all(|w| w[1] <= w[0]),
        "{name}: genus rises: {kept:?}"
    );
    assert_eq!(kept[0], plain[0], "{name}: the first level is untouched");
    for (k, level) in lod.levels.iter().enumerate() {
        let t = &level.topology;
        assert!(
            t.is_closed_manifold() && t.is_consistently_oriented(),
            "{name} level {k}: {t:?}"
        );
        assert!(level.mesh.signed_volume() > 0.0, "{name} level {k}");
        assert!(
            self_intersections(&level.mesh).is_empty(),
            "{name} level {k}: crossing triangles"
        );
        let record = level.monotone.expect("every level has its record");
        assert_eq!(record.result.genus as i64, kept[k], "{name} level {k}");
        assert_eq!(record.result.surfaces() as usize, t.components);
        if k > 0 {
            let above = &lod.levels[k - 1].topology;
            assert_eq!(record.handles_removed as i64, kept[k - 1] - kept[k]);
            assert_eq!(
                record.surfaces_gained,
                t.components as i64 - above.components as i64
            );
        }
    }
    let prevented: u64 = lod
        .levels
        .iter()
        .map(|l| l.monotone.unwrap().handles_prevented)
        .sum();
    assert!(prevented > 0, "{name}: no perforation was prevented");
    lod
}

#[test]
fn a_thin_hollow_box_closes_up_instead_of_perforating() {
    let outer = Shape::cuboid(DVec3::splat(-1.0), DVec3::splat(1.0));
    let inner = Shape::cuboid(DVec3::splat(-0.94), DVec3::splat(0.94));
    let resolutions = [96, 64, 48, 40, 32, 24, 16, 12];
    let lod = check_never_rises("hollow box", outer.minus(inner), &resolutions);
    // The finest level is the hollow box: its outside and its cavity, no handle; the coarsest
    // is one solid block, the cavity filled (a component lost on the way).
    let first = &lod.levels[0].topology;
    assert_eq!((first.genus, first.components), (Some(0), 2));
    let last = &lod.levels.last().unwrap().topology;
    assert_eq!((last.genus, last.components), (Some(0), 1));
    assert!(lod
        .levels
        .iter()
        .any(|l| l.monotone.unwrap().surfaces_gained == -1));
}

#[test]
fn a_thin_hollow_sphere_never_gains_handles() {
    let outer = Shape::sphere(DVec3::ZERO, 1.0);
    let inner = Shape::sphere(DVec3::ZERO, 0.93);
    let resolutions = [96, 72, 56, 44, 36, 28, 20, 14, 10];
    let lod = check_never_rises("hollow sphere", outer.minus(inner), &resolutions);
    let last = &lod.levels.last().unwrap().topology;
    assert_eq!((last.genus, last.components), (Some(0), 1));
}

#[test]
fn a_thin_wall_does_not_perforate() {
    // A plate 0.12 thick with a spherical dimple from above leaving 0.03 at its centre.
    let plate = Shape::cuboid(DVec3::new(-1.0, -1.0, -0.06), DVec3::new(1.0, 1.0, 0.06));
    let dimple = Shape::sphere(DVec3::new(0.0, 0.0, 0.39), 0.42);
    let resolutions = [128, 96, 72, 56, 44, 36, 28];
    let lod = check_never_rises("thin wall", plate.minus(dimple), &resolutions);
    assert!(lod.levels.iter().all(|l| l.topology.genus == Some(0)));
}
