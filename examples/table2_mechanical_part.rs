//! The voxel paper's Table 2 regenerated on our own CSG mechanical part (a plate with a boss,
//! a counterbored through-bore, a cross hole, bolt holes, small holes and a notch; see
//! `voxlod::paper_tables::mechanical_part`), Gaussian filter, at 200×200×120 down to 5×5×3,
//! our triangle counts and genus beside the paper's counts.
//!
//!     cargo run --release --example table2_mechanical_part [-- OUT_DIR]
//!
//! With OUT_DIR, each level is written there as `table2-a.ply`, `table2-b.ply`, …

use std::path::PathBuf;

use voxlod::lod::LodSource;
use voxlod::paper_tables::{format_rows, mechanical_part, reproduce, table2, write_level};
use voxlod::sampling::CsgSolid;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // An empty or "-" folder writes nothing.
    let output = std::env::args()
        .nth(1)
        .filter(|d| !d.is_empty() && d != "-")
        .map(PathBuf::from);
    let solid = CsgSolid::new(mechanical_part())?;
    let table = table2();
    println!(
        "Table 2 of He et al. (1995): {} (ours: 100 x 100 x 60 mm, genus 11), {} filter, radius \
         one voxel per level, iso 0.5\n",
        table.object,
        table.filter.name()
    );
    let mut failure = None;
    let rows = reproduce(&LodSource::Solid(&solid), &table, 0.5, |row, level| {
        if let Some(dir) = &output {
            if let Err(e) = write_level(dir, &table, row, level) {
                failure.get_or_insert(e);
            }
        }
    })?;
    print!("{}", format_rows(&rows));
    match failure {
        Some(e) => Err(e.into()),
        None => Ok(()),
    }
}
