//! The voxel paper's Table 2 regenerated on our own CSG mechanical part (a plate with a boss,
//! a counterbored through-bore, a cross hole, bolt holes, small holes and a notch; see
//! `voxlod_eval::paper_tables::mechanical_part`), Gaussian filter, at 200×200×120 down to 5×5×3,
//! our triangle counts and genus beside the paper's counts.
//!
//!     cargo run --release -p voxlod --example table2_mechanical_part [-- OUT_DIR]
//!
//! With OUT_DIR, each level is written there as `table2-a.ply`, `table2-b.ply`, …

use voxlod::lod::LodSource;
use voxlod::sampling::CsgSolid;
use voxlod_eval::paper_tables::{mechanical_part, output_folder, reproduce_and_print, table2};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // An empty or "-" folder writes nothing.
    let output = output_folder(std::env::args().nth(1));
    let solid = CsgSolid::new(mechanical_part())?;
    let table = table2();
    println!(
        "Table 2 of He et al. (1995): {} (ours: 100 x 100 x 60 mm, genus 11), {} filter, radius \
         one voxel per level, iso 0.5\n",
        table.object,
        table.filter.name()
    );
    reproduce_and_print(&LodSource::Solid(&solid), &table, output.as_deref())?;
    Ok(())
}
