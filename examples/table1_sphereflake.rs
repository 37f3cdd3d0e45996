//! The voxel paper's Table 1 regenerated: the 820-sphere sphereflake, Gaussian filter, at
//! 200³, 100³, 50³, 30³, 15³ and 5³, our triangle counts beside the paper's (the same run as
//! `voxlod demo`, through the library).
//!
//!     cargo run --release -p voxlod --example table1_sphereflake [-- OUT_DIR]
//!
//! With OUT_DIR, each level is written there as `table1-a.ply`, `table1-b.ply`, …

use voxlod::lod::LodSource;
use voxlod::sampling::{sphereflake, CsgSolid};
use voxlod_eval::paper_tables::{output_folder, reproduce_and_print, table1};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // An empty or "-" folder writes nothing.
    let output = output_folder(std::env::args().nth(1));
    let solid = CsgSolid::new(sphereflake(3))?;
    let table = table1();
    println!(
        "Table 1 of He et al. (1995): {}, {} filter, radius one voxel per level, iso 0.5\n",
        table.object,
        table.filter.name()
    );
    reproduce_and_print(&LodSource::Solid(&solid), &table, output.as_deref())?;
    Ok(())
}
