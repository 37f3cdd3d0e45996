//! The genus along the pyramid of every shared mesh and of the CT head (thresholded at 1500,
//! the bone), plain and made monotone (beyond the paper; `voxlod_sampling::monotone_topology`).
//! Ignored by default (minutes on two cores); run with
//! `cargo test -p voxlod-sampling --test monotone_real_data -- --ignored --nocapture`, and set
//! `VOXLOD_MONOTONE_RESOLUTION` (default 128) for the finest level. Skips with a printed reason
//! when `../shared/data` is absent.

use std::path::Path;

use voxlod_core::TriangleMesh;
use voxlod_sampling::{
    filtered_density, plan_levels, Filter, MeshSolid, MonotoneChain, MonotoneOptions,
    PyramidOptions, Solid, ThresholdSolid,
};
use voxlod_testkit::data::shared_meshes;
use voxlod_testkit::readers::{read_ascii_stl, read_obj};
use voxlod_testkit::volumes::shared_ct_head;

fn finest() -> usize {
    std::env::var("VOXLOD_MONOTONE_RESOLUTION")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(128)
}

/// Plain and monotone genus per level of `solid`'s six-level hyper-cone pyramid.
fn genus_sequences(solid: &dyn Solid) -> (Vec<u64>, Vec<u64>) {
    let pyramid = PyramidOptions::halving(finest(), 6, Filter::Hypercone);
    let plans = plan_levels(&solid.bounds(), &pyramid).unwrap();
    let (mut raw, mut monotone) = (Vec::new(), Vec::new());
    let mut chain = MonotoneChain::new(MonotoneOptions::default());
    for plan in &plans {
        let filter = plan.density_options(&pyramid);
        let (density, _) = filtered_density(solid, &plan.grid, &filter).unwrap();
        let (_, record) = chain.next(&density, 0.5, &filter).unwrap();
        raw.push(record.raw.genus);
        monotone.push(record.result.genus);
    }
    assert!(monotone.windows(2).all(|w| w[1] <= w[0]), "{monotone:?}");
    (raw, monotone)
}

fn read_mesh(path: &Path) -> Option<TriangleMesh> {
    match path.extension()?.to_str()? {
        "obj" => Some(read_obj(path)),
        "stl" => Some(read_ascii_stl(path)),
        _ => None,
    }
}

#[test]
#[ignore = "minutes on two cores: the genus sequences of the shared data"]
fn genus_sequences_of_the_shared_data() {
    for path in shared_meshes("genus_sequences_of_the_shared_data") {
        let Some(mesh) = read_mesh(&path) else {
            eprintln!("{}: not read here (OBJ and STL only)", path.display());
            continue;
        };
        let solid = MeshSolid::new(&mesh).unwrap();
        let (raw, monotone) = genus_sequences(&solid);
        let name = path.file_name().unwrap().to_string_lossy();
        eprintln!("{name}: plain {raw:?} monotone {monotone:?}");
    }
    let Some(volume) = shared_ct_head("genus_sequences_of_the_shared_data") else {
        return;
    };
    let solid = ThresholdSolid::new(&volume, 1500.0).unwrap();
    let (raw, monotone) = genus_sequences(&solid);
    eprintln!("CT head at 1500: plain {raw:?} monotone {monotone:?}");
}
