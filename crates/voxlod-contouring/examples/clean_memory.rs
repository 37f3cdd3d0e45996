//! Peak memory of cleaning (`clean_mesh`), in bytes per input triangle beyond what was resident
//! before (the input mesh included there): the sphereflake field at 192³ contoured, then cleaned
//! with the defaults. What `clean_mesh::CLEAN_BYTES_PER_TRIANGLE` must stay above. Linux only:
//! it reads `/proc/self/status` after resetting the peak through `/proc/self/clear_refs`, and
//! says so and stops where it cannot.
//!
//!     cargo run --release -p voxlod-contouring --example clean_memory

use voxlod_contouring::{clean_mesh, marching_cubes, CleanOptions, ContourOptions};
use voxlod_testkit::fields::sphereflake_field;

/// A field of `/proc/self/status` in KiB (`VmRSS:`, `VmHWM:`).
fn status(field: &str) -> Option<u64> {
    let text = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = text.lines().find(|l| l.starts_with(field))?;
    line.split_whitespace().nth(1)?.parse::<u64>().ok()
}

fn main() {
    let volume = sphereflake_field(192).expect("the sphereflake field");
    let mesh = marching_cubes(&volume, &ContourOptions::at(0.0)).expect("a level");
    let cell = volume.grid.spacing[0];
    drop(volume);
    if std::fs::write("/proc/self/clear_refs", "5").is_err() {
        eprintln!("cannot reset the peak resident size (/proc/self/clear_refs): nothing measured");
        return;
    }
    let (Some(before), Some(_)) = (status("VmRSS:"), status("VmHWM:")) else {
        eprintln!("no /proc/self/status: nothing measured");
        return;
    };
    let (clean, _) = clean_mesh(&mesh, cell, &CleanOptions::default()).expect("cleaning");
    let peak = status("VmHWM:").expect("the peak resident size");
    println!(
        "{} triangles -> {}: peak {} KiB over {} KiB resident, {:.0} bytes per triangle",
        mesh.triangles.len(),
        clean.triangles.len(),
        peak,
        before,
        peak.saturating_sub(before) as f64 * 1024.0 / mesh.triangles.len() as f64
    );
}
