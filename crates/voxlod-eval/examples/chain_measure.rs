//! A budget chain as `voxlod lod --triangles B1,B2,…` makes it, beside the same budgets each
//! asked alone (as `voxlod evaluate` asks them) and beside meshoptimizer's `simplify` and
//! `simplifySloppy` at each budget: two-sided Hausdorff and mean distance (100 000 samples a
//! side, `voxlod compare`'s measure) and the silhouette difference over 14 views of 256²
//! (`evaluate`'s), each in % (distances of the input's diagonal).
//!
//! Usage: `cargo run --release -p voxlod-eval --example chain_measure -- MESH B1,B2,…`

use voxlod::core::{PolyMesh, TriangleMesh};
use voxlod::portfolio::{levels, PortfolioOptions};
use voxlod::render::SilhouetteReference;
use voxlod::{compare, CompareOptions};

type Res<T> = Result<T, Box<dyn std::error::Error>>;

fn main() -> Res<()> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 3 {
        return Err("usage: chain_measure MESH B1,B2,...".into());
    }
    let input = voxlod::read_mesh(&args[1])?;
    let budgets = (args[2].split(','))
        .map(|b| b.trim().parse::<usize>())
        .collect::<Result<Vec<_>, _>>()?;
    let reference = SilhouetteReference::new(&input, 14, 256)?;
    let row = |name: String, level: &TriangleMesh| -> Res<()> {
        let d = compare(&input, level, &CompareOptions::default())?.distance;
        let s = reference.difference(&PolyMesh::from(level.clone()))?;
        println!(
            "{name:24} {:>7} triangles  Hausdorff {:.3} %  mean {:.3} %  silhouette {:.2} %",
            level.triangles.len(),
            100.0 * d.hausdorff_fraction,
            100.0 * d.mean_fraction,
            100.0 * s.fraction
        );
        Ok(())
    };
    let chain = levels(&input, &PortfolioOptions::for_triangles(&budgets))?;
    for level in &chain.levels {
        row(format!("chain @{}", level.report.budget), &level.mesh)?;
    }
    for &b in &budgets {
        let alone = levels(&input, &PortfolioOptions::for_triangles(&[b]))?;
        row(format!("alone @{b}"), &alone.levels[0].mesh)?;
        row(
            format!("simplify @{b}"),
            &voxlod::quadric::simplify_unchecked(&input, b, false)?.0,
        )?;
        row(
            format!("sloppy @{b}"),
            &voxlod::quadric::simplify_sloppy(&input, b)?,
        )?;
    }
    Ok(())
}
