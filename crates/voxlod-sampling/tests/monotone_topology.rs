//! Topology that only simplifies along a pyramid (beyond the paper; see
//! `voxlod_sampling::monotone_topology`): the digital genus is marching cubes' genus, the guard
//! never opens a tunnel, hollow shells and thin plates close up instead of perforating, and a
//! hole that the filter fills legitimately still drops the genus.

use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use voxlod_contouring::{marching_cubes, tables::tables, ContourOptions};
use voxlod_core::{mesh_topology, Axis, Grid, Volume};
use voxlod_sampling::digital_topology::{digital_topology, local_numbers};
use voxlod_sampling::monotone_topology::MonotoneStage;
use voxlod_sampling::{
    filtered_density, monotone_level, plan_levels, CsgSolid, Filter, LevelShape, MonotoneChain,
    MonotoneOptions, PyramidOptions, Shape, TopologyRecord,
};

/// Marching cubes' genus, components and closedness of `volume` at `iso`.
fn contoured(volume: &Volume, iso: f32) -> (i64, usize) {
    let mesh = marching_cubes(volume, &ContourOptions::geometry_only(iso)).unwrap();
    let t = mesh_topology(&mesh);
    assert!(
        t.is_closed_manifold() && t.is_consistently_oriented(),
        "{t:?}"
    );
    (t.genus.expect("an oriented manifold"), t.components)
}

/// A random binary volume with an outside border, as 0/1 densities.
fn random_volume(rng: &mut Pcg64, n: usize, fill: f64) -> Volume {
    let grid = Grid::unit([n, n, n]).unwrap();
    let values = (0..grid.len())
        .map(|i| {
            let (x, y, z) = (i % n, (i / n) % n, i / (n * n));
            let border = [x, y, z].iter().any(|&c| c == 0 || c == n - 1);
            (!border && rng.random_bool(fill)) as u8 as f32
        })
        .collect();
    Volume::from_vec(grid, values).unwrap()
}

fn inside_of(volume: &Volume) -> Vec<bool> {
    volume.as_slice().iter().map(|&v| v >= 0.5).collect()
}

#[test]
fn loop_counts_agree_with_the_marching_cubes_tables() {
    // Every case's loops from a one-cell volume: digital χ against the table's loops.
    let t = tables();
    for case in 1..255usize {
        let grid = Grid::unit([4, 4, 4]).unwrap();
        let mut values = vec![0.0f32; 64];
        for c in 0..8 {
            if case >> c & 1 == 1 {
                values[grid.index(1 + (c & 1), 1 + (c >> 1 & 1), 1 + (c >> 2 & 1))] = 1.0;
            }
        }
        let volume = Volume::from_vec(grid, values).unwrap();
        let (genus, components) = contoured(&volume, 0.5);
        let d = digital_topology(grid.dims, &inside_of(&volume)).unwrap();
        assert_eq!(d.genus as i64, genus, "case {case}");
        assert_eq!(d.surfaces() as usize, components, "case {case}");
        assert!(t.loop_count[case] >= 1);
    }
}

#[test]
fn digital_topology_is_marching_cubes_topology_on_random_volumes() {
    let mut rng = Pcg64::seed_from_u64(12);
    let mut handles = 0;
    for round in 0..300 {
        let fill = [0.3, 0.5, 0.7][round % 3];
        let volume = random_volume(&mut rng, 8, fill);
        let (genus, components) = contoured(&volume, 0.5);
        let d = digital_topology(volume.grid.dims, &inside_of(&volume)).unwrap();
        assert_eq!(d.genus as i64, genus, "round {round}");
        assert_eq!(d.surfaces() as usize, components, "round {round}");
        handles += genus;
    }
    assert!(
        handles > 100,
        "the random volumes should have handles, got {handles}"
    );
}

#[test]
fn guarded_flips_never_add_a_handle_and_simple_flips_change_nothing() {
    let mut rng = Pcg64::seed_from_u64(7);
    let (mut simple, mut guarded) = (0, 0);
    for _ in 0..60 {
        let volume = random_volume(&mut rng, 7, 0.5);
        let dims = volume.grid.dims;
        let mut inside = inside_of(&volume);
        let mut before = digital_topology(dims, &inside).unwrap();
        for _ in 0..40 {
            let i = rng.random_range(0..inside.len());
            let p = [i % 7, (i / 7) % 7, i / 49];
            if p.iter().any(|&c| c == 0 || c == 6) {
                continue;
            }
            let local = local_numbers(dims, &inside, i);
            let allowed = if inside[i] {
                local.outside == 1
            } else {
                local.inside <= 1
            };
            if !allowed {
                continue;
            }
            inside[i] = !inside[i];
            let after = digital_topology(dims, &inside).unwrap();
            let values = inside.iter().map(|&s| s as u8 as f32).collect();
            let (genus, _) = contoured(&Volume::from_vec(volume.grid, values).unwrap(), 0.5);
            assert_eq!(after.genus as i64, genus);
            assert!(after.genus <= before.genus, "{before:?} -> {after:?}");
            if local.is_simple() {
                assert_eq!(after, before, "a simple flip changed the topology");
                simple += 1;
            }
            guarded += 1;
            before = after;
        }
    }
    assert!(
        simple > 100 && guarded > simple,
        "{simple} simple of {guarded}"
    );
}

/// Levels of `shape` at `resolutions` (radius one voxel, hyper-cone), each made monotone.
/// Returns the records and checks each level's contour against its record.
fn chain(shape: Shape, resolutions: &[usize], options: &MonotoneOptions) -> Vec<TopologyRecord> {
    let solid = CsgSolid::new(shape).unwrap();
    let pyramid = PyramidOptions::for_resolutions(resolutions.to_vec(), Filter::Hypercone);
    let plans = plan_levels(&voxlod_sampling::Solid::bounds(&solid), &pyramid).unwrap();
    let mut previous: Option<LevelShape> = None;
    let mut records = Vec::new();
    for plan in &plans {
        let (density, _) =
            filtered_density(&solid, &plan.grid, &plan.density_options(&pyramid)).unwrap();
        let filter = plan.density_options(&pyramid);
        let level = monotone_level(&density, 0.5, &filter, previous.as_ref(), options).unwrap();
        let (genus, components) = contoured(&level.volume, 0.5);
        assert_eq!(
            genus, level.record.result.genus as i64,
            "{:?}",
            level.record
        );
        assert_eq!(components, level.record.result.surfaces() as usize);
        records.push(level.record);
        previous = Some(level.shape);
    }
    records
}

fn genera(records: &[TopologyRecord], raw: bool) -> Vec<u64> {
    records
        .iter()
        .map(|r| if raw { r.raw.genus } else { r.result.genus })
        .collect()
}

fn assert_never_rises(records: &[TopologyRecord]) {
    let g = genera(records, false);
    assert!(g.windows(2).all(|w| w[1] <= w[0]), "genus rises: {g:?}");
}

fn raw_rises(records: &[TopologyRecord]) -> bool {
    records
        .windows(2)
        .any(|w| w[1].raw.genus > w[0].result.genus)
}

/// The chain of a shape whose plain levels perforate: prints both genus sequences and checks
/// that the plain chain rises somewhere and the monotone one never does.
fn perforating_chain(shape: Shape, resolutions: &[usize]) -> Vec<TopologyRecord> {
    let records = chain(shape, resolutions, &MonotoneOptions::default());
    eprintln!("raw genus {:?}", genera(&records, true));
    eprintln!("monotone  {:?}", genera(&records, false));
    assert!(raw_rises(&records), "the plain chain should perforate");
    assert_never_rises(&records);
    records
}

#[test]
fn a_thin_hollow_box_closes_up_instead_of_perforating() {
    let outer = Shape::cuboid(DVec3::splat(-1.0), DVec3::splat(1.0));
    let inner = Shape::cuboid(DVec3::splat(-0.94), DVec3::splat(0.94));
    let resolutions = [96, 64, 48, 40, 32, 24, 16, 12];
    let records = perforating_chain(outer.minus(inner), &resolutions);
    // The finest level is the hollow box: one component, one cavity, no handle.
    let first = records[0].result;
    assert_eq!((first.genus, first.components, first.cavities), (0, 1, 1));
    // Every level is one solid without handles, and the cavity closed up at some level.
    for r in &records {
        assert_eq!((r.result.genus, r.result.components), (0, 1), "{r:?}");
    }
    let last = records.last().unwrap();
    assert_eq!(last.result.cavities, 0);
    assert!(records.iter().any(|r| r.samples_filled > 0));
}

#[test]
fn a_thin_hollow_sphere_never_gains_handles_and_ends_solid() {
    let outer = Shape::sphere(DVec3::ZERO, 1.0);
    let inner = Shape::sphere(DVec3::ZERO, 0.93);
    let resolutions = [96, 72, 56, 44, 36, 28, 20, 14, 10];
    let records = perforating_chain(outer.minus(inner), &resolutions);
    assert_eq!(records[0].result.cavities, 1);
    let last = records.last().unwrap().result;
    assert_eq!((last.genus, last.components, last.cavities), (0, 1, 0));
}

#[test]
fn a_plate_with_a_thin_spot_does_not_perforate() {
    // A plate 0.12 thick with a spherical dimple from above leaving 0.03 at its centre.
    let plate = Shape::cuboid(DVec3::new(-1.0, -1.0, -0.06), DVec3::new(1.0, 1.0, 0.06));
    let dimple = Shape::sphere(DVec3::new(0.0, 0.0, 0.39), 0.42);
    let resolutions = [128, 96, 72, 56, 44, 36, 28];
    let records = perforating_chain(plate.minus(dimple), &resolutions);
    assert_eq!(records[0].result.genus, 0);
    assert!(records.iter().any(|r| r.samples_kept_inside > 0));
}

#[test]
fn a_washer_loses_its_hole_as_the_filter_grows() {
    let disc = Shape::cylinder(DVec3::ZERO, Axis::Z, 1.0, 0.25);
    let hole = Shape::cylinder(DVec3::ZERO, Axis::Z, 0.12, 1.0);
    let resolutions = [64, 32, 16, 8];
    let records = chain(disc.minus(hole), &resolutions, &MonotoneOptions::default());
    eprintln!("raw genus {:?}", genera(&records, true));
    assert_eq!(genera(&records, false), genera(&records, true));
    let g = genera(&records, false);
    assert_eq!((g[0], *g.last().unwrap()), (1, 0), "{g:?}");
    let dropped = records.iter().find(|r| r.handles_removed == 1).unwrap();
    assert_eq!(dropped.stage, MonotoneStage::Unchanged);
    assert_eq!(dropped.handles_prevented, 0);
}

#[test]
fn the_first_level_is_untouched_and_bad_input_is_refused() {
    let grid = Grid::unit([6, 6, 6]).unwrap();
    let mut values = vec![0.0f32; grid.len()];
    values[grid.index(2, 2, 2)] = 1.0;
    values[grid.index(3, 2, 2)] = f32::NAN;
    let volume = Volume::from_vec(grid, values).unwrap();
    let filter = voxlod_sampling::DensityOptions::new(Filter::Hypercone, 1.0);
    let options = MonotoneOptions::default();
    let level = monotone_level(&volume, 0.5, &filter, None, &options).unwrap();
    assert_eq!(level.volume.as_slice()[..5], volume.as_slice()[..5]);
    assert_eq!(level.record.stage, MonotoneStage::Unchanged);
    assert_eq!(level.record.result.components, 1);
    let err = monotone_level(&volume, f32::NAN, &filter, None, &options).unwrap_err();
    assert!(err.to_string().contains("isodensity NaN"), "{err}");
}

/// The pyramids of a thin hollow sphere (its cavity filled) and of a plate with a thin spot
/// (its perforation guarded) through two chains each, one given each level's density by
/// reference (`next`), one by value (`next_owned`, no copy): the same volumes bit for bit and
/// the same records at every level, and both rules acted.
#[test]
fn a_chain_of_owned_levels_is_the_chain_of_borrowed_ones() {
    let shell = Shape::sphere(DVec3::ZERO, 1.0).minus(Shape::sphere(DVec3::ZERO, 0.93));
    let plate = Shape::cuboid(DVec3::new(-1.0, -1.0, -0.06), DVec3::new(1.0, 1.0, 0.06));
    let dimpled = plate.minus(Shape::sphere(DVec3::new(0.0, 0.0, 0.39), 0.42));
    let (mut filled, mut kept) = (0, 0);
    for (shape, resolutions) in [
        (shell, vec![96, 72, 56, 44, 36, 28, 20, 14, 10]),
        (dimpled, vec![128, 96, 72, 56, 44, 36, 28]),
    ] {
        let solid = CsgSolid::new(shape).unwrap();
        let pyramid = PyramidOptions::for_resolutions(resolutions, Filter::Hypercone);
        let plans = plan_levels(&voxlod_sampling::Solid::bounds(&solid), &pyramid).unwrap();
        let mut borrowed = MonotoneChain::new(MonotoneOptions::default());
        let mut owned = MonotoneChain::new(MonotoneOptions::default());
        for plan in &plans {
            let filter = plan.density_options(&pyramid);
            let (density, _) = filtered_density(&solid, &plan.grid, &filter).unwrap();
            let (by_ref, record) = borrowed.next(&density, 0.5, &filter).unwrap();
            let (by_value, owned_record) = owned.next_owned(density, 0.5, &filter).unwrap();
            assert_eq!(owned_record, record, "level {}", plan.level);
            assert_eq!(by_value.grid, by_ref.grid);
            let bits =
                |v: &Volume| -> Vec<u32> { v.as_slice().iter().map(|x| x.to_bits()).collect() };
            assert!(bits(&by_value) == bits(&by_ref), "level {}", plan.level);
            filled += record.samples_filled;
            kept += record.samples_kept_inside + record.samples_kept_outside;
        }
    }
    assert!(filled > 0 && kept > 0, "filled {filled}, kept {kept}");
}
